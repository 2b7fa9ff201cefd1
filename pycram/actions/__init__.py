"""Robot-agnostic plans that use designators only (the actions layer): today `search_for`."""

from pycram.actions.search import Lookout, ObjectNotFound, look_around, lookouts, search_for

__all__ = ["Lookout", "ObjectNotFound", "look_around", "lookouts", "search_for"]
