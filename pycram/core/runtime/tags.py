"""Tags: names for sub-tasks that other tasks can refer to (CRAM's `with-tags` / `:tag`), and
looking tasks up in the task tree by path.

`tag(name, fn)` returns a callable that runs `fn` as a child task named `name` (kind "tag");
used directly as a branch of `par`/`pursue`/... the branch task itself is the tagged task.
Inside `with with_tags() as tags:` every tagged task started by the block — in any thread,
at any depth — is registered in `tags`, where other tasks find it::

    with with_tags() as tags:
        par(tag("tracking", track_head),
            lambda: with_task_suspended(tags.wait_task("tracking"), ask_for_help))

`tags.wait_task(name)` blocks until the tagged task exists (evaporable, optional time-out);
`tags[name]` returns it if it exists. A tagged task that another task evaporates ends
EVAPORATED and its `tag(...)` call returns None: only the tagged sub-task stops, not the code
around it (as in CRAM). `tag` introduces no parallelism: `fn` runs in the calling thread.

`find_task(path)` / `find_tasks(pattern)` look tasks up by their slash-separated path
(`fnmatch` patterns: `*/tracking`) under a root (default: the calling thread's root task).
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable, Iterator
from typing import Any, Literal

from pycram.core.fluent import Fluent
from pycram.core.runtime.evaporation import Evaporated
from pycram.core.runtime.task import Task, current_task, run_subtask
from pycram.core.runtime.task_variables import TaskVariable

__all__ = ["Tags", "with_tags", "tag", "find_task", "find_tasks"]

_registry: TaskVariable[Tags | None] = TaskVariable("pycram.tags", default=None)


class Tags:
    """A registry of tagged tasks (see the module doc). Thread-safe."""

    def __init__(self) -> None:
        self._fluents: dict[str, Fluent] = {}

    def _fluent(self, name: str) -> Fluent:
        return self._fluents.setdefault(name, Fluent(name=f"tag {name}"))  # dict.setdefault is atomic

    def register(self, name: str, task: Task) -> None:
        """Record `task` under `name` (a later task with the same tag replaces it)."""
        self._fluent(name).set_value(task)

    def __getitem__(self, name: str) -> Task:
        fluent = self._fluents.get(name)
        task: Task | None = fluent.get_value() if fluent is not None else None
        if task is None:
            raise KeyError(f"no task tagged {name!r} has started (yet); tags so far: {sorted(self.names())}")
        return task

    def __contains__(self, name: str) -> bool:
        fluent = self._fluents.get(name)
        return fluent is not None and fluent.get_value() is not None

    def names(self) -> list[str]:
        """The tags whose tasks have started."""
        return [name for name, fluent in list(self._fluents.items()) if fluent.get_value() is not None]

    def wait_task(self, name: str, timeout: float | None = None) -> Task:
        """The task tagged `name`, waiting until it has started. Raises `TimeoutError` after
        `timeout` [s] (active clock); evaporable."""
        fluent = self._fluent(name)
        if not fluent.wait_for(timeout):
            raise TimeoutError(f"no task tagged {name!r} started within {timeout:g} s")
        task: Task = fluent.get_value()  # registered tasks only (see register)
        return task

    def tag(self, name: str, fn: Callable[[], Any]) -> Callable[[], Any]:
        """`tag(name, fn)` registering in this registry (whatever `with_tags` is innermost)."""
        return _tagged(name, fn, self)


class with_tags:
    """`with with_tags() as tags:` — tagged tasks started inside the block register in `tags`."""

    def __init__(self) -> None:
        self.tags = Tags()
        self._binding: Any = None

    def __enter__(self) -> Tags:
        self._binding = _registry.bound(self.tags)
        self._binding.__enter__()
        return self.tags

    def __exit__(self, *exc_info: Any) -> Literal[False]:
        self._binding.__exit__(*exc_info)
        return False


def tag(name: str, fn: Callable[[], Any]) -> Callable[[], Any]:
    """A callable running `fn` as a child task named `name`, registered in the innermost
    `with_tags` registry of the calling task (see the module doc)."""
    return _tagged(name, fn, None)


def _tagged(name: str, fn: Callable[[], Any], tags: Tags | None) -> Callable[[], Any]:
    if not isinstance(name, str) or not name:
        raise TypeError(f"tag(): name must be a non-empty string, got {name!r}")
    if not callable(fn):
        raise TypeError(f"tag({name!r}): fn must be a callable taking no arguments, got {type(fn).__name__}: {fn!r}")

    def run_tagged() -> Any:
        registry = tags if tags is not None else _registry.get()
        here = current_task()
        if here.kind == "branch" and here.name == name and not here.children and "tag" not in here.info:
            # a branch of a concurrent expression, named after the tag already: it is the tagged
            # task (evaporating it ends only this branch, as with any branch)
            here.info["tag"] = name
            if registry is not None:
                registry.register(name, here)
            return fn()
        started: list[Task] = []

        def tagged_body() -> Any:
            task = current_task()
            started.append(task)
            task.info["tag"] = name
            if registry is not None:
                registry.register(name, task)
            return fn()

        try:
            return run_subtask(name, tagged_body, kind="tag")
        except Evaporated:
            task = started[0] if started else None
            if task is not None and task.evaporating and not here.evaporating:
                return None  # only the tagged task was evaporated: the code around it goes on
            raise

    run_tagged.__pycram_name__ = name  # type: ignore[attr-defined]
    run_tagged.__name__ = name
    return run_tagged


def _root() -> Task:
    task = current_task()
    while task.parent is not None:
        task = task.parent
    return task


def find_tasks(pattern: str, root: Task | None = None) -> list[Task]:
    """Every task under `root` (default: the calling thread's root task) whose path matches
    `pattern` (exact, or an `fnmatch` pattern such as `*/tracking`), depth first."""
    found: Iterator[Task] = (root or _root()).walk()
    return [task for task in found if task.path == pattern or fnmatch.fnmatchcase(task.path, pattern)]


def find_task(pattern: str, root: Task | None = None) -> Task:
    """The first task (depth first) matching `pattern` (see `find_tasks`); `LookupError` naming
    the pattern if there is none."""
    matches = find_tasks(pattern, root)
    if not matches:
        raise LookupError(f"no task matches {pattern!r} under {(root or _root()).path}")
    return matches[0]
