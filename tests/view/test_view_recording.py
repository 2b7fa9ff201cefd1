"""A run's view saved as an .rrd and read back with Rerun's Python API; the view rebuilt from
the trace database alone; a view changes nothing in a lock-step run (its fingerprint)."""

from __future__ import annotations

import re
import sqlite3
from pathlib import Path

import pytest

pytest.importorskip("rerun")
pytest.importorskip("mujoco")

from view_helpers import run_pycram  # noqa: E402

from pycram.trace.view.rrd import RecordingContents  # noqa: E402


def _status_changes_in_database(db_file: Path, run_id: int) -> int:
    """Task-status changes the trace database recorded for a run: each task started (a start
    time) and each task ended (an end time)."""
    with sqlite3.connect(db_file) as db:
        (count,) = db.execute(
            'SELECT SUM(start IS NOT NULL) + SUM("end" IS NOT NULL) FROM pycram_tasks WHERE run_id = ?', (run_id,)
        ).fetchone()
    return int(count)


@pytest.fixture(scope="module")
def set_table_run(tmp_path_factory):
    """A recorded set-table run (PR2, seed 7) with its view saved (--rrd, the default), pictures in
    the run's own folder below output/."""
    folder = tmp_path_factory.mktemp("view-set-table")
    db_file = folder / "runs.sqlite3"
    done = run_pycram(
        ["demo", "--scenario", "set-table", "--seed", "7", "--db", f"sqlite:///{db_file}", "--no-animation", "-q"],
        folder,
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    saved = re.search(r"view saved in (\S+)", done.stderr)
    assert saved, done.stderr[-2000:]
    return folder, db_file, folder / saved.group(1)


def test_the_rrd_lies_next_to_the_runs_pictures_and_names_the_run(set_table_run):
    folder, _, rrd = set_table_run
    assert rrd.name == "run.rrd"
    assert (rrd.parent / "start.png").is_file() and (rrd.parent / "end.png").is_file()
    assert rrd.parent.parent == folder / "output"
    assert rrd.parent.name.endswith("-1")  # the run's own folder (run id 1)
    assert list((folder / "output").rglob("*.rrd")) == [rrd]


def test_the_rrd_holds_robot_objects_in_truth_and_belief_camera_and_task_tree(set_table_run):
    _, db_file, rrd = set_table_run
    contents = RecordingContents.read(rrd)
    paths = contents.entity_paths
    # the robot's links, nested as its kinematic tree, with their geometry
    assert contents.has("/truth/robot/base_footprint/base_link/torso_lift_link")
    assert any(p.startswith("/truth/robot/") and p.endswith("/mesh") for p in contents.static)
    assert contents.rows["/truth/robot/base_footprint"] > 1, "the base's pose was never logged as it drove"
    # each simulator object in truth, and a believed object of its type in the belief
    truth = {p.split("/")[3] for p in paths if p.startswith("/truth/objects/")}
    belief = {p.split("/")[3] for p in paths if p.startswith("/belief/objects/")}
    assert len(truth) >= 4, truth
    for name in truth:
        kind = re.sub(r"\\? \d+$", "", name)
        assert any(b.startswith(kind + "-") for b in belief), f"{name} is in the truth but no {kind} in the belief"
    assert all(contents.rows[f"/belief/objects/{b}"] >= 1 for b in belief)
    assert contents.has("/belief/containers")
    # the camera at each look, with what it detected drawn on the image
    assert contents.rows["/camera/head"] >= 3
    assert contents.rows["/camera/head/detections"] == contents.rows["/camera/head"]
    # the location reasoning: costmap layers and the candidates tried
    assert contents.has("/reasoning/costmap")
    assert contents.rows["/reasoning/candidates"] >= 1
    # the motion plans: each arm's latest planned tool path
    assert any(contents.rows[p] >= 1 for p in contents.entity_paths if p.startswith("/reasoning/motion/"))
    # the task tree: one row per status change, as many as the trace database has
    assert contents.rows["/tree/status"] == _status_changes_in_database(db_file, 1)
    assert contents.rows["/tree/graph"] >= 1 and contents.rows["/plan/current"] >= 1
    assert contents.recording_id and contents.recording_id.startswith("pycram-")


def test_pycram_view_rebuilds_the_run_from_the_database_alone(set_table_run, tmp_path):
    folder, db_file, _ = set_table_run
    target = tmp_path / "from-db.rrd"
    done = run_pycram(["view", "1", "--db", f"sqlite:///{db_file}", "--no-rrd", "--save", str(target)], folder)
    assert done.returncode == 0, done.stderr[-2000:]
    changes = _status_changes_in_database(db_file, 1)
    assert f"{changes} task-status changes" in done.stderr
    contents = RecordingContents.read(target)
    assert contents.rows["/tree/status"] == changes
    assert contents.rows["/log"] > 0  # the process-module executions and performed designators
    assert contents.has("/tree/graph") and contents.has("/plan/current") and contents.has("/run")
    assert not contents.has("/truth"), "the database has no world: nothing may pretend it has"


def test_pycram_view_finds_the_runs_rrd_and_refuses_an_unknown_run(set_table_run, tmp_path):
    from pycram.apps.cli.view import run_rrd

    folder, db_file, rrd = set_table_run
    assert run_rrd(1, folder / "output") == rrd
    assert run_rrd(99, folder / "output") is None
    done = run_pycram(["view", "99", "--db", f"sqlite:///{db_file}", "--save", str(tmp_path / "x.rrd")], folder)
    assert done.returncode == 1
    assert "no run 99" in done.stderr


def _fingerprint(db_file: Path, run_id: int) -> str:
    import json

    with sqlite3.connect(db_file) as db:
        (info,) = db.execute("SELECT info FROM pycram_runs WHERE id = ?", (run_id,)).fetchone()
    return json.loads(info)["fingerprint"]["hash"]


def test_a_view_changes_nothing_in_a_lockstep_run(tmp_path):
    """The thesis demo with a theft (PR2, seed 3): the same fingerprint with and without --rrd."""
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    common = ["demo", "--db", db, "--no-animation", "-q", "--steal", "1", "--seed", "3"]
    plain = run_pycram([*common, "--no-rrd", "-o", str(tmp_path / "plain")], tmp_path)
    viewed = run_pycram([*common, "--rrd", "-o", str(tmp_path / "viewed")], tmp_path)
    assert plain.returncode == 0 and viewed.returncode == 0, plain.stderr[-1500:] + viewed.stderr[-1500:]
    assert not (tmp_path / "plain" / "run.rrd").exists()
    contents = RecordingContents.read(tmp_path / "viewed" / "run.rrd")
    assert contents.rows["/tree/status"] == _status_changes_in_database(tmp_path / "runs.sqlite3", 2)
    assert _fingerprint(tmp_path / "runs.sqlite3", 1) == _fingerprint(tmp_path / "runs.sqlite3", 2)


def test_pycram_run_saves_the_view_of_a_plan_script(tmp_path):
    """`pycram run FILE --rrd`: the script builds its own world; the view finds it through the
    active robot, and the .rrd goes to output/view-DATE-TIME (the script writes no pictures)."""
    from view_helpers import ROOT

    db_file = tmp_path / "runs.sqlite3"
    done = run_pycram(
        ["run", "--db", f"sqlite:///{db_file}", "--rrd", str(ROOT / "examples" / "first_plan_on_sim.py")], tmp_path
    )
    assert done.returncode == 0, done.stderr[-2000:]
    saved = re.search(r"view saved in (\S+) \(open it with `pycram view 1`\)", done.stderr)
    assert saved, done.stderr[-2000:]
    rrd = tmp_path / saved.group(1)
    assert rrd.parent.parent == tmp_path / "output" and rrd.parent.name.startswith("view-")
    contents = RecordingContents.read(rrd)
    assert contents.has("/truth/robot/base_footprint") and contents.has("/truth/objects")
    assert contents.rows["/tree/status"] == _status_changes_in_database(db_file, 1)
    assert contents.rows["/log"] >= 1  # the script's own log lines ("first plan: ...")


def test_pycram_view_serves_a_run_from_the_database_until_ctrl_c(set_table_run):
    """`pycram view RUN --no-rrd`: the viewer serves the rebuilt run on 127.0.0.1; Ctrl-C stops it
    (exit code 0) and its temporary recording is gone."""
    import subprocess
    import sys
    import tempfile
    import urllib.request

    from view_helpers import interrupt, pycram_env

    from pycram.core.process_lifetime import end_with_parent

    folder, db_file, _ = set_table_run
    before = set(Path(tempfile.gettempdir()).glob("pycram-view-*/run-1-db.rrd"))
    child = subprocess.Popen(
        [sys.executable, "-m", "pycram.apps.cli", "view", "1", "--db", f"sqlite:///{db_file}", "--no-rrd"]
        + ["--view-port", "0"],
        cwd=folder,
        env=pycram_env(),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=end_with_parent,  # ended with the test run even when a time-out kills it
    )
    try:
        lines = []
        for line in child.stderr:
            lines.append(line)
            found = re.search(r"view: open (http://127\.0\.0\.1:(\d+)/\S+) in a browser", line)
            if found:
                break
        assert found, "".join(lines)
        assert "from the database alone" in "".join(lines)
        page = urllib.request.urlopen(f"http://127.0.0.1:{found.group(2)}/", timeout=30).read()
        assert b"re_viewer.js" in page
    finally:
        code = interrupt(child)
    assert code == 0
    assert set(Path(tempfile.gettempdir()).glob("pycram-view-*/run-1-db.rrd")) <= before


def test_attach_views_logs_the_world_before_the_plan_starts(tmp_path):
    """`attach_views` attaches every active session to a world and returns once its geometry is
    logged (the start-up a run pays before its plan); attached sessions, closed sessions and no
    session at all make it do nothing."""
    from pycram.backends.sim import World
    from pycram.trace.view.session import ViewSession, attach_views

    attach_views(object())  # no active session: not even looked at
    with World("pr2", []) as world:
        session = ViewSession(rrd=tmp_path / "run.rrd").start()
        try:
            assert "geoms" not in session.counts
            attach_views(world)
            assert session.counts["geoms"] > 20  # the kitchen's and the robot's shapes
            assert session._attached
            attach_views(object())  # attached before: left as it is
        finally:
            session.close()
        attach_views(object())  # closed: no longer active
    assert RecordingContents.read(tmp_path / "run.rrd").rows
