"""`pycram experiment`: local worker processes, a real local Ray, resuming, bad input.

The thesis scenario runs for real (headless, ~1.5 s per run); the resume test uses
`pycram.testing.scenario_double` (no simulation), which sends the driver a real SIGINT at a
chosen seed.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

sa = pytest.importorskip("sqlalchemy")
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
runner = CliRunner()
os.environ.setdefault("MUJOCO_GL", "egl")


def _rows(db: Path, table: str) -> list:
    engine = sa.create_engine(f"sqlite:///{db}")
    try:
        with engine.connect() as conn:
            return list(conn.execute(sa.text(f"SELECT * FROM {table}")).mappings())
    finally:
        engine.dispose()


def _check_thesis_experiment(db: Path, out: Path, result) -> None:
    assert result.exit_code == 0, result.output
    runs = _rows(db, "pycram_experiment_runs")
    assert sorted(r["seed"] for r in runs) == [1, 2, 3, 4]
    assert all(r["status"] == "done" and r["success"] for r in runs), runs
    assert all(r["sim_time"] > 5.0 and r["wall_time"] > 0.0 for r in runs)
    # each run recorded its own trace in the same database
    traces = {r["id"]: r for r in _rows(db, "pycram_runs")}
    assert all(traces[r["trace_run_id"]]["outcome"] == "succeeded" for r in runs)
    experiment = _rows(db, "pycram_experiments")
    assert len(experiment) == 1 and experiment[0]["status"] == "finished"
    text = " ".join(result.output.split())
    assert "100.0 % (4)" in text and "no failures" in text, text
    assert (out / "experiment.png").stat().st_size > 10_000


def test_thesis_on_two_local_workers(tmp_path):
    db, out = tmp_path / "t.sqlite3", tmp_path / "out"
    result = runner.invoke(
        app,
        ["experiment", "--scenario", "thesis", "--robot", "pr2", "--seeds", "1-4", "--workers", "2"]
        + ["--db", str(db), "--output", str(out)],
    )
    _check_thesis_experiment(db, out, result)
    workers = {json.loads(r["result"])["worker"] for r in _rows(db, "pycram_experiment_runs")}
    assert len(workers) == 2 and all(w.split(":")[1] != str(os.getpid()) for w in workers)


# -- Ray ------------------------------------------------------------------------------------------


def _ray_processes(session_dir: str) -> list[str]:
    """Command lines of live processes that belong to the Ray session `session_dir`."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            continue
        if session_dir in cmdline and "State:\tZ" not in status:
            found.append(f"{pid}: {cmdline[:120]}")
    return found


@pytest.fixture(scope="module")
def local_ray():
    """One real local Ray instance (2 CPUs) for this module, shut down at the end; checks that
    no process of its session is left behind."""
    try:
        import ray
    except ImportError:
        pytest.skip("Ray is not installed (the 'ray' extra: pip install 'pycram[ray]')")
    from pycram.apps.experiments.runner import ray_runtime_env

    ray.init(num_cpus=2, include_dashboard=False, runtime_env=ray_runtime_env(), logging_level="WARNING")
    session_dir = ray._private.worker._global_node.get_session_dir_path()
    try:
        yield ray
    finally:
        ray.shutdown()
        deadline = time.monotonic() + 15.0
        while _ray_processes(session_dir) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not _ray_processes(session_dir), _ray_processes(session_dir)


def test_thesis_on_local_ray(tmp_path, local_ray):
    db, out = tmp_path / "t.sqlite3", tmp_path / "out"
    result = runner.invoke(
        app,
        ["experiment", "--scenario", "thesis", "--robot", "pr2", "--seeds", "1-4", "--ray", "auto"]
        + ["--faults", "misplaced,steal", "--db", str(db), "--output", str(out)],
    )
    _check_thesis_experiment(db, out, result)
    # the faults happened, and the plan recovered from them: grasps failed, the mug was taken
    results = [json.loads(r["result"]) for r in _rows(db, "pycram_experiment_runs")]
    assert all(r["faults"] == ["misplaced", "steal"] and r["failed_grasps"] >= 1 for r in results), results
    assert all(r["recoveries"] >= 1 and r["objects"]["mug"]["placed"] for r in results), results
    assert local_ray.is_initialized()  # a connection the caller made is left open
    # the runs ran in Ray's worker processes, not here
    workers = {json.loads(r["result"])["worker"] for r in _rows(db, "pycram_experiment_runs")}
    assert all(w.split(":")[1] != str(os.getpid()) for w in workers)


# -- resuming -------------------------------------------------------------------------------------

DOUBLE = "pycram.testing:scenario_double"


def _experiment_process(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "pycram", "experiment", *args],
        capture_output=True,
        text=True,
        cwd=REPO,
        env={**os.environ, "PYTHONPATH": str(REPO), **env},
        timeout=120,
    )


def test_an_interrupted_experiment_resumes_without_redoing_finished_seeds(tmp_path):
    db, log = tmp_path / "t.sqlite3", tmp_path / "runs.log"
    common = ["--db", str(db), "--output", str(tmp_path / "out"), "--workers", "2"]
    spec = ["--scenario", DOUBLE, "--robot", "pr2", "--seeds", "1-30", "--faults", "drop", "--name", "resumable"]
    # the double sends the driver SIGINT (a real Ctrl-C) while running seed 3
    first = _experiment_process(
        spec + common, {"PYCRAM_SCENARIO_DOUBLE_LOG": str(log), "PYCRAM_SCENARIO_DOUBLE_INTERRUPT": "3"}
    )
    assert first.returncode == 130, first.stdout + first.stderr
    assert "resume with `pycram experiment --resume 1`" in first.stderr
    done = {r["seed"] for r in _rows(db, "pycram_experiment_runs")}
    assert 3 in done and len(done) < 30  # the runs under way finished; the rest never started
    assert _rows(db, "pycram_experiments")[0]["status"] == "interrupted"
    ran_first = [int(line.split()[1]) for line in log.read_text().splitlines()]
    assert sorted(ran_first) == sorted(done)  # every run that ran was recorded

    second = _experiment_process(["--resume", "resumable", *common], {"PYCRAM_SCENARIO_DOUBLE_LOG": str(log)})
    assert second.returncode == 0, second.stdout + second.stderr
    assert f"{len(done)} recorded before, {30 - len(done)} to run" in " ".join(second.stderr.split())
    seeds = [int(line.split()[1]) for line in log.read_text().splitlines()]
    assert sorted(seeds) == list(range(1, 31))  # each seed ran exactly once over both invocations
    runs = _rows(db, "pycram_experiment_runs")
    assert len(runs) == 30 and sum(not r["success"] for r in runs) == 10  # "drop" fails every third seed
    assert _rows(db, "pycram_experiments")[0]["status"] == "finished"
    assert "ObjectSlipped" in second.stdout

    # the same name with the same options resumes too: nothing is left to run
    third = _experiment_process(spec + common, {"PYCRAM_SCENARIO_DOUBLE_LOG": str(log)})
    assert third.returncode == 0 and "30 recorded before, 0 to run" in " ".join(third.stderr.split())
    assert len(log.read_text().splitlines()) == 30


# -- bad input ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--scenario", "dinner", "--seeds", "1-2"], ["unknown scenario 'dinner'", "set-table", "thesis"]),
        (["--seeds", "5-1"], ["bad seed range '5-1'", "ends before it starts", "1-200"]),
        (["--seeds", "one-two"], ["bad seed range 'one-two'", "1-200"]),
        (["--robot", "pr2,r2d2", "--seeds", "1"], ["unknown robot(s) r2d2", "available robots: pr2, tiago"]),
        (["--seeds", "1", "--faults", "fire"], ["unknown fault(s) fire", "misplaced, steal"]),
        (["--robot", "pr2"], ["--seeds is missing"]),
        (["--resume", "no-such-experiment"], ["no experiment 'no-such-experiment'"]),
        (["--seeds", "1", "--workers", "0"], ["--workers must be at least 1"]),
        (["--scenario", "no.such.module:run", "--seeds", "1"], ["no.such.module", "thesis"]),
    ],
)
def test_bad_input_exits_with_2_naming_the_valid_choices(tmp_path, args, expected):
    result = runner.invoke(app, ["experiment", *args, "--db", str(tmp_path / "t.sqlite3")])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    for part in expected:
        assert part in text, text


def test_set_table_is_registered_lazily():
    from pycram.apps.experiments.scenarios import SCENARIOS, UnknownScenario, get_scenario

    entry = SCENARIOS["set-table"]
    assert entry.target == "pycram.apps.scenarios.set_table:run_set_table"
    try:
        import pycram.apps.scenarios.set_table  # noqa: F401
    except ModuleNotFoundError:
        with pytest.raises(
            UnknownScenario,
            match="set-table.*does not exist.*available scenarios: set-table, set-table-open, thesis",
        ):
            get_scenario("set-table")
    else:
        from pycram.apps.scenarios.set_table import FAULTS

        assert callable(get_scenario("set-table").load())
        # `--faults all` expands to the scenario's faults (the registry reads them after import)
        assert get_scenario("set-table").known_faults() == tuple(sorted(FAULTS))
        assert get_scenario("set-table-open").known_faults() == tuple(sorted(FAULTS))


def test_seed_parsing():
    from pycram.apps.experiments.runner import ExperimentInputError, parse_seeds

    assert parse_seeds("1-3,7, 2,10-11") == [1, 2, 3, 7, 10, 11]
    for bad in ("", "-1", "1-", "3-2", "a", "1.5"):
        with pytest.raises(ExperimentInputError):
            parse_seeds(bad)


def test_a_scenario_error_is_recorded_and_run_again_on_resume(tmp_path, monkeypatch):
    """An exception of the scenario is a recorded failure (status "error", exit code 1); a
    resume runs only that run again and replaces its record."""
    db = tmp_path / "t.sqlite3"
    args = ["experiment", "--scenario", DOUBLE, "--robot", "pr2,tiago", "--seeds", "1-2", "--name", "e"]
    args += ["--db", str(db), "--output", str(tmp_path / "out"), "--workers", "1"]
    from pycram.apps.experiments import runner as experiment_runner

    real = experiment_runner.execute_run
    calls = []

    def flaky(scenario, robot, seed, variant, db_url, record=True):
        calls.append((robot, seed))
        if robot == "tiago" and seed == 2 and len(calls) <= 4:
            raise_in = "pycram.testing:no_such_function"  # the scenario cannot even be found
            return real(raise_in, robot, seed, variant, db_url, record)
        return real(scenario, robot, seed, variant, db_url, record)

    monkeypatch.setattr(experiment_runner, "execute_run", flaky)
    monkeypatch.setattr(experiment_runner, "_run_local", _run_inline)
    first = runner.invoke(app, args)
    assert first.exit_code == 1, first.output
    assert "1 runs raised an error" in " ".join(first.output.split())
    rows = {(r["robot"], r["seed"]): r for r in _rows(db, "pycram_experiment_runs")}
    assert rows[("tiago", 2)]["status"] == "error" and not rows[("tiago", 2)]["success"]
    assert json.loads(rows[("tiago", 2)]["failure_causes"]) == ["UnknownScenario"]
    second = runner.invoke(app, ["experiment", "--resume", "e", "--db", str(db), "-o", str(tmp_path / "out")])
    assert second.exit_code == 0, second.output
    assert calls[4:] == [("tiago", 2)]
    rows = {(r["robot"], r["seed"]): r for r in _rows(db, "pycram_experiment_runs")}
    assert len(rows) == 4 and all(r["status"] == "done" for r in rows.values())


def _run_inline(prepared, workers, stop, finished, outcome):
    """`_run_local` without worker processes (the test patches `execute_run` in this process)."""
    from pycram.apps.experiments import runner as experiment_runner

    for key in prepared.todo:  # (robot, seed, variant, environment)
        result = experiment_runner.execute_run(prepared.scenario.spec, key[0], key[1], key[2], prepared.db)
        finished(key, result)


@pytest.mark.skipif(
    not os.environ.get("PYCRAM_TEST_POSTGRES_URL"),
    reason="PYCRAM_TEST_POSTGRES_URL is not set (.ci/run sets it; start a server with scripts/start_test_postgres.sh)",
)
def test_an_experiment_in_postgresql(tmp_path):
    """The experiment's tables and resuming work in PostgreSQL as in SQLite."""
    url = os.environ["PYCRAM_TEST_POSTGRES_URL"]
    name = f"pg-{os.getpid()}-{time.time_ns()}"
    args = ["experiment", "--scenario", DOUBLE, "--robot", "pr2,tiago", "--seeds", "1-6", "--faults", "drop"]
    args += ["--name", name, "--db", url, "--output", str(tmp_path / "out"), "--workers", "2"]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    assert "66.7 % (4)" in " ".join(first.output.split())
    again = runner.invoke(app, args)
    assert again.exit_code == 0 and "12 recorded before, 0 to run" in " ".join(again.output.split())


def test_a_scenario_registered_in_the_driver_runs_in_the_workers(tmp_path):
    """Workers find a registered callable by its import path: no registration there."""
    from pycram.apps.experiments.scenarios import SCENARIOS, register_scenario
    from pycram.testing import scenario_double

    register_scenario("double", scenario_double, faults=("drop", "slow"))
    try:
        assert SCENARIOS["double"].spec == "pycram.testing:scenario_double"
        db = tmp_path / "t.sqlite3"
        result = runner.invoke(
            app,
            ["experiment", "--scenario", "double", "--seeds", "1-3", "--faults", "slow"]
            + ["--db", str(db), "--output", str(tmp_path / "out")],
        )
        assert result.exit_code == 0, result.output
        runs = _rows(db, "pycram_experiment_runs")
        assert [r["sim_time"] for r in sorted(runs, key=lambda r: r["seed"])] == [22.0, 24.0, 26.0]
        assert _rows(db, "pycram_experiments")[0]["scenario"] == "double"
    finally:
        SCENARIOS.pop("double", None)


def test_the_stepping_is_recorded_passed_to_every_run_and_kept_on_resume(tmp_path):
    """Runs simulate in lock-step unless `--stepping free` is asked for; the experiment keeps
    its stepping, and a resume asking for another is refused (exit 2, one line)."""
    db = tmp_path / "t.sqlite3"
    common = ["--db", str(db), "--output", str(tmp_path / "out"), "--workers", "1"]
    for name, extra, expected in (("a", [], "lockstep"), ("b", ["--stepping", "free"], "free")):
        result = runner.invoke(
            app, ["experiment", "--scenario", DOUBLE, "--seeds", "1-2", "--name", name, *extra, *common]
        )
        assert result.exit_code == 0, result.output
        experiment = next(r for r in _rows(db, "pycram_experiments") if r["name"] == name)
        assert json.loads(experiment["info"]) == {"stepping": expected}
        runs = [r for r in _rows(db, "pycram_experiment_runs") if r["experiment_id"] == experiment["id"]]
        assert [json.loads(r["result"])["stepping"] for r in runs] == [expected, expected]
    refused = runner.invoke(app, ["experiment", "--resume", "b", "--stepping", "lockstep", *common])
    assert refused.exit_code == 2
    assert "was recorded with --stepping free, not lockstep" in " ".join(refused.output.split())
    bad = runner.invoke(app, ["experiment", "--scenario", DOUBLE, "--seeds", "1", "--stepping", "fast", *common])
    assert bad.exit_code == 2 and "--stepping must be free or lockstep, not 'fast'" in " ".join(bad.output.split())


def test_a_scenario_without_a_stepping_argument_runs_only_in_the_default_stepping():
    from pycram.apps.experiments.runner import execute_run

    spec = "pycram.apps.experiments.scenarios:_thesis_options"  # takes (seed, faults): no stepping
    result = execute_run(spec, "pr2", 1, "", None, record=False, stepping="free")
    assert result["failure_causes"] == ["ValueError"] and "takes no 'stepping' argument" in result["error"]
