"""The action library: robot-agnostic plans behind action designators.

Each action has a typed constructor that returns an `ActionDesignator`; `perform` runs it::

    from pycram.actions import PickUp, Place, Search
    from pycram.designator import LocationDesignator, ObjectDesignator, perform

    cup = perform(Search(ObjectDesignator(type="cup")))
    held = perform(PickUp(cup))
    perform(Place(held, LocationDesignator([("on", "table"), ("for", "cup")])))

The plans use designators, motions, fluents and the robot's belief only, so they run unchanged
on every robot (PR2: either arm; TIAGo: its one arm). They recover from failures inside (next
grasp or standing pose, perceiving again, searching again) a bounded number of times and then
raise a typed failure of `pycram.failures`. The plan for an action type can be replaced per
robot or world by an action resolver of its own (asked before the library's).

May import: core, designators, execution, world, environments and reasoning -- never a robot
package, never a backend (robot-specific numbers come from the active robot's description).
"""

from pycram.designators.action import ActionDesignator
from pycram.execution.failures import ObjectNotFound

from .basic import Detect, LookAt, MoveTorso, Navigate, ParkArms, Search, SetGripper
from .container_state import believed_open
from .containers import Close, Open
from .core import ACTION_PLANS, ActionParameterError, resolve_action
from .held import Held, held_objects
from .pick_up import PickUp
from .place import Place
from .search import Lookout, look_around, lookouts, search_for
from .transport import Transport

if resolve_action not in ActionDesignator.resolvers:
    ActionDesignator.resolvers.append(resolve_action)

__all__ = [
    "Navigate",
    "LookAt",
    "ParkArms",
    "MoveTorso",
    "SetGripper",
    "Detect",
    "Search",
    "PickUp",
    "Place",
    "Transport",
    "Open",
    "Close",
    "believed_open",
    "Held",
    "held_objects",
    "ACTION_PLANS",
    "ActionParameterError",
    "resolve_action",
    "Lookout",
    "ObjectNotFound",
    "look_around",
    "lookouts",
    "search_for",
]
