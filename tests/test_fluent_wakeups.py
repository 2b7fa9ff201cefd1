"""Which pulses wake a fluent's waiters (issue 31): a pulse that leaves a value the runtime
computes None wakes nobody -- in lock-step, nobody takes a turn for nothing -- while a fluent
valued by the user's own callable wakes its waiters on every pulse, and no wake-up is lost."""

from __future__ import annotations

import threading

import pytest

from pycram.core.fluent import Fluent
from pycram.core.runtime.clock import use_clock
from pycram.core.runtime.lockstep import Condition, LockstepClock, PlanThread


def _waiting(clock: LockstepClock, fluent: Fluent) -> tuple[PlanThread, list[bool]]:
    """A plan thread blocked in `fluent.wait_for()` (returns once the clock is quiet)."""
    returned: list[bool] = []
    thread = PlanThread(target=lambda: returned.append(fluent.wait_for()), daemon=True)
    thread.start()
    clock.wait_until_quiet(lambda: False)  # gives it its turn, returns once it waits
    return thread, returned


def _finish(clock: LockstepClock, thread: PlanThread) -> None:
    clock.wait_until_quiet(lambda: False)
    thread.join(10.0)
    assert not thread.is_alive()


def test_a_pulse_that_leaves_a_network_none_wakes_nobody():
    clock = LockstepClock()
    with use_clock(clock):
        opening = Fluent(0.05)
        dropped = opening < 0.01
        thread, returned = _waiting(clock, dropped)
        for value in (0.05, 0.04, 0.03):
            opening.set_value(value)
            # woken, the waiter would count as running at once (before this call returned)
            assert clock.running == 0 and clock.quiet()
        assert not returned
        opening.set_value(0.0)
        assert clock.running == 1  # counted as running before it even woke: the world waits for it
        _finish(clock, thread)
    assert returned == [True]


def test_a_pulse_fluent_wakes_its_waiter_on_each_pulse():
    clock = LockstepClock()
    with use_clock(clock):
        source = Fluent(0)
        pulsed = source.pulsed()
        thread, returned = _waiting(clock, pulsed)
        source.set_value(0)
        assert clock.running == 1
        _finish(clock, thread)
    assert returned == [True]


@pytest.mark.parametrize("network", [False, True])
def test_a_value_of_the_users_own_callable_wakes_its_waiters_on_every_pulse(network):
    """The runtime cannot know what a callable of the user's returns in the waiter's thread:
    such a fluent (and a network over it) wakes its waiters even when it reads None here."""
    clock = LockstepClock()
    answers = [None]
    with use_clock(clock):
        own = Fluent(lambda: answers[-1])
        waited = (own > 3) if network else own
        thread, returned = _waiting(clock, waited)
        own.pulse()  # still None: the waiter wakes, finds None, waits again
        assert clock.running == 1
        clock.wait_until_quiet(lambda: False)
        assert not returned and thread.is_alive()
        answers.append(5)
        own.pulse()
        _finish(clock, thread)
    assert returned == [True]


def test_a_network_set_from_two_threads_at_once_loses_no_wake_up():
    """Two threads change the inputs of `a + b >= 2 n` while a third waits on it (plain
    threads, the wall clock): the wait ends each time, however the changes interleave."""
    n = 300
    for _ in range(20):
        a, b = Fluent(0), Fluent(0)
        done = (a + b) >= 2 * n
        returned: list[bool] = []
        waiter = threading.Thread(target=lambda d=done, r=returned: r.append(d.wait_for(timeout=30.0)))
        waiter.start()
        setters = [threading.Thread(target=lambda f=f: [f.set_value(i) for i in range(n + 1)]) for f in (a, b)]
        for thread in setters:
            thread.start()
        for thread in (*setters, waiter):
            thread.join(60.0)
        assert returned == [True]


def test_notify_all_without_the_lock_is_refused_also_with_nobody_waiting():
    condition = Condition(threading.Lock())
    with pytest.raises(RuntimeError, match="un-acquired lock"):
        condition.notify_all()
    with condition:
        condition.notify_all()  # nobody waits: nothing to do
