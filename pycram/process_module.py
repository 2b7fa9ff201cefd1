"""Process modules: the only place that talks to hardware or the simulator (thesis ch. 3.4).

A public face: the implementation is :mod:`pycram.execution.process_module`.
"""

from pycram.execution.process_module import *  # noqa: F401,F403
from pycram.execution.process_module import __all__  # noqa: F401
