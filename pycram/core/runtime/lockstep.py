"""Lock-step time: a simulation that advances only while every plan thread waits, and plan
threads that run one at a time, in task order.

A `LockstepClock` is a `ManualClock` that also knows which plan threads are running. A
simulation driving it (`pycram.sim.World(stepping="lockstep")`, the default) steps only while
none is: plan code that computes for a long wall time (IK, costmaps, a loaded machine) costs no
simulated time, so what a plan does no longer depends on how fast the machine thinks. The cost
model of thinking is nothing: simulated time stands still while any plan thread runs.

**Turns.** Of the plan threads that could run, one runs at a time: the one first in *task
order*. A thread's key is its spawner's key followed by how many threads the spawner had
started before it (the thread that created the world is ``(0,)``; the branches of a `par` in
it ``(0, 0)``, ``(0, 1)``...), so a parent comes before its children and siblings come in the
order they were started -- the same order in every run, whatever the operating system does. A
thread keeps the turn until it waits in PyCRAM (or ends); then the next one in task order gets
it. The threads a simulation step woke (a fluent changed, a deadline passed, a command ended)
get their turns only once the step is over and every sensor fluent shows the new state, and the
simulation steps again only when all of them wait again. So everything the plan does -- the
commands it sends, the belief updates it makes, the random numbers it draws -- happens in one
order, and the same seed gives the same run. (The alternative, letting threads run in parallel
and sorting what they did afterwards, would have to know every kind of shared state a plan may
touch; turns make the order a property of the runtime, as a deterministic simulator's scheduler
does.)

Which threads count ("plan threads"):

* a task's thread from the moment its parent spawns it until it ends (`TaskGroup.spawn`), and a
  `PlanThread`;
* the thread that creates a lock-step world (`enter`).

Any other thread is no plan thread: its PyCRAM waits are plain waits, and the world steps while
it runs (a test's helper thread acting as a person, a display). A thread of your own that runs
plan code is a `PlanThread` (or calls `enter`), or its work runs as a task.

A plan thread is *running* unless it blocks in a PyCRAM wait (`wait_until`: fluent waits,
`sleep`, process-module executions, command handles). When a waiter is woken, the thread that
wakes it counts it as running again at once -- before the simulation could take another step
-- as long as the condition it waited on is a PyCRAM `Condition` (every condition of the
runtime, fluents and process modules is). A waiter on a plain `threading.Condition` counts as
running only once it has woken up (and takes the next turn free): waits on those are not
lock-step.

A plan thread blocked outside PyCRAM (a lock, a queue, `time.sleep`, joining another thread)
keeps the turn: the simulation and every other plan thread stand still until it waits in
PyCRAM again. Waiting for the simulation or for another plan thread that way hangs a lock-step
world -- wait on fluents or command handles; a thread that only watches a plan by wall time
`leave`s first (or waits inside `LockstepClock.watching()`). A PyCRAM wait while holding
another lock that a plan thread may need deadlocks too (the waiter, woken, waits for its turn
holding it).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from pycram.core.runtime.clock import ManualClock, current_clock

__all__ = ["DEFAULT_STEPPING", "STEPPING_MODES", "Condition", "LockstepClock", "PlanThread", "current_lockstep"]

#: How a simulation keeps time with the plan (`pycram.sim.World(stepping=...)`): "free" runs as
#: fast as it can beside the plan (what the plan computes lets it run on: not reproducible);
#: "lockstep" advances only while every plan thread waits (a `LockstepClock`).
STEPPING_MODES = ("free", "lockstep")

#: What a simulation does unless told otherwise: keep step with the plan (reproducible runs).
DEFAULT_STEPPING = "lockstep"

_RUNNING, _BLOCKED, _WOKEN = "running", "blocked", "woken"

#: The key of a plan thread that is no task's: after every task of the tree (by arrival).
_OUTSIDE = 1 << 40


class _Ticket:
    """A plan thread's place in the queue for the turn before its thread exists (a spawned
    task, a handed-over count)."""

    __slots__ = ("key",)

    def __init__(self, key: tuple[int, ...]) -> None:
        self.key = key


class LockstepClock(ManualClock):
    """A `ManualClock` that lets one plan thread run at a time and the simulation step only
    while none does (see the module docstring).

    The simulation asks `quiet()` before each step and blocks in `wait_until_quiet` while a plan
    thread runs; `wait_until_quiet` is also where the threads its step woke get their turns.
    Everything here is thread-safe; its lock is taken after a condition's lock (never the other
    way round), and nobody waits for the turn holding a condition's lock.
    """

    def __init__(self, start: float = 0.0) -> None:
        super().__init__(start)
        self._guard = threading.Lock()
        self._quiet = threading.Condition(self._guard)  # guards everything below
        self._turn_of: dict[object, threading.Condition] = {}  # who waits for the turn -> its condition
        self._running = 0  # plan threads running or woken (and spawned, not yet started)
        self._threads: dict[int, str] = {}  # thread ident -> running / blocked / woken
        self._waiting: dict[int, set[int]] = {}  # id(condition) -> idents blocked on it
        self._keys: dict[int, tuple[int, ...]] = {}  # thread ident -> its place in task order
        self._children: dict[int, int] = {}  # thread ident -> how many threads it spawned
        self._ready: dict[object, tuple[int, ...]] = {}  # who wants the turn (ident or ticket) -> key
        self._holder: object | None = None  # whose turn it is (ident or ticket)
        self._handed: list[_Ticket] = []  # counts handed over, for `adopt()`
        self._outside = 0
        self._stopped = False
        self._stepper: int | None = None  # the simulation's thread (`steps_here`)

    # -- what the simulation asks ----------------------------------------------------------
    def quiet(self) -> bool:
        """Whether every plan thread waits (the simulation may step)."""
        return self._running == 0

    @property
    def running(self) -> int:
        """How many plan threads run now (spawned and not yet started included)."""
        return self._running

    def wait_until_quiet(self, interrupted: Callable[[], bool]) -> None:
        """Give the turns (in task order) and block until every plan thread waits, or
        `interrupted()` (checked whenever `poke` is called: a command arrived, the world is
        closing)."""
        with self._guard:
            while self._running > 0 and not interrupted():
                self._grant()
                self._quiet.wait()

    def steps_here(self) -> None:
        """The calling thread steps the simulation: the threads it wakes get their turns in
        `wait_until_quiet`, once its step is over (others' wake-ups are given turns at once)."""
        with self._guard:
            self._stepper = threading.get_ident()

    def poke(self) -> None:
        """Wake `wait_until_quiet` to look at `interrupted()` again."""
        with self._guard:
            self._quiet.notify_all()

    def stop(self) -> None:
        """The simulation has ended: from now on plan threads run without taking turns (nothing
        steps any more that they could keep in order)."""
        with self._guard:
            self._stopped = True
            for turn in self._turn_of.values():
                turn.notify()

    # -- what plan threads do ----------------------------------------------------------------
    def wait(self, condition: threading.Condition, deadline: float | None) -> None:
        if deadline is not None and deadline <= self._now:
            return
        me = threading.get_ident()
        with self._guard:
            state = self._threads.get(me)
            registered = state is not None  # else no plan thread: a plain wait (nobody waits for it)
            if state in (_RUNNING, _WOKEN):
                self._less()
            if registered:
                self._release(me)
                self._threads[me] = _BLOCKED
                self._waiting.setdefault(id(condition), set()).add(me)
        if not registered:
            condition.wait()
            return
        try:
            condition.wait()
        finally:
            with self._guard:
                waiters = self._waiting.get(id(condition))
                if waiters is not None:
                    waiters.discard(me)
                    if not waiters:
                        del self._waiting[id(condition)]
                if self._threads.get(me) != _WOKEN:  # woken by a plain condition: counts from now
                    self._running += 1
                    self._ready[me] = self._keys.get(me) or self._outsider()
                    self._grant()  # nobody else will: it was not woken in the simulation's step
                self._threads[me] = _RUNNING
            # wait for the turn without the condition's lock (its holder may need that lock)
            saved = condition._release_save()  # type: ignore[attr-defined]
            try:
                with self._guard:
                    self._take(me)
            finally:
                condition._acquire_restore(saved)  # type: ignore[attr-defined]

    def notified(self, condition: threading.Condition) -> None:
        """`condition` (held by the caller) is about to wake all its waiters: count them as
        running, each waiting for its turn."""
        with self._guard:
            waiters = self._waiting.pop(id(condition), None)
            for ident in waiters or ():
                if self._threads.get(ident) == _BLOCKED:
                    self._threads[ident] = _WOKEN
                    self._running += 1
                    self._ready[ident] = self._keys.get(ident) or self._outsider()
            if waiters and self._holder is None and threading.get_ident() != self._stepper:
                self._grant()  # woken by a thread that is neither a plan thread nor the simulation

    def spawned(self) -> _Ticket:
        """A task thread is about to start: it runs from now on (before its thread does), after
        its spawner in task order. Returns the ticket its thread `adopt`s."""
        with self._guard:
            me = threading.get_ident()
            parent = self._keys.get(me)
            if parent is None:
                key = self._outsider()
            else:
                n = self._children.get(me, 0)
                self._children[me] = n + 1
                key = (*parent, n)
            ticket = _Ticket(key)
            self._running += 1
            self._ready[ticket] = key
            return ticket

    def enter(self) -> None:
        """The calling thread is a plan thread from now on, running (no-op if it is one); waits
        for its turn."""
        with self._guard:
            me = threading.get_ident()
            if me in self._threads:
                return
            self._threads[me] = _RUNNING
            self._running += 1
            self._keys[me] = key = (len([k for k in self._keys.values() if len(k) == 1]),)
            self._ready[me] = key
            self._grant()
            self._take(me)

    def leave(self) -> None:
        """The calling thread is no plan thread any more (a driver that only watches the plan,
        e.g. with wall-clock waits): the simulation no longer waits for it."""
        with self._guard:
            me = threading.get_ident()
            if self._threads.pop(me, _BLOCKED) != _BLOCKED:
                self._less()
            self._release(me)
            self._forget(me)

    @contextmanager
    def watching(self) -> Iterator[None]:
        """Inside the block the calling plan thread only watches (by wall time, plain waits):
        it is no plan thread, and the simulation and the other plan threads go on; on leaving
        the block it is one again and waits for its turn. A thread that is no plan thread just
        runs the block."""
        with self._guard:
            was = threading.get_ident() in self._threads
        if was:
            self.leave()
        try:
            yield
        finally:
            if was:
                self.enter()

    def adopt(self, ticket: _Ticket | None = None) -> None:
        """The calling thread is the one `ticket` was spawned for (its count is taken over), or,
        without a ticket, the one the count last handed over (`hand_over`) is for. Waits for its
        turn."""
        with self._guard:
            me = threading.get_ident()
            if ticket is None:
                if not self._handed:
                    raise RuntimeError("adopt() without a ticket needs a count handed over by hand_over()")
                ticket = self._handed.pop(0)
            self._threads[me] = _RUNNING
            self._keys[me] = ticket.key
            self._children[me] = 0
            if self._holder is ticket:
                self._holder = me
            else:
                self._ready[me] = self._ready.pop(ticket, ticket.key)
            self._take(me)

    def ended(self) -> None:
        """The calling task thread has ended its task."""
        with self._guard:
            me = threading.get_ident()
            if self._threads.pop(me, _RUNNING) != _BLOCKED:
                self._less()
            self._release(me)
            self._forget(me)

    def hand_over(self) -> None:
        """The calling thread ends, but the world keeps standing still for whoever `adopt`s its
        count next (a driver that watched the plan and now judges the world it left)."""
        with self._guard:
            me = threading.get_ident()
            ticket = _Ticket(self._keys.get(me) or self._outsider())
            if self._threads.pop(me, _RUNNING) == _BLOCKED:
                self._running += 1
            if self._holder == me:
                self._holder = ticket  # the turn stays taken until the adopter has it
            else:
                self._ready.pop(me, None)
                self._ready[ticket] = ticket.key
            self._handed.append(ticket)
            self._forget(me)

    # -- turns (all with the guard held) ----------------------------------------------------
    def _outsider(self) -> tuple[int, ...]:
        self._outside += 1
        return (_OUTSIDE, self._outside)

    def _grant(self) -> None:
        """Give the turn to the first thread in task order that wants it, if nobody has it."""
        if self._holder is None and self._ready:
            holder = min(self._ready, key=self._ready.__getitem__)
            del self._ready[holder]
            self._holder = holder
            turn = self._turn_of.get(holder)
            if turn is not None:
                turn.notify()  # only the one whose turn it is (a par of 100 wakes 1, not 100)

    def _take(self, me: int) -> None:
        if self._holder != me and not self._stopped:
            turn = self._turn_of[me] = threading.Condition(self._guard)
            try:
                while self._holder != me and not self._stopped:
                    turn.wait()
            finally:
                del self._turn_of[me]
        self._ready.pop(me, None)

    def _release(self, me: int) -> None:
        """The calling thread stops running: the next one in task order gets the turn."""
        self._ready.pop(me, None)
        if self._holder == me:
            self._holder = None
            self._grant()

    def _forget(self, me: int) -> None:
        self._keys.pop(me, None)
        self._children.pop(me, None)

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
        if not self._waiters:  # type: ignore[attr-defined]
            # Nobody waits: nothing to count or wake (most pulses of a simulation's sensor
            # fluents). Read with this condition's lock held (checked below), so no wake-up is
            # lost: a waiter enqueues itself in `wait()` before it releases the lock, and it
            # tested its predicate under the same lock, after the notifier changed the value
            # or before the notifier could take the lock.
            if not self._is_owned():  # type: ignore[attr-defined]
                raise RuntimeError("cannot notify on un-acquired lock")
            return
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
        self._ticket: _Ticket | None = None

    def start(self) -> None:
        self._lockstep = current_lockstep()
        if self._lockstep is not None:
            self._ticket = self._lockstep.spawned()
        super().start()

    def run(self) -> None:
        lockstep = self._lockstep
        if lockstep is not None:
            lockstep.adopt(self._ticket)
        try:
            super().run()
        finally:
            if lockstep is not None:
                lockstep.hand_over() if self._hand_over else lockstep.ended()
