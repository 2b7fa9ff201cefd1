"""Process modules: thesis API, FIFO and mutual exclusion, status, cancellation, errors."""

from __future__ import annotations

import threading

import pytest

from pycram.designator import MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.language import State, par, pursue
from pycram.process_module import (
    Execution,
    ExecutionCancelled,
    NoProcessModuleError,
    ProcessModule,
    ProcessModuleError,
    ProcessModuleFailure,
    ProcessModuleOffline,
    ProcessModuleStatus,
)
from pycram.robot import Robot, use_robot, use_world
from pycram.runtime import Evaporated, TaskGroup, current_task
from pycram.testing import ScriptedProcessModule

S = ProcessModuleStatus
TIMEOUT = 5.0


@pytest.fixture(autouse=True)
def _clean_globals():
    saved = list(ProcessModule.resolvers), list(MotionDesignator.resolvers)
    ProcessModule.resolvers.clear()
    MotionDesignator.resolvers.clear()
    previous_robot, previous_world = use_robot(None), use_world(None)
    yield
    ProcessModule.resolvers[:] = saved[0]
    MotionDesignator.resolvers[:] = saved[1]
    use_robot(previous_robot)
    use_world(previous_world)


def route_all_to(module):
    ProcessModule.resolvers.append(lambda d: module)


def motion(i, **more):
    return MotionDesignator([("type", "moving"), ("n", i)], **more)


def wait_true(fluent_network, timeout=TIMEOUT):
    assert fluent_network.wait_for(timeout), f"timed out waiting for {fluent_network!r}"


# --------------------------------------------------------------------------- thesis API


def test_thesis_perform_execute_and_overridable_execute():
    calls = []

    class Pr2Navigation(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            if solution["cmd"] == "move":
                calls.append((solution["pose"], solution["wait"], solution["frame"]))
            return "moved"

    def pr2_motion_designators(desig):
        solutions = []
        if desig.check_constraints([("type", "moving"), "pose"]):
            solutions.append(
                desig.make_dictionary([("cmd", "move"), "pose", ("wait", True), ("frame", "base_footprint")])
            )
        return solutions

    pr2_navigation = Pr2Navigation()

    def available_pr2_process_modules(design):
        if design.check_constraints([("type", "moving")]):
            return pr2_navigation
        return None

    MotionDesignator.resolvers.append(pr2_motion_designators)
    ProcessModule.resolvers.append(available_pr2_process_modules)
    assert ProcessModule.perform(MotionDesignator([("type", "moving"), ("pose", "p0")])) == "moved"
    assert perform(MotionDesignator(type="moving", pose="p1")) == "moved"
    assert calls == [("p0", True, "base_footprint"), ("p1", True, "base_footprint")]
    assert pr2_navigation.status.get_value() is S.SUCCEEDED
    assert pr2_navigation._running.get_value() is False
    assert ProcessModule().execute(motion(0)) is None  # default _execute does nothing


# --------------------------------------------------------------------------- FIFO + exclusion


def test_fifo_and_mutual_exclusion_with_50_performers():
    module = ScriptedProcessModule("arm", hold=True, default=lambda d: d.prop_value("n"))
    route_all_to(module)
    results = [None] * 50
    group = TaskGroup()

    def performer(i):
        def run():
            results[i] = perform(motion(i))

        return run

    group.spawn("performer-0", performer(0))
    assert module.wait_started(1, TIMEOUT)
    for i in range(1, 50):  # arrive one after the other: i-1 designators already queued
        group.spawn(f"performer-{i}", performer(i))
        wait_true(module.queued >= i)
    assert module.status.get_value() is S.RUNNING
    assert module._designators[0].prop_value("n") == 0 and len(module._designators) == 50
    module.release(50)
    group.wait_all()
    assert [d.prop_value("n") for d in module.executed] == list(range(50))
    assert module.max_concurrency == 1
    assert results == list(range(50))  # each performer got its own designator's result
    assert all(t.status.get_value().name == "SUCCEEDED" for t in group.tasks)
    assert module.status.get_value() is S.SUCCEEDED and module.queued.get_value() == 0


def test_mutual_exclusion_under_a_burst_of_concurrent_performers():
    class Exclusive(ProcessModule):
        def __init__(self):
            super().__init__("exclusive")
            self.inside = 0
            self.overlaps = 0
            self.count = 0

        def _execute(self, designator):
            self.inside += 1
            if self.inside != 1:
                self.overlaps += 1
            for _ in range(200):  # give other threads a chance to sneak in
                pass
            self.count += 1
            self.inside -= 1

    module = Exclusive()
    route_all_to(module)
    barrier = threading.Barrier(50)

    def performer(i):
        def run():
            barrier.wait(TIMEOUT)
            perform(motion(i))

        return run

    group = TaskGroup()
    for i in range(50):
        group.spawn(f"p{i}", performer(i))
    group.wait_all()
    assert module.count == 50 and module.overlaps == 0


def test_two_modules_run_concurrently():
    left, right = ScriptedProcessModule("left", hold=True), ScriptedProcessModule("right", hold=True)
    ProcessModule.resolvers.append(lambda d: left if d.prop_value("arm") == "left" else right)
    handles = [ProcessModule.perform_nowait(MotionDesignator(type="moving", arm=a)) for a in ("left", "right")]
    assert left.wait_started(1, TIMEOUT) and right.wait_started(1, TIMEOUT)  # both at once
    assert left.status.get_value() is S.RUNNING and right.status.get_value() is S.RUNNING
    left.release()
    right.release()
    for h in handles:
        h.wait(TIMEOUT)


# --------------------------------------------------------------------------- status


def test_status_transitions():
    module = ScriptedProcessModule("nav", hold=True, script=["ok", RuntimeError("blocked")])
    route_all_to(module)
    assert module.status.get_value() is S.WAITING
    h = ProcessModule.perform_nowait(motion(1))
    wait_true(module.status == S.RUNNING)
    assert h.status.get_value() is S.RUNNING
    module.release()
    assert h.wait(TIMEOUT) == "ok"
    assert module.status.get_value() is S.SUCCEEDED and h.status.get_value() is S.SUCCEEDED
    h2 = ProcessModule.perform_nowait(motion(2))
    wait_true(module.status == S.RUNNING)
    module.release()
    with pytest.raises(ProcessModuleFailure):
        h2.wait(TIMEOUT)
    assert module.status.get_value() is S.FAILED and h2.status.get_value() is S.FAILED
    module.shutdown()
    assert module.status.get_value() is S.OFFLINE
    with pytest.raises(ProcessModuleOffline, match="nav is offline"):
        perform(motion(3))
    module.start()
    assert module.status.get_value() is S.WAITING


class RecordingFluent(Fluent):
    """A fluent that remembers every value it was set to (to check exact transitions)."""

    def __init__(self, value):
        super().__init__(value)
        self.history = [value]

    def set_value(self, value):
        self.history.append(value)
        super().set_value(value)


def test_status_fluent_exact_transitions_over_every_outcome():
    module = ScriptedProcessModule("arm", hold=True, script=["ok", RuntimeError("stuck"), "never"])
    module.status = RecordingFluent(module.status.get_value())
    route_all_to(module)
    module.release(2)
    assert perform(motion(1)) == "ok"
    with pytest.raises(ProcessModuleFailure):
        perform(motion(2))
    state = pursue(lambda: perform(motion(3)), lambda: module.wait_started(3, TIMEOUT))
    assert state.get_value() is State.SUCCEEDED
    module.shutdown()
    module.start()
    assert module.status.history == [
        S.WAITING,
        S.RUNNING,
        S.SUCCEEDED,
        S.RUNNING,
        S.FAILED,
        S.RUNNING,
        S.CANCELLED,
        S.OFFLINE,
        S.WAITING,
    ]


def test_plan_waits_on_the_status_fluent():
    """A plan branch waits for the module to be RUNNING, then for its outcome."""
    module = ScriptedProcessModule("head", hold=True)
    route_all_to(module)
    seen = []

    def watcher():
        wait_true(module.status == S.RUNNING)
        seen.append(module.status.get_value())
        module.release()
        wait_true(module.status == S.SUCCEEDED)
        seen.append(module.status.get_value())

    state = par(lambda: perform(motion(1)), watcher)
    assert state.get_value() is State.SUCCEEDED and seen == [S.RUNNING, S.SUCCEEDED]


def test_shutdown_fails_queued_designators():
    module = ScriptedProcessModule("nav", hold=True)
    route_all_to(module)
    running = ProcessModule.perform_nowait(motion(1))
    assert module.wait_started(1, TIMEOUT)
    queued = ProcessModule.perform_nowait(motion(2))
    wait_true(module.queued >= 1)
    module.shutdown()
    with pytest.raises(ExecutionCancelled):
        queued.wait(TIMEOUT)
    assert isinstance(queued.exception, ProcessModuleOffline)
    module.release()
    running.wait(TIMEOUT)  # the running one finishes
    assert module.status.get_value() is S.OFFLINE
    assert [d.prop_value("n") for d in module.executed] == [1]


# --------------------------------------------------------------------------- failures


def test_failure_reaches_caller_with_cause_and_module_is_freed():
    module = ScriptedProcessModule("arm", script=[RuntimeError("arm stuck")])
    route_all_to(module)
    with pytest.raises(ProcessModuleFailure) as info:
        perform(motion(1, arm="left"))
    error = info.value
    assert isinstance(error.cause, RuntimeError) and error.__cause__ is error.cause
    assert error.module is module and error.designator.prop_value("n") == 1
    assert "arm stuck" in str(error) and "('arm', 'left')" in str(error)
    assert isinstance(error, ProcessModuleError)
    assert perform(motion(2)) is None  # freed: the next one runs
    assert module.status.get_value() is S.SUCCEEDED


def test_failure_inside_par_reaches_the_plan():
    module = ScriptedProcessModule("arm", script=[ValueError("bad joint")])
    route_all_to(module)
    errors = []
    state = par(lambda: perform(motion(1)), errors=errors)
    assert state.get_value() is State.FAILED
    assert isinstance(errors[0], ProcessModuleFailure) and isinstance(errors[0].cause, ValueError)


def test_no_module_names_designator_and_active_robot():
    with pytest.raises(NoProcessModuleError) as info:
        perform(MotionDesignator([("type", "flying"), ("height", 2)]))
    assert "('type', 'flying')" in str(info.value) and "no active robot" in str(info.value)
    robot = Robot("one-armed-test-robot")
    robot.add_process_module("arm", ScriptedProcessModule("arm"))
    with robot, pytest.raises(NoProcessModuleError) as info:
        perform(MotionDesignator([("type", "flying")]))
    assert "'one-armed-test-robot'" in str(info.value) and "['arm']" in str(info.value)


def test_resolver_errors_are_clear():
    def broken(d):
        raise KeyError("arm")

    ProcessModule.resolvers.append(broken)
    with pytest.raises(ProcessModuleError, match="broken"):
        perform(motion(1))
    ProcessModule.resolvers[:] = [lambda d: "not a module"]
    with pytest.raises(ProcessModuleError, match="not a ProcessModule"):
        perform(motion(1))


# --------------------------------------------------------------------------- cancellation


def test_cancel_on_evaporation_while_queued():
    module = ScriptedProcessModule("nav", hold=True)
    route_all_to(module)
    first = ProcessModule.perform_nowait(motion("A"))
    assert module.wait_started(1, TIMEOUT)
    state = pursue(lambda: perform(motion("B")), lambda: wait_true(module.queued >= 1))
    assert state.get_value() is State.SUCCEEDED  # the waiter won; B was evaporated in the queue
    assert module.queued.get_value() == 0
    third = ProcessModule.perform_nowait(motion("C"))
    wait_true(module.queued >= 1)
    module.release(2)
    first.wait(TIMEOUT)
    third.wait(TIMEOUT)
    assert [d.prop_value("n") for d in module.executed] == ["A", "C"]
    assert [d.prop_value("n") for d in module.cancelled] == ["B"]  # the hook ran for B, which never ran


def test_cancel_on_evaporation_while_running_runs_hook_and_frees_module():
    module = ScriptedProcessModule("nav", hold=True)
    route_all_to(module)
    queued = []

    def queue_next_and_release_it():  # a caller outside the pursue, queued behind 'A'
        if module.wait_started(1, TIMEOUT):
            queued.append(ProcessModule.perform_nowait(motion("next")))
            if module.wait_started(2, TIMEOUT):
                module.release()

    tasks = []

    def mover():
        tasks.append(current_task())
        perform(motion("A"))

    def stopper():
        wait_true(module.queued >= 1)

    helper = threading.Thread(target=queue_next_and_release_it, daemon=True)
    helper.start()
    state = pursue(mover, stopper)
    helper.join(TIMEOUT)
    assert state.get_value() is State.SUCCEEDED
    assert [d.prop_value("n") for d in module.cancelled] == ["A"]
    assert tasks[0].status.get_value().name == "EVAPORATED"
    # the module was freed: the next queued designator started and ran
    assert queued[0].wait(TIMEOUT) is None
    assert [e for e, _ in module.log] == ["start", "cancel", "start", "end"]
    assert module.status.get_value() is S.SUCCEEDED


def test_evaporating_a_task_blocked_in_perform():
    module = ScriptedProcessModule("head", hold=True)
    route_all_to(module)
    group = TaskGroup()
    caught = []

    def body():
        try:
            perform(motion(1))
        except Evaporated:
            caught.append(True)
            raise

    task = group.spawn("looker", body)
    assert module.wait_started(1, TIMEOUT)
    task.evaporate()
    group.wait_all()
    assert caught == [True] and module.cancelled[0].prop_value("n") == 1
    assert module.status.get_value() is S.CANCELLED and module.current is None


# --------------------------------------------------------------------------- non-blocking


def test_nowait_via_wait_false_property_and_handle():
    module = ScriptedProcessModule("gripper", hold=True, script=[7])
    route_all_to(module)
    handle = perform(MotionDesignator([("type", "setting_gripper"), ("wait", False)]))
    assert isinstance(handle, Execution)
    wait_true(handle.status == S.RUNNING)
    with pytest.raises(TimeoutError):
        handle.wait(timeout=0.01)
    module.release()
    assert handle.wait(TIMEOUT) == 7 and handle.done


def test_handle_cancel_while_running_and_while_queued():
    module = ScriptedProcessModule("arm", hold=True)
    route_all_to(module)
    running = ProcessModule.perform_nowait(motion(1))
    assert module.wait_started(1, TIMEOUT)
    queued = ProcessModule.perform_nowait(motion(2))
    last = ProcessModule.perform_nowait(motion(3))
    wait_true(module.queued >= 2)
    queued.cancel()
    with pytest.raises(ExecutionCancelled):
        queued.wait(TIMEOUT)
    running.cancel()
    with pytest.raises(ExecutionCancelled):
        running.wait(TIMEOUT)
    assert [d.prop_value("n") for d in module.cancelled] == [1]
    module.release()
    last.wait(TIMEOUT)
    assert [d.prop_value("n") for d in module.executed] == [1, 3]
    running.cancel()  # idempotent, no effect once done
    assert running.status.get_value() is S.CANCELLED


def test_cancel_while_running_plain_python_execute():
    """An _execute that never calls into pycram is stopped by the injected evaporation."""

    class Busy(ProcessModule):
        def __init__(self):
            super().__init__("busy")
            self.started = threading.Event()
            self.stopped = []

        def _execute(self, designator):
            self.started.set()
            x = 0
            while True:  # plain Python: no pycram wait to wake up
                x += 1

        def _cancel(self, designator):
            self.stopped.append(designator.prop_value("n"))

    module = Busy()
    route_all_to(module)
    state = pursue(lambda: perform(motion(1)), lambda: module.started.wait(TIMEOUT))
    assert state.get_value() is State.SUCCEEDED
    assert module.stopped == [1] and module.status.get_value() is S.CANCELLED
    assert module.current is None and module.queued.get_value() == 0


def test_executions_and_performed_designators_are_published_as_events():
    from pycram.core import events

    executed, performed = [], []
    unsubscribe = [
        events.subscribe(events.PROCESS_MODULE_EXECUTED, lambda **kw: executed.append(kw)),
        events.subscribe(events.DESIGNATOR_PERFORMED, lambda **kw: performed.append(kw)),
    ]
    try:
        module = ScriptedProcessModule("nav", hold=True, script=[lambda d: d.reference(), KeyError("map")])
        route_all_to(module)
        MotionDesignator.resolvers.append(lambda d: [{"cmd": "move", "n": d.prop_value("n")}])
        module.release(2)
        perform(motion(1))
        with pytest.raises(ProcessModuleFailure):
            perform(motion(2))
        pursue(lambda: perform(motion(3)), lambda: module.wait_started(3, TIMEOUT))
    finally:
        for u in unsubscribe:
            u()
    assert [(e["module"], e["designator"].prop_value("n"), e["outcome"]) for e in executed] == [
        (module, 1, "succeeded"),
        (module, 2, "failed"),
        (module, 3, "cancelled"),
    ]
    assert all(e["start"] is not None and e["start"] <= e["end"] for e in executed)
    assert isinstance(executed[1]["error"], KeyError)  # the module's own error
    assert executed[0]["error"] is None and executed[2]["error"] is None
    assert [(p["designator"].prop_value("n"), type(p["error"]).__name__) for p in performed] == [
        (1, "NoneType"),
        (2, "ProcessModuleFailure"),
        (3, "Evaporated"),
    ]
    assert performed[0]["solution"] == {"cmd": "move", "n": 1}  # resolved by _execute


def test_public_surface():
    import pycram.process_module as pm
    import pycram.robot as robot_module
    import pycram.testing as testing

    for module in (pm, robot_module, testing):
        for name in module.__all__:
            assert hasattr(module, name), (module.__name__, name)


@pytest.mark.parametrize("exit_exception", [SystemExit(3), KeyboardInterrupt()])
def test_execution_ended_by_systemexit_or_keyboardinterrupt_is_failed_not_cancelled(exit_exception):
    module = ScriptedProcessModule("nav", script=[exit_exception])
    route_all_to(module)
    with pytest.raises(type(exit_exception)) as raised:
        ProcessModule.perform(motion(1))
    assert raised.value is exit_exception  # propagates unchanged, not wrapped
    assert module.status.get_value() is S.FAILED
    assert module.cancelled == []  # not a cancellation: the cancel hook did not run
    # the module is free again
    module.script.append("ok")
    assert ProcessModule.perform(motion(2)) == "ok"


def test_nowait_execution_ended_by_keyboardinterrupt_reports_failed():
    module = ScriptedProcessModule("nav", script=[KeyboardInterrupt()])
    route_all_to(module)
    handle = ProcessModule.perform_nowait(motion(1))
    with pytest.raises(KeyboardInterrupt):
        handle.wait(TIMEOUT)
    assert handle.status.get_value() is S.FAILED
    assert isinstance(handle.exception, KeyboardInterrupt)
