"""`pycram run --verbose` (issue 33, section 4): a plan script's typed failure ends its traceback in
two short lines (what failed, why, what to try) without the nested causes; with --verbose the
whole traceback, every cause and every attempt (real subprocesses: what a user sees)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from pycram.execution.failures import SUMMARY_LINE

REPO = Path(__file__).resolve().parent.parent

#: A plan script whose grasp fails three resolution layers deep, after two attempts.
SCRIPT = """\
from pycram.designators import NoSolutionError
from pycram.failures import ObjectOutOfReach

NESTED = "Cannot resolve location designator LocationDesignator([(to_reach, cup-1)]): " * 12

def reach():
    raise NoSolutionError(NESTED + "gave up after 100 candidates rejected by validators ['reachable']")

def grasp():
    try:
        reach()
    except NoSolutionError as error:
        raise ObjectOutOfReach(
            f"no standing pose from which the robot can grasp cup-1: {error}",
            attempts=["from the north: arm 'left' out of reach", "from the east: base in collision"],
        ) from error

grasp()
"""


def _run(script: Path, *options: str) -> subprocess.CompletedProcess:
    """`pycram run --no-record [options] script`."""
    exe = Path(sys.executable).with_name("pycram")
    cli = [str(exe)] if exe.exists() else [sys.executable, "-m", "pycram.apps.cli"]
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return subprocess.run(
        [*cli, "run", "--no-record", *options, str(script)],
        capture_output=True,
        text=True,
        env=env,
        cwd=script.parent,
        timeout=120,
    )


def test_a_typed_failure_ends_in_two_lines_and_verbose_tells_all_of_it(tmp_path):
    script = tmp_path / "fetch_cup.py"
    script.write_text(SCRIPT)
    short = _run(script)
    assert short.returncode == 1, short.stderr
    report = short.stderr[short.stderr.index("Traceback (most recent call last):") :]
    assert f'File "{script}", line 18, in <module>' in report  # the script's frames
    lines = report.rstrip("\n").split("\n")
    assert lines[-3].startswith("ObjectOutOfReach (out_of_reach): no standing pose from which the robot can grasp")
    assert lines[-2].startswith("  try: ") and all(len(line) <= SUMMARY_LINE for line in lines[-3:-1]), lines[-3:]
    assert lines[-1] == "(its causes in full: pycram run --verbose, or `pycram show RUN` for a recorded run)"
    assert "Cannot resolve location designator" not in report and "NoSolutionError" not in report, report
    assert "from the east" not in report

    full = _run(script, "--verbose")
    assert full.returncode == 1, full.stderr
    assert "The above exception was the direct cause of the following exception" in full.stderr
    assert full.stderr.count("Cannot resolve location designator") >= 24  # the whole message, in both
    assert "caused by NoSolutionError: Cannot resolve location designator" in full.stderr
    assert "attempt 2: from the east: base in collision" in full.stderr


def test_a_plain_python_error_is_reported_as_python_does_with_or_without_verbose(tmp_path):
    script = tmp_path / "plain.py"
    script.write_text("import pycram.language\n\nraise KeyError('cup-1')\n")
    for options in ((), ("--verbose",)):
        out = _run(script, *options)
        assert out.returncode == 1, out.stderr
        assert out.stderr.rstrip().endswith("KeyError: 'cup-1'"), out.stderr
        assert "the whole failure" not in out.stderr and "--verbose" not in out.stderr
