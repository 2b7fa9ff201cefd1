"""CRAM's own language tests (cram2/cram, cram_core/cram_language/tests/*.lisp) translated to PyCRAM.

Each test names the CRAM test it translates. CRAM signals a failure from `top-level`; PyCRAM's
expressions return a state fluent and collect failures in `errors` instead. Timing assertions
compare orderings of clock readings, never absolute durations.
"""

from __future__ import annotations

import itertools
import random
import threading

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

from pycram.language import Tags, find_tasks, seq, tag, with_tags  # noqa: E402
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

_end_order = itertools.count()  # a global order of the workers' end times


def _worker(name: str, times: dict):
    def work() -> None:
        sleep(random.random() * 0.02)
        times[name] = next(_end_order)

    return tag(name, work)


def test_partial_order_1_one_task_directly_depends_on_another() -> None:
    times: dict = {}
    state = partial_order([_worker("worker-1", times), _worker("worker-2", times)], [("worker-1", "worker-2")])
    assert state.get_value() is State.SUCCEEDED
    assert times["worker-1"] < times["worker-2"]


def test_partial_order_2_sequential_ordering_of_three_tasks() -> None:
    times: dict = {}
    partial_order(
        [_worker(f"worker-{i}", times) for i in (1, 2, 3)], [("worker-1", "worker-3"), ("worker-3", "worker-2")]
    )
    assert times["worker-1"] < times["worker-3"] < times["worker-2"]


def test_partial_order_3_task_constrained_by_two_parallel_tasks() -> None:
    times: dict = {}
    partial_order(
        [_worker(f"worker-{i}", times) for i in (1, 2, 3)], [("worker-1", "worker-3"), ("worker-2", "worker-3")]
    )
    assert times["worker-1"] < times["worker-3"] and times["worker-2"] < times["worker-3"]


def test_partial_order_4_ring_dependencies_are_rejected_instead_of_deadlocking() -> None:
    # CRAM: "Ring dependencies in orderings will always lead to deadlocks" (the test expects a
    # hang). PyCRAM refuses the cycle before anything runs.
    ran = []
    with pytest.raises(ValueError, match="cycle"):
        partial_order(
            [tag("worker-1", lambda: ran.append(1)), tag("worker-2", lambda: ran.append(2))],
            [("worker-1", "worker-2"), ("worker-2", "worker-1")],
        )
    assert ran == []


# -- task suspension (language-tests.lisp and task-tests.lisp) ------------------------------------

from pycram.language import on_suspension, par, pursue, suspend, wake_up, with_task_suspended  # noqa: E402
from pycram.runtime import TaskStatus  # noqa: E402

S = TaskStatus


def _becomes(task, *statuses) -> bool:
    """Wait until `task` shows one of `statuses` (CRAM's wait-until (become ...))."""
    network = task.status.IS(statuses[0])
    for status in statuses[1:]:
        network = network.OR(task.status.IS(status))
    return network.wait_for(TIMEOUT)


def test_with_task_suspended_1_suspend_then_wake_up() -> None:
    seen = []
    with with_tags() as tags:

        def controller() -> None:
            slave = tags.wait_task("slave", TIMEOUT)
            with with_task_suspended(slave):
                seen.append(_becomes(slave, S.SUSPENDED))
            seen.append(_becomes(slave, S.RUNNING, S.SUCCEEDED))

        state = par(tag("slave", lambda: sleep(0.2)), controller)
    assert state.get_value() is State.SUCCEEDED and seen == [True, True]


def test_with_task_suspended_2_suspends_and_wakes_a_whole_tree() -> None:
    knob = Fluent()
    end_of_time = Fluent()
    with with_tags() as tags:

        def waiters():
            return pursue(
                tag("winner", lambda: (knob.wait_for(), "A")[1]),
                lambda: (end_of_time.wait_for(), "B")[1],
                lambda: (end_of_time.wait_for(), "C")[1],
            )

        state = par(
            tag("waiters", waiters),
            lambda: with_task_suspended(tags.wait_task("waiters", TIMEOUT), lambda: knob.set_value(True)),
        )
    assert state.get_value() is State.SUCCEEDED
    assert tags["winner"].result == "A"


def test_with_task_suspended_3_suspended_tree_makes_no_progress() -> None:
    knob = Fluent()
    counter = []
    aux = []

    def wait() -> None:
        knob.wait_for()
        counter.append(1)

    def suspender(tags) -> None:
        def body() -> None:
            knob.set_value(True)
            sleep(0.1)
            aux.append(len(counter))

        with_task_suspended(tags.wait_task("waiters", TIMEOUT), body)

    with with_tags() as tags:
        par(tag("waiters", lambda: par(wait, lambda: par(wait, wait, wait), wait)), lambda: suspender(tags))
    assert aux == [0] and len(counter) == 5


def test_with_task_suspended_4_on_suspension_runs_when_suspended() -> None:
    order = itertools.count()
    final = {}
    blockee_ready, blocker_finished = Fluent(), Fluent()

    def blocker(tags) -> None:
        blockee_ready.wait_for()
        with with_task_suspended(tags.wait_task("blockee", TIMEOUT)):
            start = next(order)
            blocker_finished.set_value(True)
            sleep(0.1)
            final["blocker"] = (start, next(order))

    def blockee() -> None:
        start = []
        with on_suspension(lambda: start.append(next(order))):
            blockee_ready.set_value(True)
            blocker_finished.wait_for()
        final["blockee"] = (start[0], next(order))

    with with_tags() as tags:
        state = par(lambda: blocker(tags), tag("blockee", blockee))
    assert state.get_value() is State.SUCCEEDED
    # the blockee was suspended before the blocker's body ran and woke after it had ended
    assert final["blockee"][0] < final["blocker"][0] and final["blockee"][1] > final["blocker"][1]


def test_misc_1_deadline_active_again_after_wake_up() -> None:
    fluent = Fluent()
    with with_tags() as tags:

        def controller() -> str:
            waiter = tags.wait_task("waiter", TIMEOUT)
            sleep(0.02)
            suspend(waiter)
            sleep(0.02)
            wake_up(waiter)
            sleep(0.02)
            waiter.evaporate()
            return "B"

        state = par(tag("waiter", lambda: (fluent.wait_for(), "A")[1]), controller)
    assert state.get_value() is State.SUCCEEDED
    assert tags["waiter"].status.get_value() is S.EVAPORATED


def test_failure_1_failures_of_a_suspended_tree_are_propagated() -> None:
    knob = Fluent()
    errors: list = []

    def slave():
        state = pursue(lambda: (knob.wait_for(), _raise(Fail("slave")))[1], lambda: sleep(3.0), lambda: sleep(3.0))
        if state.get_value() is State.FAILED:
            raise Fail("pursue failed")

    with with_tags() as tags:
        state = par(
            tag("slave", slave),
            lambda: with_task_suspended(tags.wait_task("slave", TIMEOUT), lambda: knob.set_value(True)),
            errors=errors,
        )
    assert state.get_value() is State.FAILED and [str(e) for e in errors] == ["pursue failed"]


def _raise(error: BaseException) -> None:
    raise error


def _hierarchy(knob: Fluent):
    """CRAM's with-task-hierarchy ((A -> B)): A waits for knob in parallel with its child B."""
    tags = Tags()  # a plain thread's tasks are outside any with_tags block: register explicitly
    box = {}

    def a() -> None:
        box["state"] = par(lambda: knob.wait_for(), tags.tag("B", lambda: knob.wait_for()))

    thread = threading.Thread(target=lambda: box.setdefault("outer", par(tags.tag("A", a))), daemon=True)
    thread.start()
    return tags, thread, box


def test_tasks_suspend_1_suspending_the_parent_suspends_the_child() -> None:
    knob = Fluent()
    tags, thread, box = _hierarchy(knob)
    a, b = tags.wait_task("A", TIMEOUT), tags.wait_task("B", TIMEOUT)
    suspend(a)
    assert a.status.get_value() is S.SUSPENDED and b.status.get_value() is S.SUSPENDED
    knob.set_value(True)
    sleep(0.05)
    assert a.status.get_value() is S.SUSPENDED and b.status.get_value() is S.SUSPENDED  # still
    wake_up(a)
    thread.join(TIMEOUT)
    assert a.status.get_value() is S.SUCCEEDED and b.status.get_value() is S.SUCCEEDED


def test_tasks_suspend_4_suspending_the_child_leaves_the_parent_alone() -> None:
    # tasks--suspend.3/4: in PyCRAM a parent never ends before its children (tasks--suspend.3's
    # "parent succeeds, suspended child is evaporated" has no counterpart); .4 wakes the child.
    knob = Fluent()
    tags, thread, box = _hierarchy(knob)
    a, b = tags.wait_task("A", TIMEOUT), tags.wait_task("B", TIMEOUT)
    suspend(b)
    assert b.status.get_value() is S.SUSPENDED and a.status.get_value() is S.RUNNING
    knob.set_value(True)
    wake_up(b)
    thread.join(TIMEOUT)
    assert a.status.get_value() is S.SUCCEEDED and b.status.get_value() is S.SUCCEEDED


# -- walker-tests.lisp: tag handling ---------------------------------------------------------------
# CRAM's walker finds the :tag forms in plan code statically. PyCRAM has no code walker; the
# same questions are answered from the task tree after (or while) the plan runs.


def _tags_in(tags) -> set:
    return set(tags.names())


def test_walk_with_tag_handler_simple() -> None:
    with with_tags() as tags:
        par(tag("tag1", lambda: [1, 2]), tag("tag2", lambda: [3, 4]))
    assert _tags_in(tags) == {"tag1", "tag2"}


def test_walk_with_tag_handler_nested_tags_and_paths() -> None:
    with with_tags() as tags:
        par(
            tag("tag1", lambda: [1, 2]),
            tag("tag2", lambda: seq(tag("tag3", tag("tag4", lambda: None)), tag("tag5", lambda: None))),
        )
    assert _tags_in(tags) == {"tag1", "tag2", "tag3", "tag4", "tag5"}
    tag4 = tags["tag4"]
    assert tag4.parent is tags["tag3"] and tags["tag2"].path.endswith("/par/tag2")  # a branch: no extra level
    root = tag4
    while root.parent is not None:
        root = root.parent
    assert find_tasks("*/tag3/tag4", root) == [tag4]


def test_walk_with_tag_handler_bodies() -> None:
    with with_tags() as tags:
        seq(tag("t1", lambda: [1, 2]), tag("t2", lambda: None))
    assert tags["t1"].result == [1, 2] and tags["t2"].result is None


def test_correct_parents() -> None:
    with with_tags() as tags:
        par(tag("a", lambda: seq(lambda: None, tag("b", lambda: par(lambda: None)))))
    root = tags["a"]
    while root.parent is not None:
        root = root.parent
    for task in root.walk():
        assert all(child.parent is task for child in task.children)
