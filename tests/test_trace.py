"""Run recording (pycram.trace): round trips on SQLite and PostgreSQL, crash safety,
concurrent runs, idempotent schema, clear errors for bad URLs, non-blocking callbacks.

PostgreSQL tests use `$PYCRAM_TEST_POSTGRES_URL` (set by `.ci/run`, which starts a throwaway
server with `scripts/start_test_postgres.sh`); without it they are skipped, saying so.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest

sa = pytest.importorskip("sqlalchemy")

import pycram.core.events as events  # noqa: E402
from pycram.fluent import Fluent  # noqa: E402
from pycram.language import State, par, pursue, seq  # noqa: E402
from pycram.runtime import run_subtask, sleep  # noqa: E402
from pycram.trace import query  # noqa: E402
from pycram.trace.db import TraceDatabaseError, connect, ensure_schema  # noqa: E402
from pycram.trace.recorder import Recorder, recording_enabled, start_recording  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
PG_URL = os.environ.get("PYCRAM_TEST_POSTGRES_URL")
NO_PG = "PYCRAM_TEST_POSTGRES_URL is not set (.ci/run sets it; start a server with scripts/start_test_postgres.sh)"


@pytest.fixture(scope="session")
def postgres_url():
    """A fresh PostgreSQL database for this test session (dropped afterwards)."""
    if not PG_URL:
        pytest.skip(NO_PG)
    admin = sa.create_engine(sa.make_url(PG_URL).set(drivername="postgresql+psycopg"), isolation_level="AUTOCOMMIT")
    name = f"pycram_t_{uuid.uuid4().hex[:12]}"
    with admin.connect() as conn:
        conn.execute(sa.text(f"CREATE DATABASE {name}"))
    url = sa.make_url(PG_URL).set(drivername="postgresql+psycopg", database=name).render_as_string(hide_password=False)
    yield url
    from pycram.trace.db import _engines

    for key in [k for k in _engines if name in k]:
        _engines.pop(key).dispose()
    with admin.connect() as conn:
        conn.execute(sa.text(f"DROP DATABASE IF EXISTS {name} WITH (FORCE)"))
    admin.dispose()


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    return request.getfixturevalue("postgres_url")


class Boom(Exception):
    pass


def _grasp() -> None:
    raise Boom("the gripper closed on air")


def _sample_plan() -> None:
    errors: list = []
    seq(lambda: None, lambda: par(lambda: None, lambda: sleep(0.01)), name="main")
    run_subtask("perform grasping", _try_grasp, kind="action")
    pursue(lambda: sleep(5.0), lambda: sleep(0.01), errors=errors)


def _try_grasp() -> None:
    errors: list = []
    state = seq(_grasp, errors=errors)
    assert state.get_value() is State.FAILED and errors


def test_round_trip(db_url):
    pose = Fluent(0.0, name="pose")
    recorder = start_recording(db_url, plan="round trip", robot="pr2")
    recorder.watch(pose, "pose", max_rate_hz=None)
    for i in range(1, 4):
        pose.set_value(float(i))
    _sample_plan()
    events.designator_performed("a designator", solution="a solution")
    events.process_module_executed("navigation", "go there", "succeeded", 1.0, 3.5)
    events.process_module_executed("gripper", "grasp", "failed", 4.0, 4.5, error=Boom("slipped"))
    run_id = recorder.finish("succeeded")

    run = query.get_run(run_id, db_url)
    assert (run.plan, run.robot, run.outcome, run.state) == ("round trip", "pr2", "succeeded", "succeeded")
    assert run.duration is not None and run.duration > 0 and run.ended_at >= run.started_at
    assert [r.id for r in query.runs(db_url)][0] == run_id

    records = query.tasks(run_id, db_url)
    by_name = {}
    for r in records:
        by_name.setdefault(r.name, []).append(r)
    assert by_name["main"][0].status == "succeeded" and by_name["main"][0].kind == "seq"
    assert all(r.status != "running" for r in records if r.kind != "root")
    assert {r.status for r in records if r.kind == "branch"} >= {"succeeded", "evaporated"}
    grasp = by_name["perform grasping"][0]
    assert grasp.kind == "action" and grasp.status == "succeeded"
    failed = query.failed_tasks(name="grasp", url=db_url)
    assert failed and failed[0].error_type == "Boom" and "closed on air" in failed[0].error_message
    assert all(r.run_id == run_id for r in failed)

    roots = query.task_tree(run_id, db_url)
    assert len(roots) == 1 and roots[0].record.kind == "root"
    main = next(n for n in roots[0].children if n.record.name == "main")
    assert [c.record.name for c in main.children] == ["1", "2"]
    paths = {r.path for r in records}
    assert all(r.parent_id is None or any(p.task_id == r.parent_id for p in records) for r in records)
    assert any(p.endswith("/main/2/par") for p in paths)

    assert len(query.durations("perform grasping", url=db_url, run_id=run_id)) == 1
    execs = query.executions(run_id, url=db_url)
    assert [(x.module, x.outcome, x.duration) for x in execs] == [
        ("navigation", "succeeded", 2.5),
        ("gripper", "failed", 0.5),
    ]
    assert execs[1].error_type == "Boom"
    assert query.executions(outcome="failed", url=db_url)[-1].module == "gripper"
    desigs = query.designators(run_id, url=db_url)
    assert len(desigs) == 1 and desigs[0].solution == "a solution"
    samples = query.fluent_samples(run_id, "pose", db_url)
    assert [s.number for s in samples] == [0.0, 1.0, 2.0, 3.0]


def test_task_locations_are_recorded(tmp_path):
    url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    recorder = start_recording(url, plan="locations")
    run_subtask("step", lambda: None, location="plan.py:12")
    run_subtask("anonymous step", lambda: None)
    run_id = recorder.finish("succeeded")
    by_name = {r.name: r for r in query.tasks(run_id, url)}
    assert by_name["step"].location == "plan.py:12"
    assert by_name["anonymous step"].location is None


def test_fluent_rate_limit_keeps_last_value(tmp_path):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    f = Fluent(0, name="counter")
    recorder = start_recording(url, plan="rate")
    recorder.watch(f, "counter", max_rate_hz=5.0)
    started = time.monotonic()
    for i in range(1, 2001):
        f.set_value(i)
    elapsed = time.monotonic() - started
    time.sleep(0.5)  # the held-back value is written once its window has passed
    recorder.flush()
    mid = [s.number for s in query.fluent_samples(recorder.run_id, "counter", url)]
    run_id = recorder.finish()
    samples = [s.number for s in query.fluent_samples(run_id, "counter", url)]
    assert samples[-1] == 2000 and mid[-1] == 2000
    allowed = 2 + 5.0 * (elapsed + 0.6) + 1
    assert len(samples) <= allowed, (samples, elapsed)
    f.set_value(5)  # after finish: not recorded, no error
    assert len(query.fluent_samples(run_id, "counter", url)) == len(samples)


def test_watch_holds_no_polling_thread_and_unwatch(tmp_path):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    f = Fluent(1, name="x")
    with Recorder(url, plan="watch") as recorder:
        before = threading.active_count()
        recorder.watch(f, "x", max_rate_hz=100)
        assert threading.active_count() == before
        recorder.watch(f, "x")  # same fluent, same name: no-op
        with pytest.raises(ValueError, match="already watched"):
            recorder.watch(Fluent(2), "x")
        recorder.unwatch("x")
        f.set_value(7)
    assert [s.number for s in query.fluent_samples(recorder.run_id, url=url)] == [1.0]


def test_callbacks_never_wait_for_the_database(tmp_path):
    """A writer stuck in the database must not stop the plan: rows are queued, written later.

    The writer is blocked inside a statement (a SQLAlchemy hook waits on a gate) while a plan
    runs 300 tasks, sets a watched fluent and publishes events. If any plan-thread callback
    waited for the database, the plan could not end before the gate opens.
    """
    url = f"sqlite:///{tmp_path / 'blocked.sqlite3'}"
    recorder = start_recording(url, plan="blocked")
    entered, gate = threading.Event(), threading.Event()

    def block_writer(*_args) -> None:
        if threading.current_thread() is recorder._writer:
            entered.set()
            gate.wait()

    sa.event.listen(recorder._engine, "before_cursor_execute", block_writer)
    fluent = Fluent(0, name="level")
    recorder.watch(fluent, "level", max_rate_hz=None)
    try:
        seq(lambda: None, name="first")
        assert entered.wait(30), "the writer never tried to write"

        def plan() -> None:
            seq(*[(lambda: None) for _ in range(300)], name="fast")
            for i in range(50):
                fluent.set_value(i)
            events.process_module_executed("arm", "reach", "succeeded", 0.0, 1.0)
            events.designator_performed("a designator", solution="a solution")

        runner = threading.Thread(target=plan)
        runner.start()
        runner.join(60)
        plan_ended_while_writer_blocked = not runner.is_alive() and not gate.is_set()
    finally:
        gate.set()
    assert plan_ended_while_writer_blocked
    run_id = recorder.finish("succeeded")
    names = [r.name for r in query.tasks(run_id, url)]
    assert names.count("fast") == 1 and len(names) >= 303
    assert [s.number for s in query.fluent_samples(run_id, "level", url)] == [float(i) for i in [0, *range(50)]]
    assert len(query.executions(run_id, url=url)) == 1 and len(query.designators(run_id, url=url)) == 1


def test_idle_run_keeps_a_heartbeat(tmp_path):
    """A plan that creates no task for a while still shows as alive (last_seen_at advances)."""
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    recorder = start_recording(url, plan="idle", heartbeat_interval=0.05)
    try:
        first = query.get_run(recorder.run_id, url).last_seen_at
        deadline = time.monotonic() + 30
        seen = first
        while seen == first and time.monotonic() < deadline:
            time.sleep(0.05)  # polling the database from the test, not timing the recorder
            seen = query.get_run(recorder.run_id, url).last_seen_at
        assert seen > first
        assert query.get_run(recorder.run_id, url).state == "running"
    finally:
        recorder.finish()


def test_module_level_watch_and_default_rate(tmp_path):
    import pycram.trace as trace

    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    f = Fluent(0, name="speed")
    assert trace.watch(f) == 0  # nothing records: a no-op
    recorder = trace.start_recording(url, plan="watch", fluent_rate_hz=None)  # default: every change
    assert trace.active_recorders() == [recorder]
    assert trace.watch(f) == 1  # named after the fluent
    for i in range(1, 20):
        f.set_value(i)
    run_id = recorder.finish()
    assert trace.active_recorders() == [] and trace.watch(Fluent(1)) == 0
    assert [s.number for s in query.fluent_samples(run_id, "speed", url)] == [float(i) for i in range(20)]


def test_designators_and_process_modules_of_a_real_plan(tmp_path):
    """perform() of action and motion designators on a robot's process modules is recorded:
    the designator with the solution it resolved to, and each execution with module,
    designator, outcome and duration."""
    from pycram.designator import ActionDesignator, MotionDesignator, perform, plan_for
    from pycram.process_module import ProcessModuleFailure
    from pycram.robot import Robot
    from pycram.testing import ScriptedProcessModule

    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    head = ScriptedProcessModule("head")
    gripper = ScriptedProcessModule("gripper", script=[RuntimeError("slipped")])
    robot = Robot("test-robot")
    robot.add_process_module("head", head)
    robot.add_process_module("gripper", gripper)
    robot.process_module_resolvers.append(lambda d: head if d.prop_value("type") == "looking" else gripper)
    robot.motion_resolvers.append(lambda d: [{"command": d.prop_value("type")}])

    def look_around(designator) -> None:
        perform(MotionDesignator(type="looking", target="table"))

    robot.action_resolvers.append(plan_for("looking-around", look_around))
    recorder = start_recording(url, plan="designators", robot=robot.name)
    with robot:
        perform(ActionDesignator(type="looking-around"))
        with pytest.raises(ProcessModuleFailure):
            perform(MotionDesignator(type="gripping"))
    run_id = recorder.finish("succeeded")

    desigs = {d.designator_type: d for d in query.designators(run_id, url=url)}
    assert set(desigs) == {"looking-around", "looking", "gripping"}
    assert desigs["looking-around"].designator_class == "ActionDesignator"
    assert "look_around" in desigs["looking-around"].solution  # the plan it resolved to
    assert desigs["looking"].designator_class == "MotionDesignator"
    assert desigs["looking"].solution == "{'command': 'looking'}" and desigs["looking"].error_type is None
    assert "'target', 'table'" in desigs["looking"].designator
    assert desigs["gripping"].error_type == "ProcessModuleFailure" and "slipped" in desigs["gripping"].error_message
    execs = query.executions(run_id, url=url)
    assert [(x.module, x.designator_type, x.outcome) for x in execs] == [
        ("head", "looking", "succeeded"),
        ("gripper", "gripping", "failed"),
    ]
    assert all(x.duration is not None and x.duration >= 0 for x in execs)
    assert "slipped" in execs[1].error_message
    action = next(r for r in query.tasks(run_id, url) if r.name == "perform looking-around")
    assert execs[0].task_id == action.task_id  # the execution belongs to the action's task
    assert query.executions(outcome="failed", url=url)[0].module == "gripper"


def test_query_across_runs(tmp_path):
    """The query API over several runs: all failed grasps, the durations of one action."""
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"

    def grasp(ok: bool) -> None:
        if not ok:
            raise Boom("nothing between the fingers")

    run_ids = []
    for outcomes in ([False, True], [False, False, True], [True]):
        recorder = start_recording(url, plan="fetch")
        for ok in outcomes:
            seq(lambda ok=ok: run_subtask("perform grasping", grasp, ok, kind="action"), errors=[])
        run_subtask("perform navigating", sleep, 0.001, kind="action")
        run_ids.append(recorder.finish("succeeded"))
    failed = query.failed_tasks(name="grasp", kind="action", url=url)
    assert [r.run_id for r in failed] == [run_ids[1], run_ids[1], run_ids[0]]  # newest run first
    assert {r.error for r in failed} == {"Boom: nothing between the fingers"}
    assert query.failed_tasks(error_type="boom", run_id=run_ids[2], url=url) == []
    assert len(query.durations("perform grasping", url=url)) == 6
    assert len(query.durations("perform grasping", status="succeeded", url=url)) == 3
    navigating = query.durations("perform navigating", kind="action", url=url)
    assert len(navigating) == 3 and all(d >= 0.001 for d in navigating)
    assert [r.id for r in query.runs(url, plan="FET")] == run_ids[::-1]


def test_reading_a_missing_sqlite_file_creates_nothing(tmp_path):
    path = tmp_path / "nothing-here.sqlite3"
    assert query.runs(f"sqlite:///{path}") == []
    with pytest.raises(query.RunNotFound, match="no run has been recorded"):
        query.get_run(None, str(path))
    assert query.failed_tasks(url=str(path)) == []
    assert not path.exists()


def test_scope_records_only_tasks_below(tmp_path):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    seen = {}

    def scoped() -> None:
        from pycram.runtime import current_task

        seen["task"] = current_task()
        seq(lambda: None, name="inside")

    def run_scoped() -> None:
        from pycram.runtime import task_scope

        with task_scope("scope", "task") as scope:
            recorder.scope = scope.task
            scoped()

    recorder = Recorder(url, plan="scoped").start()
    seq(lambda: None, name="outside-before")
    run_scoped()
    run_id = recorder.finish()
    names = {r.name for r in query.tasks(run_id, url)}
    assert "inside" in names and "scope" in names and "outside-before" not in names


def test_schema_creation_is_idempotent(db_url):
    engine = connect(db_url)
    ensure_schema(engine)
    threads = [threading.Thread(target=ensure_schema, args=(engine,)) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    ensure_schema(engine)
    inspector = sa.inspect(engine)
    assert {"pycram_runs", "pycram_tasks", "pycram_designators", "pycram_executions", "pycram_fluent_samples"} <= set(
        inspector.get_table_names()
    )
    engine.dispose()
    recorder = start_recording(db_url, plan="after schema")
    assert recorder.finish() >= 1


@pytest.mark.parametrize(
    "url, fragment",
    [
        ("not a url", "invalid database URL 'not a url'"),
        ("nosuchdb://host/x", "unknown database kind 'nosuchdb'"),
        (
            "postgresql+psycopg://someone:secret@127.0.0.1:1/x",
            "cannot use database postgresql+psycopg://someone:***@127.0.0.1:1/x",
        ),
    ],
)
def test_bad_urls_get_a_clear_error(url, fragment):
    with pytest.raises(TraceDatabaseError) as info:
        start_recording(url, plan="bad")
    message = str(info.value)
    assert fragment in message
    assert "secret" not in message


def test_unwritable_sqlite_location(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    url = f"sqlite:///{blocker / 'sub' / 'runs.sqlite3'}"
    with pytest.raises(TraceDatabaseError, match="cannot create the folder"):
        start_recording(url)


def test_default_url_and_env(monkeypatch, tmp_path):
    from pycram.trace.db import default_url, resolve_url

    monkeypatch.delenv("PYCRAM_DB_URL", raising=False)
    monkeypatch.setenv("PYCRAM_HOME", str(tmp_path / "home"))
    assert default_url() == f"sqlite:///{tmp_path / 'home' / 'runs.sqlite3'}"
    monkeypatch.setenv("PYCRAM_DB_URL", "sqlite:///elsewhere.sqlite3")
    assert resolve_url(None) == "sqlite:///elsewhere.sqlite3"
    monkeypatch.setenv("PYCRAM_DB_URL", str(tmp_path / "env.sqlite3"))  # a bare path: a SQLite file
    assert resolve_url(None) == f"sqlite:///{tmp_path / 'env.sqlite3'}"
    assert resolve_url("  ") == f"sqlite:///{tmp_path / 'env.sqlite3'}"
    monkeypatch.delenv("PYCRAM_DB_URL")
    monkeypatch.delenv("PYCRAM_HOME")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert default_url() == f"sqlite:///{tmp_path / 'xdg' / 'pycram' / 'runs.sqlite3'}"
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "user"))
    assert default_url() == f"sqlite:///{tmp_path / 'user' / '.local' / 'share' / 'pycram' / 'runs.sqlite3'}"
    assert resolve_url("sqlite:///x.db") == "sqlite:///x.db"
    assert resolve_url(str(tmp_path / "a.sqlite3")) == f"sqlite:///{tmp_path / 'a.sqlite3'}"


@pytest.mark.parametrize(
    "value, default, expected",
    [
        (None, True, True),
        (None, False, False),
        ("0", True, False),
        ("1", False, True),
        ("off", True, False),
        ("true", False, True),
        ("", True, True),
    ],
)
def test_recording_switch_from_environment(monkeypatch, value, default, expected):
    if value is None:
        monkeypatch.delenv("PYCRAM_RECORD", raising=False)
    else:
        monkeypatch.setenv("PYCRAM_RECORD", value)
    assert recording_enabled(default) is expected


def test_library_import_does_not_load_sqlalchemy():
    code = (
        "import sys, pycram, pycram.trace, pycram.language, pycram.core.events; "
        "assert 'sqlalchemy' not in sys.modules, 'sqlalchemy imported'; "
        "assert 'matplotlib' not in sys.modules; print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=60)
    assert out.returncode == 0 and "ok" in out.stdout, out.stderr


def test_library_use_records_nothing_unless_asked(tmp_path):
    """Recording is off for library use: running plans writes no database and loads no
    recorder, whatever $PYCRAM_RECORD says (that switch is for `pycram run` / `pycram demo`)."""
    code = (
        "import sys; from pycram.language import par, seq; "
        "seq(lambda: None, lambda: par(lambda: None, lambda: None)); "
        "assert 'pycram.trace.recorder' not in sys.modules; print('ok')"
    )
    for record in ("", "1"):
        env = dict(os.environ, PYCRAM_HOME=str(tmp_path / "home"), PYCRAM_RECORD=record)
        env.pop("PYCRAM_DB_URL", None)
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, env=env, timeout=60
        )
        assert out.returncode == 0 and "ok" in out.stdout, out.stderr
    assert not (tmp_path / "home").exists()


def test_events_bus_is_free_when_nobody_listens():
    assert not events.has_subscribers("nobody.listens")
    events.publish("nobody.listens", x=1)
    got = []
    unsubscribe = events.subscribe("t.topic", lambda **kw: got.append(kw))
    events.subscribe("t.topic", lambda **kw: 1 / 0)  # a broken observer never breaks the publisher
    events.publish("t.topic", a=1)
    unsubscribe()
    events.publish("t.topic", a=2)
    assert got == [{"a": 1}]
    events._subscribers.pop("t.topic", None)


# -- crash safety and concurrent processes -----------------------------------------------------

_CHILD = textwrap.dedent("""
    import sys, time
    from pycram.runtime import run_subtask
    from pycram.trace import start_recording
    url, plan, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
    recorder = start_recording(url, plan=plan)
    print("run", recorder.run_id, flush=True)
    for i in range(count):
        run_subtask(f"{plan} step {i}", time.sleep, 0.005)
        print("done", i, time.monotonic(), flush=True)
    recorder.finish("succeeded")
    print("finished", flush=True)
""")


def _child(url: str, plan: str, count: int) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", _CHILD, url, plan, str(count)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_sigkilled_run_keeps_its_trace_up_to_the_last_second(db_url, tmp_path):
    proc = _child(db_url, "killed", 100_000)
    try:
        first = proc.stdout.readline().split()
        assert first[0] == "run", proc.stderr.read()
        run_id = int(first[1])
        progress: list[tuple[int, float]] = []
        started = time.monotonic()
        while time.monotonic() - started < 2.5:
            line = proc.stdout.readline().split()
            progress.append((int(line[1]), float(line[2])))
        killed_at = time.monotonic()
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL
    # every step that ended more than a second before the kill is in the database
    safe = max(i for i, t in progress if t < killed_at - 1.0)
    run = query.get_run(run_id, db_url)
    assert run.outcome is None and run.ended_at is None
    records = query.tasks(run_id, db_url)
    done = {r.name for r in records if r.status == "succeeded"}
    assert all(f"killed step {i}" in done for i in range(safe + 1))
    assert run.last_seen_at is not None
    # the partial trace is readable by the CLI and the pictures (the run shows as unfinished
    # once its heartbeat is 10 s old; until then as running)
    from typer.testing import CliRunner

    from pycram.apps.cli import app
    from pycram.trace.pictures import write_run_pictures

    shown = CliRunner().invoke(app, ["show", str(run_id), "--db", db_url, "--max-nodes", "50"])
    assert shown.exit_code == 0, shown.output
    assert f"run {run_id}: killed" in shown.output and "killed step 0" in shown.output
    listed = CliRunner().invoke(app, ["runs", "--db", db_url])
    assert listed.output.splitlines()[1].startswith(f"{run_id} ")  # below the header row
    svg, png = write_run_pictures(run_id, tmp_path / "pictures", url=db_url)
    assert "killed step 0" in svg.read_text() and png.stat().st_size > 1000


def test_concurrent_runs_in_one_database_stay_separate(db_url):
    connect(db_url).dispose()  # the schema exists before the race (creation is tested separately)
    children = [_child(db_url, f"proc{k}", 60) for k in range(3)]
    run_ids = {}
    for k, proc in enumerate(children):
        out, errs = proc.communicate(timeout=60)
        assert proc.returncode == 0, errs
        run_ids[k] = int(out.split()[1])
    assert len(set(run_ids.values())) == 3
    for k, run_id in run_ids.items():
        names = [r.name for r in query.tasks(run_id, db_url) if r.kind != "root"]
        assert names == [f"proc{k} step {i}" for i in range(60)]
        assert query.get_run(run_id, db_url).plan == f"proc{k}"


def test_two_recorders_in_one_process(tmp_path):
    url = f"sqlite:///{tmp_path / 'r.sqlite3'}"
    a = start_recording(url, plan="a")
    seq(lambda: None, name="shared")
    b = start_recording(url, plan="b")
    seq(lambda: None, name="both")
    a_id = a.finish()
    seq(lambda: None, name="only b")
    b_id = b.finish()
    names_a = {r.name for r in query.tasks(a_id, url)}
    names_b = {r.name for r in query.tasks(b_id, url)}
    assert {"shared", "both"} <= names_a and "only b" not in names_a
    assert {"both", "only b"} <= names_b and "shared" not in names_b


# -- collapsing repeated siblings in displays ----------------------------------------------------


def _record(
    task_id: int, parent: int | None, name: str, status: str = "succeeded", start: float = 0.0, kind: str = "task"
) -> query.TaskRecord:
    return query.TaskRecord(
        1,
        task_id,
        parent,
        name,
        kind,
        None,
        None,
        status,
        start,
        start + 0.1,
        0.1,
        "Boom" if status == "failed" else None,
        None,
    )


def test_collapse_merges_identical_successful_siblings_only():
    from pycram.trace.collapse import collapse

    records = [_record(1, None, "MainThread", kind="root"), _record(2, 1, "loop")]
    next_id = 3

    def add(parent: int, name: str, status: str = "succeeded", child: str | None = None) -> None:
        nonlocal next_id
        task_id = next_id
        records.append(_record(task_id, parent, name, status, start=float(task_id)))
        next_id += 1
        if child is not None:
            records.append(_record(next_id, task_id, child, start=float(task_id)))
            next_id += 1

    for _ in range(4):
        add(2, "look", child="move head")  # identical subtrees: merged, children merged too
    add(2, "look", child="move eyes")  # a different subtree: its own node
    add(2, "look", "failed")
    add(2, "look", "failed")  # failures are never merged
    add(2, "grasp")
    add(2, "grasp")  # a run shorter than 3 stays as it is
    roots = collapse(query.build_tree(records))
    shown = [(node.record.name, node.count, depth) for node, depth in roots[0].walk()]
    assert shown == [
        ("MainThread", 1, 0),
        ("loop", 1, 1),
        ("look", 4, 2),
        ("move head", 4, 3),
        ("look", 1, 2),
        ("move eyes", 1, 3),
        ("look", 1, 2),
        ("look", 1, 2),
        ("grasp", 1, 2),
        ("grasp", 1, 2),
    ]
    every = sorted(r.task_id for node, _ in roots[0].walk() for r in node.records)
    assert every == sorted(r.task_id for r in records)  # nothing dropped, nothing twice
    assert [n.count for n, _ in collapse(query.build_tree(records), min_run=0)[0].walk()] == [1] * len(records)
    group = roots[0].children[0].children[0]
    assert group.total_duration == pytest.approx(0.4) and group.duration_range == pytest.approx((0.1, 0.1))
