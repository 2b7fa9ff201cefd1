"""Task runtime: task tree, clocks, sleep, worker threads, import hygiene."""

from __future__ import annotations

import subprocess
import sys
import threading
import time

import pytest

from pycram.fluent import Fluent
from pycram.language import State, par, pursue, seq, with_timeout
from pycram.runtime import (
    ManualClock,
    TaskStatus,
    add_task_listener,
    current_clock,
    current_task,
    format_task_tree,
    remove_task_listener,
    run_subtask,
    sleep,
    use_clock,
)
from pycram.runtime.workers import shutdown_idle_workers, worker_count

WAIT = 5.0


def test_current_task_is_a_root_outside_expressions_and_the_branch_inside():
    root = current_task()
    assert root.kind == "root" and root.parent is None
    seen = []
    par(lambda: seen.append(current_task()), name="tour")
    branch = seen[0]
    assert branch.kind == "branch" and branch.parent.name == "tour"
    assert branch.path == f"{root.path}/tour/{branch.name}"


def test_task_status_transitions_and_times():
    observed = []
    gate = Fluent()

    def body():
        me = current_task()
        observed.append(me.status.get_value())
        gate.wait_for(timeout=WAIT)

    def watcher():
        branch = current_task().parent.children[0]
        assert (branch.status == TaskStatus.RUNNING).wait_for(timeout=WAIT)
        gate.set_value(True)
        assert branch.status.IS_NOT(TaskStatus.RUNNING).wait_for(timeout=WAIT)

    assert par(body, watcher).get_value() is State.SUCCEEDED
    task = current_task().children[-1].children[0]
    assert observed == [TaskStatus.RUNNING]
    assert task.status.get_value() is TaskStatus.SUCCEEDED
    assert task.duration is not None and task.duration >= 0


def test_run_subtask_returns_result_and_records_failure():
    assert run_subtask("answer", lambda: 42) == 42
    with pytest.raises(ZeroDivisionError):
        run_subtask("divide", lambda: 1 / 0)
    task = current_task().children[-1]
    assert task.name == "divide" and task.status.get_value() is TaskStatus.FAILED
    assert isinstance(task.exception, ZeroDivisionError)


def test_format_task_tree_shows_statuses_durations_and_failures():
    def broken():
        raise ValueError("gripper empty")

    seq(lambda: None, broken, name="fetch")
    text = format_task_tree(current_task().children[-1])
    lines = text.splitlines()
    assert lines[0].startswith("✘ fetch [seq] failed")
    assert "ms" in lines[0]
    assert "✔ 1 [step] succeeded" in lines[1]
    assert "✘ 2:broken [step] failed" in lines[2] and "ValueError: gripper empty" in lines[2]


def test_task_listeners_see_every_start_and_end_in_order():
    events = []

    class Listener:
        def task_started(self, task):
            events.append(("start", task.name))

        def task_ended(self, task):
            events.append(("end", task.name, task.status.get_value()))

    listener = Listener()
    add_task_listener(listener)
    try:
        seq(lambda: None, name="observed")
    finally:
        remove_task_listener(listener)
    seq(lambda: None, name="unobserved")
    assert events == [
        ("start", "observed"),
        ("start", "1"),
        ("end", "1", TaskStatus.SUCCEEDED),
        ("end", "observed", TaskStatus.SUCCEEDED),
    ]


def test_sleep_follows_the_active_clock():
    clock = ManualClock(start=100.0)
    done = Fluent()

    def sleeper():
        sleep(5.0)
        done.set_value(current_clock().now())

    with use_clock(clock):
        thread = threading.Thread(target=sleeper, daemon=True)
        thread.start()
        deadline = time.monotonic() + WAIT
        while clock.next_deadline() is None and time.monotonic() < deadline:
            time.sleep(0.001)  # wait (bounded) for the sleeper to register its deadline
        assert clock.next_deadline() == 105.0
        thread.join(0.02)
        assert thread.is_alive() and done.get_value() is None  # wall time does not wake it
        clock.advance(4.0)
        thread.join(0.02)
        assert thread.is_alive() and done.get_value() is None
        clock.advance(1.0)
        thread.join(WAIT)
    assert done.get_value() == pytest.approx(105.0)
    assert isinstance(current_clock(), type(current_clock()))  # wall clock is back


def test_task_times_use_the_active_clock():
    clock = ManualClock(start=7.0)
    with use_clock(clock):
        seq(lambda: clock.advance(2.0), name="timed")
    task = current_task().children[-1]
    assert (task.start_time, task.end_time) == (7.0, 9.0)


def test_no_branch_thread_outlives_its_expression():
    before = {t.ident for t in threading.enumerate()}
    for _ in range(20):
        pursue(lambda: Fluent().wait_for(), lambda: par(lambda: None, lambda: sleep(0.001)))
        assert worker_count()[0] == 0  # no worker is running a branch any more
    shutdown_idle_workers()
    after = {t.ident for t in threading.enumerate()}
    assert after <= before | {None}
    assert not [t for t in threading.enumerate() if t.name.startswith("pycram-worker")]


def test_many_idle_monitors_cost_no_cpu():
    flags = [Fluent() for _ in range(300)]
    stop = Fluent()

    def monitor(flag):
        return lambda: flag.wait_for()

    def measure():
        started = time.process_time()
        stop.wait_for(timeout=0.3)
        measure.cpu = time.process_time() - started

    pursue(*[monitor(f) for f in flags], measure)
    assert measure.cpu < 0.05  # process CPU while 300 monitors wait 0.3 s: essentially nothing


def test_with_timeout_on_a_manual_clock_is_exact():
    clock = ManualClock()
    errors = []

    def body():
        Fluent().wait_for()

    def run():
        run.state = with_timeout(3.0, body, errors=errors)

    with use_clock(clock):
        thread = threading.Thread(target=run, daemon=True)
        thread.start()
        deadline = time.monotonic() + WAIT
        while clock.next_deadline() != 3.0 and time.monotonic() < deadline:
            time.sleep(0.001)
        clock.advance_to(2.999)
        thread.join(0.02)
        assert thread.is_alive()
        clock.advance_to(3.0)
        thread.join(WAIT)
    assert run.state.get_value() is State.FAILED and isinstance(errors[0], TimeoutError)


def test_language_core_imports_fast_and_only_the_standard_library():
    code = (
        "import sys, time\n"
        "before = set(sys.modules)\n"
        "t = time.perf_counter()\n"
        "import pycram.language, pycram.fluent, pycram.runtime\n"
        "elapsed = time.perf_counter() - t\n"
        "stdlib = set(sys.stdlib_module_names)\n"
        "third = sorted({m.split('.')[0] for m in set(sys.modules) - before} - stdlib - {'pycram', '__main__'})\n"
        "import threading\n"
        "print(elapsed, third, threading.active_count())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split(" ", 1)
    elapsed, rest = float(out[0]), out[1]
    assert elapsed < 0.3
    assert rest.startswith("[] 1"), rest  # no third-party module, no thread started at import
