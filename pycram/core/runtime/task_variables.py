"""Task-local variables (CRAM's `define-task-variable`), with `contextvars` semantics over tasks.

A `TaskVariable` has one value per task. A task sees the value bound in itself or, failing
that, in its nearest ancestor — also across threads: the branches of `par` see what the task
that started the `par` had bound. A binding lives as long as its task (or its `with` block):
nothing a child binds is visible to its parent or its siblings, and `with var.bound(v):`
restores the previous binding on exit, even on failure or evaporation::

    speed = TaskVariable("speed", default=1.0)
    with speed.bound(0.5):
        par(move_base, move_arm)   # both branches read speed.get() == 0.5
    speed.get()                    # 1.0 again

Reads walk up the task tree (O(depth)); no locks are taken (a task's bindings are only
changed by its own thread).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, Generic, TypeVar

from pycram.core.runtime.task import Task, current_task

__all__ = ["TaskVariable"]

T = TypeVar("T")
_KEY = "_task_variables"  # key of a task's bindings in `Task.info`
_UNSET: Any = object()


class TaskVariable(Generic[T]):
    """A variable with a value per task, inherited by child tasks (see the module doc)."""

    __slots__ = ("name", "default")

    def __init__(self, name: str, default: T = _UNSET) -> None:
        self.name = name
        self.default = default

    def get(self, default: T = _UNSET) -> T:
        """The value seen by the calling task; raises `LookupError` (naming the variable) when
        neither it nor an ancestor bound one and there is no default."""
        task: Task | None = current_task()
        while task is not None:
            bindings = task.info.get(_KEY)
            if bindings is not None and self in bindings:
                value: T = bindings[self]  # bound through set/bound, which take a T
                return value
            task = task.parent
        if default is not _UNSET:
            return default
        if self.default is not _UNSET:
            return self.default
        raise LookupError(f"task variable {self.name!r} has no value in task {current_task().path} and no default")

    def set(self, value: T) -> None:
        """Bind `value` in the calling task (visible to it and to the children it starts later)."""
        task = current_task()
        bindings = task.info.get(_KEY)
        if bindings is None:
            bindings = task.info[_KEY] = {}
        bindings[self] = value

    @contextmanager
    def bound(self, value: T) -> Iterator[T]:
        """Bind `value` in the calling task for the block; the previous binding is restored on
        exit, however the block ends."""
        task = current_task()
        bindings = task.info.get(_KEY)
        if bindings is None:
            bindings = task.info[_KEY] = {}
        previous = bindings.get(self, _UNSET)
        bindings[self] = value
        try:
            yield value
        finally:
            if previous is _UNSET:
                bindings.pop(self, None)
            else:
                bindings[self] = previous

    def __repr__(self) -> str:
        return f"<TaskVariable {self.name}>"
