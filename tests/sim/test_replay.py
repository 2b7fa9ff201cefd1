"""Replay and stop-at (issue 31, point 3): a recorded run stores what it needs to run again and
its fingerprint; `pycram replay RUN` says "identical" or where it first diverged; `pycram demo
--until T` stops a run at simulated time T and writes the pictures and the task tree so far."""

from __future__ import annotations

import json
import os

import pytest

pytest.importorskip("sqlalchemy")
import sqlalchemy as sa  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402
from pycram.trace.fingerprint import compare_records, pack_record, unpack_record  # noqa: E402

os.environ.setdefault("MUJOCO_GL", "egl")
runner = CliRunner()


def _cli(*args: str):
    return runner.invoke(app, list(args), catch_exceptions=False)


def _run_info(url: str, run_id: int) -> dict:
    from pycram.trace.db import connect, runs_table

    with connect(url).begin() as conn:
        return json.loads(conn.execute(sa.select(runs_table.c.info).where(runs_table.c.id == run_id)).scalar_one())


def _set_run_info(url: str, run_id: int, info: dict) -> None:
    from pycram.trace.db import connect, runs_table

    with connect(url).begin() as conn:
        conn.execute(runs_table.update().where(runs_table.c.id == run_id).values(info=json.dumps(info)))


def test_a_recorded_run_replays_identically_and_a_perturbed_pose_is_located(tmp_path):
    from pycram.apps.demos.kitchen import DemoOptions, run_demo

    url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    result = run_demo(DemoOptions(seed=2, db=url, quiet=True, animation=False, pictures=False))
    assert result.exit_code == 0 and result.run_id is not None, result.message
    info = _run_info(url, result.run_id)
    replay = info["replay"]
    assert (replay["scenario"], replay["robot"], replay["environment"], replay["seed"]) == (
        "thesis",
        "pr2",
        "thesis-kitchen",
        2,
    )
    assert replay["stepping"] == "lockstep" and replay["options"]["pictures"] is False and replay["pycram"]
    record = unpack_record(info["fingerprint"])
    assert len(record["trajectory"]) >= int(result.sim_time)  # a sample every simulated second
    assert record["tasks"][0].startswith("fetch_and_place [plan] SUCCEEDED")

    same = _cli("replay", str(result.run_id), "--db", url)
    assert same.exit_code == 0, same.output
    assert "identical" in same.output

    # one object's pose at one sample, off by 2 um: found, with the time, the object and both values
    t, sample = record["trajectory"][5]
    numbers = sample["mug"].split()
    numbers[0] = f"{float(numbers[0]) + 2e-6:.6f}"
    sample["mug"] = " ".join(numbers)
    _set_run_info(url, result.run_id, {**info, "fingerprint": pack_record(record)})
    moved = _cli("replay", str(result.run_id), "--db", url)
    assert moved.exit_code == 1, moved.output
    assert f"t={t:.1f} s" in moved.output and "'mug'" in moved.output
    assert sample["mug"] in moved.output.replace("\n", " ")  # what was recorded, beside what was replayed

    # the debugging loop: replay, stop at a simulated time, look
    stop = _cli("replay", str(result.run_id), "--db", url, "--until", "4", "-o", str(tmp_path / "look"))
    assert stop.exit_code == 0, stop.output  # the samples up to t=4 s are the recorded ones
    assert "identical up to t=4 s" in stop.output
    folder = tmp_path / "look" / "until-4.0s"
    assert {"scene.png", "belief.png", "task-tree.txt", "task-tree.svg"} <= {p.name for p in folder.iterdir()}


def test_until_stops_the_run_at_that_simulated_time_with_pictures_and_the_tree_so_far(tmp_path):
    from pycram.trace import query

    url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    out = tmp_path / "demo"
    result = _cli("demo", "--until", "6.5", "--no-animation", "-q", "--db", url, "-o", str(out))
    assert result.exit_code == 0, result.output
    assert "STOPPED" in result.output and "t=6.50 s" in result.output
    folder = out / "until-6.5s"
    names = {p.name for p in folder.iterdir()}
    assert {"scene.png", "belief.png", "task-tree.txt", "task-tree.svg", "timeline.png"} <= names
    assert "fetch_and_place [plan] running" in (folder / "task-tree.txt").read_text()
    run = query.get_run(None, url)
    assert run.outcome == "interrupted" and "--until 6.5" in (run.error or "")
    tasks = query.tasks(run.id, url)
    assert tasks and max(t.end for t in tasks if t.end is not None) <= 6.5 + 1e-9  # nothing ran past T
    # a run stopped so is not replayed: it says so, in one line
    again = _cli("replay", str(run.id), "--db", url)
    assert again.exit_code == 2 and "stopped at t=6.5 s by --until" in again.output
    assert len(again.output.strip().splitlines()) == 1


def test_what_cannot_be_replayed_is_refused_in_one_line_with_exit_2(tmp_path):
    from pycram.trace import start_recording

    url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    plain = start_recording(url=url, plan="a script")
    plain.finish("succeeded")
    free = start_recording(url=url, plan="thesis, free-running")
    free.set_run_info(replay={"scenario": "thesis", "robot": "pr2", "seed": 0, "stepping": "free", "options": {}})
    free.finish("succeeded")
    cases = [
        (["replay", "1"], "recorded without what a replay needs"),
        (["replay", "2"], "free-running"),
        (["replay", "99"], "no run 99"),
        (["replay", "1", "--until", "-1"], "--until must be a simulated time >= 0"),
    ]
    for args, why in cases:
        result = _cli(*args, "--db", url)
        assert result.exit_code == 2, (args, result.output)
        assert why in result.output and len(result.output.strip().splitlines()) == 1, result.output
    for args in (["demo", "--until", "-2"], ["demo", "--until", "nan"]):
        result = _cli(*args)
        assert result.exit_code == 2 and "--until must be a simulated time >= 0" in result.output, result.output


def test_a_task_that_differs_is_located_by_its_path_and_time():
    recorded = {
        "tasks": [
            "plan [plan] SUCCEEDED 0.000 9.000",
            "  fetch [seq] SUCCEEDED 0.000 4.000",
            "  place [seq] SUCCEEDED 4.000 9.000",
            "    open [step] SUCCEEDED 4.000 5.500",
        ],
        "trajectory": [[0.0, {"base": "0 0 0"}], [1.0, {"base": "1 0 0"}]],
        "poses": {"base": "1 0 0"},
    }
    replayed = json.loads(json.dumps(recorded))
    replayed["tasks"][3] = "    open [step] FAILED 4.000 5.700"
    divergence = compare_records(recorded, replayed)
    assert divergence is not None and divergence.task == "plan/place/open" and divergence.time == 5.5
    assert "plan/place/open" in str(divergence) and "t=5.500 s" in str(divergence)
    assert compare_records(recorded, json.loads(json.dumps(recorded))) is None
