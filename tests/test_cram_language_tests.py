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
