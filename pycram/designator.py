"""Designators (thesis ch. 3.3), under the thesis' import path ``pycram.designator``.

The implementation lives in the :mod:`pycram.designators` package, one module per kind:
``core`` (the ``Designator`` API, errors, ``GeneratorList``), ``motion``, ``object``,
``location``, ``action`` and ``perform``.
"""

from pycram.designators import *  # noqa: F401,F403
from pycram.designators import __all__  # noqa: F401
