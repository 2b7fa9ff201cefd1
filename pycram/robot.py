"""Robots: one bundle of resolvers and process modules per robot, and which robot is active.

A public face: :class:`Robot` lives in :mod:`pycram.execution.robot`, the resolver sets it
builds on in :mod:`pycram.designators.resolvers`.
"""

from pycram.execution.robot import *  # noqa: F401,F403
from pycram.execution.robot import __all__  # noqa: F401
