"""The `pycram` command line: runs, show, graph, timeline, run, demo (typer's CliRunner and a
real subprocess)."""

from __future__ import annotations

import os
import subprocess
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytest.importorskip("sqlalchemy")
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
runner = CliRunner()

PLAN = """
import sys
from pycram.language import seq, par, pursue
from pycram.runtime import sleep

class GraspFailed(Exception):
    pass

def grasp():
    raise GraspFailed("nothing between the fingers")

errors = []
seq(lambda: None, lambda: par(lambda: sleep(0.02), lambda: sleep(0.01)), name="fetch")
seq(grasp, errors=errors, name="grasp")
pursue(lambda: sleep(5), lambda: sleep(0.01), name="watch")
print("script args", sys.argv[1:])
if "--fail" in sys.argv:
    raise SystemExit(3)
"""


REPEATING_PLAN = """
from pycram.fluent import STOP, Fluent, whenever
from pycram.language import seq
from pycram.runtime import run_subtask

tick = Fluent(True)  # a whenever loop that points the head on every pass
count = 0

def point_head():
    global count
    count += 1
    if count == 251:
        raise RuntimeError("head stuck")

def body():
    try:
        run_subtask("head: pointing_head", point_head, kind="process-module")
    except RuntimeError:
        pass
    return STOP if count >= 254 else None

seq(lambda: whenever(tick, body), name="watch head")
"""


@pytest.fixture
def db(tmp_path, monkeypatch):
    url = f"sqlite:///{tmp_path / 'cli.sqlite3'}"
    monkeypatch.setenv("PYCRAM_DB_URL", url)
    monkeypatch.delenv("PYCRAM_RECORD", raising=False)
    return url


@pytest.fixture
def plan_file(tmp_path):
    path = tmp_path / "plan.py"
    path.write_text(PLAN)
    return path


def _invoke(*args: str):
    result = runner.invoke(app, list(args), catch_exceptions=False)
    return result


def test_run_records_by_default_and_inspection_commands(db, plan_file, tmp_path, monkeypatch):
    import pycram.apps.cli

    monkeypatch.setattr(pycram.apps.cli.console, "width", 200)  # one line per tree line and per run
    result = _invoke("run", str(plan_file), "x", "--y")
    assert result.exit_code == 0, result.output
    assert "script args ['x', '--y']" in result.output
    result = _invoke("run", str(plan_file), "--fail")
    assert result.exit_code == 3

    result = _invoke("runs")
    assert result.exit_code == 0
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 3
    assert lines[0].split() == ["id", "started", "plan", "robot", "outcome", "took", "reason"]
    assert lines[1].startswith("2 ") and "plan.py" in lines[1] and "failed" in lines[1]
    assert lines[1].rstrip().endswith("SystemExit: 3")  # the reason column
    assert lines[2].startswith("1 ") and "succeeded" in lines[2]

    result = _invoke("show")  # the newest run
    assert result.exit_code == 0
    assert "run 2" in result.output and "GraspFailed: nothing between the fingers" in result.output
    assert "evaporated" in result.output and "fetch" in result.output
    assert _invoke("show", "1").exit_code == 0

    svg = tmp_path / "pics" / "tree.svg"
    result = _invoke("graph", "1", "-o", str(svg))
    assert result.exit_code == 0, result.output
    root = ET.parse(svg).getroot()
    assert root.tag.endswith("svg")
    texts = [el.text for el in root.iter() if el.tag.endswith("text")]
    assert "fetch" in texts and "grasp" in texts

    png = tmp_path / "pics" / "timeline.png"
    result = _invoke("timeline", "-o", str(png))
    assert result.exit_code == 0, result.output
    import matplotlib.image

    image = matplotlib.image.imread(png)
    assert image.shape[0] > 100 and image.shape[1] > 100
    assert image[..., :3].std() > 0.05  # not blank


def test_no_record_flag_and_environment(db, plan_file, monkeypatch):
    assert _invoke("run", str(plan_file), "--no-record").exit_code == 0
    monkeypatch.setenv("PYCRAM_RECORD", "0")
    assert _invoke("run", str(plan_file)).exit_code == 0
    result = _invoke("runs")
    assert "no runs recorded" in result.output
    assert _invoke("run", str(plan_file), "--record").exit_code == 0  # the flag beats the env
    assert _invoke("runs").output.splitlines()[1].startswith("1 ")


def test_unknown_run_and_bad_database_are_clear_errors(db):
    result = _invoke("show", "42")
    assert result.exit_code == 1 and "no run has been recorded" not in result.output
    assert "no run 42" in result.output or "no run" in result.output
    result = _invoke("runs", "--db", "nosuchdb://x/y")
    assert result.exit_code == 1 and "unknown database kind 'nosuchdb'" in result.output
    result = _invoke("graph", "--db", "not a url", "-o", "x.svg")
    assert result.exit_code == 1 and "invalid database URL 'not a url'" in result.output


def test_demo_passes_options_through(monkeypatch, db):
    calls = {}

    def fake_main(**kwargs):
        calls.update(kwargs)
        return 0

    fake = types.ModuleType("pycram.apps.demos.kitchen")
    fake.main = fake_main
    monkeypatch.setitem(sys.modules, "pycram.apps.demos.kitchen", fake)
    result = _invoke(
        "demo",
        "--robot",
        "tiago",
        "--output",
        "out",
        "--item-at",
        "2",
        "--steal",
        "1",
        "--seed",
        "7",
        "--realtime",
        "--db",
        "sqlite:///x.sqlite3",
        "--no-record",
        "--quiet",
        "--no-animation",
        "--backend",
        "ros",
    )
    assert result.exit_code == 0, result.output
    assert calls == dict(
        robot="tiago",
        output="out",
        item_at=2,
        steal=1,
        seed=7,
        realtime=True,
        interactive=False,
        db="sqlite:///x.sqlite3",
        record=False,
        quiet=True,
        animation=False,
        backend="ros",
        stepping=None,  # the backend's own: lock-step in the simulator, the bridge's time over ROS
    )
    monkeypatch.setenv("PYCRAM_RECORD", "0")
    _invoke("demo")
    assert calls["record"] is False and calls["robot"] == "pr2"
    monkeypatch.delenv("PYCRAM_RECORD")
    _invoke("demo")
    assert calls["record"] is True and calls["animation"] is True


@pytest.fixture
def fake_demo(monkeypatch):
    """A stand-in for the demo that records whether it was started."""
    started = []
    fake = types.ModuleType("pycram.apps.demos.kitchen")
    fake.main = lambda **kwargs: started.append(kwargs) or 0
    monkeypatch.setitem(sys.modules, "pycram.apps.demos.kitchen", fake)
    return started


def test_demo_output_that_cannot_be_written_is_one_line_and_exit_2(fake_demo, tmp_path):
    """Tests run as root: a path under a regular file is what cannot be created."""
    a_file = tmp_path / "a-file"
    a_file.write_text("not a folder")
    for output, expected in ((a_file / "sub", f"{a_file} is not a folder"), (a_file, "exists and is not a folder")):
        result = _invoke("demo", "--output", str(output))
        assert result.exit_code == 2, result.output
        lines = result.output.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: --output"), result.output
        assert expected in lines[0] and "Traceback" not in result.output
    assert fake_demo == []
    # where permission bits say yes but nothing can be made (a pseudo file system)
    result = _invoke("demo", "--no-record", "--output", "/proc/pycram-nope")
    assert result.exit_code == 2 and "Traceback" not in result.output, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "cannot create a folder in /proc" in lines[0], result.output
    assert fake_demo == []
    assert _invoke("demo", "--output", str(tmp_path / "new" / "folder")).exit_code == 0
    assert not (tmp_path / "new").exists()  # the check creates nothing; the demo does


@pytest.mark.parametrize(
    "option,value", [("--steal", "-1"), ("--steal", "101"), ("--item-at", "4"), ("--item-at", "-1"), ("--seed", "-3")]
)
def test_demo_options_out_of_range_are_refused_with_exit_2(fake_demo, option, value):
    result = _invoke("demo", option, value)
    assert result.exit_code == 2, result.output
    assert option in result.output and "Traceback" not in result.output
    assert fake_demo == []


def test_demo_missing_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "pycram.apps.demos.kitchen", None)
    result = _invoke("demo")
    assert result.exit_code == 1
    assert "kitchen demo" in result.output


def test_console_script_subprocess(tmp_path, plan_file):
    env = dict(os.environ, PYCRAM_DB_URL=f"sqlite:///{tmp_path / 'sub.sqlite3'}")
    env.pop("PYCRAM_RECORD", None)
    exe = Path(sys.executable).with_name("pycram")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "pycram"]
    out = subprocess.run(
        [*command, "run", str(plan_file)], capture_output=True, text=True, env=env, cwd=REPO, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert "recorded as run 1" in out.stderr
    out = subprocess.run([*command, "runs"], capture_output=True, text=True, env=env, cwd=REPO, timeout=60)
    assert out.returncode == 0 and out.stdout.splitlines()[1].startswith("1 "), out.stderr


def test_repeated_siblings_are_collapsed_in_displays_not_in_the_data(db, tmp_path, monkeypatch):
    """250 identical successful head motions are one line / box / row "×250"; the failure
    between them stays visible; the database keeps every task; --expand shows them all."""
    import pycram.apps.cli

    monkeypatch.setattr(pycram.apps.cli.console, "width", 200)  # one tree line per task line
    plan = tmp_path / "head_loop.py"
    plan.write_text(REPEATING_PLAN)
    assert _invoke("run", str(plan)).exit_code == 0
    from pycram.trace import query

    assert sum(r.name == "head: pointing_head" for r in query.tasks(1, db)) == 254

    result = _invoke("show")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert any("head: pointing_head ×250" in line and "succeeded" in line for line in lines)
    assert any("head: pointing_head [" in line and "RuntimeError: head stuck" in line for line in lines)
    assert any("head: pointing_head ×3" in line for line in lines)
    assert sum("head: pointing_head" in line for line in lines) == 3
    assert "257 tasks, 1 failed" in result.output and "not shown" not in result.output

    expanded = _invoke("show", "--expand")
    assert sum("head: pointing_head" in line for line in expanded.output.splitlines()) == 254

    svg = tmp_path / "tree.svg"
    assert _invoke("graph", "-o", str(svg)).exit_code == 0
    root = ET.parse(svg).getroot()
    texts = [el.text for el in root.iter() if el.tag.endswith("text")]
    assert "head: pointing_head ×250" in texts and "head: pointing_head ×3" in texts
    boxes = [el for el in root.iter() if el.tag.endswith("g") and "task" in (el.get("class") or "")]
    assert len(boxes) < 10
    assert _invoke("graph", "--expand", "-o", str(svg)).exit_code == 0
    texts = [el.text for el in ET.parse(svg).getroot().iter() if el.tag.endswith("text")]
    assert texts.count("head: pointing_head") == 254

    from pycram.trace.pictures import _rows_for_timeline

    rows, left_out = _rows_for_timeline(query.tasks(1, db), max_rows=200)
    assert left_out == 0 and [n.count for n, _ in rows if n.record.name == "head: pointing_head"] == [250, 1, 3]
    png = tmp_path / "timeline.png"
    assert _invoke("timeline", "-o", str(png)).exit_code == 0 and png.stat().st_size > 1000


def test_db_option_names_the_database(tmp_path, plan_file, monkeypatch):
    monkeypatch.delenv("PYCRAM_RECORD", raising=False)
    monkeypatch.setenv("PYCRAM_DB_URL", f"sqlite:///{tmp_path / 'env.sqlite3'}")
    other = tmp_path / "other.sqlite3"
    assert (
        _invoke("run", str(plan_file), "--db", f"sqlite:///{other}", "--plan", "by option", "--robot", "pr2").exit_code
        == 0
    )
    assert other.exists() and not (tmp_path / "env.sqlite3").exists()
    line = _invoke("runs", "--db", str(other)).output.splitlines()[1]  # a bare path works too
    fields = [field.strip() for field in line.split("  ") if field.strip()]
    assert fields[0] == "1" and fields[2:5] == ["by option", "pr2", "succeeded"]
    assert "no runs recorded" in _invoke("runs").output  # $PYCRAM_DB_URL: nothing there
    assert not (tmp_path / "env.sqlite3").exists()  # reading created nothing


# -- SIGINT / SIGTERM end `pycram run` as "interrupted" (issue 12, point 6) -------------------------

WAITING_PLAN = """
from pycram.language import par
from pycram.runtime import sleep

def wait_long():
    print("branch waiting", flush=True)
    sleep(600)

par(wait_long, wait_long)
"""


@pytest.mark.parametrize(
    "signame, code, reason",
    [("SIGINT", 130, "interrupted by Ctrl-C (SIGINT)"), ("SIGTERM", 143, "terminated by SIGTERM")],
)
def test_run_ends_as_interrupted_on_a_signal(tmp_path, signame, code, reason):
    """The script waits in two `par` branches; the signal stops it (its branches end too), the
    run is recorded as interrupted with the reason, the exit code is 128 + signal, one line says
    why, no traceback; no task of the run is left "running" (the main thread's root included)."""
    import signal

    from signal_helpers import Command

    from pycram.trace import query

    script = tmp_path / "waiting.py"
    script.write_text(WAITING_PLAN)
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    run = Command(["run", str(script)], db, tmp_path)
    run.wait_for_line("branch waiting")
    run.send(getattr(signal, signame))
    assert run.wait(60) == code, run.output
    assert f"pycram run: {reason}; the script was stopped" in run.stderr and "Traceback" not in run.output
    (info,) = query.runs(db)
    assert info.outcome == "interrupted" and info.error == reason
    tasks = query.tasks(info.id, db)
    assert [t.status for t in tasks if t.kind == "branch"] == ["evaporated", "evaporated"]
    assert not [t.name for t in tasks if t.status == "running"]
