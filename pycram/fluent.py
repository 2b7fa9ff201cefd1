"""Fluents: observable values, networks of them, and pulses (thesis ch. 3.2.2).

A public face: the implementation is :mod:`pycram.core.fluent`.
"""

from pycram.core.fluent import *  # noqa: F401,F403
from pycram.core.fluent import __all__  # noqa: F401
