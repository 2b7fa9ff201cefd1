"""Expressions: seq, try_in_order, par, try_all, pursue, failure_handling, with_timeout (thesis 3.2.3)."""

from __future__ import annotations

import threading
import time

import pytest

from pycram.core.block_forms import BlockSyntaxNotEnabled
from pycram.fluent import Fluent, whenever
from pycram.language import (
    RetriesExhausted,
    State,
    current_attempt,
    failure_handling,
    par,
    pursue,
    retry,
    seq,
    try_all,
    try_in_order,
    with_timeout,
)
from pycram.runtime import (
    Evaporated,
    TaskStatus,
    check_evaporation,
    current_task,
    no_evaporation,
    run_subtask,
    sleep,
)

WAIT = 5.0


class Boom(Exception):
    pass


def fail(message: str = "boom"):
    def failing():
        raise Boom(message)

    failing.__name__ = f"fail_{message}"
    return failing


def record(log: list, value):
    def recording():
        log.append(value)
        return value

    recording.__name__ = f"record_{value}"
    return recording


def block_forever():
    Fluent().wait_for()


def last_expression_task():
    return current_task().children[-1]


def statuses(task):
    return [child.status.get_value() for child in task.children]


# -- seq and try_in_order -----------------------------------------------------------------------------


def test_seq_runs_in_order_and_succeeds():
    log = []
    errors = []
    s = seq(record(log, 1), record(log, 2), record(log, 3), errors=errors)
    assert s.get_value() is State.SUCCEEDED
    assert log == [1, 2, 3] and errors == []


def test_seq_stops_at_first_failure_and_never_raises():
    log, errors = [], []
    s = seq(record(log, 1), fail("s2"), record(log, 3), errors=errors)
    assert s.get_value() is State.FAILED
    assert log == [1]
    assert [str(e) for e in errors] == ["s2"]
    task = last_expression_task()
    assert task.kind == "seq" and task.status.get_value() is TaskStatus.FAILED
    assert statuses(task) == [TaskStatus.SUCCEEDED, TaskStatus.FAILED]


def test_try_in_order_stops_at_first_success():
    log, errors = [], []
    s = try_in_order(fail("a"), record(log, "b"), record(log, "c"), errors=errors)
    assert s.get_value() is State.SUCCEEDED
    assert log == ["b"] and [str(e) for e in errors] == ["a"]


def test_try_in_order_fails_only_if_all_fail():
    errors = []
    s = try_in_order(fail("a"), fail("b"), errors=errors)
    assert s.get_value() is State.FAILED
    assert [str(e) for e in errors] == ["a", "b"]


# -- par -----------------------------------------------------------------------------------------------


def test_par_runs_branches_concurrently():
    barrier = threading.Barrier(3, timeout=WAIT)  # all three must be running at the same time
    s = par(barrier.wait, barrier.wait, barrier.wait)
    assert s.get_value() is State.SUCCEEDED


def test_par_first_failure_evaporates_siblings():
    errors = []
    s = par(block_forever, fail("x"), block_forever, errors=errors)
    assert s.get_value() is State.FAILED
    assert [str(e) for e in errors] == ["x"]  # evaporated branches add nothing
    task = last_expression_task()
    assert statuses(task) == [TaskStatus.EVAPORATED, TaskStatus.FAILED, TaskStatus.EVAPORATED]


def test_thesis_par_branch_polls_state_fluent():
    errors = []
    seen = []

    def s1():
        raise Boom("s1 failed")

    def watcher():
        while True:
            if s.get_value() == State.FAILED:
                seen.append("state is FAILED")
                break

    s = Fluent()
    par(s1, watcher, errors=errors, state=s)
    assert s.get_value() is State.FAILED
    # The watcher either saw the state or was evaporated while polling: both are CRAM-correct.
    assert seen in ([], ["state is FAILED"])
    assert [str(e) for e in errors] == ["s1 failed"]


def test_thesis_par_with_if_true_grouping_equivalent():
    log = []

    def group():  # `if True: s1; s2` — one branch of two statements
        log.append("s1")
        log.append("s2")

    s = par(group, record(log, "s3"))
    assert s.get_value() is State.SUCCEEDED
    assert log.index("s1") < log.index("s2") and "s3" in log


def test_state_fluent_is_bound_before_branches_start():
    s = Fluent()
    observed = []
    par(lambda: observed.append(s.get_value()), state=s)
    assert observed == [None] and s.get_value() is State.SUCCEEDED


# -- try_all and pursue -----------------------------------------------------------------------------------


def after_sibling(index: int, status: TaskStatus):
    """A branch that succeeds once its sibling number `index` has ended with `status`."""

    def waiting():
        sibling = current_task().parent.children[index]
        assert (sibling.status == status).wait_for(timeout=WAIT)

    return waiting


def test_try_all_first_success_evaporates_the_rest():
    errors = []
    s = try_all(fail("a"), after_sibling(0, TaskStatus.FAILED), block_forever, errors=errors)
    assert s.get_value() is State.SUCCEEDED
    assert [str(e) for e in errors] == ["a"]
    assert statuses(last_expression_task())[1:] == [TaskStatus.SUCCEEDED, TaskStatus.EVAPORATED]


def test_try_all_fails_when_all_fail():
    errors = []
    s = try_all(fail("a"), fail("b"), errors=errors)
    assert s.get_value() is State.FAILED
    assert sorted(str(e) for e in errors) == ["a", "b"]


def test_pursue_first_to_end_decides_success():
    s = pursue(block_forever, lambda: None)
    assert s.get_value() is State.SUCCEEDED
    assert statuses(last_expression_task()) == [TaskStatus.EVAPORATED, TaskStatus.SUCCEEDED]


def test_pursue_first_to_end_decides_failure():
    errors = []
    s = pursue(block_forever, fail("first"), errors=errors)
    assert s.get_value() is State.FAILED
    assert [str(e) for e in errors] == ["first"]


def test_errors_list_is_optional_and_type_checked():
    assert par(fail()).get_value() is State.FAILED
    with pytest.raises(TypeError, match="errors must be a list"):
        par(lambda: None, errors=())
    with pytest.raises(TypeError, match="branch 2 must be a callable"):
        seq(lambda: None, 42)


# -- nesting and the task tree -----------------------------------------------------------------------------


def test_nested_expressions_form_one_task_tree():
    s = par(lambda: seq(lambda: None, lambda: None, name="inner"), name="outer")
    assert s.get_value() is State.SUCCEEDED
    outer = last_expression_task()
    assert outer.name == "outer" and outer.kind == "par"
    branch = outer.children[0]
    inner = branch.children[0]
    assert inner.name == "inner" and inner.parent is branch
    assert inner.path.endswith("/outer/1:<lambda>/inner") or inner.path.endswith("/outer/1/inner")
    assert all(t.done for t in outer.walk())
    assert all(t.start_time is not None and t.end_time >= t.start_time for t in outer.walk())


def test_expression_returns_only_after_all_descendants_ended():
    finished = []
    started = [Fluent(), Fluent()]

    def slow_cleanup(index):
        try:
            started[index].set_value(True)
            Fluent().wait_for()
        finally:
            with no_evaporation():  # clean-up that itself waits must shield itself
                sleep(0.02)
                finished.append("cleanup")

    def winner():
        assert started[0].AND(started[1]).wait_for(timeout=WAIT)

    pursue(lambda: par(lambda: slow_cleanup(0), lambda: slow_cleanup(1)), winner)
    assert finished == ["cleanup", "cleanup"]


def test_evaporation_is_sticky_and_finally_blocks_run():
    events = []
    started = Fluent()

    def stubborn():
        try:
            started.set_value(True)
            try:
                Fluent().wait_for()
            except BaseException:  # a bare except cannot save the task ...
                events.append("caught")
            sleep(0.5)  # ... every later pycram call raises again
            events.append("resurrected")
        finally:
            events.append("finally")

    s = pursue(stubborn, lambda: started.wait_for(timeout=WAIT))
    assert s.get_value() is State.SUCCEEDED
    assert events == ["caught", "finally"]


def test_evaporation_is_sticky_for_every_later_pycram_call():
    started = Fluent()
    raised = []
    calls = {
        "check_evaporation": check_evaporation,
        "wait_for": lambda: Fluent(1).wait_for(),  # even a wait that would not block
        "sleep": lambda: sleep(0),
        "whenever": lambda: whenever(Fluent(1), lambda: None),
        "seq": lambda: seq(lambda: None),
        "par": lambda: par(lambda: None),
        "with_timeout": lambda: with_timeout(1, lambda: None),
        "failure_handling": lambda: failure_handling(lambda: None),
        "retry": retry,
    }

    def stubborn(name, call):
        started.set_value(True)
        try:
            Fluent().wait_for()
        except BaseException:
            pass  # a bare except ...
        try:
            call()
        except Evaporated:
            raised.append(name)  # ... cannot save the task: every pycram call raises again
            raise

    for name, call in calls.items():
        started.set_value(None)
        pursue(lambda name=name, call=call: stubborn(name, call), lambda: started.wait_for(timeout=WAIT))
        assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED
    assert raised == list(calls)


def test_a_bare_except_loop_loser_ends_right_after_the_winner():
    """`while True: try: sleep() except: pass` swallows every Evaporated a PyCRAM call raises;
    the runtime re-delivers it where the loop would swallow it again, so the loop ends after at
    most two more passes (structural), well within 100 ms (a generous bound against a hang)."""
    won = Fluent()
    passes_after_win = []

    def stubborn():
        while True:
            try:
                sleep(0.01)
            except:  # noqa: E722 - the point of the test
                pass
            if won.get_value():
                passes_after_win.append(1)

    def winner():
        sleep(0.03)
        won.set_value(time.monotonic())

    state = pursue(stubborn, winner)
    returned = time.monotonic()
    assert state.get_value() is State.SUCCEEDED
    loser = last_expression_task().children[0]
    assert loser.status.get_value() is TaskStatus.EVAPORATED
    assert len(passes_after_win) <= 2, f"{len(passes_after_win)} passes of the loop after the winner ended"
    assert loser._runner.resurfacing >= 1  # it swallowed, and was re-delivered
    assert returned - won.get_value() < 1.0  # a hang guard, not a speed test


def test_a_bare_except_loop_in_a_seq_step_inside_a_loser_ends_too():
    def stubborn_step():
        while True:
            try:
                Fluent().wait_for(timeout=0.01)
                check_evaporation()
            except BaseException:
                pass

    state = pursue(lambda: seq(stubborn_step), lambda: sleep(0.02))
    assert state.get_value() is State.SUCCEEDED
    assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED


class _Clean:
    """A context manager whose exit records whether it ran to its end."""

    def __init__(self, log, in_cleanup, go):
        self.log, self.in_cleanup, self.go = log, in_cleanup, go

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.log.append("exit started")
        self.in_cleanup.set()
        self.go.wait(WAIT)
        self.log.append("exit finished")
        return False


@pytest.mark.parametrize("cleanup", ["finally", "context manager", "except-and-raise"])
def test_a_task_letting_evaporated_propagate_is_never_interrupted_in_its_cleanup(cleanup):
    """Deterministic: while the evaporated loser sits in its clean-up, it is evaporated again
    three times (as enclosing expressions do); nothing may land in the clean-up."""
    log = []
    in_cleanup, go = threading.Event(), threading.Event()
    started = Fluent()

    def clean_up_slowly():
        log.append("cleanup started")
        in_cleanup.set()
        go.wait(WAIT)  # C-level blocking: a pending asynchronous exception would land right after
        log.append("cleanup finished")

    def loser():
        started.set_value(True)
        if cleanup == "finally":
            try:
                Fluent().wait_for()
            finally:
                clean_up_slowly()
        elif cleanup == "context manager":
            with _Clean(log, in_cleanup, go):
                Fluent().wait_for()
        else:
            try:
                Fluent().wait_for()
            except Evaporated:
                clean_up_slowly()
                raise

    tasks = []

    def evaporate_again():
        assert in_cleanup.wait(WAIT)
        for _ in range(3):
            tasks[0].evaporate()
        go.set()

    def loser_task():
        tasks.append(current_task())
        loser()

    helper = threading.Thread(target=evaporate_again, daemon=True)
    helper.start()
    state = pursue(loser_task, lambda: started.wait_for(timeout=WAIT))
    helper.join(WAIT)
    assert state.get_value() is State.SUCCEEDED
    assert log[-1] in ("cleanup finished", "exit finished"), log
    assert tasks[0].status.get_value() is TaskStatus.EVAPORATED
    assert tasks[0]._runner.resurfacing == 0  # it never swallowed


def test_no_evaporation_still_protects_a_task_that_swallows_evaporated():
    """A bare-except loop whose passes run a protected section: every section that began runs
    to its end; the loop still ends (Evaporated is raised at the end of a section, swallowed,
    then re-delivered)."""
    started = Fluent()
    steps = []

    def stubborn():
        while True:
            try:
                with no_evaporation():
                    steps.append("begin")
                    started.set_value(True)
                    sleep(0.005)  # not interrupted inside the block
                    check_evaporation()  # does not raise inside the block
                    steps.append("end")
                sleep(0.005)
            except:  # noqa: E722 - the point of the test
                pass

    state = pursue(stubborn, lambda: started.wait_for(timeout=WAIT) and sleep(0.02))
    assert state.get_value() is State.SUCCEEDED
    assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED
    assert steps and steps.count("begin") == steps.count("end"), steps
    assert steps[-1] == "end"


class Resource:
    """A context manager that records that its clean-up ran, and why."""

    def __init__(self, log: list) -> None:
        self.log = log

    def __enter__(self) -> Resource:
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        self.log.append(exc_type.__name__ if exc_type else None)
        return False


def test_evaporation_runs_context_managers_and_finally_in_waits_and_busy_loops():
    log = []
    started = [Fluent(), Fluent()]

    def waiting():
        with Resource(log):
            try:
                started[0].set_value(True)
                Fluent().wait_for()
            finally:
                log.append("finally waiting")

    def busy():
        with Resource(log):
            started[1].set_value(True)
            _spin()

    s = pursue(waiting, busy, lambda: started[0].AND(started[1]).wait_for(timeout=WAIT))
    assert s.get_value() is State.SUCCEEDED
    assert sorted(map(str, log)) == ["Evaporated", "Evaporated", "finally waiting"]
    assert statuses(last_expression_task())[:2] == [TaskStatus.EVAPORATED, TaskStatus.EVAPORATED]


def _spin() -> None:
    x = 0
    while True:
        x += 1


def test_no_evaporation_holds_back_the_interrupt_of_a_busy_loop():
    events = []
    inside = Fluent()

    def critical():
        me = current_task()
        with no_evaporation():
            inside.set_value(True)
            while not me.evaporating:  # plain Python: would be interrupted without the shield
                pass
            for _ in range(200_000):
                pass
            events.append("critical done")
        events.append("after")

    pursue(critical, lambda: inside.wait_for(timeout=WAIT))
    assert events == ["critical done"]
    assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED


def test_no_evaporation_delays_delivery_to_the_end_of_the_block():
    events = []
    inside = Fluent()

    def critical():
        with no_evaporation():
            inside.set_value(True)
            sleep(0.03)  # not interrupted
            events.append("critical done")
        events.append("after")  # never reached: Evaporated is raised when the block ends

    def winner():
        inside.wait_for(timeout=WAIT)

    pursue(critical, winner)
    assert events == ["critical done"]
    assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED


def test_busy_python_loop_is_evaporated():
    def spin():
        x = 0
        while True:
            x += 1

    s = with_timeout(0.05, spin)
    assert s.get_value() is State.FAILED
    assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED


def test_retry_does_not_restart_an_evaporating_body():
    runs = Fluent(0)

    def body():
        runs.set_value(runs.get_value() + 1)
        try:
            Fluent().wait_for()
        except BaseException:
            retry()  # raises Evaporated again instead of restarting

    pursue(lambda: failure_handling(body), lambda: (runs >= 1).wait_for(timeout=WAIT))
    assert runs.get_value() == 1


def test_evaporation_is_delivered_in_waits_sleep_and_whenever():
    for blocked in (lambda: Fluent().wait_for(), lambda: sleep(0.5), lambda: whenever(Fluent(), lambda: None)):
        s = pursue(blocked, lambda: None)
        assert s.get_value() is State.SUCCEEDED
        assert last_expression_task().children[0].status.get_value() is TaskStatus.EVAPORATED


# -- failure_handling and retry --------------------------------------------------------------------------------


def test_thesis_failure_handling_with_limit_runs_body_limit_plus_one_times():
    runs = []

    def body():
        runs.append(current_attempt())
        try:
            raise Boom("c")
        except Exception:
            retry()

    with pytest.raises(Boom, match="c"):  # retries used up: retry() re-raises the real error
        failure_handling(body, 5)
    assert runs == [1, 2, 3, 4, 5, 6]
    task = last_expression_task()
    assert task.info["attempts"] == 6 and len(task.children) == 6
    assert task.status.get_value() is TaskStatus.FAILED and isinstance(task.exception, Boom)


def test_retry_beyond_the_limit_reraises_the_handled_exception_of_that_type():
    class GraspFailed(Exception):
        pass

    def body():
        try:
            raise GraspFailed(f"attempt {current_attempt()}")
        except GraspFailed:
            retry()
        return "swallowed"  # never reached: retry() does not return

    with pytest.raises(GraspFailed, match="attempt 3"):
        failure_handling(body, max_retries=2)


def test_retry_beyond_the_limit_without_a_handled_exception_is_a_clear_error():
    def body():
        retry()

    with pytest.raises(RetriesExhausted, match=r"after 1 of 1 retries in fh.*no exception being handled"):
        failure_handling(body, max_retries=1, name="fh")
    assert issubclass(RetriesExhausted, RuntimeError)


def test_current_attempt_is_unchanged_by_exhausted_retries():
    seen = []

    def body():
        seen.append(current_attempt())
        try:
            raise Boom("x")
        except Boom:
            retry()

    with pytest.raises(Boom):
        failure_handling(body, max_retries=0)
    assert seen == [1]


def test_attempt_count_is_observable_inside_and_after():
    seen = []

    def body():
        seen.append((current_attempt(), current_task().parent.info["attempts"]))
        if len(seen) < 3:
            retry()
        return "ok"

    assert failure_handling(body, name="observed") == "ok"
    assert seen == [(1, 1), (2, 2), (3, 3)]
    task = last_expression_task()
    assert task.name == "observed" and task.info["attempts"] == 3
    assert [c.name for c in task.children] == ["attempt 1", "attempt 2", "attempt 3"]
    assert statuses(task) == [TaskStatus.FAILED, TaskStatus.FAILED, TaskStatus.SUCCEEDED]
    with pytest.raises(RuntimeError, match="outside any failure_handling"):
        current_attempt()


def test_failure_handling_unlimited_until_success():
    runs = []

    def body():
        runs.append(1)
        try:
            if len(runs) < 4:
                raise Boom("not yet")
            return "done"
        except Boom:
            retry()

    assert failure_handling(body) == "done"
    assert len(runs) == 4


def test_ten_thousand_retries_do_not_grow_the_stack():
    import sys

    depths = []

    def body():
        depths.append(len(_stack(sys._getframe())))
        if len(depths) <= 10_000:
            retry()

    failure_handling(body)
    assert len(depths) == 10_001
    assert max(depths) == min(depths)


def _stack(frame):
    frames = []
    while frame is not None:
        frames.append(frame)
        frame = frame.f_back
    return frames


def test_retry_outside_failure_handling_is_an_error():
    with pytest.raises(RuntimeError, match="outside any failure_handling"):
        retry()


def test_retry_from_a_par_branch_restarts_the_enclosing_body():
    runs = []

    def body():
        runs.append(1)

        def branch():
            if len(runs) < 3:
                retry()

        par(branch, lambda: None)

    failure_handling(body)
    assert len(runs) == 3


def test_other_exceptions_of_the_body_propagate():
    with pytest.raises(Boom):
        failure_handling(fail("boom"))


# -- with_timeout ----------------------------------------------------------------------------------------------


def test_with_timeout_evaporates_body_at_deadline():
    errors = []
    s = with_timeout(0.05, block_forever, errors=errors)
    assert s.get_value() is State.FAILED
    assert len(errors) == 1 and isinstance(errors[0], TimeoutError)
    body = last_expression_task().children[0]
    assert body.status.get_value() is TaskStatus.EVAPORATED


def test_with_timeout_in_time_succeeds():
    errors = []
    assert with_timeout(5, lambda: None, errors=errors).get_value() is State.SUCCEEDED
    assert errors == []


# -- block forms without block syntax -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda: par,
        lambda: seq,
        lambda: par([]),
        lambda: try_all([]),
        lambda: failure_handling,  # the thesis' bare `with failure_handling:`
        lambda: failure_handling(5),
        lambda: failure_handling(),
        lambda: whenever(Fluent()),
    ],
)
def test_block_forms_without_block_syntax_refuse_and_explain(make):
    with pytest.raises(BlockSyntaxNotEnabled, match="@plan.*pycram run.*pycram.activate"):
        with make():
            pass


def test_evaporated_is_a_base_exception():
    assert issubclass(Evaporated, BaseException) and not issubclass(Evaporated, Exception)


def test_a_task_whose_child_was_evaporated_alone_can_still_be_evaporated_later():
    """Evaporation delivered to a child task (in the same thread) must not keep a later
    evaporation of the parent from being delivered."""
    tasks = {}
    child_started, parent_waiting = Fluent(), Fluent()

    def child():
        tasks["child"] = current_task()
        child_started.set_value(True)
        Fluent().wait_for()

    def parent():
        tasks["parent"] = current_task()
        try:
            run_subtask("child", child)
        except Evaporated:
            pass  # the child alone was evaporated: the parent goes on
        parent_waiting.set_value(True)
        Fluent().wait_for()  # until the parent itself is evaporated

    def stopper():
        assert child_started.wait_for(timeout=WAIT)
        tasks["child"].evaporate()
        assert parent_waiting.wait_for(timeout=WAIT)
        tasks["parent"].evaporate()

    helper = threading.Thread(target=stopper, daemon=True)
    helper.start()
    errors = []
    state = with_timeout(WAIT, parent, errors=errors)
    helper.join(WAIT)
    assert errors == []  # not timed out: the parent's evaporation reached it
    assert tasks["child"].status.get_value() is TaskStatus.EVAPORATED
    assert tasks["parent"].status.get_value() is TaskStatus.EVAPORATED
    assert state.get_value() is State.FAILED  # its body was evaporated before the time-out
