"""`pycram experiment --env` and `pycram demo --env`: lists and ranges of environments, each run
recorded with its environment, scenarios written for one environment refusing others.

The experiment runs `environment_scenario` below (no simulation: it loads the run's environment
and checks it), in spawned worker processes, which import it from this module.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

import pytest

sa = pytest.importorskip("sqlalchemy")
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402
from pycram.apps.experiments import store  # noqa: E402
from pycram.apps.experiments.runner import ExperimentInputError, parse_environments  # noqa: E402

runner = CliRunner()
os.environ.setdefault("MUJOCO_GL", "egl")
REPO = Path(__file__).resolve().parent.parent


def environment_scenario(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = "lockstep",
    environment: str = "apartment",
) -> dict[str, Any]:
    """A scenario that runs in any environment: it loads it and succeeds when the checks of
    `pycram.environments.checks` find nothing wrong."""
    from pycram.environments import load
    from pycram.environments.checks import environment_problems

    started = time.monotonic()
    env = load(environment)
    problems = environment_problems(env)
    return {
        "robot": robot,
        "seed": seed,
        "faults": sorted(faults),
        "success": not problems,
        "failure_causes": ["EnvironmentProblem"] if problems else [],
        "sim_time": float(len(env.containers)),
        "wall_time": time.monotonic() - started,
        "drawers": sum(c.kind == "drawer" for c in env.containers),
    }


def test_environment_lists_and_ranges():
    assert parse_environments("procedural:1-3") == ["procedural:1", "procedural:2", "procedural:3"]
    assert parse_environments("apartment,procedural:3") == ["apartment", "procedural:3"]
    assert parse_environments("procedural:1,5,10-11, apartment,procedural:5") == [
        "procedural:1",
        "procedural:5",
        "procedural:10",
        "procedural:11",
        "apartment",
    ]
    sidecar = REPO / "examples" / "kitchens" / "small_kitchen.toml"
    assert parse_environments(f"file:{sidecar},procedural:0") == [f"file:{sidecar}", "procedural:0"]
    for bad, message in (
        ("procedural:3-1", "ends before it starts"),
        ("procedural:x", "is not procedural:SEED"),
        ("kitchen2", "environment 'kitchen2' does not exist"),
        ("", "no environment given"),
        ("procedural:0-20000", "more than"),
    ):
        with pytest.raises(ExperimentInputError, match=message):
            parse_environments(bad)


def test_a_bare_number_continues_only_a_procedural_entry():
    assert parse_environments("procedural:1,5") == ["procedural:1", "procedural:5"]
    with pytest.raises(ExperimentInputError, match="'2'"):
        parse_environments("apartment,2")


def test_every_run_is_recorded_with_its_environment(tmp_path):
    db, out = tmp_path / "e.sqlite3", tmp_path / "out"
    result = runner.invoke(
        app,
        ["experiment", "--scenario", "test_experiment_environments:environment_scenario", "--robot", "pr2"]
        + ["--seeds", "1-2", "--env", "procedural:4-5,apartment", "--workers", "1"]
        + ["--db", str(db), "--output", str(out), "--name", "envs"],
    )
    assert result.exit_code == 0, result.output
    assert "3 environments" in " ".join(result.output.split())
    record = store.find_experiment(str(db), "envs")
    assert record.environments == ("procedural:4", "procedural:5", "apartment")
    runs = store.run_records(str(db), record.id)
    assert sorted((r.environment, r.seed) for r in runs) == sorted((e, s) for e in record.environments for s in (1, 2))
    assert all(r.variant == "" and r.success for r in runs)  # grouped by robot and variant, as before
    for r in runs:  # the scenario really ran in the environment recorded
        from pycram.environments import load

        assert r.result["environment"] == r.environment
        assert r.result["drawers"] == sum(c.kind == "drawer" for c in load(r.environment).containers)
    # resuming with other environments is refused; without --env it resumes (nothing left)
    again = runner.invoke(app, ["experiment", "--resume", "envs", "--env", "procedural:4", "--db", str(db)])
    assert again.exit_code == 2 and "these environments differ" in " ".join(again.output.split())
    again = runner.invoke(app, ["experiment", "--resume", "envs", "--db", str(db), "--output", str(out)])
    assert again.exit_code == 0, again.output
    engine = sa.create_engine(f"sqlite:///{db}")
    try:
        with engine.connect() as conn:
            rows = conn.execute(sa.text("SELECT variant, environment, result FROM pycram_experiment_runs")).all()
    finally:
        engine.dispose()
    # the environment is in a column of its own (part of the run's key) and in its result
    assert {(v, e, json.loads(r)["environment"]) for v, e, r in rows} == {("", e, e) for e in record.environments}


@pytest.mark.parametrize(
    "args, message",
    [
        (
            ["experiment", "--scenario", "set-table", "--seeds", "1", "--env", "procedural:1"],
            "written for the apartment only",
        ),
        (
            ["experiment", "--scenario", "thesis", "--seeds", "1", "--env", "procedural:x"],
            "is not procedural:SEED or a range",
        ),
        (["demo", "--scenario", "set-table", "--env", "procedural:3"], "written for the apartment only"),
        (["demo", "--env", "garage"], "environment 'garage' does not exist"),
    ],
)
def test_environments_a_scenario_cannot_run_in_are_refused(tmp_path, args, message):
    result = runner.invoke(app, [*args, "--db", str(tmp_path / "x.sqlite3")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
