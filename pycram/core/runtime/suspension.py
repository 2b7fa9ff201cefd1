"""Task suspension (CRAM's `suspend` / `wake-up`, `with-task-suspended`, `on-suspension`,
`retry-after-suspension`).

`suspend(task)` suspends a task and its whole subtree; `wake_up(task)` lets it go on::

    with with_task_suspended(tags.wait_task("head-tracking")):
        ask_for_help()                 # the head tracking is paused meanwhile

Semantics:

* A suspended task blocks at its next PyCRAM suspension point — every PyCRAM wait
  (`Fluent.wait_for`, `whenever`, `sleep`, waiting for branches or a process module) and
  `check_evaporation()` — and stays there until woken up; a wait whose condition became true
  meanwhile still blocks (a suspended task makes no progress), its time-out keeps running.
  Plain Python code between two suspension points runs on (Python cannot stop a thread from
  outside), and inside `no_evaporation` blocks nothing is suspended.
* Every task of the subtree that has blocked shows `TaskStatus.SUSPENDED` in its status
  fluent (set by its own thread, so never after it ended) and `RUNNING` again once woken.
  Tasks started later in the subtree are suspended as well (suspension is inherited).
* Suspensions count: a task suspended twice runs again after two `wake_up`s. A task runs only
  while neither it nor an ancestor is suspended. Pair every `suspend` with a `wake_up` (or use
  `with_task_suspended`): while any suspension is in force, every PyCRAM wait also walks its
  task's ancestors.
* Evaporation wins: an evaporating task is never suspended, and evaporating a suspended task
  wakes it with `Evaporated` (its clean-up runs).
* `on_suspension(hook, on_wake)`: while the block runs, `hook()` is called in the task's own
  thread each time it blocks for suspension, `on_wake()` when it goes on (errors are logged).
* `retry_after_suspension(body)`: when the task is suspended while `body` runs, `body` is
  evaporated (its clean-up runs, its branches end) and, after the wake-up, run again from the
  start. Returns the result of the run that ended normally.
* `suspend(task, sync=True)` returns once every unfinished task of the subtree shows
  SUSPENDED (bounded by `timeout`); with `sync=False`, or when the caller is in the subtree
  itself, it returns at once.

Waiting is condition-based throughout; nothing polls. While no task is suspended, the cost
for everything else is one attribute read per wait.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, Literal

import pycram.core.fluent as _fluent
from pycram.core.runtime import evaporation as _evaporation
from pycram.core.runtime.evaporation import Evaporated, Runner, current_runner, wait_unsuspendable
from pycram.core.runtime.lockstep import Condition
from pycram.core.runtime.task import Task, TaskStatus, current_task, run_subtask, task_scope

__all__ = [
    "suspend",
    "wake_up",
    "with_task_suspended",
    "on_suspension",
    "retry_after_suspension",
    "is_suspended",
]

log = logging.getLogger(__name__)

_cv = Condition(threading.Lock())  # guards _counts; notified on every wake-up
_counts: dict[Task, int] = {}  # task -> how often it is suspended (directly)
_local = threading.local()  # .hooks: list of (on_suspend, on_wake) of the thread, outermost first


class _Point(_evaporation.SuspensionPoint):
    """The suspension point the wait loop consults (see `SuspensionPoint`)."""

    active = 0

    def due(self, runner: Runner) -> bool:
        task = runner.task
        if task is None or runner._protected or task._evaporating:
            return False
        counts = _counts
        while task is not None:
            if task in counts:
                return True
            task = task.parent
        return False

    def block(self, runner: Runner) -> None:
        _block(runner, self)


_point = _Point()


def _self_and_ancestors(task: Task) -> Iterator[Task]:
    node: Task | None = task
    while node is not None:
        yield node
        node = node.parent


def is_suspended(task: Task) -> bool:
    """True while `task` or one of its ancestors is suspended (whether or not it has blocked)."""
    return any(node in _counts for node in _self_and_ancestors(task))


def _chain(runner: Runner) -> list[Task]:
    """The calling thread's running tasks below (and including) the suspended one."""
    chain: list[Task] = []
    task = runner.task
    while task is not None and task._runner is runner:
        chain.append(task)
        if task in _counts:
            break
        task = task.parent
    return chain


def _call(hook: Callable[[], Any] | None, what: str) -> None:
    if hook is None:
        return
    try:
        hook()
    except Exception:
        log.exception("%s hook %r failed", what, hook)


def _block(runner: Runner, point: _Point) -> None:
    """Block the calling thread while its task is suspended (see the module doc)."""
    chain = _chain(runner)
    hooks = list(getattr(_local, "hooks", ()))
    for on_suspend, _ in reversed(hooks):
        _call(on_suspend, "on_suspension")
    marked = [task for task in chain if task.status.get_value() is TaskStatus.RUNNING]
    for task in marked:
        task.status.set_value(TaskStatus.SUSPENDED)
    try:
        wait_unsuspendable(_cv, lambda: not point.due(runner))
    finally:
        for task in reversed(marked):
            if task.status.get_value() is TaskStatus.SUSPENDED:
                task.status.set_value(TaskStatus.RUNNING)
        for _, on_wake in hooks:
            _call(on_wake, "on_wake")


def _runners_of(task: Task) -> list[Runner]:
    runners: list[Runner] = []
    for node in task.walk():
        runner = node._runner
        if runner is not None and not node.done and runner not in runners:
            runners.append(runner)
    return runners


def _nudge(runners: list[Runner]) -> None:
    """Wake the given threads out of their current PyCRAM wait so that they re-check."""
    caller = current_runner()
    token = caller.enter_runtime()
    try:
        for runner in runners:
            with runner._lock:
                condition = runner._waiting_on
            if condition is not None and condition is not _cv:
                with condition:
                    condition.notify_all()
    finally:
        due = caller.leave_runtime(token)
    if due:
        raise Evaporated()


def _in_subtree(task: Task, root: Task) -> bool:
    return any(node is root for node in _self_and_ancestors(task))


def _all_suspended(root: Task, watched: set[int], network: _fluent.Fluent) -> bool:
    """True when every unfinished task under `root` shows SUSPENDED; watches new tasks."""
    ok = True
    for task in root.walk():
        status = task.status.get_value()
        if id(task) not in watched:
            watched.add(id(task))
            task.status.add_child(network)
        if not status.done and status is not TaskStatus.SUSPENDED:
            ok = False
    return ok


def suspend(task: Task, *, sync: bool = True, timeout: float | None = None) -> None:
    """Suspend `task` and its subtree (see the module doc); idempotent per call, counted.

    With `sync` (and the caller not inside the subtree) returns once every unfinished task of
    the subtree shows SUSPENDED; raises `TimeoutError` naming the tasks that did not block
    within `timeout` [s] (active clock) — the suspension stays in force then. Evaporable.
    """
    if not isinstance(task, Task):
        raise TypeError(f"suspend() needs a Task, got {type(task).__name__}: {task!r}")
    if task.done:
        return
    _evaporation.install_suspension_point(_point)
    with _cv:
        _counts[task] = _counts.get(task, 0) + 1
        _point.active = len(_counts)
    _nudge(_runners_of(task))
    for node in task.walk():  # retry_after_suspension bodies are evaporated, retried on wake-up
        frame = node.info.get("_retry_after_suspension") if node.info else None
        if frame is not None and node.kind == "attempt" and not node.done:
            frame.unwound.add(node)
            node.evaporate()  # raises Evaporated if the caller is inside that body itself
    caller = current_task()
    if not sync or _in_subtree(caller, task):
        return
    watched: set[int] = set()
    network = _fluent.Fluent()
    network._value = lambda: True if _all_suspended(task, watched, network) else None
    try:
        suspended = network.wait_for(timeout)
    finally:
        # The value refers to the network: without breaking that cycle the network would live
        # until the garbage collector's next run, and every status change in the subtree (each
        # suspension and wake-up) would pulse it meanwhile -- 2,000 suspend/wake cycles left
        # dozens of them behind and doubled the wake-up latency. Dropped now, its weak
        # references in the status fluents die with it.
        network._value = None
    if not suspended:
        pending = [t.path for t in task.walk() if not t.done and t.status.get_value() is not TaskStatus.SUSPENDED]
        raise TimeoutError(f"suspend({task.path}): not suspended within {timeout:g} s: {pending}")


def wake_up(task: Task) -> None:
    """Undo one `suspend(task)`: the subtree runs again once no suspension of it or of an
    ancestor is left. No effect on a task that is not suspended. Returns at once."""
    if not isinstance(task, Task):
        raise TypeError(f"wake_up() needs a Task, got {type(task).__name__}: {task!r}")
    with _cv:
        count = _counts.get(task)
        if count is None:
            return
        if count > 1:
            _counts[task] = count - 1
        else:
            del _counts[task]
        _point.active = len(_counts)
        _cv.notify_all()


class with_task_suspended:
    """Suspend `task` for the block (`with with_task_suspended(task): ...`) or while `body()`
    runs (`with_task_suspended(task, body)` returns body's result); wakes it up however the
    block ends. Entering waits until the subtree is suspended (`suspend(sync=True)`)."""

    def __init__(self, task: Task, body: Callable[[], Any] | None = None, *, timeout: float | None = None) -> None:
        if not isinstance(task, Task):
            raise TypeError(f"with_task_suspended() needs a Task, got {type(task).__name__}: {task!r}")
        self.task = task
        self.timeout = timeout
        self.result: Any = None
        if body is not None:
            with self:
                self.result = body()

    def __enter__(self) -> Task:
        try:
            suspend(self.task, timeout=self.timeout)
        except BaseException:
            wake_up(self.task)
            raise
        return self.task

    def __exit__(self, *exc_info: Any) -> Literal[False]:
        wake_up(self.task)
        return False


@contextmanager
def on_suspension(hook: Callable[[], Any] | None, on_wake: Callable[[], Any] | None = None) -> Iterator[None]:
    """Call `hook()` whenever the calling task blocks for suspension inside the block, and
    `on_wake()` when it goes on (both in the task's thread; exceptions are logged)."""
    hooks = getattr(_local, "hooks", None)
    if hooks is None:
        hooks = _local.hooks = []
    entry = (hook, on_wake)
    hooks.append(entry)
    try:
        yield
    finally:
        hooks.remove(entry)


class _RetryFrame:
    __slots__ = ("unwound",)

    def __init__(self) -> None:
        self.unwound: set[Task] = set()


def retry_after_suspension(body: Callable[[], Any], name: str = "retry_after_suspension") -> Any:
    """Run `body`; if the task is suspended meanwhile, evaporate `body`, wait for the wake-up
    and run it again (see the module doc). Returns body's result, raises its exceptions."""
    if not callable(body):
        raise TypeError(f"retry_after_suspension() needs a callable, got {type(body).__name__}: {body!r}")
    frame = _RetryFrame()

    def attempt() -> Any:
        current_task().info["_retry_after_suspension"] = frame
        return body()

    with task_scope(name, "retry_after_suspension") as scope:
        number = 0
        while True:
            _evaporation.check_evaporation()  # blocks here while suspended
            number += 1
            scope.task.info["attempts"] = number
            try:
                return run_subtask(f"attempt {number}", attempt, kind="attempt")
            except Evaporated:
                attempt_task = scope.task.children[-1]
                if attempt_task not in frame.unwound or scope.task.evaporating:
                    raise
