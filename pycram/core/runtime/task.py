"""Tasks and the task tree.

Every expression and every branch of an expression is a `Task`. A task runs either in its
parent's thread (the steps of `seq`, the attempts of `failure_handling`) or in a thread of its
own (the branches of `par`, `pursue`, `try_all`). Each thread has a root task, created the
first time the thread touches the runtime, so `current_task()` always answers.

A task's `status` is a `Fluent` that plans can wait on: CREATED → RUNNING → SUCCEEDED | FAILED
| EVAPORATED. `evaporate()` stops a task and all its descendants (see
`pycram.core.runtime.evaporation`). `TaskGroup` starts tasks in threads and guarantees that none of
them outlives it.
"""

from __future__ import annotations

import functools
import itertools
import sys
import threading
from collections.abc import Callable, Iterator
from enum import Enum
from typing import Any, Literal, ParamSpec, Protocol, TypeVar, overload

import pycram.core.fluent as _fluent  # imported as a module: pycram.core.fluent imports this package
from pycram.core.runtime.clock import current_clock
from pycram.core.runtime.evaporation import (
    Evaporated,
    Runner,
    current_runner,
    install_runner,
    prepare_interrupts,
    shielded,
    wait_until,
)
from pycram.core.runtime.lockstep import Condition, current_lockstep
from pycram.core.runtime.workers import submit

_P = ParamSpec("_P")
_R = TypeVar("_R")

__all__ = [
    "Task",
    "TaskStatus",
    "TaskGroup",
    "TaskListener",
    "add_task_listener",
    "remove_task_listener",
    "current_task",
    "run_subtask",
    "task_scope",
    "as_task",
    "end_thread_root",
    "format_task_tree",
]


class TaskStatus(Enum):
    """Life cycle of a task: CREATED -> RUNNING -> SUCCEEDED / FAILED / EVAPORATED."""

    CREATED = "created"
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    EVAPORATED = "evaporated"
    SUSPENDED = "suspended"  #: blocked by `pycram.core.runtime.suspension` until woken up; not done

    @property
    def done(self) -> bool:
        return self in _DONE


_DONE = frozenset((TaskStatus.SUCCEEDED, TaskStatus.FAILED, TaskStatus.EVAPORATED))

# Guards the tree's structure: children lists and the spreading of evaporation flags.
_tree_lock = threading.Lock()
_ids = itertools.count(1)


class TaskListener(Protocol):
    """Observer of the task runtime (the recorder is one). Called in the task's own thread."""

    def task_started(self, task: Task) -> None: ...

    def task_ended(self, task: Task) -> None: ...


_listeners: tuple[TaskListener, ...] = ()


def add_task_listener(listener: TaskListener) -> None:
    """Call `listener.task_started(task)` / `task_ended(task)` for every task from now on.

    Listeners run synchronously in the task's thread: keep them O(1) and never block.
    """
    global _listeners
    with _tree_lock:
        _listeners = _listeners + (listener,)


def remove_task_listener(listener: TaskListener) -> None:
    """Stop notifying `listener` (no error if it was not added)."""
    global _listeners
    with _tree_lock:
        _listeners = tuple(x for x in _listeners if x is not listener)


class Task:
    """A node of the task tree.

    Attributes: `name` (what it does: `grab_item`, `perform moving`, `par`...), `kind` (e.g.
    "seq", "par", "branch", "step", "attempt", "root"), `location` (where in the plan, e.g.
    `kitchen_plan.py:203` for a block-syntax branch, else None), `parent`, `children`,
    `status` (a `Fluent` of `TaskStatus`), `start_time` / `end_time` (active clock [s]),
    `exception` (the exception that failed it), `result`, `info` (free-form details, e.g. the
    attempt count).
    """

    __slots__ = (
        "id",
        "name",
        "kind",
        "parent",
        "children",
        "status",
        "start_time",
        "end_time",
        "exception",
        "result",
        "info",
        "location",
        "_evaporating",
        "_runner",
        "_path",
        "_pending_end",
    )

    def __init__(self, name: str, kind: str = "task", parent: Task | None = None) -> None:
        self.id = next(_ids)
        self.name = name
        self.kind = kind
        self.parent = parent
        self.children: list[Task] = []
        self.status = _fluent.Fluent(TaskStatus.CREATED)
        self.start_time: float | None = None
        self.end_time: float | None = None
        self.exception: BaseException | None = None
        self.result: Any = None
        self.info: dict[str, Any] = {}
        self.location: str | None = None
        self._runner: Runner | None = None
        self._path: str | None = None
        self._pending_end: tuple[TaskStatus, BaseException | None] | None = None
        if parent is None:
            self._evaporating = False
        else:
            with _tree_lock:
                self._evaporating = parent._evaporating
                parent.children.append(self)

    # -- tree -----------------------------------------------------------------------------------

    @property
    def path(self) -> str:
        """Slash-separated names from the root, e.g. `/main/par/branch-2:grab`."""
        if self._path is None:
            prefix = self.parent.path if self.parent is not None else ""
            self._path = f"{prefix}/{self.name}"
        return self._path

    def walk(self) -> Iterator[Task]:
        """This task and all its descendants, depth first, in creation order."""
        yield self
        for child in list(self.children):
            yield from child.walk()

    @property
    def done(self) -> bool:
        return self.status.get_value() in _DONE

    @property
    def duration(self) -> float | None:
        """End minus start time [s], or None while not both are known."""
        if self.start_time is None or self.end_time is None:
            return None
        return self.end_time - self.start_time

    @property
    def evaporating(self) -> bool:
        """True once `evaporate()` reached this task."""
        return self._evaporating

    # -- life cycle -----------------------------------------------------------------------------

    def _start(self, runner: Runner) -> None:
        self._runner = runner
        self.start_time = current_clock().now()
        self.status.set_value(TaskStatus.RUNNING)
        for listener in _listeners:
            listener.task_started(self)

    def _end(self, status: TaskStatus, exception: BaseException | None = None) -> None:
        """The task's own code has ended with `status`; the task ends once its children have.

        A child may still run when its parent's code ends: a process-module execution started
        with `('wait', False)` inside a `seq` step or an `@as_task` function, for example. The
        parent's final status, end time and `task_ended` notification then wait for the last
        such child, whose own end completes the parent's (in the child's thread).
        """
        if self.children:  # children are added only from this task's own thread: no race here
            with _tree_lock:
                if any(not child.done for child in self.children):
                    self._pending_end = (status, exception)
                    return
        self._finish(status, exception)

    def _finish(self, status: TaskStatus, exception: BaseException | None) -> None:
        task: Task | None = self
        due: Evaporated | None = None
        while task is not None:
            task.end_time = current_clock().now()
            task.exception = exception
            try:
                task.status.set_value(status)
            except Evaporated as held_back:  # this thread's evaporation, due now: after the end
                due = held_back
            for listener in _listeners:
                listener.task_ended(task)
            parent, runner = task.parent, task._runner
            task = None
            # A parent whose end is pending completes with its last child. A child ending in its
            # parent's own thread cannot race the parent's `_end` (and sees any pending end): no lock.
            if parent is not None and (parent._pending_end is not None or parent._runner is not runner):
                with _tree_lock:  # the last child to end completes its parent's pending end
                    pending = parent._pending_end
                    if pending is not None and all(child.done for child in parent.children):
                        parent._pending_end = None
                        task, (status, exception) = parent, pending
        if due is not None:
            raise due

    def evaporate(self) -> None:
        """Stop this task and all its descendants; returns at once (idempotent).

        Each affected thread gets `Evaporated`: at once if it waits in PyCRAM, within the
        interpreter's switch interval if it runs plain Python code, at the end of a
        `no_evaporation` block if it is in one. Wait for `status` to know when it ended.
        """
        runners: list[Runner] = []
        with _tree_lock:
            stack = [self]
            while stack:
                task = stack.pop()
                task._evaporating = True
                if task._runner is not None and task._runner not in runners:
                    runners.append(task._runner)
                stack.extend(task.children)
        caller = current_runner()
        token = caller.enter_runtime()  # interrupting takes the waiters' condition locks
        try:
            for runner in runners:
                if runner is not caller:
                    runner.interrupt()
        finally:
            due = caller.leave_runtime(token)
        if due:
            raise Evaporated()
        if caller in runners:  # a task evaporating itself (or an ancestor): deliver as usual
            caller.interrupt()

    def __repr__(self) -> str:
        return f"<Task {self.path} {self.status.get_value().value}>"


def _root_task_for_this_thread(runner: Runner) -> Task:
    thread = threading.current_thread()
    task = Task(thread.name, kind="root")
    task._runner = runner
    task.start_time = current_clock().now()
    task.status.set_value(TaskStatus.RUNNING)
    runner.task = task
    if thread is not threading.main_thread():  # the main thread's root ends with end_thread_root()
        _thread_roots.guard = _RootGuard(task)
    return task


class _RootGuard:
    """Held in thread-local storage: when the thread ends, CPython drops it (before `join()`
    returns), and a root task still running ends SUCCEEDED."""

    __slots__ = ("task",)

    def __init__(self, task: Task) -> None:
        self.task = task

    def __del__(self) -> None:
        _end_root(self.task, None)


_thread_roots = threading.local()


def _end_root(task: Task, exception: BaseException | None) -> None:
    if task.done:
        return
    if exception is None:
        task._end(TaskStatus.SUCCEEDED)
    elif isinstance(exception, Evaporated) and task._evaporating:
        task._end(TaskStatus.EVAPORATED, exception)
    else:
        task._end(TaskStatus.FAILED, exception)


def end_thread_root(exception: BaseException | None = None) -> None:
    """End the calling thread's root task: SUCCEEDED, or FAILED (EVAPORATED for an evaporation)
    with `exception`, e.g. what ended the thread's work. No-op when the thread has no root task
    or is inside a task. A later PyCRAM call in this thread starts a new root task.

    Threads that PyCRAM did not start get a root task on their first PyCRAM call; it ends with
    the thread by itself (SUCCEEDED). Call this to end it earlier or with an outcome, e.g. in the
    main thread when a script's plans are done.
    """
    runner = current_runner()
    task = runner.task
    if task is None or task.kind != "root" or task.parent is not None:
        return
    runner.task = None
    _end_root(task, exception)  # before dropping the guard, whose finalizer would end it SUCCEEDED
    if getattr(_thread_roots, "guard", None) is not None and _thread_roots.guard.task is task:
        _thread_roots.guard = None


def current_task() -> Task:
    """The innermost task of the calling thread (a root task outside any expression)."""
    runner = current_runner()
    task = runner.task
    if task is None:
        task = _root_task_for_this_thread(runner)
    return task


def run_subtask(
    name: str, fn: Callable[..., Any], *args: Any, kind: str = "task", location: str | None = None, **kwargs: Any
) -> Any:
    """Run `fn(*args, **kwargs)` as a child task of the current task, in the calling thread.

    Returns fn's result or re-raises its exception; the child ends SUCCEEDED, FAILED or
    EVAPORATED accordingly (once its own children have ended, see `Task._end`). Raises
    `Evaporated` before starting if the caller is evaporating. `location` (e.g. `plan.py:12`)
    is stored as the task's `location`.
    """
    runner = current_runner()
    in_plan, runner.in_plan = runner.in_plan, False  # no asynchronous Evaporated in here
    parent = runner.task if runner.task is not None else _root_task_for_this_thread(runner)
    if parent._evaporating and not runner._protected:
        runner.in_plan = in_plan
        raise runner.evaporated()
    task = Task(name, kind, parent)
    task.location = location
    task._start(runner)
    runner.task = task
    try:
        _enter_plan_code(runner)
        result = fn(*args, **kwargs)
        runner.in_plan = False
        if runner._injected:
            runner.take_back_pending()  # one pending for fn lands here at the latest: as fn's
    except Evaporated as exc:
        try:
            _leave_plan_code(runner)
        except Evaporated:
            pass  # the one pending landed at the call: taken back in effect
        runner.task = parent
        task._end(TaskStatus.EVAPORATED if task._evaporating else TaskStatus.FAILED, exc)
        runner.in_plan = in_plan
        raise
    except BaseException as exc:
        try:
            _leave_plan_code(runner)
        except Evaporated:
            pass  # the one pending landed at the call: taken back in effect
        runner.task = parent
        task._end(TaskStatus.FAILED, exc)
        runner.in_plan = in_plan
        raise
    runner.task = parent
    task.result = result
    task._end(TaskStatus.SUCCEEDED)
    _back_to_plan_code(runner, in_plan)
    return result


def _leave_plan_code(runner: Runner) -> None:
    """In the runtime's handler of an exception from plan code: no asynchronous `Evaporated`
    may land from here on (one still pending is taken back; if it lands instead, it is dropped:
    an exception of the plan code is being handled already). Call it inside `try/except
    Evaporated`: a pending one may land at this very call."""
    runner.in_plan = False
    if runner._injected:
        try:
            runner.take_back_pending()
        except Evaporated:
            pass


def _enter_plan_code(runner: Runner) -> None:
    """Plan code runs from here on (see `Runner.enter_plan_code`): raises `Evaporated` if one
    became due while the runtime's bookkeeping held it back."""
    runner.enter_plan_code()


def _back_to_plan_code(runner: Runner, in_plan: bool) -> None:
    """Hand back to the caller; raise `Evaporated` here if an evaporation became due while the
    runtime's bookkeeping held it back (as if it had landed right after the call)."""
    if in_plan:
        _enter_plan_code(runner)
    else:
        runner.in_plan = False


@overload
def as_task(fn: Callable[_P, _R], *, name: str | None = None, kind: str = "plan") -> Callable[_P, _R]: ...


@overload
def as_task(
    fn: None = None, *, name: str | None = None, kind: str = "plan"
) -> Callable[[Callable[_P, _R]], Callable[_P, _R]]: ...


def as_task(fn: Callable[..., Any] | None = None, *, name: str | None = None, kind: str = "plan") -> Any:
    """Decorator: each call of the function runs as a child task named after it (`run_subtask`).

    `@as_task` or `@as_task(name="fetch", kind="action")`; the default name is the function's
    `__name__`, the default kind "plan". Stack it *above* `@plan`. The task tree then shows
    `grab_item [plan] failed — GraspFailed: ...` instead of only the expressions inside.
    Returns what the function returns and raises what it raises.
    """

    def decorate(function: Callable[_P, _R]) -> Callable[_P, _R]:
        task_name = name or function.__name__

        @functools.wraps(function)
        def run(*args: _P.args, **kwargs: _P.kwargs) -> _R:
            result: _R = run_subtask(task_name, function, *args, kind=kind, **kwargs)  # type: ignore[arg-type]  # the function's keywords pass through
            return result

        return run

    return decorate if fn is None else decorate(fn)


class task_scope:
    """Run the block as a child task of the current task, in the calling thread (runtime
    internal: the language's expressions use it for their own bookkeeping).

    Usage: `with task_scope("par", "par") as scope: ...; scope.fail(error)`. The task ends
    EVAPORATED if `Evaporated` leaves the block while it is evaporating, FAILED if another
    exception leaves it or `scope.fail()` was called, SUCCEEDED otherwise. Raises `Evaporated`
    on entry if the caller is evaporating. The block is runtime bookkeeping: no asynchronous
    `Evaporated` lands in it (it is raised after the block instead if it became due
    meanwhile); plan code inside it runs through `run_subtask`, which marks it as plan code.

    Why not plan code directly in the block: an asynchronous exception can land at the entry
    of `__exit__` (a Python frame, where the interpreter checks for it) and would leave the
    task unended for good; `run_subtask` receives it inside its own `try`.
    """

    __slots__ = ("task", "error", "_parent", "_runner", "_in_plan")

    def __init__(self, name: str, kind: str = "task") -> None:
        runner = current_runner()
        parent = runner.task if runner.task is not None else _root_task_for_this_thread(runner)
        if parent._evaporating and not runner._protected:
            raise runner.evaporated()
        self._in_plan, runner.in_plan = runner.in_plan, False  # none in the bookkeeping
        self._runner = runner
        self._parent = parent
        self.task = Task(name, kind, parent)
        self.error: BaseException | None = None

    def fail(self, error: BaseException | None) -> None:
        """End the task FAILED (with `error` as its exception) when the block ends normally."""
        self.error = error if error is not None else RuntimeError("failed")

    def __enter__(self) -> task_scope:
        self.task._start(self._runner)
        self._runner.task = self.task
        return self

    def __exit__(self, exc_type: type | None, exc: BaseException | None, tb: object) -> Literal[False]:
        task = self.task
        self._runner.task = self._parent
        if exc is None:
            if self.error is None:
                task._end(TaskStatus.SUCCEEDED)
            else:
                task._end(TaskStatus.FAILED, self.error)
        elif isinstance(exc, Evaporated) and task._evaporating:
            task._end(TaskStatus.EVAPORATED, exc)
        else:
            task._end(TaskStatus.FAILED, exc)
        if exc is None:
            _back_to_plan_code(self._runner, self._in_plan)
        else:
            self._runner.in_plan = self._in_plan
        return False


class TaskGroup:
    """Runs child tasks concurrently, each on a worker thread; none of them outlives the group.

    `spawn` starts a child of the calling thread's current task. `wait_all` returns only after
    every spawned thread has ended — even when the waiting task is evaporated meanwhile: it
    then evaporates the children, waits for them and re-raises `Evaporated`.

    `on_end(task)` is called in the child's thread when a child ends, under the group's
    condition (keep it short, never block); use it to decide the outcome of an expression.

    A `detached` group is one its creator will not necessarily wait for (a process-module
    execution started with `('wait', False)`). It still does not outlive the branch that
    started it: before that branch ends, it waits for the group — after evaporating it if the
    branch failed or was evaporated. A task whose code ends while a child still runs (a
    detached execution started in a `seq` step, say) gets its final status when that child
    has ended (see `Task._end`).
    """

    def __init__(self, on_end: Callable[[Task], None] | None = None, detached: bool = False) -> None:
        prepare_interrupts()
        self.parent = current_task()
        self.tasks: list[Task] = []
        self._cv = Condition(threading.Lock())
        self._running = 0
        self._on_end = on_end
        if detached:  # nobody may wait for it: the branch thread that started it will
            runner = current_runner()
            runner.detached = [g for g in runner.detached if g._running] + [self]

    def spawn(self, name: str, fn: Callable[[], Any], kind: str = "branch") -> Task:
        """Start `fn` as a child task on a worker thread of its own; returns the task."""
        task = Task(name, kind, self.parent)
        runner = Runner(task)
        runner.in_plan = False  # until the branch's own code runs
        task._runner = runner
        with self._cv:
            self._running += 1
        self.tasks.append(task)
        trace = _debugger_trace()
        lockstep = current_lockstep()  # the branch counts as running from now on (lock-step time)
        ticket = lockstep.spawned() if lockstep is not None else None
        submit(lambda: self._thread_main(task, runner, fn, trace, lockstep, ticket))
        return task

    def _thread_main(
        self,
        task: Task,
        runner: Runner,
        fn: Callable[[], Any],
        trace: Any = None,
        lockstep: Any = None,
        ticket: Any = None,
    ) -> None:
        if lockstep is not None:
            lockstep.adopt(ticket)  # runs when it is its turn (in task order)
        try:
            self._run_branch(task, runner, fn, trace)
        finally:
            if lockstep is not None:
                lockstep.ended()

    def _run_branch(self, task: Task, runner: Runner, fn: Callable[[], Any], trace: Any) -> None:
        install_runner(runner)
        if trace is not None:
            sys.settrace(trace)  # a debugger's breakpoints work in the branch (see _debugger_trace)
        status, result = TaskStatus.FAILED, None
        error: BaseException | None = None
        try:
            try:
                task._start(runner)
                _enter_plan_code(runner)  # raises if evaporated before this thread got to run it
                result = fn()
                runner.in_plan = False
                status = TaskStatus.SUCCEEDED
            except Evaporated as exc:
                status, error = (TaskStatus.EVAPORATED if task._evaporating else TaskStatus.FAILED), exc
            except BaseException as exc:
                status, error = TaskStatus.FAILED, exc
        except BaseException as late:  # an asynchronous exception landing in the handlers above
            status, error = TaskStatus.EVAPORATED, late
        runner.in_plan = False
        while True:  # at most one asynchronous exception can still be pending
            try:
                if trace is not None or runner.resurfacing:
                    sys.settrace(None)  # the worker thread is reused: do not trace the next branch
                runner.seal()
                break
            except BaseException:
                status = TaskStatus.EVAPORATED if task._evaporating else status
        if runner.detached:  # before the task ends: its final status comes after its children's
            _settle_detached(runner, stop=status is not TaskStatus.SUCCEEDED)
        task.result = result
        task._end(status, error)
        if self._on_end is not None:
            with self._cv:  # report the outcome at once: the expression may decide on it
                self._on_end(task)
                self._cv.notify_all()
        with self._cv:
            self._running -= 1
            self._cv.notify_all()

    def evaporate(self, except_task: Task | None = None) -> None:
        """Evaporate every child (but `except_task`)."""
        for task in self.tasks:
            if task is not except_task and not task.done:
                task.evaporate()

    def wait_all(self) -> None:
        """Block until every child has ended (see the class doc for evaporation). If the wait is
        cut short — by evaporation, or by `KeyboardInterrupt` (Ctrl-C, or SIGTERM under `pycram
        run`) — every child is evaporated and waited for before the exception propagates."""
        try:
            wait_until(self._cv, self._all_ended)
        except BaseException:
            self.stop_all()
            raise

    def stop_all(self) -> None:
        """Evaporate every child and block until all have ended (not interruptible by evaporation)."""
        with shielded():
            self.evaporate()
            wait_until(self._cv, self._all_ended)

    def _all_ended(self) -> bool:
        return self._running == 0


def _debugger_trace() -> Any:
    """The calling thread's trace function, if branch threads should inherit it.

    A debugger (pdb, bdb; also `breakpoint()` followed by `continue`) traces only the thread it
    runs in, through `sys.settrace`, so breakpoints on lines of concurrent branches — which run
    in worker threads — would never be hit. The spawning thread's trace function is therefore
    installed in the branch's thread for the branch's duration. Tools that trace every thread
    themselves (coverage.py, the `trace` module: `threading.settrace`) are left alone.
    """
    trace = sys.gettrace()
    if trace is None or threading.gettrace() is not None:
        return None
    return trace


def _settle_detached(runner: Runner, stop: bool) -> None:
    """Before a branch thread ends: wait for the groups it started without waiting (e.g. a
    process-module execution with `('wait', False)`), evaporating them first if `stop`."""
    with shielded():
        for group in runner.detached:
            if stop:
                group.evaporate()
            wait_until(group._cv, group._all_ended)
        runner.detached = []
        runner.seal()  # waiting left the runtime mode: seal the thread again before it ends


_STATUS_MARK = {
    TaskStatus.CREATED: "·",
    TaskStatus.RUNNING: "▶",
    TaskStatus.SUCCEEDED: "✔",
    TaskStatus.FAILED: "✘",
    TaskStatus.EVAPORATED: "~",
    TaskStatus.SUSPENDED: "‖",
}


def format_task_tree(task: Task | None = None, *, show_errors: bool = True) -> str:
    """The tree under `task` (default: the current thread's root) as indented text.

    One line per task: status mark, name, kind, status, duration, and the failure if any.
    """
    if task is None:
        task = current_task()
        while task.parent is not None:
            task = task.parent
    lines: list[str] = []

    def visit(node: Task, depth: int) -> None:
        status = node.status.get_value()
        duration = node.duration
        text = f"{'  ' * depth}{_STATUS_MARK[status]} {node.name} [{node.kind}] {status.value}"
        if duration is not None:
            text += f" {duration * 1000:.1f} ms" if duration < 1 else f" {duration:.2f} s"
        if show_errors and status is TaskStatus.FAILED and node.exception is not None:
            text += f" — {type(node.exception).__name__}: {node.exception}"
        lines.append(text)
        for child in list(node.children):
            visit(child, depth + 1)

    visit(task, 0)
    return "\n".join(lines)
