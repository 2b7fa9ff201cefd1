"""Fluents, fluent networks, pulses and whenever (thesis 3.2.2 and the defects it had)."""

from __future__ import annotations

import gc
import sys
import threading
import time

import pytest

from pycram.fluent import STOP, Behavior, Fluent, whenever
from pycram.language import State, par, pursue, seq
from pycram.runtime import ManualClock, sleep, use_clock

WAIT = 5.0  # generous upper bound for waits that must succeed [s]


def start_thread(fn) -> threading.Thread:
    thread = threading.Thread(target=fn, daemon=True)
    thread.start()
    return thread


# -- basics --------------------------------------------------------------------------------------


def test_thesis_get_and_set_value():
    f = Fluent(1)
    assert f.get_value() == 1
    f.set_value(2)
    assert f.get_value() == 2


def test_default_value_is_none_and_names_are_random_unless_given():
    a, b = Fluent(), Fluent()
    assert a.get_value() is None
    assert a.name != b.name and len(a.name) >= 32
    assert Fluent(name="pose").name == "pose"


def test_callable_values_are_reevaluated_on_read():
    counter = iter(range(100))
    f = Fluent(lambda: next(counter))
    assert [f.get_value(), f.get_value(), f.get_value()] == [0, 1, 2]


def test_wait_for_returns_at_once_when_set_and_false_on_timeout():
    assert Fluent(0).wait_for() is True  # 0 is not None
    assert Fluent(False).wait_for() is True
    started = time.monotonic()
    assert Fluent().wait_for(timeout=0.05) is False
    assert time.monotonic() - started >= 0.045


def test_wait_for_wakes_when_value_is_set_from_another_thread():
    goal_reached = Fluent()
    woke = threading.Event()

    def waiter():
        if goal_reached.wait_for(timeout=WAIT):
            woke.set()

    thread = start_thread(waiter)
    goal_reached.set_value(True)
    assert woke.wait(WAIT)
    thread.join(WAIT)


def _wait_until_blocked(fluent: Fluent, count: int) -> None:
    """Until `count` threads are blocked in `fluent.wait_for()` (CPython's Condition keeps its
    waiters in `_waiters`): only then does a single `set_value` have to wake all of them."""
    cv = fluent._condition()
    deadline = time.monotonic() + WAIT
    while len(cv._waiters) < count:
        assert time.monotonic() < deadline, f"only {len(cv._waiters)} of {count} waiters blocked"
        time.sleep(0.001)


def test_every_waiter_wakes_not_just_one():
    f = Fluent()
    network = f > 3  # waiters on a network wake too
    woke = []
    lock = threading.Lock()

    def waiter(i, fluent):
        if fluent.wait_for(timeout=WAIT):
            with lock:
                woke.append(i)

    threads = [start_thread(lambda i=i: waiter(i, f if i < 10 else network)) for i in range(20)]
    _wait_until_blocked(f, 10)
    _wait_until_blocked(network, 10)
    f.set_value(5)  # one change: with notify() instead of notify_all() only one would wake
    for thread in threads:
        thread.join(WAIT)
    assert sorted(woke) == list(range(20))


def test_set_value_always_pulses_even_with_the_same_value():
    f = Fluent(1)
    p = f.pulsed()
    f.set_value(1)
    assert p.get_value() is True


def test_fluent_is_hashable_by_identity_despite_overloaded_eq():
    a, b = Fluent(1), Fluent(1)
    assert len({a, b, a}) == 2
    table = {a: "a", b: "b"}
    assert table[a] == "a" and table[b] == "b"
    assert isinstance(a == b, Fluent)  # == builds a network ...
    assert (a == b).get_value() is True  # ... valued True while the values are equal


def test_bool_of_a_fluent_is_a_clear_error():
    f = Fluent(5, name="speed")
    with pytest.raises(TypeError, match="no truth value.*get_value"):
        if f > 3:
            pass


# -- networks ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "build, low, high",
    [
        (lambda f: f < 3, 5, 1),
        (lambda f: f <= 3, 4, 3),
        (lambda f: f > 3, 1, 5),
        (lambda f: f >= 3, 2, 3),
        (lambda f: f == 3, 2, 3),
        (lambda f: f != 3, 3, 2),
        (lambda f: f.IS(None), 1, None),
        (lambda f: f.IS_NOT(None), None, 1),
    ],
)
def test_comparison_networks_are_true_or_none_and_follow_their_input(build, low, high):
    f = Fluent(low)
    network = build(f)
    assert network.get_value() is None
    f.set_value(high)
    assert network.get_value() is True


def test_arithmetic_networks_and_reflected_forms():
    f = Fluent(6)
    assert (f + 1).get_value() == 7 and (1 + f).get_value() == 7
    assert (f - 1).get_value() == 5 and (10 - f).get_value() == 4
    assert (f * 2).get_value() == 12 and (2 * f).get_value() == 12
    assert (f / 3).get_value() == 2 and (12 / f).get_value() == 2
    g = Fluent(4)
    assert (f + g).get_value() == 10
    g.set_value(5)
    assert (f + g).get_value() == 11


def test_networks_over_none_are_none_not_type_errors():
    f = Fluent()
    assert (f < 3).get_value() is None
    assert (f + 1).get_value() is None
    assert (f / 3 < 1).get_value() is None


def test_logical_networks():
    a, b = Fluent(True), Fluent(None)
    assert a.AND(b).get_value() is None
    assert a.OR(b).get_value() is True
    assert b.NOT().get_value() is True
    b.set_value(1)
    assert a.AND(b).get_value() is True
    assert a.AND(True).get_value() is True and a.AND(0).get_value() is None


def test_thesis_example_wait_for_division_network():
    f = Fluent(9)
    done = threading.Event()

    def waiter():
        if (f / 3 < 1).wait_for(timeout=WAIT):
            done.set()

    thread = start_thread(waiter)
    assert not done.wait(0.02)
    f.set_value(2)
    assert done.wait(WAIT)
    thread.join(WAIT)


def test_waiter_on_network_wakes_when_either_input_changes():
    a, b = Fluent(1), Fluent(5)
    network = a > b
    done = threading.Event()

    def waiter():
        if network.wait_for(timeout=WAIT):
            done.set()

    thread = start_thread(waiter)
    b.set_value(0)  # the second input changes
    assert done.wait(WAIT)
    thread.join(WAIT)


def test_thesis_user_defined_network_with_add_child():
    f = Fluent(9)
    fluent_net = Fluent(lambda: f.get_value() / 3)
    f.add_child(fluent_net)
    done = threading.Event()

    def waiter():
        if (fluent_net < 1).wait_for(timeout=WAIT):
            done.set()

    thread = start_thread(waiter)
    f.set_value(1.5)
    assert done.wait(WAIT)
    thread.join(WAIT)


def test_a_million_temporary_networks_keep_memory_flat():
    """The thesis' parents kept every child alive: `while ...: (f < 3).wait_for()` leaked."""
    f = Fluent(1)
    for _ in range(10_000):  # warm-up: caches, free lists
        (f < 3).get_value()
    gc.collect()
    blocks = sys.getallocatedblocks()
    longest = 0
    for i in range(1_000_000):
        (f < 3).get_value()
        if i % 100_000 == 0:
            f.set_value(1)  # pulses walk the (pruned) children
            longest = max(longest, len(f._children))
    gc.collect()
    assert len(f._children) < 64 and longest < 64  # dead references are pruned
    assert [ref for ref in f._children if ref() is not None] == []
    # a leak would hold >= 1,000,000 fluents (several blocks each); allow for unrelated noise
    assert sys.getallocatedblocks() - blocks < 10_000


def test_adding_many_live_children_is_not_quadratic():
    f = Fluent(0)
    kept = [f.pulsed() for _ in range(20_000)]  # amortised O(1) each: a copy-on-add tuple was O(n)
    f.pulse()
    assert all(p.get_value() is True for p in kept)
    assert len(f._children) == 20_000


def test_networks_stay_alive_while_used_and_die_afterwards():
    f = Fluent(1)
    kept = f < 3
    for _ in range(1000):
        f + 1
    gc.collect()
    assert [ref() for ref in f._children if ref() is not None] == [kept]


# -- pulses and whenever --------------------------------------------------------------------------


def test_pulsed_fluent_becomes_true_on_set_and_on_pulse():
    f = Fluent(1)
    p = f.pulsed()
    assert p.get_value() is None
    f.pulse()
    assert p.get_value() is True


def test_pulsed_default_behavior_is_once():
    assert Fluent().pulsed()._handle_missed is Behavior.ONCE


def _count_runs_with_missed_pulses(behavior: Behavior, missed: int, expected: int) -> int:
    """Run a whenever body that is blocked while `missed` pulses arrive; count its runs."""
    loc = Fluent(0)
    pulses = loc.pulsed(behavior)
    in_body, release = threading.Event(), threading.Event()
    runs = Fluent(0)

    def body():
        runs.set_value(runs.get_value() + 1)
        if runs.get_value() == 1:
            in_body.set()
            assert release.wait(WAIT)

    def monitor():
        whenever(pulses, body)

    def driver():
        loc.set_value(1)
        assert in_body.wait(WAIT)
        for i in range(missed):
            loc.set_value(i + 2)
        release.set()
        (runs >= expected).wait_for(timeout=WAIT)
        sleep(0.02)  # room for a run too many, which the assertion would catch

    pursue(monitor, driver)
    return runs.get_value()


@pytest.mark.parametrize("behavior, expected", [(Behavior.NEVER, 1), (Behavior.ONCE, 2), (Behavior.ALWAYS, 4)])
def test_whenever_missed_pulse_behaviors(behavior, expected):
    assert _count_runs_with_missed_pulses(behavior, missed=3, expected=expected) == expected


def test_thesis_whenever_loc_pulsed_once_moves_to_each_new_location():
    loc = Fluent()
    moved = []

    def move(location):
        moved.append(location)

    def monitor():
        for _ in whenever(loc.pulsed(Behavior.ONCE)):
            move(loc.get_value())
            if loc.get_value() == "kitchen":
                return

    def update_location(location):
        loc.set_value(location)

    def user():
        for place in ("table", "sink", "kitchen"):
            update_location(place)
            sleep(0.01)

    state = par(monitor, user)
    assert state.get_value() is State.SUCCEEDED
    assert moved[-1] == "kitchen" and set(moved) <= {"table", "sink", "kitchen"}


def test_whenever_function_form_leaves_on_stop():
    f = Fluent(0)
    seen = []

    def body():
        seen.append(f.get_value())
        f.set_value(f.get_value() + 1)
        return STOP if len(seen) == 5 else None

    assert whenever(f, body) is None
    assert seen == [0, 1, 2, 3, 4]


def test_whenever_is_stopped_by_evaporation():
    f = Fluent()
    runs = []
    state = pursue(lambda: whenever(f.pulsed(), lambda: runs.append(1)), lambda: sleep(0.02))
    assert state.get_value() is State.SUCCEEDED
    assert runs == []


def test_whenever_rejects_non_fluents_with_a_clear_error():
    with pytest.raises(TypeError, match="whenever\\(\\) needs a Fluent, got int"):
        whenever(3, lambda: None)


def test_wait_for_timeout_follows_the_active_clock():
    clock = ManualClock()
    result = []
    with use_clock(clock):
        thread = start_thread(lambda: result.append(Fluent().wait_for(timeout=10.0)))
        # Wall time passes, simulated time does not: the waiter must still be blocked.
        assert not _joined(thread, 0.05)
        while clock.next_deadline() is None:
            time.sleep(0.001)  # the waiter registers its deadline right after starting
        clock.advance(10.0)
        assert _joined(thread, WAIT)
    assert result == [False]


def _joined(thread: threading.Thread, timeout: float) -> bool:
    thread.join(timeout)
    return not thread.is_alive()


def test_seq_and_par_results_are_fluents():
    assert isinstance(seq(lambda: None), Fluent)
