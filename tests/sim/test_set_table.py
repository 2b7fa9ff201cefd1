"""The set-table scenario (issue 17): the scenario's data, bad input, and end-to-end runs judged
with the simulator's truth (a few fixed seeds per robot -- not the seeds the benchmark reports --
and a faulted run that recovers).

The end-to-end runs take 20-90 s of wall time each on a 2-core machine; they are few.
"""

from __future__ import annotations

import json
import math

import pytest

from pycram.demos import set_table
from pycram.demos.set_table import FAULTS, OBJECTS, check_faults, place_settings, run_set_table, start_scene
from pycram.environments import load as load_environment

#: Seeds that set the whole table, measured (never the benchmark's seeds, 100-119), with the
#: objects each robot brings: the TIAGo's top grasps of plates and bowls on the counter fail
#: (see docs/set-table.md), so it sets the cup and the milk.
END_TO_END = [("pr2", 2, OBJECTS), ("pr2", 4, OBJECTS), ("tiago", 2, ("cup", "milk")), ("tiago", 3, ("cup", "milk"))]


def test_place_settings_are_data_on_the_table_apart_from_each_other():
    env = load_environment("apartment")
    settings = place_settings(env)
    table = env.surface("table")
    assert [s.type for s in settings] == list(OBJECTS)
    for s in settings:
        assert table.contains(s.point[0], s.point[1], 0.1), s
        assert s.point[2] > table.height
    for a in settings:
        for b in settings:
            if a is not b:
                assert math.dist(a.point[:2], b.point[:2]) > 0.2


def test_the_start_scene_comes_from_the_seed_and_stays_in_the_start_regions():
    env = load_environment("apartment")
    first, again, other = start_scene(env, 5), start_scene(env, 5), start_scene(env, 6)
    assert first == again and first != other
    for seed in range(30):
        for p in start_scene(env, seed):
            x0, y0, x1, y1 = set_table.START_REGIONS[p.type][p.support]
            assert x0 <= p.position[0] <= x1 and y0 <= p.position[1] <= y1


def test_unknown_fault_and_robot_names_are_refused_naming_the_valid_choices():
    with pytest.raises(ValueError, match=r"unknown fault\(s\) 'flood'; valid faults: moved, taken, stuck"):
        run_set_table("pr2", 1, frozenset({"flood"}))
    with pytest.raises(ValueError, match=r"valid robots: pr2, tiago"):
        run_set_table("robby", 1)
    assert check_faults("moved, taken") == frozenset({"moved", "taken"})
    assert check_faults("") == frozenset()
    assert set(FAULTS) == {"moved", "taken", "stuck", "obstacle", "missed"}


def test_the_demo_command_refuses_an_unknown_scenario_or_fault_naming_the_valid_choices():
    pytest.importorskip("typer")
    from typer.testing import CliRunner

    from pycram.cli import app

    runner = CliRunner()
    result = runner.invoke(app, ["demo", "--scenario", "dinner"])
    assert result.exit_code == 2
    assert "unknown scenario 'dinner'" in result.output and "thesis, set-table" in result.output
    result = runner.invoke(app, ["demo", "--scenario", "set-table", "--faults", "flood", "--no-record"])
    assert result.exit_code == 2
    assert "valid faults: moved, taken, stuck, obstacle, missed" in result.output
    result = runner.invoke(app, ["demo", "--faults", "taken"])
    assert result.exit_code == 2 and "set-table only" in result.output


def _assert_set(out: dict, objects: tuple[str, ...] = OBJECTS) -> None:
    assert json.loads(json.dumps(out)) == out  # JSON-serialisable, as the experiment runner needs
    assert out["success"], out["summary"]
    assert set(out["objects"]) == set(objects)
    assert all(o["placed"] and o["failure"] is None for o in out["objects"].values())
    assert out["failure_causes"] == [] and out["open_containers"] == {}
    assert out["sim_time"] > out["wall_time"] > 0  # faster than real time


@pytest.mark.timeout(400)
@pytest.mark.parametrize(("robot", "seed", "objects"), END_TO_END)
def test_the_table_is_set_end_to_end(robot, seed, objects):
    out = run_set_table(robot, seed, objects=objects)
    _assert_set(out, objects)
    assert out["robot"] == robot and out["seed"] == seed and out["faults"] == []


@pytest.mark.timeout(400)
def test_a_run_with_faults_recovers_from_a_taken_and_a_moved_object_and_an_obstacle():
    out = run_set_table("pr2", 4, frozenset({"taken", "moved", "obstacle"}))
    kinds = {f.split(":")[0] for f in out["faults_injected"]}
    assert {"taken", "moved", "obstacle"} <= kinds, out["faults_injected"]
    assert out["faults"] == ["moved", "obstacle", "taken"]
    _assert_set(out)


@pytest.mark.timeout(300)
def test_a_run_for_the_experiment_runner_is_recorded_with_pictures(tmp_path, monkeypatch):
    pytest.importorskip("sqlalchemy")
    from pycram.trace import query

    monkeypatch.chdir(tmp_path)
    url = f"sqlite:///{tmp_path / 'trace.db'}"
    out = run_set_table("tiago", 2, db_url=url, pictures=True, objects=("cup", "milk"))
    _assert_set(out, ("cup", "milk"))
    assert out["run_id"] is not None
    assert (tmp_path / "output" / "set-table-tiago-2" / "end.png").exists()
    assert any(str(r.id) == str(out["run_id"]) for r in query.runs(url=url))
