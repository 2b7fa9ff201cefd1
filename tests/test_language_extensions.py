"""Issue 18: results on state fluents, try_each_in_order, par_loop (and the later additions)."""

from __future__ import annotations

import gc
import threading

import pytest

from pycram.fluent import Fluent
from pycram.language import (
    State,
    StateFluent,
    par,
    par_loop,
    plan,
    pursue,
    seq,
    try_all,
    try_each_in_order,
    try_in_order,
    with_timeout,
)
from pycram.runtime import current_task

TIMEOUT = 5.0


class Boom(Exception):
    pass


def boom() -> None:
    raise Boom()


# -- 1. results ------------------------------------------------------------------------------------


def test_seq_result_is_the_last_step_value() -> None:
    state = seq(lambda: 1, lambda: 2)
    assert isinstance(state, StateFluent) and state.result == 2


def test_try_in_order_result_is_the_first_success() -> None:
    state = try_in_order(boom, lambda: "b", lambda: "c")
    assert state.get_value() is State.SUCCEEDED and state.result == "b"


def test_par_result_lists_every_branch_in_order() -> None:
    done = Fluent()

    def slow() -> str:
        done.wait_for(TIMEOUT)
        return "slow"

    def fast() -> str:
        done.set_value(True)
        return "fast"

    state = par(slow, fast)
    assert state.result == ["slow", "fast"]


def test_pursue_and_try_all_result_is_the_winner() -> None:
    never = Fluent()
    assert pursue(lambda: never.wait_for(), lambda: "won").result == "won"
    assert try_all(boom, lambda: "won", lambda: never.wait_for()).result == "won"


def test_failed_expression_has_no_result() -> None:
    assert seq(lambda: 1, boom).result is None
    assert par(lambda: 1, boom).result is None


def test_result_is_set_before_the_state_is_decided() -> None:
    seen = []
    state = StateFluent()

    def watcher() -> None:
        state.wait_for(TIMEOUT)
        seen.append(state.result)

    t = threading.Thread(target=watcher)
    t.start()
    try_all(lambda: 42, state=state)
    t.join(TIMEOUT)
    assert seen == [42]


def test_with_timeout_result() -> None:
    assert with_timeout(5, lambda: "x").result == "x"


def test_block_syntax_state_has_the_result() -> None:
    @plan
    def run() -> StateFluent:
        with par as s:
            _ = 1
            _ = 2
        return s

    assert run().get_value() is State.SUCCEEDED


# -- try_each_in_order / par_loop ------------------------------------------------------------------


def test_par_loop_runs_concurrently_and_collects_results() -> None:
    barrier = threading.Barrier(3, timeout=TIMEOUT)

    def body(item: int) -> int:
        barrier.wait()  # passes only if all three run at once
        return item * 2

    state = par_loop([1, 2, 3], body)
    assert state.get_value() is State.SUCCEEDED and state.result == [2, 4, 6]


def test_par_loop_failure_evaporates_the_others() -> None:
    never = Fluent()
    finished = []

    def body(item: int) -> None:
        if item == 1:
            raise Boom()
        never.wait_for()
        finished.append(item)

    errors: list = []
    state = par_loop([1, 2, 3], body, errors=errors)
    assert state.get_value() is State.FAILED and finished == []
    assert [type(e) for e in errors] == [Boom]


def test_item_branches_are_named_after_items() -> None:
    names = []
    try_each_in_order(["a"], lambda item: names.append(current_task().name))
    assert names == ["1:'a'"]


def test_bad_items_and_body_raise_clear_errors() -> None:
    with pytest.raises(TypeError, match="items must be iterable"):
        par_loop(3, lambda x: x)
    with pytest.raises(TypeError, match="body must be a callable"):
        try_each_in_order([1], 3)


def test_try_each_in_order_empty_fails() -> None:
    assert try_each_in_order([], lambda x: x).get_value() is State.FAILED


# -- 2. fluents ------------------------------------------------------------------------------------


def test_on_change_is_called_with_each_new_value_and_removable() -> None:
    f = Fluent(0)
    seen = []
    handle = f.on_change(seen.append)
    f.set_value(1)
    f.set_value(2)
    handle.remove()
    handle.remove()  # idempotent
    f.set_value(3)
    assert seen == [1, 2]


def test_on_change_of_a_network_follows_its_inputs() -> None:
    f = Fluent(0)
    network = f > 2
    seen = []
    network.on_change(seen.append)
    f.set_value(1)
    f.set_value(5)
    assert seen == [None, True]


def test_on_change_exceptions_are_logged_not_propagated(caplog: pytest.LogCaptureFixture) -> None:
    f = Fluent(0)
    seen = []

    def bad(value: object) -> None:
        raise ValueError("bridge down")

    f.on_change(bad)
    f.on_change(seen.append)
    f.set_value(1)  # does not raise
    assert seen == [1]
    assert "bridge down" in caplog.text


def test_on_change_callback_runs_outside_the_fluent_lock() -> None:
    f = Fluent(0)
    waited = []
    # a callback that waits on the same fluent would deadlock if the fluent's lock were held
    f.on_change(lambda value: waited.append(f.wait_for(0.5)))
    f.set_value(1)
    assert waited == [True]


def test_on_change_rejects_non_callables() -> None:
    with pytest.raises(TypeError, match="needs a callable"):
        Fluent().on_change(3)


def test_changes_only_pulses_only_on_a_new_value() -> None:
    f = Fluent(1, changes_only=True)
    pulses = f.pulsed()
    seen = []
    f.on_change(seen.append)
    f.set_value(1)
    assert pulses.peek() is None and seen == []
    f.set_value(2)
    assert pulses.peek() is True and seen == [2]
    plain = Fluent(1)
    plain_pulses = plain.pulsed()
    plain.set_value(1)
    assert plain_pulses.peek() is True


def test_peek_does_not_consume_a_pulse() -> None:
    f = Fluent(0)
    pulses = f.pulsed()
    f.set_value(1)
    assert pulses.peek() is True
    assert pulses.peek() is True
    runs = []
    from pycram.fluent import STOP, whenever

    whenever(pulses, lambda: runs.append(1) or STOP)
    assert runs == [1]


# -- 3. task variables -----------------------------------------------------------------------------

from pycram.language import TaskVariable  # noqa: E402


def test_task_variable_is_inherited_by_branches_across_threads() -> None:
    speed = TaskVariable("speed", default=1.0)
    seen = []
    with speed.bound(0.5):
        par(lambda: seen.append(speed.get()), lambda: seq(lambda: seen.append(speed.get())))
    assert seen == [0.5, 0.5]
    assert speed.get() == 1.0


def test_task_variable_binding_in_a_child_is_not_seen_by_parent_or_siblings() -> None:
    v = TaskVariable("v", default="outer")
    seen = []

    def first() -> None:
        v.set("inner")
        seen.append(v.get())

    seq(first, lambda: seen.append(v.get()))
    assert seen == ["inner", "outer"] and v.get() == "outer"


def test_task_variable_restored_after_failure_and_nesting() -> None:
    v = TaskVariable("v")
    with v.bound(1):
        with pytest.raises(Boom):
            with v.bound(2):
                assert v.get() == 2
                raise Boom()
        assert v.get() == 1
    with pytest.raises(LookupError, match="'v' has no value"):
        v.get()
    assert v.get(default=7) == 7


# -- 4. tags ---------------------------------------------------------------------------------------

from pycram.language import Tags, find_task, find_tasks, tag, with_tags  # noqa: E402
from pycram.runtime import TaskStatus  # noqa: E402


def test_tagged_task_is_found_by_other_branches_and_evaporated() -> None:
    never = Fluent()
    after = []

    def worker() -> None:
        tag("inner", lambda: never.wait_for())()
        after.append("worker went on")  # only the tagged task was evaporated

    with with_tags() as tags:
        state = par(worker, lambda: tags.wait_task("inner", TIMEOUT).evaporate())
    assert state.get_value() is State.SUCCEEDED
    assert tags["inner"].status.get_value() is TaskStatus.EVAPORATED
    assert after == ["worker went on"]


def test_tag_registers_at_any_depth_and_waits_for_the_end() -> None:
    with with_tags() as tags:
        state = par(
            lambda: seq(tag("deep", lambda: 41 + 1)),
            lambda: tags.wait_task("deep", TIMEOUT).status.IS(TaskStatus.SUCCEEDED).wait_for(TIMEOUT),
        )
    assert state.get_value() is State.SUCCEEDED and tags["deep"].result == 42
    assert "deep" in tags and tags.names() == ["deep"]


def test_tags_errors_name_the_problem() -> None:
    tags = Tags()
    with pytest.raises(KeyError, match="no task tagged 'x'"):
        tags["x"]
    with pytest.raises(TimeoutError, match="'x'"):
        tags.wait_task("x", 0.01)
    with pytest.raises(TypeError, match="non-empty string"):
        tag("", lambda: None)


def test_find_task_by_path_and_pattern() -> None:
    paths = []

    def look() -> None:
        me = current_task()
        paths.append(me.path)
        root = me
        while root.parent is not None:
            root = root.parent
        assert find_task(me.path, root) is me
        assert me in find_tasks("*/lookup-here", root)

    par(tag("lookup-here", look))
    with pytest.raises(LookupError, match="no task matches"):
        find_task("*/no-such-task")
    assert paths and paths[0].endswith("/lookup-here")


# -- 5. partial orders -----------------------------------------------------------------------------

from pycram.language import partial_order  # noqa: E402


def test_partial_order_failure_evaporates_waiting_and_running_steps() -> None:
    never = Fluent()
    started = []
    errors: list = []
    state = partial_order(
        {"fails": boom, "waits": lambda: never.wait_for(), "later": lambda: started.append("later")},
        [("fails", "later"), ("waits", "later")],
        errors=errors,
    )
    assert state.get_value() is State.FAILED and started == [] and [type(e) for e in errors] == [Boom]


def test_partial_order_fluent_constraint_and_results() -> None:
    door = Fluent()
    order = []
    state = partial_order(
        {"enter": lambda: order.append("enter") or "in", "open": lambda: door.set_value(True)}, [(door, "enter")]
    )
    assert state.result == ["in", None] and order == ["enter"]


def test_partial_order_bad_input_is_named() -> None:
    with pytest.raises(ValueError, match="unknown step 'c'"):
        partial_order({"a": lambda: 1}, [("a", "c")])
    with pytest.raises(ValueError, match="pair"):
        partial_order({"a": lambda: 1}, [("a",)])
    with pytest.raises(TypeError, match="step 'a' must be a callable"):
        partial_order({"a": 1}, [])


def test_partial_order_block_syntax() -> None:
    log = []

    @plan
    def run() -> StateFluent:
        with partial_order([(2, 1)]) as s:
            log.append("step 1")
            log.append("step 2")
        return s

    state = run()
    assert state.get_value() is State.SUCCEEDED
    assert log == ["step 2", "step 1"]


def test_partial_order_block_needs_the_syntax() -> None:
    from pycram.core.block_forms import BlockSyntaxNotEnabled

    with pytest.raises(BlockSyntaxNotEnabled):
        with partial_order([(1, 2)]):
            pass


# -- 6. suspension ---------------------------------------------------------------------------------

from pycram.language import is_suspended, on_suspension, retry_after_suspension, suspend, wake_up, with_task_suspended  # noqa: E402
from pycram.runtime import check_evaporation, format_task_tree  # noqa: E402


def _spawn_tagged(name: str, fn):
    """Run `par(tags.tag(name, fn))` in a thread; returns (tags, thread, box)."""
    tags = Tags()
    box: dict = {}
    thread = threading.Thread(target=lambda: box.setdefault("state", par(tags.tag(name, fn))), daemon=True)
    thread.start()
    return tags, thread, box


def test_retry_after_suspension_reruns_the_body_after_wake_up() -> None:
    go, running = Fluent(), Fluent()
    runs = []
    cleaned = []

    def body() -> str:
        runs.append(len(runs) + 1)
        running.set_value(True)
        try:
            go.wait_for()
        finally:
            cleaned.append(len(runs))
        return f"run {len(runs)}"

    tags, thread, box = _spawn_tagged("t", lambda: retry_after_suspension(body))
    task = tags.wait_task("t", TIMEOUT)
    assert running.wait_for(TIMEOUT)
    with with_task_suspended(task):
        assert cleaned == [1]  # the first run was evaporated, its clean-up ran
        go.set_value(True)
    thread.join(TIMEOUT)
    assert runs == [1, 2] and task.result == "run 2"
    attempts = task.children[0].children
    assert [t.status.get_value() for t in attempts] == [TaskStatus.EVAPORATED, TaskStatus.SUCCEEDED]


def test_suspensions_count_and_evaporation_wakes_a_suspended_task() -> None:
    never = Fluent()
    tags, thread, box = _spawn_tagged("t", lambda: never.wait_for())
    task = tags.wait_task("t", TIMEOUT)
    suspend(task)
    suspend(task)
    wake_up(task)
    assert is_suspended(task) and task.status.get_value() is TaskStatus.SUSPENDED
    assert "‖ t [branch] suspended" in format_task_tree(task.parent.parent)
    task.evaporate()
    thread.join(TIMEOUT)
    assert not thread.is_alive() and task.status.get_value() is TaskStatus.EVAPORATED
    wake_up(task)
    assert not is_suspended(task)


def test_sync_suspend_leaves_no_watcher_on_the_status_fluents() -> None:
    """The fluent a synchronous `suspend` waits on is gone when it returns, not left for the
    garbage collector: until collected it was pulsed by every status change of the subtree
    (issue 31: dozens piled up over 2,000 suspend/wake cycles and doubled the wake-up latency)."""
    never = Fluent()
    tags, thread, box = _spawn_tagged("t", lambda: never.wait_for())
    task = tags.wait_task("t", TIMEOUT)
    gc.disable()  # a collection would hide what is left behind
    try:
        for _ in range(3):
            suspend(task)
            assert task.status.get_value() is TaskStatus.SUSPENDED
            wake_up(task)
        live = [ref() for ref in task.status._children if ref() is not None]
    finally:
        gc.enable()
        task.evaporate()
        thread.join(TIMEOUT)
    assert live == []
    assert task.status.get_value() is TaskStatus.EVAPORATED


def test_check_evaporation_is_a_suspension_point_and_hooks_run() -> None:
    events = []
    started, release = Fluent(), threading.Event()

    def busy() -> None:
        with on_suspension(lambda: events.append("suspended"), lambda: events.append("woken")):
            started.set_value(True)
            release.wait(TIMEOUT)  # plain Python: not a suspension point
            check_evaporation()  # blocks here while suspended
            events.append("went on")

    tags, thread, box = _spawn_tagged("t", busy)
    task = tags.wait_task("t", TIMEOUT)
    started.wait_for(TIMEOUT)
    suspend(task, sync=False)
    release.set()
    assert _status_is(task, TaskStatus.SUSPENDED)
    assert events == ["suspended"]
    wake_up(task)
    thread.join(TIMEOUT)
    assert events == ["suspended", "woken", "went on"]


def _status_is(task, status) -> bool:
    return task.status.IS(status).wait_for(TIMEOUT)


def test_sync_suspend_times_out_naming_the_busy_task() -> None:
    release = threading.Event()
    tags, thread, box = _spawn_tagged("busy", lambda: release.wait(TIMEOUT))
    task = tags.wait_task("busy", TIMEOUT)
    try:
        with pytest.raises(TimeoutError, match="busy"):
            with with_task_suspended(task, timeout=0.05):
                pass
        assert not is_suspended(task)  # with_task_suspended woke it up again
    finally:
        release.set()
        thread.join(TIMEOUT)
    assert task.status.get_value() is TaskStatus.SUCCEEDED


def test_suspend_rejects_non_tasks() -> None:
    with pytest.raises(TypeError, match="needs a Task"):
        suspend("head")
    with pytest.raises(TypeError, match="needs a Task"):
        with_task_suspended(None)


# -- suspension of process-module executions -------------------------------------------------------

from pycram.process_module import ProcessModule  # noqa: E402


class RecordingModule(ProcessModule):
    """Test double: `_execute` waits for `finish`; every hook call is logged."""

    def __init__(self, suspension: str) -> None:
        super().__init__(f"test-{suspension}")
        self.suspension = suspension  # type: ignore[misc]
        self.log: list[str] = []
        self.started = Fluent(0)
        self.finish = Fluent()

    def _execute(self, designator: object) -> str:
        self.log.append("execute")
        self.started.set_value(self.started.get_value() + 1)
        self.finish.wait_for()
        return "moved"

    def _cancel(self, designator: object) -> None:
        self.log.append("cancel")

    def _pause(self, designator: object) -> None:
        self.log.append("pause")

    def _resume(self, designator: object) -> None:
        self.log.append("resume")


@pytest.mark.parametrize(
    "mode, expected",
    [
        ("pause", ["execute", "pause", "resume"]),
        ("cancel", ["execute", "cancel", "execute"]),
    ],
)
def test_process_module_execution_paused_or_cancelled_on_suspension(mode: str, expected: list) -> None:
    module = RecordingModule(mode)
    tags, thread, box = _spawn_tagged("move", lambda: module.execute("goal"))
    task = tags.wait_task("move", TIMEOUT)
    assert (module.started >= 1).wait_for(TIMEOUT)
    with with_task_suspended(task):
        assert module._current is None if mode == "cancel" else module._current is not None
    assert (module.started >= (2 if mode == "cancel" else 1)).wait_for(TIMEOUT)
    module.finish.set_value(True)
    thread.join(TIMEOUT)
    assert module.log == expected and task.result == "moved"


def test_process_module_rejects_an_unknown_suspension_mode() -> None:
    module = RecordingModule("halt")
    with pytest.raises(ValueError, match="'pause' or 'cancel'"):
        module.execute("goal")


# -- 7. policies -----------------------------------------------------------------------------------

from pycram.language import PolicyConditionMet, PolicyInitFailed, define_policy, timeout_policy, with_policy  # noqa: E402


def _recording_policy(log: list, init_ok: bool = True):
    return define_policy(
        "watch",
        init=lambda run, limit: (log.append(("init", limit)), run.vars.setdefault("limit", limit), init_ok)[-1],
        check=lambda run, limit: (
            (log.append("check"), run.vars["sensor"] > run.vars["limit"])[-1]
            if "sensor" in run.vars
            else _wait_sensor(run, limit)
        ),
        recover=lambda run, limit: log.append("recover"),
        clean_up=lambda run, limit: log.append("clean_up"),
    )


_sensor = Fluent(0)


def _wait_sensor(run, limit):
    run.vars["sensor"] = _sensor
    return _sensor > limit  # a Fluent network: the monitor waits on it


def test_policy_condition_met_evaporates_body_then_recovers_and_cleans_up() -> None:
    log: list = []
    never = Fluent()
    cleaned = []

    def body() -> None:
        try:
            _sensor.set_value(5)  # trips the check
            never.wait_for()
        finally:
            cleaned.append("body clean-up")

    _sensor.set_value(0)
    with pytest.raises(PolicyConditionMet, match="'watch' condition met"):
        with_policy(_recording_policy(log), body, 3)
    assert cleaned == ["body clean-up"]
    assert log == [("init", 3), "recover", "clean_up"]


def test_policy_body_ending_first_returns_its_result() -> None:
    log: list = []
    _sensor.set_value(0)
    assert with_policy(_recording_policy(log), lambda: "done", 3) == "done"
    assert log == [("init", 3), "clean_up"]


def test_policy_body_failure_propagates_and_cleans_up() -> None:
    log: list = []
    _sensor.set_value(0)
    with pytest.raises(Boom):
        with_policy(_recording_policy(log), boom, 3)
    assert log == [("init", 3), "clean_up"]


def test_policy_init_failure_runs_nothing_else() -> None:
    log: list = []
    ran = []
    with pytest.raises(PolicyInitFailed, match="'watch'"):
        with_policy(_recording_policy(log, init_ok=False), lambda: ran.append(1), 3)
    assert ran == [] and log == [("init", 3)]


def test_timeout_policy() -> None:
    never = Fluent()
    with pytest.raises(PolicyConditionMet, match="'timeout'"):
        with_policy(timeout_policy, lambda: never.wait_for(), 0.05)
    assert with_policy(timeout_policy, lambda: 7, 5.0) == 7


def test_policy_bad_input() -> None:
    with pytest.raises(TypeError, match="check must be callable"):
        define_policy("x", check=3)
    with pytest.raises(TypeError, match="needs a Policy"):
        with_policy("timeout", lambda: 1, 1.0)


# -- 8. detached children when their starter ends --------------------------------------------------

from pycram.language import detached_children  # noqa: E402


@pytest.mark.parametrize("rule", ["evaporate", "wait"])
def test_detached_children_rule_at_block_end(rule: str) -> None:
    module = RecordingModule("pause")
    seen = {}

    def starter() -> None:
        with detached_children(rule):
            execution = module.execute_nowait("goal")
            assert (module.started >= 1).wait_for(TIMEOUT)
            if rule == "wait":
                module.finish.set_value(True)
        seen["done"] = execution.done  # the block ended only after the execution ended
        seen["log"] = list(module.log)

    state = par(starter)
    assert state.get_value() is State.SUCCEEDED and seen["done"]
    assert seen["log"] == (["execute", "cancel"] if rule == "evaporate" else ["execute"])


def test_detached_children_default_rule_unchanged_and_bad_rule() -> None:
    module = RecordingModule("pause")

    def starter() -> None:
        module.execute_nowait("goal")
        assert (module.started >= 1).wait_for(TIMEOUT)
        threading.Timer(0.05, lambda: module.finish.set_value(True)).start()

    assert par(starter).get_value() is State.SUCCEEDED
    assert module.log == ["execute"]  # waited for, not evaporated
    with pytest.raises(ValueError, match="must be one of"):
        with detached_children("kill"):
            pass


def test_with_policy_block_syntax() -> None:
    never = Fluent()
    log = []

    @plan
    def run(seconds: float) -> None:
        with with_policy(timeout_policy, seconds):
            log.append("body")
            never.wait_for()

    with pytest.raises(PolicyConditionMet, match="'timeout'"):
        run(0.02)
    assert log == ["body"]


def test_with_policy_block_needs_the_syntax() -> None:
    with pytest.raises(TypeError, match="needs the block syntax"):
        with with_policy(timeout_policy, 1.0):
            pass
