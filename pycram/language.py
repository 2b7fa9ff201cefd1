"""The PyCRAM plan language (thesis ch. 3.2.3): `seq`, `par`, `pursue`, `try_all`,
`try_in_order`, `failure_handling`/`retry`, `partial_order`, policies, and the block syntax's
`plan` decorator.

A public face: the expressions live in :mod:`pycram.core.expressions`, `partial_order` in
:mod:`pycram.core.partial_order`, the policies in :mod:`pycram.core.policy` and `plan` in
:mod:`pycram.core.macros` (loaded on first use: the transformer is not needed to run plans).
"""

from typing import Any

from pycram.core.expressions import *  # noqa: F401,F403
from pycram.core.expressions import __all__ as _expressions_all
from pycram.core.partial_order import *  # noqa: F401,F403
from pycram.core.partial_order import __all__ as _partial_order_all
from pycram.core.policy import *  # noqa: F401,F403
from pycram.core.policy import __all__ as _policy_all

__all__ = [*_expressions_all, *_partial_order_all, *_policy_all]


def __getattr__(name: str) -> Any:
    if name == "plan":  # the block-syntax decorator lives with the transformer
        from pycram.core.macros import plan

        return plan
    raise AttributeError(f"module 'pycram.language' has no attribute {name!r}")
