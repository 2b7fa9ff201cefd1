"""A trace database that is wrong or fails (issue 12, sections 4 and 6): unsupported kinds and
malformed URLs get clear errors; a database named with `--db` that does not exist is said to
not exist; a database that fails while a run is recorded never fails the plan, loses as little
as it can, and the user is told how many trace records were lost; inspecting a broken
database is a one-line error with a non-zero exit code.

PostgreSQL tests use `$PYCRAM_TEST_POSTGRES_URL` (as tests/test_trace.py does) and are skipped
without it.
"""

from __future__ import annotations

import logging
import os
import sqlite3
import uuid
from pathlib import Path

import pytest

sa = pytest.importorskip("sqlalchemy")

from typer.testing import CliRunner  # noqa: E402

import pycram.core.events as events  # noqa: E402
from pycram.apps.cli import app  # noqa: E402
from pycram.language import State, seq  # noqa: E402
from pycram.trace import query  # noqa: E402
from pycram.trace.db import TraceDatabaseError  # noqa: E402
from pycram.trace.recorder import start_recording  # noqa: E402

runner = CliRunner()
PG_URL = os.environ.get("PYCRAM_TEST_POSTGRES_URL")
NO_PG = "PYCRAM_TEST_POSTGRES_URL is not set (.ci/run sets it; start a server with scripts/start_test_postgres.sh)"


def _invoke(*args: str):
    return runner.invoke(app, list(args), catch_exceptions=False)


def _one_line_error(result, *fragments: str) -> str:
    """Assert a non-zero exit with exactly one line "error: ..." containing `fragments`."""
    text = result.output.strip()
    assert result.exit_code != 0, text
    assert "Traceback" not in text and len(text.splitlines()) == 1, text
    assert text.startswith("error: "), text
    for fragment in fragments:
        assert fragment in text, text
    return text


def _steps(prefix: str, n: int) -> None:
    for i in range(n):
        seq(lambda: None, name=f"{prefix} {i}")


def _recording_then(url: str, plan: str, damage, steps: int = 2):
    """A started recorder that has committed `steps` tasks "before i"; then `damage(recorder)`."""
    recorder = start_recording(url, plan=plan)
    _steps("before", steps)
    assert recorder.flush()
    damage(recorder)
    return recorder


# -- URLs and missing databases --------------------------------------------------------------------


@pytest.mark.parametrize(
    "url, fragments",
    [
        ("postgresql://someone:secret@dbhost:notaport/runs", ["the port 'notaport' is not a number"]),
        ("sqlite:/relative.db", ["needs '://' after its kind 'sqlite'", "sqlite:///relative/path.sqlite3"]),
        ("mysql://someone@dbhost/runs", ["database kind 'mysql'", "not supported", "SQLite", "PostgreSQL"]),
        ("mysql+pymysql://someone@dbhost/runs", ["database kind 'mysql'", "not supported"]),
    ],
)
def test_malformed_and_unsupported_urls_get_a_clear_error(url, fragments, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TraceDatabaseError) as info:
        start_recording(url, plan="bad")
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message
    assert "secret" not in message and "install pycram[db]" not in message and "pip install" not in message
    for command in (["runs"], ["show"], ["graph", "-o", "x.svg"], ["timeline", "-o", "x.png"]):
        _one_line_error(_invoke(*command, "--db", url), *fragments)
    plan = tmp_path / "plan.py"
    plan.write_text("print('the plan ran')\n")
    result = _invoke("run", str(plan), "--db", url)
    assert "the plan ran" not in result.output  # refused before the plan runs
    _one_line_error(result, *fragments)
    assert list(tmp_path.iterdir()) == [plan]  # no folder named "sqlite:", no pictures


def test_inspecting_a_database_that_does_not_exist_says_so(tmp_path):
    no_folder = tmp_path / "no" / "such" / "runs.sqlite3"
    for command in (["runs"], ["show"], ["graph", "-o", str(tmp_path / "x.svg")]):
        _one_line_error(
            _invoke(*command, "--db", str(no_folder)),
            "no such database",
            f"the folder {no_folder.parent} does not exist",
        )
    no_file = tmp_path / "runs.sqlite3"
    _one_line_error(_invoke("runs", "--db", f"sqlite:///{no_file}"), "no such database", f"{no_file} does not exist")
    assert not (tmp_path / "no").exists() and not no_file.exists()  # reading created nothing


def test_a_read_only_database_is_refused_before_the_plan_runs(tmp_path):
    path = tmp_path / "runs.sqlite3"
    start_recording(f"sqlite:///{path}", plan="first").finish("succeeded")
    read_only = f"sqlite:///file:{path}?mode=ro&uri=true"
    with pytest.raises(TraceDatabaseError, match="cannot write to database .*attempt to write a readonly database"):
        start_recording(read_only, plan="second")
    assert [r.plan for r in query.runs(read_only)] == ["first"]  # reading still works


# -- inspecting broken databases -------------------------------------------------------------------


def _recorded(path: Path, runs: int = 3) -> None:
    for _ in range(runs):
        recorder = start_recording(f"sqlite:///{path}", plan="p" * 200)
        _steps("a fairly long step name " * 4, 30)
        recorder.finish("succeeded")


def _corrupt_pages(path: Path) -> None:
    """Keep the first page (header and schema), overwrite every other page with garbage."""
    _recorded(path)
    size = path.stat().st_size
    assert size > 3 * 4096 and not Path(f"{path}-wal").exists()
    with open(path, "r+b") as f:
        f.seek(4096)
        f.write(os.urandom(size - 4096))


def _not_a_database(path: Path) -> None:
    path.write_bytes(os.urandom(64 * 1024))


def _directory(path: Path) -> None:
    path.mkdir()


@pytest.mark.parametrize("damage", [_corrupt_pages, _not_a_database, _directory])
def test_inspecting_a_broken_database_is_a_one_line_error(tmp_path, damage):
    path = tmp_path / "runs.sqlite3"
    damage(path)
    for command in (
        ["runs"],
        ["show"],
        ["show", "1"],
        ["graph", "-o", str(tmp_path / "x.svg")],
        ["timeline", "-o", str(tmp_path / "x.png")],
    ):
        _one_line_error(_invoke(*command, "--db", str(path)), "database", str(path))
    with pytest.raises(TraceDatabaseError):
        query.failed_tasks(url=str(path))


# -- a database that fails while a run is recorded ----------------------------------------------


def _drop(path: Path, table: str) -> None:
    with sqlite3.connect(path) as conn:
        conn.execute(f"DROP TABLE {table}")
    conn.close()


def _rename(path: Path, old: str, new: str) -> None:
    with sqlite3.connect(path) as conn:
        conn.execute(f"ALTER TABLE {old} RENAME TO {new}")
    conn.close()


def test_a_table_dropped_under_the_writer_loses_records_not_the_plan(tmp_path, caplog):
    path = tmp_path / "runs.sqlite3"
    recorder = _recording_then(f"sqlite:///{path}", "dropped", lambda _: _drop(path, "pycram_tasks"))
    state = seq(lambda: None, lambda: None, name="after")  # the plan goes on as if nothing happened
    assert state.get_value() is State.SUCCEEDED
    with caplog.at_level(logging.WARNING, logger="pycram.trace.recorder"):
        run_id = recorder.finish("succeeded")
    assert run_id is not None and recorder.write_errors >= 1
    assert recorder.lost_records >= 4  # "after", its two steps and the run's end, at least
    report = recorder.loss_report()
    assert report.startswith(f"{recorder.lost_records} trace records could not be written: ")
    assert "no such table: pycram_tasks" in report
    assert any(report in record.getMessage() for record in caplog.records)  # in the logs too
    assert query.get_run(run_id, str(path)).outcome is None  # the end could not be written either
    shown = _invoke("show", str(run_id), "--db", str(path))  # connecting re-creates the table
    assert shown.exit_code == 0 and "0 tasks" in shown.output, shown.output


def test_a_database_that_recovers_loses_nothing(tmp_path):
    """Batches that fail are kept and written with the next batch that succeeds."""
    path = tmp_path / "runs.sqlite3"
    recorder = _recording_then(
        f"sqlite:///{path}", "recovers", lambda _: _rename(path, "pycram_tasks", "pycram_tasks_away")
    )
    _steps("during", 3)
    events.process_module_executed("base", "go", "succeeded", 1.0, 2.0)
    assert recorder.flush()
    assert recorder.write_errors >= 1 and recorder.lost_records == 0
    _rename(path, "pycram_tasks_away", "pycram_tasks")
    _steps("after", 2)
    run_id = recorder.finish("succeeded")
    assert recorder.lost_records == 0 and recorder.loss_report() is None
    names = {r.name for r in query.tasks(run_id, str(path))}
    assert {f"during {i}" for i in range(3)} <= names and {"before 0", "after 1"} <= names
    assert len(query.executions(run_id, url=str(path))) == 1
    run = query.get_run(run_id, str(path))
    assert run.outcome == "succeeded" and run.lost_records == 0


def test_rows_beyond_the_backlog_limit_are_dropped_and_counted(tmp_path, monkeypatch):
    import pycram.trace.recorder as recorder_module

    monkeypatch.setattr(recorder_module, "BACKLOG_LIMIT", 5)
    path = tmp_path / "runs.sqlite3"
    recorder = _recording_then(
        f"sqlite:///{path}", "backlog", lambda _: _rename(path, "pycram_executions", "pycram_executions_away")
    )
    for i in range(20):
        events.process_module_executed("base", f"go {i}", "succeeded", float(i), i + 0.5)
    assert recorder.flush()
    assert recorder.lost_records == 15
    _rename(path, "pycram_executions_away", "pycram_executions")
    run_id = recorder.finish("succeeded")
    kept = query.executions(run_id, url=str(path))
    assert [x.designator for x in kept] == [f"go {i}" for i in range(15, 20)]  # the newest are kept
    assert query.get_run(run_id, str(path)).lost_records == 15
    assert "15 trace records of this run could not be written" in _invoke("show", "--db", str(path)).output


def test_a_directory_in_place_of_the_file_mid_run(tmp_path):
    path = tmp_path / "runs.sqlite3"

    def replace_by_a_folder(recorder) -> None:
        recorder._engine.dispose()  # the writer must reconnect: the file is gone, a folder is there
        for suffix in ("", "-wal", "-shm"):
            Path(f"{path}{suffix}").unlink(missing_ok=True)
        path.mkdir()

    recorder = _recording_then(f"sqlite:///{path}", "replaced", replace_by_a_folder)
    _steps("after", 2)
    recorder.finish("succeeded")
    assert recorder.lost_records >= 3 and "unable to open database file" in recorder.loss_report()
    _one_line_error(_invoke("runs", "--db", str(path)), "unable to open database file")


_BREAKING_PLAN = """
import sqlite3, sys
from pycram.language import seq

seq(lambda: None, name="before")
from pycram.trace import active_recorders
active_recorders()[0].flush()
with sqlite3.connect(sys.argv[1]) as conn:
    conn.execute("DROP TABLE pycram_tasks")
seq(lambda: None, name="after")
print("the plan ended")
"""


def test_pycram_run_tells_how_many_records_were_lost_and_succeeds(tmp_path):
    path = tmp_path / "runs.sqlite3"
    plan = tmp_path / "plan.py"
    plan.write_text(_BREAKING_PLAN)
    result = _invoke("run", str(plan), str(path), "--db", str(path))
    assert result.exit_code == 0, result.output
    assert "the plan ended" in result.output and "Traceback" not in result.output
    assert "recorded as run 1 (succeeded)" in result.output
    assert "trace of run 1 incomplete:" in result.output
    assert "trace records could not be written: no such table: pycram_tasks" in result.output


def test_the_demo_succeeds_and_tells_how_many_records_were_lost(tmp_path, capsys, monkeypatch):
    """The demo's database loses its task table right after the run started: the plan
    succeeds, the pictures are drawn from memory, the end output says what was lost."""
    import pycram.apps.demos.kitchen as kitchen

    path = tmp_path / "runs.sqlite3"
    start = kitchen._start_recorder

    def start_then_break(options, plan_name):
        recorder = start(options, plan_name)
        assert recorder.flush()
        _rename(path, "pycram_tasks", "pycram_tasks_away")
        return recorder

    monkeypatch.setattr(kitchen, "_start_recorder", start_then_break)
    code = kitchen.main(output=str(tmp_path / "out"), db=str(path), quiet=True)
    out = " ".join(capsys.readouterr().out.split())  # the console wraps long lines
    assert code == 0, out
    assert "SUCCESS: the item rests on cooker #1" in out
    assert "trace of run 1 incomplete: " in out and "trace records could not be written: no such table" in out
    assert (tmp_path / "out" / "task-tree.svg").exists() and (tmp_path / "out" / "timeline.png").exists()


# -- PostgreSQL --------------------------------------------------------------------------------------


@pytest.fixture
def postgres_db():
    """A fresh PostgreSQL database of its own (the test may drop it); yields (url, admin engine)."""
    if not PG_URL:
        pytest.skip(NO_PG)
    admin = sa.create_engine(sa.make_url(PG_URL).set(drivername="postgresql+psycopg"), isolation_level="AUTOCOMMIT")
    name = f"pycram_f_{uuid.uuid4().hex[:12]}"
    with admin.connect() as conn:
        conn.execute(sa.text(f"CREATE DATABASE {name}"))
    url = sa.make_url(PG_URL).set(drivername="postgresql+psycopg", database=name)
    yield url.render_as_string(hide_password=False), admin, name
    from pycram.trace.db import _engines

    for key in [k for k in _engines if name in k]:
        _engines.pop(key).dispose()
    with admin.connect() as conn:
        conn.execute(sa.text(f"DROP DATABASE IF EXISTS {name} WITH (FORCE)"))
    admin.dispose()


def test_postgres_connections_killed_mid_run_lose_nothing(postgres_db):
    """The server drops every connection (as on a restart): the writer reconnects."""
    url, admin, name = postgres_db
    killed = []

    def terminate_connections(_) -> None:
        with admin.connect() as conn:
            killed.append(
                conn.execute(
                    sa.text(
                        "SELECT count(pg_terminate_backend(pid)) FROM pg_stat_activity "
                        "WHERE datname = :name AND pid <> pg_backend_pid()"
                    ),
                    {"name": name},
                ).scalar()
            )

    recorder = _recording_then(url, "reconnects", terminate_connections, steps=3)
    assert killed[0] >= 1
    _steps("after", 3)
    run_id = recorder.finish("succeeded")
    assert recorder.lost_records == 0
    names = {r.name for r in query.tasks(run_id, url)}
    assert {f"before {i}" for i in range(3)} | {f"after {i}" for i in range(3)} <= names
    assert query.get_run(run_id, url).outcome == "succeeded"


def test_postgres_database_dropped_mid_run(postgres_db):
    url, admin, name = postgres_db

    def drop_database(_) -> None:
        with admin.connect() as conn:
            conn.execute(sa.text(f"DROP DATABASE {name} WITH (FORCE)"))

    recorder = _recording_then(url, "dropped", drop_database)
    state = seq(lambda: None, name="after")
    assert state.get_value() is State.SUCCEEDED
    recorder.finish("succeeded")
    assert recorder.lost_records >= 2 and f'database "{name}" does not exist' in recorder.loss_report()
    from pycram.trace.db import _engines

    for key in [k for k in _engines if name in k]:
        _engines.pop(key).dispose()
    _one_line_error(_invoke("runs", "--db", url), f'database "{name}" does not exist')


# -- migrating a database of schema 1, on both kinds ----------------------------------------------


@pytest.fixture(params=["sqlite", "postgresql"])
def any_db(request, tmp_path):
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    return request.getfixturevalue("postgres_db")[0]


def test_schema_1_is_migrated_concurrently_and_read(any_db):
    """Several processes (here: engines in threads) connecting to a database of schema 1 at
    once each add the missing columns or find them added; old rows read as before."""
    import threading

    from pycram.trace.db import connect, create_engine, ensure_schema

    engine = connect(any_db)
    with engine.begin() as conn:  # back to schema 1
        conn.exec_driver_sql("ALTER TABLE pycram_tasks DROP COLUMN error_origin")
        conn.exec_driver_sql("ALTER TABLE pycram_runs DROP COLUMN clock")
        conn.exec_driver_sql("ALTER TABLE pycram_runs DROP COLUMN lost_records")
        conn.exec_driver_sql(
            "INSERT INTO pycram_runs (uuid, plan, started_at, outcome) "
            "VALUES ('old', 'old run', '2026-01-01 10:00:00', 'failed')"
        )
        run_id = conn.exec_driver_sql("SELECT id FROM pycram_runs").scalar()
        conn.exec_driver_sql(
            "INSERT INTO pycram_tasks (run_id, task_id, parent_id, name, kind, status, error_type, error_message) "
            f"VALUES ({run_id}, 1, NULL, 'seq', 'seq', 'failed', 'Boom', 'x'), "
            f"({run_id}, 2, 1, 'grab', 'step', 'failed', 'Boom', 'x')"
        )
    engine.dispose()
    errors: list = []

    def migrate() -> None:
        other = create_engine(any_db)
        try:
            ensure_schema(other)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)
        finally:
            other.dispose()

    threads = [threading.Thread(target=migrate) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    columns = {c["name"] for c in sa.inspect(engine).get_columns("pycram_tasks")}
    assert "error_origin" in columns
    engine.dispose()
    assert [r.name for r in query.failed_tasks(url=any_db)] == ["grab"]
    assert query.get_run(run_id, any_db).clock is None
