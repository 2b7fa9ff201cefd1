"""ROS 1: process modules that drive a robot over ROS, and the transport they use.

A public face: the ROS backend is :mod:`pycram.backends.ros`; importing it needs no ROS.
"""

from pycram.backends.ros import *  # noqa: F401,F403
from pycram.backends.ros import __all__  # noqa: F401
