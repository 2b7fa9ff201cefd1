"""The core layer: fluents, the task runtime (:mod:`pycram.core.runtime`), the plan language's
expressions, partial orders and policies, and the thesis' block syntax (macros and activation).

May import: the standard library only -- no third-party package and no other pycram layer, and
nothing happens at import time. Users import it through the public faces :mod:`pycram.language`,
:mod:`pycram.fluent`, :mod:`pycram.runtime` and :mod:`pycram.macros`.
"""
