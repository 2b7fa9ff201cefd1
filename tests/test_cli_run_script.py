"""`pycram run FILE` and `python -m pycram FILE` behave like `python FILE` for the script: it
configures logging itself, and its errors are reported from its own first frame (real
subprocesses; the output is what a user sees)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

FAILING_SCRIPT = """\
import logging
from pycram.language import seq

logging.basicConfig(level=logging.INFO, format="%(message)s")
logging.getLogger("my plan").info("starting the plan")

class GraspFailed(Exception):
    pass

def grasp():
    raise GraspFailed("nothing between the fingers")

def fetch():
    grasp()

seq(lambda: None)
fetch()
"""


def _commands(tmp_path: Path) -> dict[str, list[str]]:
    exe = Path(sys.executable).with_name("pycram")
    cli = [str(exe)] if exe.exists() else [sys.executable, "-m", "pycram.apps.cli"]
    return {"pycram run": [*cli, "run", "--no-record"], "python -m pycram": [sys.executable, "-m", "pycram"]}


def _run(command: list[str], *args: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(REPO), PYCRAM_DB_URL=f"sqlite:///{tmp_path / 'runs.sqlite3'}")
    env.pop("PYCRAM_RECORD", None)
    return subprocess.run([*command, *args], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120)


@pytest.mark.parametrize("how", ["pycram run", "python -m pycram"])
def test_the_script_configures_logging(how, tmp_path):
    """examples/language_tour.py logs at INFO with its own basicConfig: every line shows."""
    out = _run(_commands(tmp_path)[how], str(REPO / "examples" / "language_tour.py"), tmp_path=tmp_path)
    assert out.returncode == 0, out.stderr
    for line in (
        "driving: State.SUCCEEDED",
        "grasping: State.SUCCEEDED after 1 failed attempt(s)",
        "placed the item on try 3",
        "park arms",
    ):
        assert line in out.stderr, out.stderr
    assert not out.stderr.startswith("INFO "), "the CLI's format must not replace the script's"


@pytest.mark.parametrize("how", ["pycram run", "python -m pycram"])
def test_a_scripts_traceback_starts_at_the_scripts_code(how, tmp_path):
    script = tmp_path / "my_plan.py"
    script.write_text(FAILING_SCRIPT)
    out = _run(_commands(tmp_path)[how], str(script), tmp_path=tmp_path)
    assert out.returncode == 1
    assert "starting the plan" in out.stderr  # the script's own logging
    report = out.stderr[out.stderr.index("Traceback (most recent call last):") :]
    files = re.findall(r'^  File "([^"]+)", line (\d+), in (\S+)', report, flags=re.MULTILINE)
    assert files == [(str(script), "17", "<module>"), (str(script), "14", "fetch"), (str(script), "11", "grasp")], (
        report
    )
    assert report.rstrip().endswith("GraspFailed: nothing between the fingers")
    for internal in ("typer", "click", "cli.py", "macros.py", "runpy"):
        assert internal not in report, report


def test_a_syntax_error_is_reported_like_python_does(tmp_path):
    script = tmp_path / "broken.py"
    script.write_text("from pycram.language import par\n\nx = (\n")
    out = _run(_commands(tmp_path)["pycram run"], str(script), tmp_path=tmp_path)
    assert out.returncode == 1
    assert "Traceback" not in out.stderr, out.stderr
    assert f'File "{script}", line 3' in out.stderr and "SyntaxError" in out.stderr


def test_a_failed_script_is_still_recorded_with_its_error(tmp_path):
    script = tmp_path / "my_plan.py"
    script.write_text(FAILING_SCRIPT)
    cli = _commands(tmp_path)["pycram run"][:-2]
    out = _run([*cli, "run"], str(script), tmp_path=tmp_path)
    assert out.returncode == 1
    assert "recorded as run 1 (failed)" in out.stderr
    runs = _run([*cli, "show", "1"], tmp_path=tmp_path)
    assert runs.returncode == 0, runs.stderr
    assert "GraspFailed: nothing between the fingers" in runs.stdout
