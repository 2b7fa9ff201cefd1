"""Typed failures of plans, actions and process modules.

A public face: the implementation is :mod:`pycram.execution.failures`.
"""

from pycram.execution.failures import *  # noqa: F401,F403
from pycram.execution.failures import __all__  # noqa: F401
