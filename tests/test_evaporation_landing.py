"""An asynchronous `Evaporated` may land at any point where the interpreter checks for it while
the runtime says plan code runs (`Runner.in_plan`). These tests make it land at each such point
in turn, deterministically, and check that every task still ends and the expression returns.

How: a trace function (opcode events) in the branch's thread counts the points where CPython
(3.11+) handles a pending asynchronous exception — a function's entry (`RESUME`), the
instruction after a call of a C function (a blocking one may have released the GIL meanwhile),
the loop head after a backward jump — while `in_plan` is true. At the n-th it evaporates the
branch's task as `pursue` would and raises `Evaporated` there, as the asynchronous exception
would. Raising from a trace function ends tracing of that thread, so each run lands once.

The race this pins down was found by the random-plan property test in CI: the exception
landing at the entry of a `with task_scope(...)` exit left the tag's task RUNNING for good.
"""

from __future__ import annotations

import dis
import gc
import inspect
import sys
from collections.abc import Callable
from typing import Any

import pytest

import pycram
from pycram.core.runtime.evaporation import _USER, Evaporated, current_runner, shielded
from pycram.designator import MotionDesignator, perform
from pycram.language import (
    State,
    TaskVariable,
    current_attempt,
    failure_handling,
    par,
    par_loop,
    partial_order,
    pursue,
    retry,
    retry_after_suspension,
    seq,
    tag,
    timeout_policy,
    try_each_in_order,
    try_in_order,
    with_policy,
    with_timeout,
)
from pycram.process_module import ProcessModule, ProcessModuleStatus
from pycram.runtime import Task, as_task, current_task
from pycram.testing import ScriptedProcessModule

MAX_POINTS = 400  # more than any scenario below executes


_GENERATOR_FLAGS = inspect.CO_GENERATOR | inspect.CO_COROUTINE | inspect.CO_ASYNC_GENERATOR


def _landing_tracer(n: int, landed: list[str]) -> Callable[..., Any]:
    """A trace function raising `Evaporated` at the n-th check point seen with `in_plan`."""
    seen = [0]
    after_call: dict[int, bool] = {}  # frame id -> its last instruction was a call of C code
    last_offset: dict[int, int] = {}  # frame id -> offset of its last instruction

    def land(frame: Any, event: str) -> Any:
        runner = current_runner()
        if not runner.in_plan or runner._mode != _USER or runner.task is None or runner._lock.locked():
            return  # only plan code outside runtime sections (a point under the runner's own lock
            # would be one: the raise below needs that lock)
        seen[0] += 1
        if seen[0] != n:
            return
        branch = runner.task
        while branch.kind != "branch" and branch.parent is not None:
            branch = branch.parent
        with shielded():  # flags set as `evaporate()` sets them; delivered by the raise below
            branch.evaporate()
        runner._mark_delivered()
        where = f"{frame.f_code.co_filename.rsplit('/', 1)[-1]}:{frame.f_lineno} ({frame.f_code.co_name})"
        landed.append(f"{event} {where}")
        raise Evaporated()

    def tracer(frame: Any, event: str, arg: Any) -> Any:
        if event == "call":
            frame.f_trace_opcodes = True
            if frame.f_back is not None:
                after_call[id(frame.f_back)] = False  # the caller called Python code, not C
            if not (frame.f_code.co_flags & _GENERATOR_FLAGS and frame.f_lasti > 0):  # not a resumption
                land(frame, "entry")
            return tracer
        if event == "return":  # (frame ids are reused once a frame is gone)
            after_call.pop(id(frame), None)
            last_offset.pop(id(frame), None)
            return tracer
        if event != "opcode":
            return tracer
        key = id(frame)
        pending_c_call = after_call.pop(key, False)
        opname = dis.opname[frame.f_code.co_code[frame.f_lasti]]
        if opname == "CALL":
            after_call[key] = True
        if pending_c_call:
            land(frame, "after a C call at")
        elif frame.f_lasti < last_offset.get(key, -1):
            land(frame, "loop head")
        last_offset[key] = frame.f_lasti
        return tracer

    return tracer


def _run_branch_with_landing(n: int, body: Callable[[], Any]) -> tuple[list[str], Task, State]:
    """Run `body` as the one branch of a `par`, landing an `Evaporated` at traced point n."""
    landed: list[str] = []

    def branch() -> Any:
        sys.settrace(_landing_tracer(n, landed))
        try:
            return body()
        finally:
            sys.settrace(None)

    parent = current_task()
    before = len(parent.children)
    gc.disable()  # no garbage-collection callback (e.g. a library's) runs in the traced thread
    try:
        state = par(branch).get_value()
    finally:
        gc.enable()
    return landed, parent.children[before], state


def _assert_every_point(body: Callable[[], Any]) -> int:
    points = 0
    for n in range(1, MAX_POINTS + 1):
        landed, expression, state = _run_branch_with_landing(n, body)
        unfinished = [t.path for t in expression.walk() if not t.done]
        assert not unfinished, f"landing at traced point {n} ({landed}): tasks never ended: {unfinished}"
        assert state in (State.SUCCEEDED, State.FAILED), state
        if not landed:
            return points  # n passed the last traced point: every point was covered
        points += 1
    pytest.fail(f"more than {MAX_POINTS} traced points: raise MAX_POINTS")


def _work() -> int:
    total = 0
    for i in range(3):
        total += i
    return total


def _retrying() -> int:
    def body() -> int:
        if current_attempt() == 1:
            try:
                raise ValueError("first attempt fails")
            except ValueError:
                retry()
        return _work()

    return failure_handling(body, max_retries=2)


VARIABLE = TaskVariable("landing-test variable", default=0)


def _bound() -> int:
    with VARIABLE.bound(3):
        return _work() + VARIABLE.get()


SCENARIOS: dict[str, Callable[[], Any]] = {
    "nested tags": tag("b", tag("c", _work)),
    "retry_after_suspension": lambda: retry_after_suspension(_work),
    "seq": lambda: seq(_work, _work),
    "try_in_order": lambda: try_in_order(_work, _work),
    "failure_handling with a retry": _retrying,
    "with_timeout": lambda: with_timeout(5.0, _work),
    "nested pursue": lambda: pursue(_work, lambda: pycram.sleep(0.2)),
    "partial_order": lambda: partial_order([_work, _work], [(1, 2)]),
    "par_loop": lambda: par_loop([1, 2], lambda item: _work()),
    "try_each_in_order": lambda: try_each_in_order([1, 2], lambda item: _work()),
    "with_policy": lambda: with_policy(timeout_policy, _work, 0.2),
    "task variable": _bound,
    "as_task": as_task(_work),
}


@pytest.mark.parametrize("scenario", list(SCENARIOS))
def test_an_evaporation_landing_anywhere_ends_every_task(scenario: str) -> None:
    points = _assert_every_point(SCENARIOS[scenario])
    assert points > 5  # the scenario really ran through the runtime's bookkeeping


@pytest.fixture()
def scripted_module() -> Any:
    saved = list(ProcessModule.resolvers), list(MotionDesignator.resolvers)
    ProcessModule.resolvers.clear()
    MotionDesignator.resolvers.clear()
    module = ScriptedProcessModule("landing-test module")
    ProcessModule.resolvers.append(lambda designator: module)
    yield module
    ProcessModule.resolvers[:] = saved[0]
    MotionDesignator.resolvers[:] = saved[1]


@pytest.mark.parametrize("wait", [True, False])
def test_an_evaporation_landing_anywhere_in_a_process_module_execution_frees_the_module(
    scripted_module: ScriptedProcessModule, wait: bool
) -> None:
    def body() -> None:
        execution = perform(MotionDesignator([("type", "moving"), ("wait", wait)]))
        if not wait:
            execution.wait()

    points = _assert_every_point(body)
    assert points > 5
    # the module is free again: a plain execution after all those evaporations goes through
    perform(MotionDesignator([("type", "moving")]))
    assert scripted_module.status.get_value() is ProcessModuleStatus.SUCCEEDED
