"""Location reasoning: where to stand, where to look, where to put things.

A public face: the implementation is :mod:`pycram.reasoning.locations`.
"""

from pycram.reasoning.locations import *  # noqa: F401,F403
from pycram.reasoning.locations import __all__  # noqa: F401
