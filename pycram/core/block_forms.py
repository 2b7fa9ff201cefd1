"""Placeholders for the thesis' block syntax when it is not switched on.

`with par(errors) as s:` only means "run each statement as a branch" after PyCRAM's block
syntax has rewritten the code (see `pycram.macros`). Without that rewrite Python would simply
call `par(errors)` and run the block once, sequentially — silently wrong. So the expression
objects and `whenever(fluent)` refuse to be used as context managers and say how to switch
the syntax on.
"""

from __future__ import annotations

from typing import Generic, Literal, TypeVar

__all__ = ["BlockSyntaxNotEnabled", "BlockForm", "NOT_ENABLED_MESSAGE", "BRANCHES"]

#: The error text when block syntax is used without being switched on; ``{form}`` is the block's form.
NOT_ENABLED_MESSAGE = (
    "`with {form}:` is PyCRAM block syntax, which is not switched on for this code. "
    "Switch it on in one of three ways: decorate the enclosing function with "
    "`@plan` (from pycram.language import plan); run the script with "
    "`pycram run FILE.py` or `python -m pycram FILE.py`; or `import pycram.activate` "
    "before importing the module that holds the plan. Without it the block would run "
    "sequentially as plain Python, so PyCRAM refuses to run it."
)


class BlockSyntaxNotEnabled(RuntimeError):
    """A block form (`with par(...)`, `with whenever(...)`, ...) ran without the block syntax."""

    def __init__(self, form: str) -> None:
        super().__init__(NOT_ENABLED_MESSAGE.format(form=form))
        self.form = form


_Bound = TypeVar("_Bound")


class BlockForm(Generic[_Bound]):
    """Mixin: objects that are only meaningful as the head of a rewritten `with` block.

    The type argument is what `with form as x:` binds once the block syntax has rewritten the
    block (an expression's state fluent, say), so that type checkers read block-syntax plans
    right; without the rewrite `__enter__` only raises.
    """

    _block_form_name = "block"

    def __enter__(self) -> _Bound:
        raise BlockSyntaxNotEnabled(self._block_form_name)

    def __exit__(self, *exc_info: object) -> Literal[False]:
        return False


BRANCHES: dict[tuple[str, str], tuple[str | None, str]] = {}
"""What the block syntax knows about each branch it generated, for naming its task: keyed by
(file name, code name of the branch function, e.g. `par@plan.py:12#1`), the value is (what the
branch does — the callee of a branch that is a single call, e.g. `grab_item` or `perform
moving`, else None — and where it is, e.g. `plan.py:13`). Filled when plans are compiled."""
