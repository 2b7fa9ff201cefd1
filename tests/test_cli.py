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

from pycram.cli import app  # noqa: E402

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


def test_run_records_by_default_and_inspection_commands(db, plan_file, tmp_path):
    result = _invoke("run", str(plan_file), "x", "--y")
    assert result.exit_code == 0, result.output
    assert "script args ['x', '--y']" in result.output
    result = _invoke("run", str(plan_file), "--fail")
    assert result.exit_code == 3

    result = _invoke("runs")
    assert result.exit_code == 0
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 2
    assert lines[0].startswith("2 ") and "plan.py" in lines[0] and "failed" in lines[0]
    assert lines[1].startswith("1 ") and "succeeded" in lines[1]

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
    assert _invoke("runs").output.startswith("1 ")


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

    fake = types.ModuleType("pycram.demos.kitchen")
    fake.main = fake_main
    monkeypatch.setitem(sys.modules, "pycram.demos.kitchen", fake)
    result = _invoke("demo", "--robot", "tiago", "--output", "out", "--item-at", "2", "--steal", "1",
                     "--seed", "7", "--realtime", "--db", "sqlite:///x.sqlite3", "--no-record")
    assert result.exit_code == 0, result.output
    assert calls == dict(robot="tiago", output="out", item_at=2, steal=1, seed=7, realtime=True,
                         interactive=False, db="sqlite:///x.sqlite3", record=False)
    monkeypatch.setenv("PYCRAM_RECORD", "0")
    _invoke("demo")
    assert calls["record"] is False and calls["robot"] == "pr2"
    monkeypatch.delenv("PYCRAM_RECORD")
    _invoke("demo")
    assert calls["record"] is True


def test_demo_missing_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "pycram.demos.kitchen", None)
    result = _invoke("demo")
    assert result.exit_code == 1
    assert "kitchen demo" in result.output


def test_console_script_subprocess(tmp_path, plan_file):
    env = dict(os.environ, PYCRAM_DB_URL=f"sqlite:///{tmp_path / 'sub.sqlite3'}")
    env.pop("PYCRAM_RECORD", None)
    exe = Path(sys.executable).with_name("pycram")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "pycram"]
    out = subprocess.run([*command, "run", str(plan_file)], capture_output=True, text=True, env=env,
                         cwd=REPO, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "recorded as run 1" in out.stderr
    out = subprocess.run([*command, "runs"], capture_output=True, text=True, env=env, cwd=REPO, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("1 "), out.stderr
