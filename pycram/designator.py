"""Designators (thesis ch. 3.3), under the thesis' import path ``pycram.designator``.

A public face: the designators live in the :mod:`pycram.designators` package, one module per
kind (``core``: the ``Designator`` API, errors, ``GeneratorList``; ``motion``, ``object``,
``location``, ``action``), and :func:`perform` in :mod:`pycram.execution.perform`.
"""

from pycram.designators import *  # noqa: F401,F403
from pycram.designators import __all__ as _designators_all
from pycram.execution.perform import perform

__all__ = [*_designators_all, "perform"]
