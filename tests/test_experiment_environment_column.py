"""The environment of an experiment's run in a column of its own (trace schema 5, issue 33):
new databases have it, databases of schema 4 (the environment after "@" in the run's variant)
are migrated on connect keeping every run, reports group by robot, variant and environment,
`pycram experiment --verbose` tells each failed run, and the development/evaluation split of
seeds and generated apartments is documented, kept apart in the code and warned about.

The experiments run `split_scenario` below (no simulation) in spawned worker processes, which
import it from this module.
"""

from __future__ import annotations

import datetime as dt
import json
import os
import re
import threading
import time
from pathlib import Path
from typing import Any

import pytest

sa = pytest.importorskip("sqlalchemy")
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402
from pycram.apps.experiments import report, store  # noqa: E402
from pycram.trace.db import SCHEMA_VERSION, connect, experiment_runs_table, present_columns  # noqa: E402

runner = CliRunner()
os.environ.setdefault("MUJOCO_GL", "egl")
REPO = Path(__file__).resolve().parent.parent
PG_URL = os.environ.get("PYCRAM_TEST_POSTGRES_URL")
LONG_REASON = "Cannot resolve location designator " * 20 + "no standing pose reaches the cup"


def split_scenario(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = "lockstep",
    environment: str = "apartment",
) -> dict[str, Any]:
    """Loads its environment; succeeds everywhere except in ``procedural:2``, where it fails
    with a long reason (as a nested resolution failure would read)."""
    from pycram.environments import load

    started = time.monotonic()
    env = load(environment)
    ok = environment != "procedural:2"
    return {
        "robot": robot,
        "seed": seed,
        "faults": sorted(faults),
        "success": ok,
        "failure_causes": [] if ok else ["ObjectOutOfReach"],
        "summary": "every object at its place" if ok else f"cup: ObjectOutOfReach ({LONG_REASON})",
        "sim_time": float(len(env.containers)),
        "wall_time": time.monotonic() - started,
    }


def one_cup_clear_table(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = "lockstep",
    environment: str = "apartment",
) -> dict[str, Any]:
    """`clear-table` with its cup only (a short run), as `pycram experiment` runs it."""
    from pycram.apps.scenarios.clear_table.driver import TASK
    from pycram.apps.scenarios.common.driver import run_task_for_experiment

    return run_task_for_experiment(TASK, robot, seed, faults, db_url, pictures, stepping, environment, objects=("cup",))


# -- the schema --------------------------------------------------------------------------------


def test_a_new_database_keys_runs_by_their_environment(tmp_path):
    url = f"sqlite:///{tmp_path / 'new.sqlite3'}"
    engine = connect(url)
    assert SCHEMA_VERSION == 5
    assert "environment" in present_columns(engine, experiment_runs_table)
    unique = sa.inspect(engine).get_unique_constraints("pycram_experiment_runs")
    assert [sorted(u["column_names"]) for u in unique] == [
        sorted(["experiment_id", "robot", "seed", "variant", "environment"])
    ]
    record = store.create_experiment(url, "e", "x:y", ["pr2"], [1], [()], environments=["procedural:1", "procedural:2"])
    for environment in ("procedural:1", "procedural:2"):  # same robot, seed and variant: two runs
        store.record_run(url, record.id, "pr2", 1, "", {"success": True, "run_id": 7}, environment=environment)
    store.record_run(url, record.id, "pr2", 1, "", {"success": False}, environment="procedural:1")  # kept once
    runs = store.run_records(url, record.id)
    assert [(r.environment, r.success, r.trace_run_id) for r in runs] == [
        ("procedural:1", True, 7),  # a scenario's `run_id` is the run's trace
        ("procedural:2", True, 7),
    ]
    assert store.finished_keys(url, record.id) == set(record.keys())
    with engine.connect() as conn:
        assert conn.execute(sa.text("SELECT DISTINCT variant FROM pycram_experiment_runs")).scalars().all() == [""]


#: The two experiment tables as trace schema 4 created them (before the environment column).
_SCHEMA_4 = """
CREATE TABLE pycram_experiments (
    id {serial} NOT NULL, name VARCHAR(255) NOT NULL, scenario VARCHAR(512) NOT NULL,
    robots TEXT NOT NULL, seeds TEXT NOT NULL, variants TEXT NOT NULL, created_at {time} NOT NULL,
    updated_at {time}, status VARCHAR(32), host VARCHAR(255), command TEXT, info TEXT,
    PRIMARY KEY (id), UNIQUE (name)
);
CREATE TABLE pycram_experiment_runs (
    id {serial} NOT NULL, experiment_id INTEGER NOT NULL, robot VARCHAR(255) NOT NULL,
    seed INTEGER NOT NULL, variant VARCHAR(512) NOT NULL, status VARCHAR(16) NOT NULL,
    success BOOLEAN NOT NULL, failure_causes TEXT, sim_time FLOAT, wall_time FLOAT,
    trace_run_id INTEGER, error TEXT, result TEXT, worker VARCHAR(255), finished_at {time},
    PRIMARY KEY (id),
    CONSTRAINT uq_pycram_experiment_runs_key UNIQUE (experiment_id, robot, seed, variant),
    FOREIGN KEY(experiment_id) REFERENCES pycram_experiments (id) ON DELETE CASCADE
)
"""


def _old_database(url: str) -> None:
    """A database as PyCRAM wrote it with trace schema 4: an experiment over two generated
    apartments (its runs' environments after "@" in `variant`) and one without environments."""
    from pycram.trace.db import metadata

    engine = sa.create_engine(url)
    # the other tables were there already (their columns of schema 4 differ not: see the trace tests)
    metadata.create_all(
        engine, tables=[t for t in metadata.sorted_tables if not t.name.startswith("pycram_experiment")]
    )
    postgres = engine.dialect.name == "postgresql"
    kinds = {
        "serial": "SERIAL" if postgres else "INTEGER",
        "time": "TIMESTAMP WITH TIME ZONE" if postgres else "DATETIME",
    }
    now = dt.datetime.now(dt.UTC)
    with engine.begin() as conn:
        for statement in _SCHEMA_4.format(**kinds).split(";"):
            conn.exec_driver_sql(statement)
        experiments = sa.table(
            "pycram_experiments", *(sa.column(c) for c in "name scenario robots seeds variants created_at info".split())
        )
        runs = sa.table(
            "pycram_experiment_runs",
            *(sa.column(c) for c in "experiment_id robot seed variant status success result".split()),
        )
        for name, environments in (("with-envs", ["procedural:1", "procedural:2"]), ("plain", [])):
            info = {"stepping": "lockstep", **({"environments": environments} if environments else {})}
            conn.execute(
                sa.insert(experiments).values(
                    name=name,
                    scenario="x:y",
                    robots='["pr2"]',
                    seeds="[1, 2]",
                    variants='[[], ["moved"]]',
                    created_at=now,
                    info=json.dumps(info),
                )
            )
        rows = [
            (1, seed, variant + (f"@{env}" if env else ""), env)
            for seed in (1, 2)
            for variant in ("", "moved")
            for env in ("procedural:1", "procedural:2")
        ] + [(2, seed, variant, None) for seed in (1, 2) for variant in ("", "moved")]
        for experiment, seed, variant, env in rows:
            conn.execute(
                sa.insert(runs).values(
                    experiment_id=experiment,
                    robot="pr2",
                    seed=seed,
                    variant=variant,
                    status="done",
                    success=seed == 1,
                    result=json.dumps({"environment": env}),
                )
            )
    engine.dispose()


def _check_migrated(url: str, again: bool = False) -> None:
    """The migrated runs of `_old_database`; unless `again`, then a run in a third apartment is
    recorded (`again`: expected there already)."""
    engine = connect(url)
    assert "environment" in present_columns(engine, experiment_runs_table)
    with engine.connect() as conn:
        rows = conn.execute(
            sa.text("SELECT experiment_id, seed, variant, environment, result FROM pycram_experiment_runs")
        ).all()
    assert len(rows) == 12 + again  # every run kept
    for experiment, _seed, variant, environment, result in rows:
        assert "@" not in variant and variant in ("", "moved")
        if again and environment == "procedural:3":
            continue  # recorded after the migration
        assert environment == (json.loads(result)["environment"] or "")  # moved out of the variant
        assert (environment != "") == (experiment == 1)
    with_envs = store.find_experiment(url, "with-envs")
    runs = store.run_records(url, with_envs.id)
    assert {(r.variant, r.environment) for r in runs} == {
        (v, e) for v in ("", "moved") for e in ("procedural:1", "procedural:2")
    } | ({("", "procedural:3")} if again else set())
    if again:
        return
    # resuming finds every run of both experiments recorded: nothing left to run
    for name in ("with-envs", "plain"):
        record = store.find_experiment(url, name)
        assert store.finished_keys(url, record.id) == set(record.keys())
    # the run's key now has the environment: a third apartment for the same robot, seed and variant
    store.record_run(url, with_envs.id, "pr2", 1, "", {"success": True}, environment="procedural:3")
    groups = report.summarize(store.run_records(url, with_envs.id))
    assert [(g.variant, g.environment, g.runs, g.successes) for g in groups] == [
        ("", "procedural:1", 2, 1),
        ("", "procedural:2", 2, 1),
        ("", "procedural:3", 1, 1),
        ("moved", "procedural:1", 2, 1),
        ("moved", "procedural:2", 2, 1),
    ]
    with pytest.raises(sa.exc.IntegrityError):  # and the key holds in the database itself
        with engine.begin() as conn:
            conn.execute(
                sa.insert(experiment_runs_table).values(
                    experiment_id=with_envs.id,
                    robot="pr2",
                    seed=1,
                    variant="",
                    environment="procedural:3",
                    status="done",
                    success=True,
                )
            )


def test_an_old_sqlite_database_is_migrated_on_connect_keeping_every_run(tmp_path):
    url = f"sqlite:///{tmp_path / 'old.sqlite3'}"
    _old_database(url)
    _check_migrated(url)
    _check_migrated(url, again=True)  # connecting again changes nothing


def test_processes_connecting_to_an_old_database_at_once_migrate_it_once(tmp_path):
    url = f"sqlite:///{tmp_path / 'old.sqlite3'}"
    _old_database(url)
    errors: list[BaseException] = []

    def open_it() -> None:
        try:
            connect(url).dispose()  # a new engine each: as another process would
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=open_it) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    _check_migrated(url)


def test_an_old_database_that_cannot_be_migrated_is_still_read(tmp_path, caplog):
    path = tmp_path / "old.sqlite3"
    _old_database(f"sqlite:///{path}")
    url = f"sqlite:///file:{path}?mode=ro&uri=true"  # read-only: the migration fails
    record = store.find_experiment(url, "with-envs")
    assert "cannot migrate pycram_experiment_runs" in caplog.text
    runs = store.run_records(url, record.id)
    assert {(r.variant, r.environment) for r in runs} == {
        (v, e) for v in ("", "moved") for e in ("procedural:1", "procedural:2")
    }
    assert store.finished_keys(url, record.id) == set(record.keys())
    with pytest.raises(store.TraceDatabaseError, match="could not be migrated"):
        store.record_run(url, record.id, "pr2", 3, "", {"success": True}, environment="procedural:1")


@pytest.mark.skipif(not PG_URL, reason="PYCRAM_TEST_POSTGRES_URL is not set (scripts/start_test_postgres.sh)")
def test_an_old_postgresql_database_is_migrated_on_connect_keeping_every_run():
    import uuid

    admin = sa.create_engine(sa.make_url(PG_URL).set(drivername="postgresql+psycopg"), isolation_level="AUTOCOMMIT")
    name = f"pycram_t_{uuid.uuid4().hex[:12]}"
    with admin.connect() as conn:
        conn.execute(sa.text(f"CREATE DATABASE {name}"))
    url = sa.make_url(PG_URL).set(drivername="postgresql+psycopg", database=name).render_as_string(hide_password=False)
    try:
        _old_database(url)
        _check_migrated(url)
        _check_migrated(url, again=True)
    finally:
        from pycram.trace.db import _engines

        for key in [k for k in _engines if name in k]:
            _engines.pop(key).dispose()
        with admin.connect() as conn:
            conn.execute(sa.text(f"DROP DATABASE IF EXISTS {name} WITH (FORCE)"))
        admin.dispose()


# -- the report and the command line --------------------------------------------------------------


def _flat(text: str) -> str:
    return " ".join(text.split())


def _experiment(tmp_path: Path, *args: str) -> Any:
    return runner.invoke(
        app,
        ["experiment", "--scenario", "test_experiment_environment_column:split_scenario", "--robot", "pr2"]
        + ["--workers", "1", "--db", str(tmp_path / "e.sqlite3"), "--output", str(tmp_path / "out"), *args],
        env={"COLUMNS": "220"},
    )


def test_an_experiment_over_generated_apartments_reports_each_environment(tmp_path):
    result = _experiment(tmp_path, "--seeds", "1-2", "--env", "procedural:1-2", "--name", "per-env")
    assert result.exit_code == 0, result.output
    rows = [line for line in result.output.splitlines() if re.search(r"│ pr2 +│", line)]
    # one row per environment (2 seeds each), then one over both of them
    assert len(rows) == 3, result.output
    assert "procedural:1" in rows[0] and "100.0 % (2)" in rows[0], rows
    assert "procedural:2" in rows[1] and "0.0 % (0)" in rows[1], rows
    assert "procedural" not in rows[2] and "50.0 % (2)" in rows[2], rows
    output = _flat(result.output)
    assert "over all 2 environments" in output
    assert "split: development seeds and generated apartments: not evaluation figures" in output
    assert "2 runs failed; --verbose tells each of them in full" in output
    assert LONG_REASON not in output
    assert (tmp_path / "out" / "experiment.png").is_file()


def test_verbose_tells_every_failed_run_in_full(tmp_path):
    result = _experiment(tmp_path, "--seeds", "1-2", "--env", "procedural:2", "--verbose")
    assert result.exit_code == 0, result.output
    output = _flat(result.output)
    assert "2 runs failed:" in output
    for seed in (1, 2):
        assert f"- pr2 seed {seed} in procedural:2, faults none: cup: ObjectOutOfReach ({LONG_REASON})" in output


def test_evaluation_seeds_mixed_with_development_ones_are_warned_about(tmp_path):
    mixed = _experiment(tmp_path, "--seeds", "3,1000000-1000001", "--env", "procedural:1000000", "--name", "m")
    assert mixed.exit_code == 0, mixed.output
    output = _flat(mixed.output)
    warning = "warning: not an evaluation: seed 3 is not an evaluation seed (those are 1000000 and above"
    assert output.count(warning) == 2, output  # before the runs, and with the report
    clean = _experiment(tmp_path, "--seeds", "1000000-1000001", "--env", "procedural:1000000", "--name", "c")
    assert clean.exit_code == 0, clean.output
    assert "not an evaluation" not in clean.output
    assert "split: evaluation seeds and generated apartments" in _flat(clean.output)


# -- the documented split -----------------------------------------------------------------------


def test_the_documented_development_and_evaluation_ranges_are_the_codes_and_do_not_overlap():
    from pycram.apps.experiments.splits import DEV_SEEDS, EVAL_FIRST, environment_split, experiment_split, seed_split

    assert DEV_SEEDS.start == 0 and DEV_SEEDS.stop <= EVAL_FIRST  # disjoint, development first
    assert not set(range(DEV_SEEDS.stop - 5, DEV_SEEDS.stop)) & set(range(EVAL_FIRST, EVAL_FIRST + 5))
    assert (seed_split(DEV_SEEDS.stop - 1), seed_split(DEV_SEEDS.stop), seed_split(EVAL_FIRST)) == (
        "dev",
        "unsplit",
        "eval",
    )
    assert environment_split(f"procedural:{EVAL_FIRST}") == "eval" and environment_split("apartment") == "hand-made"
    docs = _flat((REPO / "docs" / "experiments.md").read_text(encoding="utf-8"))
    first, last = DEV_SEEDS.start, DEV_SEEDS.stop - 1
    assert f"development seeds are {first}-{last}" in docs, "docs/experiments.md must state the code's dev range"
    assert f"evaluation seeds are {EVAL_FIRST} and above" in docs, "docs/experiments.md must state the eval range"
    assert experiment_split([EVAL_FIRST], ["apartment"]).label == "evaluation"
    assert experiment_split([1, EVAL_FIRST]).label == "mixed"


# -- replaying a run of an experiment -------------------------------------------------------------


@pytest.mark.timeout(600)
def test_a_run_of_an_experiment_in_a_generated_apartment_replays_in_that_apartment(tmp_path):
    """The experiment's row links the run's trace; `pycram replay` rebuilds procedural:1 from it
    and runs the same run again."""
    pytest.importorskip("mujoco")
    db = str(tmp_path / "e.sqlite3")
    result = runner.invoke(
        app,
        ["experiment", "--scenario", "test_experiment_environment_column:one_cup_clear_table", "--robot", "pr2"]
        + ["--seeds", "1", "--env", "procedural:1", "--workers", "1", "--db", db, "--name", "replayed"]
        + ["--output", str(tmp_path / "out")],
    )
    assert result.exit_code == 0, result.output
    (run,) = store.run_records(db, store.find_experiment(db, "replayed").id)
    assert run.environment == "procedural:1" and run.trace_run_id is not None
    from pycram.apps.replay import load_replay

    _info, replay, _record = load_replay(run.trace_run_id, db)
    assert (replay["scenario"], replay["environment"], replay["options"]["objects"]) == (
        "clear-table",
        "procedural:1",
        ["cup"],
    )
    again = runner.invoke(app, ["replay", str(run.trace_run_id), "--db", db])
    assert again.exit_code == 0, again.output
    output = _flat(again.output)
    assert "clear-table, robot pr2, seed 1, in procedural:1" in output and "identical" in output
