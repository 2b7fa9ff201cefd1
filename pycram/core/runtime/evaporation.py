"""Evaporation and the one blocking primitive every PyCRAM wait goes through.

Evaporation stops a task from outside (CRAM's term: `pursue` evaporates the losers). It is
delivered as the exception `Evaporated`, derived from `BaseException` so that `except
Exception` in plan code does not swallow it:

* at once inside any PyCRAM wait (`wait_until`, hence `Fluent.wait_for`, `whenever`, `sleep`,
  process-module execution): the waiting thread's condition is notified;
* in plain Python code (`while True: x += 1`) by an asynchronous exception injected into the
  thread, which the interpreter raises within its switch interval (5 ms by default);
* never inside a `no_evaporation()` block — it is delivered when the block ends.

It is sticky: catching it does not save the task. Every later PyCRAM call made by an evaporating
task (`check_evaporation`, waits, `sleep`, expressions, `retry`) raises it again. A task that
swallowed it (a later PyCRAM call finds it still evaporating, outside any handler or `finally`
of an `Evaporated`) is re-delivered `Evaporated` at the next line its own code executes, and
again each time it swallows it, until it ends — so even `while True: try: sleep(0.01)
except: pass` ends (see `Runner.evaporated`).

It is delivered once: a task that lets `Evaporated` propagate is never interrupted again on
its way up, so its `finally` blocks and context-manager exits run uninterrupted.

Every thread that runs PyCRAM code has a `Runner`: its current task and the state needed to
interrupt it. This module knows tasks only through two attributes: `_evaporating` (bool) and
`_runner`.
"""

from __future__ import annotations

import functools
import os
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, ParamSpec, TypeVar

from pycram.core.runtime.clock import current_clock
from pycram.core.runtime.lockstep import Condition

if TYPE_CHECKING:  # the task module imports this one
    from pycram.core.runtime.task import Task, TaskGroup

_P = ParamSpec("_P")
_R = TypeVar("_R")

__all__ = [
    "Evaporated",
    "check_evaporation",
    "is_evaporating",
    "no_evaporation",
    "shielded",
    "sleep",
    "wait_until",
]

_USER = 0  # running user code: may be interrupted by an asynchronous exception
_RUNTIME = 1  # inside the runtime or blocked in a wait: interrupted through its condition
_SEALED = 2  # the task's thread is finishing: never interrupted again


class Evaporated(BaseException):
    """Raised in a task that was evaporated (stopped from outside).

    Derives from `BaseException`: `except Exception` does not catch it. Catching it anyway does
    not resurrect the task — every later PyCRAM call raises it again, and a task that swallowed
    it gets it re-delivered at its next line — so let it propagate and put clean-up in `finally`
    blocks or context managers, which then run uninterrupted.
    """


class Runner:
    """The per-thread execution state: current task, wait registration, interrupt state."""

    __slots__ = (
        "task",
        "ident",
        "detached",
        "_mode",
        "_waiting_on",
        "_injected",
        "_missed",
        "_protected",
        "_lock",
        "_sleep",
        "_delivered_to",
        "_delivered_top",
        "resurfacing",
        "in_plan",
    )

    def __init__(self, task: Task | None = None, ident: int | None = None) -> None:
        self.task = task
        self.ident = ident  # the thread's identifier once the runner is installed in it
        self.detached: list[TaskGroup] = []  # task groups started without waiting (see TaskGroup)
        self._mode = _USER
        self._waiting_on: threading.Condition | None = None
        self._injected = False
        self._missed = False  # an interrupt found the thread in runtime code, not waiting
        self._protected = 0
        self._lock = threading.Lock()
        self._sleep: threading.Condition | None = None
        self._delivered_to: Task | None = None  # the task evaporation was last delivered to,
        self._delivered_top: Task | None = None  # and its outermost ancestor evaporating then
        self.resurfacing = 0  # how often a swallowed evaporation was re-delivered (see evaporated)
        # True while the thread runs plan code (the only place an asynchronous Evaporated may
        # land); the task runtime sets it False around its own bookkeeping (see take_back_pending)
        self.in_plan = True

    # -- state of the current task -------------------------------------------------------------

    def evaporation_due(self) -> bool:
        """True when the current task is evaporating and not inside `no_evaporation`."""
        task = self.task
        return task is not None and task._evaporating and not self._protected

    def _delivered_here(self) -> bool:
        """True when evaporation was delivered to the current task, or to a descendant of it
        and this task was already evaporating then (its `Evaporated` is on its way up here)."""
        current, task = self.task, self._delivered_to
        while task is not None:
            if task is current:
                return True
            if task is self._delivered_top:
                return False
            task = task.parent
        return False

    def _mark_delivered(self) -> None:
        task = top = self.task
        assert top is not None  # called only while the current task is evaporating
        while top.parent is not None and top.parent._evaporating:
            top = top.parent
        self._delivered_to, self._delivered_top = task, top

    def evaporated(self) -> Evaporated:
        """The `Evaporated` a PyCRAM call raises on finding its task evaporating.

        If it had been delivered already and the call is not made while an `Evaporated` is
        being handled (an `except` clause, a `finally` block, a context manager's exit on its
        way up), the task swallowed it: from now on each line of the task's own code re-raises
        it (a trace function on the thread's plan frames, never inside PyCRAM or the standard
        library), until the task ends.
        """
        if self._delivered_here() and not isinstance(sys.exc_info()[1], Evaporated):
            self.resurfacing += 1
            _resurface_in_plan_frames(sys._getframe(1))
        self._mark_delivered()
        return Evaporated()

    # -- entering and leaving the runtime -----------------------------------------------------

    def enter_runtime(self) -> tuple[int, bool]:
        """Begin runtime code that holds locks: no asynchronous `Evaporated` reaches the thread
        until `leave_runtime` (one already pending is taken back). Nests; returns the token
        for `leave_runtime`.

        Why: `with condition:` runs Python frames (`Condition.__enter__`/`__exit__`); an
        asynchronous exception landing in one of them while the lock is held would leave the
        lock held for good, and every later waiter on it would hang.
        """
        with self._lock:
            took_back = self._injected
            if took_back:  # first, so that a late delivery leaves the state untouched
                self._injected = False
                assert self.ident is not None  # set before anything is injected (see interrupt)
                _take_back_async_exception(self.ident)
            previous = self._mode
            if previous == _USER:
                self._mode = _RUNTIME
            return previous, took_back

    def leave_runtime(self, token: tuple[int, bool]) -> bool:
        """End a section begun by `enter_runtime`.

        Returns True when an evaporation was held back by the section (a pending `Evaporated`
        taken back, or an interrupt that found the thread here) and is still due: the caller
        must then raise `Evaporated` itself, on its normal path, where the asynchronous one
        would have landed.
        """
        previous, took_back = token
        with self._lock:
            self._waiting_on = None
            if self._mode == _RUNTIME and previous == _USER:
                self._mode = _USER
                took_back, self._missed = took_back or self._missed, False
        return took_back and self.evaporation_due()

    def enter_plan_code(self) -> None:
        """Mark the thread as running plan code from here on, where an asynchronous
        `Evaporated` may land; raise `Evaporated` instead if an evaporation became due while
        the runtime's bookkeeping held it back (an interrupt finding `in_plan` false injects
        nothing).

        Atomic with `interrupt` (both under the runner's lock): an evaporation is either raised
        here or injected into the plan code, never lost in between, never both."""
        with self._lock:
            if not self.evaporation_due():
                self.in_plan = True
                return
            self._mark_delivered()
        raise Evaporated()

    def take_back_pending(self) -> None:
        """Cancel an asynchronous `Evaporated` still pending for the calling thread (the runtime
        calls it after setting `in_plan` False, when `_injected` says one may be pending). The
        pending exception may land at this call instead: callers treat it as the plan code's."""
        with self._lock:
            if self._injected:
                self._injected = False
                assert self.ident is not None  # set before anything is injected (see interrupt)
                _take_back_async_exception(self.ident)

    def _wait_on(self, condition: threading.Condition) -> None:
        """Register the condition a wait blocks on, so that `interrupt` can notify it."""
        with self._lock:
            self._waiting_on = condition

    def seal(self) -> None:
        """Mark the thread as finishing: no asynchronous exception can reach it after this."""
        with self._lock:
            if self._injected:
                self._injected = False
                assert self.ident is not None  # set before anything is injected (see interrupt)
                _take_back_async_exception(self.ident)
            self._mode = _SEALED
            self._waiting_on = None

    # -- interrupting ---------------------------------------------------------------------------

    def interrupt(self) -> None:
        """Deliver evaporation to this thread if its current task is evaporating.

        A thread blocked in a PyCRAM wait is woken through its condition; a thread running user
        code gets an asynchronous `Evaporated`; a thread inside the runtime or inside
        `no_evaporation` notices the flag at its next check.
        """
        if not self.evaporation_due() or self._delivered_here():
            return  # not due, or on its way up already: never interrupt its clean-up
        injected = False
        inject = _api()[0]
        with self._lock:
            self._mark_delivered()
            condition = self._waiting_on
            # Only into plan code: the runtime's own bookkeeping (in_plan False) checks for a due
            # evaporation when it hands back to plan code. No eval-breaker check lies between
            # reading in_plan and the C call, so the thread cannot leave plan code in between.
            if (
                condition is None
                and self._mode == _USER
                and self.in_plan
                and not self._injected
                and self.ident is not None
            ):
                self._injected = injected = True
                inject(self.ident, Evaporated)
            elif condition is None and self._mode == _RUNTIME:
                self._missed = True  # raised by the runtime code when it leaves (leave_runtime)
        if condition is not None:
            with condition:
                condition.notify_all()
        elif injected and self.ident != threading.get_ident():
            # CPython raises a pending asynchronous exception only when the target thread next
            # handles its "eval breaker"; a thread busy in pure Python does that when another
            # thread asks for the GIL. Releasing and re-taking the GIL once makes that request,
            # so the exception lands within one switch interval instead of "eventually".
            os.sched_yield()

    def sleep_condition(self) -> threading.Condition:
        condition = self._sleep
        if condition is None:
            condition = self._sleep = Condition(threading.Lock())
        return condition


_local = threading.local()


def current_runner() -> Runner:
    """The calling thread's runner (created on first use for threads PyCRAM did not start)."""
    try:
        runner: Runner = _local.runner
        return runner
    except AttributeError:
        runner = _local.runner = Runner(ident=threading.get_ident())
        return runner


def install_runner(runner: Runner) -> None:
    """Make `runner` the calling thread's runner (used by the task module for new threads)."""
    with runner._lock:
        runner.ident = threading.get_ident()
    _local.runner = runner


def runtime_code(fn: Callable[_P, _R]) -> Callable[_P, _R]:
    """Decorator: calls of `fn` are runtime bookkeeping, also when plan code makes them (e.g. a
    process module's queue): no asynchronous `Evaporated` lands inside (one still pending is
    taken back, or lands at the call); one that became due meanwhile is raised when `fn`
    returns, as if it had landed right after the call. Waits inside stay evaporable.

    Why: an asynchronous exception landing in bookkeeping — e.g. inside `Condition.__enter__`
    right after the lock was taken, or at the entry of a `finally` clause's clean-up call —
    would leave a lock held or a queue entry behind for good."""

    @functools.wraps(fn)
    def run(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        runner = current_runner()
        in_plan = runner.in_plan
        runner.in_plan = False
        try:
            if runner._injected:
                runner.take_back_pending()  # (or it lands right here: as at the call)
            result = fn(*args, **kwargs)
        except BaseException:
            runner.in_plan = in_plan
            raise
        if in_plan:
            runner.enter_plan_code()
        return result

    return run


def call_plan_code(fn: Callable[..., _R], *args: Any, **kwargs: Any) -> _R:
    """Call `fn` (plan code, e.g. a process module's `_execute`) from runtime code: an
    asynchronous `Evaporated` may land inside it; one still pending when it ends is taken back
    (or lands at the end of it, as `fn`'s). Raises `Evaporated` before calling if one is due."""
    runner = current_runner()
    in_plan = runner.in_plan
    runner.enter_plan_code()
    try:
        return fn(*args, **kwargs)
    finally:
        runner.in_plan = in_plan
        if runner._injected and not in_plan:
            runner.take_back_pending()


def is_evaporating() -> bool:
    """True when the calling task is evaporating (outside `no_evaporation`). Never raises."""
    return current_runner().evaporation_due()


def check_evaporation() -> None:
    """Raise `Evaporated` if the calling task is evaporating.

    Call it in long computations that make no other PyCRAM call; plain Python loops are also
    interrupted asynchronously, but an explicit check is immediate and exact. It is also a
    suspension point: a suspended task blocks here until woken up.
    """
    runner = current_runner()
    if runner.evaporation_due():
        raise runner.evaporated()
    point = _suspension
    if point is not None and point.active and point.due(runner):
        point.block(runner)  # a suspended task stops here until woken up


@contextmanager
def shielded() -> Iterator[Runner]:
    """Hold evaporation back for the block, without raising at its end (runtime internal).

    Used where the runtime must finish bookkeeping (starting a group of threads, waiting for
    evaporated children to end) even though its own task is evaporating.
    """
    runner = current_runner()
    with runner._lock:
        if runner._injected:  # an interrupt raced with entering: take it back
            runner._injected = False
            assert runner.ident is not None  # set before anything is injected (see interrupt)
            _take_back_async_exception(runner.ident)
        runner._protected += 1
    try:
        yield runner
    finally:
        with runner._lock:
            runner._protected -= 1


@contextmanager
def no_evaporation() -> Iterator[None]:
    """Protect a critical section: evaporation is held back until the block ends.

    Inside the block waits are not interrupted and no asynchronous exception is injected. If
    the task was evaporated meanwhile, `Evaporated` is raised when the block ends (after the
    block's own clean-up has run). Blocks nest.
    """
    with shielded() as runner:
        yield
    if runner.evaporation_due():
        raise runner.evaporated()


def wait_until(
    condition: threading.Condition,
    predicate: Callable[[], object],
    timeout: float | None = None,
) -> bool:
    """Block until `predicate()` is true; the one blocking primitive of PyCRAM.

    `predicate` is evaluated with `condition` held, first at once and then each time the
    condition is notified. Returns True when the predicate holds, False when `timeout` [s] of
    the active clock has passed. Raises `Evaporated` at once when the calling task is (or
    becomes) evaporating. A suspended task (`pycram.core.runtime.suspension`) stays blocked here
    until woken up, even if the predicate became true meanwhile; the time-out keeps running.
    Never polls.
    """
    return _wait(condition, predicate, timeout, True)


def _wait(
    condition: threading.Condition, predicate: Callable[[], object], timeout: float | None, suspendable: bool
) -> bool:
    runner = current_runner()
    if runner.evaporation_due():
        raise runner.evaporated()
    deadline = None
    if timeout is not None and timeout > 0:
        deadline = current_clock().now() + timeout
    while True:
        token = runner.enter_runtime()  # before taking the condition's lock, left after releasing it
        try:
            with condition:
                satisfied = _wait_locked(runner, condition, predicate, timeout, deadline, suspendable)
        finally:
            due = runner.leave_runtime(token)
        if due:
            raise Evaporated()
        if satisfied is not _SUSPENDED:
            return satisfied  # type: ignore[return-value]
        _suspension.block(runner)  # type: ignore[union-attr]


def _wait_locked(
    runner: Runner,
    condition: threading.Condition,
    predicate: Callable[[], object],
    timeout: float | None,
    deadline: float | None,
    suspendable: bool,
) -> object:
    """The body of `wait_until`, with `condition` held and the runner in runtime mode.

    Returns True / False (predicate / time-out) or `_SUSPENDED` when the task must block for
    suspension first (the caller does that without holding `condition`)."""
    if suspendable and _suspension is not None and _suspension.active and _suspension.due(runner):
        return _SUSPENDED
    if predicate():
        return True
    if timeout is not None and timeout <= 0:
        return False
    clock = current_clock()
    handle = None if deadline is None else clock.register(deadline, condition)
    runner._wait_on(condition)
    try:
        while True:
            if runner.evaporation_due():
                raise Evaporated()
            if suspendable and _suspension is not None and _suspension.active and _suspension.due(runner):
                return _SUSPENDED
            if predicate():
                return True
            if deadline is not None and clock.now() >= deadline:
                return False
            clock.wait(condition, deadline)
    finally:
        if handle is not None:
            clock.unregister(handle)


_SUSPENDED = object()  # result of `_wait_locked`: block for suspension, then wait again


class SuspensionPoint:
    """What the wait loop needs from `pycram.core.runtime.suspension` (installed there on first use).

    `active` is non-zero while any task is suspended (the fast path skips everything else);
    `due(runner)` tells whether the runner's current task must block; `block(runner)` blocks
    it until woken up (evaporable), called without any lock held.
    """

    active = 0

    def due(self, runner: Runner) -> bool:
        raise NotImplementedError

    def block(self, runner: Runner) -> None:
        raise NotImplementedError


_suspension: SuspensionPoint | None = None


def install_suspension_point(point: SuspensionPoint) -> None:
    """Make waits and `check_evaporation` honour suspension (runtime internal)."""
    global _suspension
    _suspension = point


def wait_unsuspendable(
    condition: threading.Condition, predicate: Callable[[], object], timeout: float | None = None
) -> bool:
    """`wait_until` that a suspension does not stop (runtime internal: the suspension block)."""
    return _wait(condition, predicate, timeout, False)


def notify_waiters(condition: threading.Condition) -> None:
    """Wake every thread waiting on `condition`; safe against asynchronous evaporation.

    Raises `Evaporated` only where an asynchronous one was about to land anyway.
    """
    runner = current_runner()
    if runner.task is None and not runner._injected:
        # A thread without a task (a simulation's thread, a sensor driver): nothing can inject
        # an asynchronous `Evaporated` into it (`Runner.interrupt` only reaches a task's
        # thread, and only the thread itself gives its runner a task), so the guard below is
        # not needed.
        with condition:
            condition.notify_all()
        return
    token = runner.enter_runtime()
    try:
        with condition:
            condition.notify_all()
    finally:
        due = runner.leave_runtime(token)
    if due:
        raise Evaporated()


def sleep(seconds: float) -> None:
    """Sleep `seconds` [s] of the active clock (simulated time when a simulation runs).

    Evaporable: raises `Evaporated` at once if the task is evaporated while sleeping.
    """
    runner = current_runner()
    wait_until(runner.sleep_condition(), _never, seconds)


def _never() -> bool:
    return False


_async_exc_api: tuple[Callable[..., int], Callable[..., int]] | None = None


def prepare_interrupts() -> None:
    """Load the C API used to interrupt busy threads (done before the first branch starts, so
    that the first evaporation is not slowed down by importing ctypes under GIL contention)."""
    _api()


def _api() -> tuple[Callable[..., int], Callable[..., int]]:
    """The C function `PyThreadState_SetAsyncExc`, typed once to set and once to clear."""
    global _async_exc_api
    if _async_exc_api is None:
        import ctypes

        setter = ctypes.PYFUNCTYPE(ctypes.c_int, ctypes.c_ulong, ctypes.py_object)(
            ("PyThreadState_SetAsyncExc", ctypes.pythonapi)
        )
        clearer = ctypes.PYFUNCTYPE(ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p)(
            ("PyThreadState_SetAsyncExc", ctypes.pythonapi)
        )
        _async_exc_api = (setter, clearer)
    return _async_exc_api


def _inject_async_exception(ident: int) -> None:
    _api()[0](ident, Evaporated)


class _TakenBack(BaseException):
    """Stand-in asynchronous exception that replaces a pending `Evaporated`; never escapes."""


def _delivery_point() -> None:
    """An empty Python function: entering it is an eval-breaker check, where CPython raises a
    pending asynchronous exception."""


def _take_back_async_exception(ident: int) -> None:
    """Cancel an asynchronous `Evaporated` that may still be pending for the calling thread.

    `ident` must be the calling thread's id. Setting the pending exception to NULL, the
    documented way, leaves CPython 3.11/3.12's interpreter-wide "asynchronous exception
    pending" flag set for good: every thread then takes the slow path of the eval loop at
    every call and loop iteration, and a thread traced by a debugger (pdb, bdb) or coverage
    spins forever. Instead the pending exception is replaced by `_TakenBack` and delivered,
    and caught, right here — delivery is what clears the flag. If nothing was pending, this
    delivers and catches only the stand-in.
    """
    setter = _api()[0]
    for _ in range(100):
        try:
            setter(ident, _TakenBack)  # CPython may raise it as this call returns ...
            _delivery_point()  # ... and will at the latest here
        except _TakenBack:
            return
    _api()[1](ident, None)  # pragma: no cover - never seen: fall back to the documented way


# -- re-delivering a swallowed evaporation ------------------------------------------------------

_code_dirs: tuple[str, tuple[str, ...], tuple[str, ...]] | None = None


def _is_plan_code(filename: str) -> bool:
    """True for a plan's own code; False for PyCRAM itself and the standard library, where an
    exception raised between two lines could leave a lock held or a queue inconsistent."""
    global _code_dirs
    if _code_dirs is None:
        import sysconfig  # only once a task swallowed evaporation: keeps `import pycram` lean

        pycram_dir = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep
        library = {os.path.abspath(sysconfig.get_paths()[k]) + os.sep for k in ("stdlib", "platstdlib")}
        _code_dirs = (pycram_dir, (os.path.join(pycram_dir, "demos") + os.sep,), tuple(library))
    pycram_dir, plan_dirs, library_dirs = _code_dirs
    path = os.path.abspath(filename)
    if path.startswith(pycram_dir):
        return path.startswith(plan_dirs)
    return not path.startswith(library_dirs) and not filename.startswith("<frozen")


def _resurface_in_plan_frames(frame: object) -> None:
    """Trace the calling thread's plan frames from `frame` outwards, so that the task is
    re-delivered `Evaporated` where it would swallow it again (see `_raise_if_swallowing`).

    Raising from a trace function unsets it (CPython), so each swallow re-arms it through the
    next PyCRAM call. A thread already traced by a debugger or coverage is left alone (its
    evaporation stays sticky at every PyCRAM call, as before).
    """
    if sys.gettrace() is not None:
        return
    while frame is not None:
        if _is_plan_code(frame.f_code.co_filename):  # type: ignore[attr-defined]
            frame.f_trace = _raise_if_swallowing  # type: ignore[attr-defined]
            frame.f_trace_lines = True  # type: ignore[attr-defined]
        frame = frame.f_back  # type: ignore[attr-defined]
    sys.settrace(_trace_no_new_frames)  # line events reach f_trace only while a trace is set


def _trace_no_new_frames(frame: object, event: str, arg: object) -> None:
    return None  # frames called from now on (PyCRAM, the library, `__exit__`s) run untraced


def _raise_if_swallowing(frame: Any, event: str, arg: object) -> object:
    """Line trace of a plan frame of a task that swallowed `Evaporated`: raise it again at a
    line outside any exception handler, and inside a handler that ends by swallowing what it
    handles (`except: pass`) — never in a `finally` block or a handler that re-raises, which
    is the task letting it propagate."""
    if event != "line":
        return _raise_if_swallowing
    runner = current_runner()
    task = runner.task
    if task is None or not task._evaporating:
        sys.settrace(None)  # the evaporated task ended: stop tracing this thread
        return None
    if runner.evaporation_due() and runner._mode == _USER:
        if sys.exc_info()[1] is None or _handler_swallows(frame.f_code, frame.f_lasti):
            runner._mark_delivered()
            raise Evaporated()
    return _raise_if_swallowing


_handler_ends: dict[tuple[Any, int], bool] = {}


def _handler_swallows(code: Any, offset: int) -> bool:
    """True if the exception handler running at `offset` of `code` ends by dropping the
    exception (`POP_EXCEPT` comes first) rather than re-raising it (`RERAISE`, `raise`)."""
    key = (code, offset)
    found = _handler_ends.get(key)
    if found is None:
        import dis  # only for tasks that swallowed evaporation

        found = False
        for instruction in dis.get_instructions(code):
            if instruction.offset < offset:
                continue
            if instruction.opname == "POP_EXCEPT":
                found = True
                break
            if instruction.opname in ("RERAISE", "RAISE_VARARGS"):
                break
        if len(_handler_ends) > 4096:
            _handler_ends.clear()
        _handler_ends[key] = found
    return found
