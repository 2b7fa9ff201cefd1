"""CRAM's own language tests (cram2/cram, cram_core/cram_language/tests/*.lisp) translated to PyCRAM.

Each test names the CRAM test it translates. CRAM signals a failure from `top-level`; PyCRAM's
expressions return a state fluent and collect failures in `errors` instead. Timing assertions
compare orderings of clock readings, never absolute durations.
"""

from __future__ import annotations

import itertools
import random
import threading
import time

import pytest

from pycram.fluent import Fluent
from pycram.language import State, try_each_in_order

TIMEOUT = 5.0  # [s] bound of every wait in these tests


class Fail(Exception):
    """CRAM's (fail)."""


# -- try-each-in-order ---------------------------------------------------------------------------


def test_try_each_in_order_1_success_on_first_iteration() -> None:
    state = try_each_in_order([1, 2, 3], lambda value: value)
    assert state.get_value() is State.SUCCEEDED and state.result == 1


def test_try_each_in_order_2_success_on_second_iteration() -> None:
    def body(value: int) -> int:
        if value % 2:
            raise Fail(value)
        return value

    state = try_each_in_order([1, 2, 3], body)
    assert state.get_value() is State.SUCCEEDED and state.result == 2


def test_try_each_in_order_3_failure_lists_every_failure() -> None:
    values: list[int] = []
    errors: list = []

    def body(value: int) -> None:
        values.append(value)
        raise Fail(value)

    state = try_each_in_order([1, 2, 3], body, errors=errors)
    assert state.get_value() is State.FAILED and state.result is None
    assert values == [1, 2, 3]
    assert [e.args[0] for e in errors] == [1, 2, 3]


# -- with-tags ------------------------------------------------------------------------------------

from pycram.language import seq, tag, with_tags  # noqa: E402
from pycram.runtime import sleep  # noqa: E402


def test_with_tags_1_tags_introduce_no_hidden_parallelism() -> None:
    bag: list[str] = []

    def step(name: str):
        return tag(name, lambda: (bag.append(name), sleep(random.random() * 0.01)))

    with with_tags():
        seq(*(step(name) for name in "ABCDE"))
    assert bag == list("ABCDE")


# -- partial-order --------------------------------------------------------------------------------

from pycram.language import partial_order  # noqa: E402


def _worker(name: str, times: dict, clock=itertools.count()):
    def work() -> None:
        sleep(random.random() * 0.02)
        times[name] = next(clock)  # a global order of the end times

    return tag(name, work)


def test_partial_order_1_one_task_directly_depends_on_another() -> None:
    times: dict = {}
    state = partial_order([_worker("worker-1", times), _worker("worker-2", times)], [("worker-1", "worker-2")])
    assert state.get_value() is State.SUCCEEDED
    assert times["worker-1"] < times["worker-2"]


def test_partial_order_2_sequential_ordering_of_three_tasks() -> None:
    times: dict = {}
    partial_order([_worker(f"worker-{i}", times) for i in (1, 2, 3)],
                  [("worker-1", "worker-3"), ("worker-3", "worker-2")])
    assert times["worker-1"] < times["worker-3"] < times["worker-2"]


def test_partial_order_3_task_constrained_by_two_parallel_tasks() -> None:
    times: dict = {}
    partial_order([_worker(f"worker-{i}", times) for i in (1, 2, 3)],
                  [("worker-1", "worker-3"), ("worker-2", "worker-3")])
    assert times["worker-1"] < times["worker-3"] and times["worker-2"] < times["worker-3"]


def test_partial_order_4_ring_dependencies_are_rejected_instead_of_deadlocking() -> None:
    # CRAM: "Ring dependencies in orderings will always lead to deadlocks" (the test expects a
    # hang). PyCRAM refuses the cycle before anything runs.
    ran = []
    with pytest.raises(ValueError, match="cycle"):
        partial_order([tag("worker-1", lambda: ran.append(1)), tag("worker-2", lambda: ran.append(2))],
                      [("worker-1", "worker-2"), ("worker-2", "worker-1")])
    assert ran == []
