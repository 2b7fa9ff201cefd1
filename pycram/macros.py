"""The thesis' block syntax (`with par:` ...) compiled to the plan language's functional forms.

A public face: the implementation is :mod:`pycram.core.macros`.
"""

from pycram.core.macros import *  # noqa: F401,F403
from pycram.core.macros import __all__  # noqa: F401
