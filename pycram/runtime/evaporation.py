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
task (`check_evaporation`, waits, `sleep`, expressions, `retry`) raises it again.

Every thread that runs PyCRAM code has a `Runner`: its current task and the state needed to
interrupt it. This module knows tasks only through two attributes: `_evaporating` (bool) and
`_runner`.
"""

from __future__ import annotations

import os
import threading
from contextlib import contextmanager
from typing import Callable, Iterator

from pycram.runtime.clock import current_clock

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
    not resurrect the task — every later PyCRAM call raises it again — so let it propagate and
    put clean-up in `finally` blocks or context managers, which always run.
    """


class Runner:
    """The per-thread execution state: current task, wait registration, interrupt state."""

    __slots__ = ("task", "ident", "detached", "_mode", "_waiting_on", "_injected", "_missed", "_protected", "_lock",
                 "_sleep")

    def __init__(self, task: object | None = None, ident: int | None = None) -> None:
        self.task = task
        self.ident = ident  # the thread's identifier once the runner is installed in it
        self.detached: list = []  # task groups started without waiting (see TaskGroup)
        self._mode = _USER
        self._waiting_on: threading.Condition | None = None
        self._injected = False
        self._missed = False  # an interrupt found the thread in runtime code, not waiting
        self._protected = 0
        self._lock = threading.Lock()
        self._sleep: threading.Condition | None = None

    # -- state of the current task -------------------------------------------------------------

    def evaporation_due(self) -> bool:
        """True when the current task is evaporating and not inside `no_evaporation`."""
        task = self.task
        return task is not None and task._evaporating and not self._protected

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

    def _wait_on(self, condition: threading.Condition) -> None:
        """Register the condition a wait blocks on, so that `interrupt` can notify it."""
        with self._lock:
            self._waiting_on = condition

    def seal(self) -> None:
        """Mark the thread as finishing: no asynchronous exception can reach it after this."""
        with self._lock:
            if self._injected:
                self._injected = False
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
        if not self.evaporation_due():
            return
        injected = False
        with self._lock:
            condition = self._waiting_on
            if condition is None and self._mode == _USER and not self._injected and self.ident is not None:
                self._injected = injected = True
                _inject_async_exception(self.ident)
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
            condition = self._sleep = threading.Condition(threading.Lock())
        return condition


_local = threading.local()


def current_runner() -> Runner:
    """The calling thread's runner (created on first use for threads PyCRAM did not start)."""
    try:
        return _local.runner
    except AttributeError:
        runner = _local.runner = Runner(ident=threading.get_ident())
        return runner


def install_runner(runner: Runner) -> None:
    """Make `runner` the calling thread's runner (used by the task module for new threads)."""
    with runner._lock:
        runner.ident = threading.get_ident()
    _local.runner = runner


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
        raise Evaporated()
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
        raise Evaporated()


def wait_until(
    condition: threading.Condition,
    predicate: Callable[[], object],
    timeout: float | None = None,
) -> bool:
    """Block until `predicate()` is true; the one blocking primitive of PyCRAM.

    `predicate` is evaluated with `condition` held, first at once and then each time the
    condition is notified. Returns True when the predicate holds, False when `timeout` [s] of
    the active clock has passed. Raises `Evaporated` at once when the calling task is (or
    becomes) evaporating. A suspended task (`pycram.runtime.suspension`) stays blocked here
    until woken up, even if the predicate became true meanwhile; the time-out keeps running.
    Never polls.
    """
    return _wait(condition, predicate, timeout, True)


def _wait(condition: threading.Condition, predicate: Callable[[], object], timeout: float | None,
          suspendable: bool) -> bool:
    runner = current_runner()
    if runner.evaporation_due():
        raise Evaporated()
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


def _wait_locked(runner: Runner, condition: threading.Condition, predicate: Callable[[], object],
                 timeout: float | None, deadline: float | None, suspendable: bool) -> object:
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
    """What the wait loop needs from `pycram.runtime.suspension` (installed there on first use).

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


def wait_unsuspendable(condition: threading.Condition, predicate: Callable[[], object],
                       timeout: float | None = None) -> bool:
    """`wait_until` that a suspension does not stop (runtime internal: the suspension block)."""
    return _wait(condition, predicate, timeout, False)


def notify_waiters(condition: threading.Condition) -> None:
    """Wake every thread waiting on `condition`; safe against asynchronous evaporation.

    Raises `Evaporated` only where an asynchronous one was about to land anyway.
    """
    runner = current_runner()
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


_async_exc_api: tuple | None = None


def prepare_interrupts() -> None:
    """Load the C API used to interrupt busy threads (done before the first branch starts, so
    that the first evaporation is not slowed down by importing ctypes under GIL contention)."""
    _api()


def _api() -> tuple:
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
