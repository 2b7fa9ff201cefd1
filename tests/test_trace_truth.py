"""The trace tells the truth (issue 12, section 3): every process-module execution is in the
task tree, each failure is counted once, a failed demo run says why, `pycram runs` has a
header and a reason column, and `pycram show` says which times are simulated and which are
wall-clock. Databases written before these columns existed are migrated and still read.
"""

from __future__ import annotations

import sqlite3

import pytest

sa = pytest.importorskip("sqlalchemy")

from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402
from pycram.language import seq, try_in_order  # noqa: E402
from pycram.runtime import ManualClock, as_task, run_subtask, use_clock  # noqa: E402
from pycram.trace import query  # noqa: E402
from pycram.trace.recorder import start_recording  # noqa: E402

runner = CliRunner()


@pytest.fixture
def wide(monkeypatch):
    """One terminal line per tree line and per run (the CLI console is 80 columns in tests)."""
    import pycram.apps.cli

    monkeypatch.setattr(pycram.apps.cli.console, "width", 250)


def _invoke(*args: str):
    return runner.invoke(app, list(args), catch_exceptions=False)


# -- every process-module execution is in the tree ---------------------------------------------


def _robot_with_modules():
    from pycram.robot import Robot
    from pycram.testing import ScriptedProcessModule

    base = ScriptedProcessModule("base")
    arm = ScriptedProcessModule("arm", script=[None, RuntimeError("joint limit")])
    robot = Robot("test-robot")
    robot.add_process_module("base", base)
    robot.add_process_module("arm", arm)
    robot.process_module_resolvers.append(lambda d: base if d.prop_value("type") == "moving" else arm)
    robot.motion_resolvers.append(lambda d: [{"command": d.prop_value("type")}])
    return robot


def test_blocking_and_non_blocking_executions_are_in_the_task_tree(tmp_path, wide):
    """A blocking execution runs in the performing task's thread (no task of its own): it is
    shown as a child of that task, in time order among its siblings; a non-blocking one is
    its own task and is shown once."""
    from pycram.designator import MotionDesignator, perform
    from pycram.process_module import ProcessModuleFailure

    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    robot = _robot_with_modules()

    def fetch() -> None:
        drive = perform(MotionDesignator(type="moving", wait=False))  # its own task
        drive.wait()
        seq(lambda: None, name="look")
        perform(MotionDesignator(type="reaching"))  # blocking: no task of its own
        with pytest.raises(ProcessModuleFailure):
            perform(MotionDesignator(type="gripping"))

    recorder = start_recording(url, plan="modules")
    with robot:
        run_subtask("fetch", fetch, kind="plan")
    run_id = recorder.finish("succeeded")
    assert len(query.executions(run_id, url=url)) == 3

    out = _invoke("show", "--expand", "--db", url).output
    lines = out.splitlines()
    assert sum("base: moving [process-module]" in line for line in lines) == 1, out
    assert sum("arm: reaching [process-module] succeeded" in line for line in lines) == 1, out
    assert (
        sum("arm: gripping [process-module] failed" in line and "RuntimeError: joint limit" in line for line in lines)
        == 1
    ), out
    assert "3 process-module executions" in out

    tasks, executions = query.tree_records(run_id, url)
    assert [x.name for x in executions] == ["arm: reaching", "arm: gripping"]
    fetch_node = next(
        n for root in query.build_tree(tasks + executions) for n, _ in root.walk() if n.record.name == "fetch"
    )
    assert [c.record.name for c in fetch_node.children] == ["base: moving", "look", "arm: reaching", "arm: gripping"]

    svg = tmp_path / "tree.svg"
    assert _invoke("graph", "--db", url, "-o", str(svg)).exit_code == 0
    assert "arm: reaching" in svg.read_text()


# -- each failure counted once ------------------------------------------------------------------


class GraspFailed(Exception):
    pass


@as_task
def grab_item(ok: bool) -> None:
    if not ok:
        raise GraspFailed("the gripper closed on nothing")


def _fetch(outcomes: list[bool]) -> None:
    """Try to grasp at each place in turn (as the demo does); re-raise the last failure."""
    errors: list = []
    state = try_in_order(*[lambda ok=ok: grab_item(ok) for ok in outcomes], errors=errors)
    if state.get_value().value == "failed":
        raise errors[-1]


def test_a_failure_re_raised_by_enclosing_tasks_is_counted_once(tmp_path, wide):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    expected = 0
    for outcomes in ([False, True], [False, False, False]):
        recorder = start_recording(url, plan="fetch")
        seq(lambda outcomes=outcomes: _fetch(outcomes), errors=[], name="fetch")
        recorder.finish("succeeded")
        expected += outcomes.count(False)

    failed = query.failed_tasks(error_type="GraspFailed", url=url)
    assert len(failed) == expected == 4  # the question "how many grasps failed in all runs"
    assert {r.name for r in failed} == {"grab_item"} and not any(r.propagated for r in failed)
    every = query.failed_tasks(error_type="GraspFailed", url=url, propagated=True)
    # in the failing run GraspFailed also failed the step, the try_in_order, the fetch step, the seq
    assert len(every) > len(failed)
    by_id = {(r.run_id, r.task_id): r for r in every}
    for r in every:
        origin = by_id[(r.run_id, r.error_origin)]
        assert origin.name == "grab_item" and origin.error_message == r.error_message

    out = _invoke("show", "--db", url).output
    assert "GraspFailed passed on from grab_item" in out
    assert "GraspFailed: the gripper closed on nothing" in out


def test_the_demo_database_counts_each_failed_grasp_once_and_shows_every_execution(tmp_path, wide):
    """A real demo run with no item: three grasps fail (each re-raised by its `try_in_order`
    step and the `try_in_order`), the run's error is recorded, and the task tree lists the
    blocking reaching motions."""
    from pycram.apps.demos.kitchen import DemoOptions, run_demo

    url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    result = run_demo(DemoOptions(output=tmp_path / "out", quiet=True, db=url, item_at=0, animation=False))
    assert result.exit_code != 0 and result.failed_grasps == 3

    assert len(query.failed_tasks(error_type="GraspFailed", url=url)) == 3
    assert len(query.failed_tasks(error_type="GraspFailed", url=url, propagated=True)) > 3
    run = query.get_run(result.run_id, url)
    assert run.error == result.message and run.error.startswith("NoItemGrasped: could not grasp")
    assert run.clock == "simulated"

    listed = _invoke("runs", "--db", url).output.splitlines()
    assert listed[0].split() == ["id", "started", "plan", "robot", "outcome", "took", "reason"]
    assert "failed" in listed[1] and "NoItemGrasped: could not grasp" in listed[1]

    executions = query.executions(result.run_id, url=url)
    out = _invoke("show", "--expand", "--db", url).output
    assert sum("[process-module]" in line for line in out.splitlines()) >= len(executions)
    reaching = sum(x.designator_type == "reaching" for x in executions)
    assert (
        reaching >= 3 and sum("arm_right: reaching [process-module]" in line for line in out.splitlines()) == reaching
    )
    assert "times in the tree: simulated clock" in out and "(wall-clock)" in out


# -- runs, clocks --------------------------------------------------------------------------------


def test_runs_has_a_header_and_the_failure_reason(tmp_path, wide):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    start_recording(url, plan="good").finish("succeeded")
    start_recording(url, plan="bad").finish("failed", GraspFailed("no item at (0.10, -1.15)"))
    lines = _invoke("runs", "--db", url).output.splitlines()
    assert lines[0].split() == ["id", "started", "plan", "robot", "outcome", "took", "reason"]
    assert lines[1].startswith("2 ") and lines[1].rstrip().endswith("GraspFailed: no item at (0.10, -1.15)")
    assert lines[2].startswith("1 ") and lines[2].rstrip().endswith("succeeded") is False
    assert "succeeded" in lines[2]


def test_show_says_which_times_are_simulated_and_which_wall_clock(tmp_path, wide):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    recorder = start_recording(url, plan="wall")
    seq(lambda: None, name="on the wall clock")
    wall = recorder.finish("succeeded")

    recorder = start_recording(url, plan="simulated")  # started on the wall clock
    clock = ManualClock(100.0)
    with use_clock(clock):

        def step() -> None:
            clock.advance(2.5)

        run_subtask("on the simulated clock", step)
    simulated = recorder.finish("succeeded")  # finished on the wall clock again

    recorder = start_recording(url, plan="mixed")
    seq(lambda: None, name="wall")
    with use_clock(ManualClock(0.0)):
        seq(lambda: None, name="simulated")
    mixed = recorder.finish("succeeded")

    assert [query.get_run(r, url).clock for r in (wall, simulated, mixed)] == [
        "wall-clock",
        "simulated",
        "wall-clock+simulated",
    ]
    out = _invoke("show", str(simulated), "--db", url).output
    assert "times in the tree: simulated clock" in out and "(wall-clock)" in out
    assert "on the simulated clock [task] succeeded 2.50 s" in out
    assert "times in the tree: wall clock" in _invoke("show", str(wall), "--db", url).output
    assert "mixed: wall clock and simulated clock" in _invoke("show", str(mixed), "--db", url).output


# -- databases of schema 1 -----------------------------------------------------------------------

_SCHEMA_1 = """
CREATE TABLE pycram_runs (id INTEGER PRIMARY KEY AUTOINCREMENT, uuid VARCHAR(36) NOT NULL UNIQUE,
    plan VARCHAR(255), robot VARCHAR(255), host VARCHAR(255), pid INTEGER, command TEXT,
    started_at DATETIME NOT NULL, ended_at DATETIME, last_seen_at DATETIME, outcome VARCHAR(32),
    duration FLOAT, clock_origin FLOAT, error TEXT, info TEXT);
CREATE TABLE pycram_tasks (id INTEGER PRIMARY KEY AUTOINCREMENT, run_id INTEGER NOT NULL, task_id INTEGER NOT NULL,
    parent_id INTEGER, name VARCHAR(512) NOT NULL, kind VARCHAR(64), path TEXT, thread VARCHAR(255),
    status VARCHAR(16) NOT NULL, start FLOAT, "end" FLOAT, duration FLOAT, error_type VARCHAR(255),
    error_message TEXT);
CREATE TABLE pycram_designators (id INTEGER PRIMARY KEY AUTOINCREMENT, run_id INTEGER NOT NULL, task_id INTEGER,
    time FLOAT, designator_class VARCHAR(255), designator_type VARCHAR(255), designator TEXT, solution TEXT,
    error_type VARCHAR(255), error_message TEXT);
CREATE TABLE pycram_executions (id INTEGER PRIMARY KEY AUTOINCREMENT, run_id INTEGER NOT NULL, task_id INTEGER,
    module VARCHAR(255), designator_type VARCHAR(255), designator TEXT, outcome VARCHAR(32), start FLOAT,
    "end" FLOAT, duration FLOAT, error_type VARCHAR(255), error_message TEXT);
CREATE TABLE pycram_fluent_samples (id INTEGER PRIMARY KEY AUTOINCREMENT, run_id INTEGER NOT NULL,
    name VARCHAR(255) NOT NULL, time FLOAT, value TEXT, number FLOAT);
INSERT INTO pycram_runs (id, uuid, plan, started_at, outcome) VALUES (1, 'u1', 'old', '2026-01-01 10:00:00', 'failed');
INSERT INTO pycram_tasks (run_id, task_id, parent_id, name, kind, status, error_type, error_message) VALUES
    (1, 1, NULL, 'MainThread', 'root', 'running', NULL, NULL),
    (1, 2, 1, 'try_in_order', 'try_in_order', 'failed', 'GraspFailed', 'no item at 2'),
    (1, 3, 2, 'step 1', 'step', 'failed', 'GraspFailed', 'no item at 1'),
    (1, 4, 3, 'grab_item', 'plan', 'failed', 'GraspFailed', 'no item at 1'),
    (1, 5, 2, 'step 2', 'step', 'failed', 'GraspFailed', 'no item at 2'),
    (1, 6, 5, 'grab_item', 'plan', 'failed', 'GraspFailed', 'no item at 2');
"""


def _schema_1_database(path) -> None:
    with sqlite3.connect(path) as conn:
        conn.executescript(_SCHEMA_1)
    conn.close()


def test_a_schema_1_database_is_migrated_and_counts_failures_once(tmp_path, wide):
    path = tmp_path / "old.sqlite3"
    _schema_1_database(path)
    url = f"sqlite:///{path}"
    failed = query.failed_tasks(error_type="GraspFailed", url=url)
    assert [(r.task_id, r.name) for r in failed] == [(4, "grab_item"), (6, "grab_item")]
    assert len(query.failed_tasks(error_type="GraspFailed", url=url, propagated=True)) == 5
    run = query.get_run(1, url)
    assert run.clock is None and run.error is None
    with sqlite3.connect(path) as conn:
        columns = {row[1] for row in conn.execute("PRAGMA table_info(pycram_tasks)")}
    conn.close()
    assert "error_origin" in columns  # migrated in place
    assert "not recorded for this run" in _invoke("show", "1", "--db", url).output
    recorder = start_recording(url, plan="new")  # a new run goes into the migrated database
    seq(lambda: None, name="fresh")
    assert query.get_run(recorder.finish("succeeded"), url).clock == "wall-clock"


def test_a_schema_1_database_that_cannot_be_migrated_is_still_read(tmp_path):
    """A read-only connection (as for a file the user may not write) cannot add the columns:
    reading works all the same, the new columns read as None."""
    path = tmp_path / "old.sqlite3"
    _schema_1_database(path)
    read_only = f"sqlite:///file:{path}?mode=ro&uri=true"
    failed = query.failed_tasks(error_type="GraspFailed", url=read_only)
    assert [r.task_id for r in failed] == [4, 6] and all(r.error_origin is None for r in failed)
    assert query.get_run(1, read_only).clock is None
    assert len(query.tasks(1, read_only)) == 6
    with sqlite3.connect(path) as conn:
        columns = {row[1] for row in conn.execute("PRAGMA table_info(pycram_tasks)")}
    conn.close()
    assert "error_origin" not in columns
