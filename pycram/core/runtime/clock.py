"""Clocks: where plan time comes from.

Every timed wait in PyCRAM (`Fluent.wait_for(timeout)`, `pycram.sleep`, `with_timeout`, task
start and end times) reads the *active clock*. By default that is the wall clock; a simulation
installs a `ManualClock` that it advances from its own thread, so plans run faster than real time
and time-outs follow simulated time.

Waiting is always condition-based: a clock never polls. `WallClock` waits with the native
timeout of `threading.Condition.wait`; `ManualClock` keeps a heap of deadlines and notifies
the waiters' conditions when `advance_to` passes them.
"""

from __future__ import annotations

import heapq
import itertools
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = [
    "Clock",
    "WallClock",
    "ManualClock",
    "current_clock",
    "use_clock",
    "set_clock",
    "add_clock_listener",
    "remove_clock_listener",
]


class Clock:
    """Source of plan time in seconds.

    Subclasses implement `now` and `wait`, and may implement `register`/`unregister` when their
    time does not flow by itself. A timed wait is: `handle = register(deadline, condition)`, then
    `wait(condition, deadline)` in a loop that re-checks its predicate and `now() >= deadline`,
    then `unregister(handle)`. `wait` is called with `condition` held and must release it while
    blocking (as `threading.Condition.wait` does); spurious wake-ups are allowed.

    `kind` says what its times mean to a reader of a trace: "wall-clock", "simulated" ("custom"
    for a subclass that does not say).
    """

    kind = "custom"

    def now(self) -> float:
        """The current time [s]."""
        raise NotImplementedError

    def wait(self, condition: threading.Condition, deadline: float | None) -> None:
        """Block on `condition` (held by the caller) until notified or until `deadline` [s]."""
        raise NotImplementedError

    def register(self, deadline: float, condition: threading.Condition) -> object:
        """Arrange for `condition` to be notified at `deadline` [s]; returns a handle."""
        return None

    def unregister(self, handle: object) -> None:
        """Cancel a wake-up made by `register` (a no-op for None)."""


class WallClock(Clock):
    """The monotonic wall clock (`time.monotonic`); deadlines use the native condition time-out."""

    kind = "wall-clock"

    def now(self) -> float:
        return time.monotonic()

    def wait(self, condition: threading.Condition, deadline: float | None) -> None:
        if deadline is None:
            condition.wait()
        else:
            remaining = deadline - time.monotonic()
            if remaining > 0:
                condition.wait(remaining)

    def __repr__(self) -> str:
        return "WallClock()"


class ManualClock(Clock):
    """A clock that only moves when told to: by a simulation after each step, or by a test.

    `advance_to(t)` is thread-safe and notifies every registered waiter whose deadline is at or
    before `t`. A timed wait on a `ManualClock` that nobody advances blocks until something else
    wakes the waiter (a fluent change or evaporation) — it never busy-waits.

    Its `kind` is "simulated": its time is what a simulation (or a test) says it is.
    """

    kind = "simulated"

    def __init__(self, start: float = 0.0) -> None:
        self._now = float(start)
        self._lock = threading.Lock()
        self._heap: list[list[Any]] = []  # [deadline, order, condition, alive]
        self._order = itertools.count()

    def now(self) -> float:
        return self._now

    def wait(self, condition: threading.Condition, deadline: float | None) -> None:
        if deadline is not None and deadline <= self._now:
            return
        condition.wait()

    def register(self, deadline: float, condition: threading.Condition) -> object:
        entry = [deadline, next(self._order), condition, True]
        with self._lock:
            heapq.heappush(self._heap, entry)
        return entry

    def unregister(self, handle: object) -> None:
        if handle is not None:
            handle[3] = False  # type: ignore[index]

    def advance(self, dt: float) -> None:
        """Move the clock forward by `dt` [s]."""
        self.advance_to(self._now + dt)

    def advance_to(self, t: float) -> None:
        """Set the time to `t` [s] (never backwards) and wake the waiters whose deadline passed."""
        due: list[threading.Condition] = []
        with self._lock:
            if t > self._now:
                self._now = float(t)
            heap = self._heap
            while heap and heap[0][0] <= self._now:
                entry = heapq.heappop(heap)
                if entry[3]:
                    due.append(entry[2])
        for condition in due:
            with condition:
                condition.notify_all()

    def next_deadline(self) -> float | None:
        """The earliest pending deadline [s], or None (lets a test jump straight to it)."""
        with self._lock:
            heap = self._heap
            while heap and not heap[0][3]:
                heapq.heappop(heap)
            return heap[0][0] if heap else None

    def __repr__(self) -> str:
        return f"ManualClock(now={self._now:.3f})"


_WALL_CLOCK = WallClock()
_active_clock: Clock = _WALL_CLOCK
_clock_listeners: tuple[Callable[[Clock], None], ...] = ()
_listeners_lock = threading.Lock()


def add_clock_listener(listener: Callable[[Clock], None]) -> None:
    """Call `listener(new_clock)` whenever `set_clock` changes the active clock (in the thread
    that changed it; keep it short and never block -- a trace recorder notes the clock kind)."""
    global _clock_listeners
    with _listeners_lock:
        _clock_listeners = (*_clock_listeners, listener)


def remove_clock_listener(listener: Callable[[Clock], None]) -> None:
    """Stop calling `listener` (no error if it was not added)."""
    global _clock_listeners
    with _listeners_lock:
        _clock_listeners = tuple(x for x in _clock_listeners if x != listener)


def current_clock() -> Clock:
    """The active clock (process-wide, shared by all plan threads)."""
    return _active_clock


def set_clock(clock: Clock | None) -> Clock:
    """Make `clock` the active clock (None: the wall clock); returns the previous one."""
    global _active_clock
    previous = _active_clock
    _active_clock = clock if clock is not None else _WALL_CLOCK
    if _active_clock is not previous:
        for listener in _clock_listeners:
            listener(_active_clock)
    return previous


@contextmanager
def use_clock(clock: Clock) -> Iterator[Clock]:
    """Activate `clock` for the duration of the block, then restore the previous clock."""
    previous = set_clock(clock)
    try:
        yield clock
    finally:
        set_clock(previous)
