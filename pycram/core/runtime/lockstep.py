"""Lock-step time: a simulation that advances only while every plan thread waits.

A `LockstepClock` is a `ManualClock` that also knows which plan threads are running. A
simulation driving it (`pycram.sim.World(stepping="lockstep")`) steps only while none is: plan
code that computes for a long wall time (IK, costmaps, a loaded machine) costs no simulated
time, so what a plan does no longer depends on how fast the machine thinks. The cost model of
thinking is nothing: simulated time stands still while any plan thread runs.

Which threads count ("plan threads"):

* a task's thread from the moment its parent spawns it until it ends (`TaskGroup.spawn`);
* the thread that creates a lock-step world (`enter`), and any other thread from its first
  PyCRAM wait on the clock on (a thread that performs a plan directly), whenever it is not
  waiting.

A plan thread is *running* unless it blocks in a PyCRAM wait (`wait_until`: fluent waits,
`sleep`, process-module executions, command handles). When a waiter is woken, the thread that
wakes it counts it as running again at once -- before the simulation could take another step
-- as long as the condition it waited on is a PyCRAM `Condition` (every condition of the
runtime, fluents and process modules is). A waiter on a plain `threading.Condition` counts as
running only once it has woken up: waits on those are not lock-step.

A plan thread blocked outside PyCRAM (a lock, a queue, `time.sleep`) counts as running: the
simulation stands still until it waits in PyCRAM again. Waiting for the simulation that way
(with wall-clock sleeps) hangs a lock-step world -- wait on its fluents or command handles.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from pycram.core.runtime.clock import ManualClock, current_clock

__all__ = ["STEPPING_MODES", "Condition", "LockstepClock", "PlanThread", "current_lockstep"]

#: How a simulation keeps time with the plan (`pycram.sim.World(stepping=...)`): "free" runs as
#: fast as it can beside the plan (what the plan computes lets it run on: not reproducible);
#: "lockstep" advances only while every plan thread waits (a `LockstepClock`).
STEPPING_MODES = ("free", "lockstep")

_RUNNING, _BLOCKED, _WOKEN = "running", "blocked", "woken"


class LockstepClock(ManualClock):
    """A `ManualClock` that counts the plan threads running (see the module docstring).

    The simulation asks `quiet()` before each step and blocks in `wait_until_quiet` while a plan
    thread runs. Everything here is thread-safe; its lock is taken after a condition's lock
    (never the other way round), and the simulation waits holding neither.
    """

    def __init__(self, start: float = 0.0) -> None:
        super().__init__(start)
        self._quiet = threading.Condition(threading.Lock())  # guards the counts below
        self._running = 0  # plan threads running or woken (and spawned, not yet started)
        self._threads: dict[int, str] = {}  # thread ident -> running / blocked / woken
        self._waiting: dict[int, set[int]] = {}  # id(condition) -> idents blocked on it

    # -- what the simulation asks ----------------------------------------------------------
    def quiet(self) -> bool:
        """Whether every plan thread waits (the simulation may step)."""
        return self._running == 0

    @property
    def running(self) -> int:
        """How many plan threads run now (spawned and not yet started included)."""
        return self._running

    def wait_until_quiet(self, interrupted: Callable[[], bool]) -> None:
        """Block until every plan thread waits, or `interrupted()` (checked whenever `poke` is
        called: a command arrived, the world is closing)."""
        with self._quiet:
            while self._running > 0 and not interrupted():
                self._quiet.wait()

    def poke(self) -> None:
        """Wake `wait_until_quiet` to look at `interrupted()` again."""
        with self._quiet:
            self._quiet.notify_all()

    # -- what plan threads do ----------------------------------------------------------------
    def wait(self, condition: threading.Condition, deadline: float | None) -> None:
        if deadline is not None and deadline <= self._now:
            return
        me = threading.get_ident()
        with self._quiet:
            if self._threads.get(me) in (_RUNNING, _WOKEN):
                self._less()
            self._threads[me] = _BLOCKED
            self._waiting.setdefault(id(condition), set()).add(me)
        try:
            condition.wait()
        finally:
            with self._quiet:
                waiters = self._waiting.get(id(condition))
                if waiters is not None:
                    waiters.discard(me)
                    if not waiters:
                        del self._waiting[id(condition)]
                if self._threads.get(me) != _WOKEN:  # woken by a plain condition: counts from now
                    self._running += 1
                self._threads[me] = _RUNNING

    def notified(self, condition: threading.Condition) -> None:
        """`condition` (held by the caller) is about to wake all its waiters: count them as running."""
        with self._quiet:
            waiters = self._waiting.pop(id(condition), None)
            for ident in waiters or ():
                if self._threads.get(ident) == _BLOCKED:
                    self._threads[ident] = _WOKEN
                    self._running += 1

    def spawned(self) -> None:
        """A task thread is about to start: it runs from now on (before its thread does)."""
        with self._quiet:
            self._running += 1

    def enter(self) -> None:
        """The calling thread is a plan thread from now on, running (no-op if it is one)."""
        with self._quiet:
            me = threading.get_ident()
            if me not in self._threads:
                self._threads[me] = _RUNNING
                self._running += 1

    def leave(self) -> None:
        """The calling thread is no plan thread any more (a driver that only watches the plan,
        e.g. with wall-clock waits): the simulation no longer waits for it."""
        with self._quiet:
            if self._threads.pop(threading.get_ident(), _BLOCKED) != _BLOCKED:
                self._less()

    def adopt(self) -> None:
        """The calling thread is the task thread last `spawned` (its count is taken over)."""
        with self._quiet:
            self._threads[threading.get_ident()] = _RUNNING

    def ended(self) -> None:
        """The calling task thread has ended its task."""
        with self._quiet:
            if self._threads.pop(threading.get_ident(), _RUNNING) != _BLOCKED:
                self._less()

    def hand_over(self) -> None:
        """The calling thread ends, but the world keeps standing still for whoever `adopt`s its
        count next (a driver that watched the plan and now judges the world it left)."""
        with self._quiet:
            if self._threads.pop(threading.get_ident(), _RUNNING) == _BLOCKED:
                self._running += 1

    def _less(self) -> None:
        self._running -= 1
        if self._running == 0:
            self._quiet.notify_all()

    def __repr__(self) -> str:
        return f"LockstepClock(now={self._now:.3f}, running={self._running})"


def current_lockstep() -> LockstepClock | None:
    """The active clock if it is a `LockstepClock`, else None."""
    clock = current_clock()
    return clock if isinstance(clock, LockstepClock) else None


class Condition(threading.Condition):
    """A `threading.Condition` whose `notify_all` counts its waiters as running again on an
    active `LockstepClock` before waking them (so a lock-step simulation cannot step past the
    wake-up). Behaves exactly as `threading.Condition` otherwise; use `notify_all`, not
    `notify`, for waits that may be lock-step."""

    def notify_all(self) -> None:
        clock = current_clock()
        if isinstance(clock, LockstepClock):
            clock.notified(self)
        super().notify_all()


class PlanThread(threading.Thread):
    """A `threading.Thread` that is a plan thread of the lock-step clock active when it is
    started (if any), from `start()` to the end of its target -- as a task's thread is: the
    simulation does not step between its start and its first wait. Otherwise a plain thread.

    With `hand_over`, its end does not let the world run on: the thread that joins it takes its
    count over with `LockstepClock.adopt()` (the world the plan left is judged as it was left).
    """

    def __init__(self, *args: Any, hand_over: bool = False, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._hand_over = hand_over
        self._lockstep: LockstepClock | None = None

    def start(self) -> None:
        self._lockstep = current_lockstep()
        if self._lockstep is not None:
            self._lockstep.spawned()
        super().start()

    def run(self) -> None:
        lockstep = self._lockstep
        if lockstep is not None:
            lockstep.adopt()
        try:
            super().run()
        finally:
            if lockstep is not None:
                lockstep.hand_over() if self._hand_over else lockstep.ended()
