"""The task runtime: tasks, evaporation, suspension, tags, clocks and worker threads.

A public face: the implementation is :mod:`pycram.core.runtime` (one module per concept).
"""

from pycram.core.runtime import *  # noqa: F401,F403
from pycram.core.runtime import __all__  # noqa: F401
