"""Failure messages a new user can act on (issue 33, section 4): what failed, why and what to
try in at most two short lines; the nested detail only with ``--verbose`` and in the trace."""

from __future__ import annotations

import inspect
import os
import subprocess
import sys
from pathlib import Path

import pytest

from pycram.apps.terminal import failure_hint, failure_text
from pycram.designators.core import NoSolutionError
from pycram.execution import failures
from pycram.execution.failures import (
    SUMMARY_LINE,
    GraspFailed,
    ObjectOutOfReach,
    PlacingFailed,
    PlanFailure,
    SimulationFault,
    failure_summary,
    innermost_clause,
)
from pycram.execution.process_module import ProcessModuleFailure

REPO = Path(__file__).resolve().parents[1]

#: A resolution that failed three layers deep, as location reasoning reports it (one layer per
#: designator, each repeating the designator's properties).
_DESIGNATOR = "LocationDesignator([(to_reach, cup-1), (arm, 'left'), (grasp, 'side'), (torso, [0.1, 0.2, 0.3])])"
NESTED = (
    f"Cannot resolve location designator {_DESIGNATOR}: "
    f"Cannot resolve {_DESIGNATOR}: "
    f"Cannot resolve {_DESIGNATOR}: "
    "gave up after 100 consecutive candidates rejected by validators ['reachable', 'collision_free'] "
    "(last generator reach_costmap)"
)


def _out_of_reach() -> ObjectOutOfReach:
    cause = NoSolutionError(NESTED + " " + "x" * 2000)
    try:
        try:
            raise cause
        except NoSolutionError as error:
            raise ObjectOutOfReach(f"no standing pose from which the robot can grasp cup-1: {error}") from error
    except ObjectOutOfReach as failure:
        return failure


def test_the_summary_is_two_short_lines_with_the_cause_and_a_hint():
    failure = _out_of_reach()
    assert len(str(failure)) > 2000
    text = failure_summary(failure)
    lines = text.split("\n")
    assert len(lines) == 2 and all(len(line) <= SUMMARY_LINE for line in lines), text
    assert lines[0].startswith("ObjectOutOfReach (out_of_reach): no standing pose from which the robot can grasp cup-1")
    assert "Cannot resolve" not in text  # none of the nested layers
    assert "try: out of reach from every standing pose tried: try another grasp" in lines[1]
    assert failure.summary() == text


def test_the_innermost_cause_of_a_process_module_failure_is_named():
    inner = failures.MotionFailure("reach:left failed: collision: the forearm touches 'counter'", reason="collision")
    wrapped = ProcessModuleFailure("arm module failed to execute MotionDesignator(...)", cause=inner)
    outer = GraspFailed("could not pick up cup-1 after 2 attempts: " + "; ".join(["from (1.00, 2.00): blocked"] * 40))
    outer.__cause__ = wrapped
    text = failure_summary(outer)
    assert len(text.split("\n")) == 2 and len(text) <= 2 * SUMMARY_LINE + 3
    assert "cause: reach:left failed: collision: the forearm touches 'counter'" in text
    assert "try another grasp or arm" in text


def test_innermost_clause_keeps_what_failed_and_drops_every_resolve_layer():
    assert innermost_clause("ObjectOutOfReach: " + NESTED + "\nmore") == (
        "ObjectOutOfReach: gave up after 100 consecutive candidates rejected by validators "
        "['reachable', 'collision_free'] (last generator reach_costmap)"
    )


def _typed_failures() -> list[type]:
    return [
        cls
        for _, cls in inspect.getmembers(failures, inspect.isclass)
        if cls.__module__ == failures.__name__ and issubclass(cls, (PlanFailure, SimulationFault))
    ]


@pytest.mark.parametrize("cls", _typed_failures(), ids=lambda c: c.__name__)
def test_every_concrete_typed_failure_says_what_to_try(cls):
    bases = {PlanFailure, failures.ManipulationFailure, failures.PerceptionFailure}
    if cls in bases:
        return
    assert failure_hint(cls.__name__), f"{cls.__name__} has no hint"


def test_placing_failed_hints_follow_the_reason():
    assert "fell over" in PlacingFailed("x", reason="toppled").hint
    assert PlacingFailed("x").hint == PlacingFailed.default_hint
    assert PlacingFailed("x", hint="do this").hint == "do this"


def test_verbose_tells_the_whole_chain():
    failure = _out_of_reach()
    text = failure_text(failure, verbose=True)
    assert str(failure) in text and "caused by NoSolutionError: Cannot resolve location designator" in text
    assert failure_text("a\nb" + "c" * 500, verbose=False) == "a"


def test_a_simulation_fault_passes_every_recovery():
    fault = SimulationFault("cup left the world at t=1.00 s", "cup", "left_world", 1.0, (-97.9, -138.8, 0.4))
    assert not isinstance(fault, Exception)  # `except Exception` / `except PlanFailure` let it pass
    copy = fault.again()
    assert copy is not fault and (str(copy), copy.object, copy.reason, copy.position) == (
        str(fault),
        "cup",
        "left_world",
        (-97.9, -138.8, 0.4),
    )
    assert failure_summary(fault).startswith("SimulationFault (left_world): cup left the world")
    with pytest.raises(ValueError, match="unknown physics fault 'exploded'"):
        SimulationFault("x", "cup", "exploded")


def test_a_failing_demo_prints_two_lines_and_all_of_it_with_verbose(tmp_path):
    """`pycram demo --item-at 0` fails (nothing to grasp at any of the three positions): its
    last line is short; with --verbose it names every attempt."""
    pytest.importorskip("mujoco")
    exe = Path(sys.executable).with_name("pycram")
    cli = [str(exe)] if exe.exists() else [sys.executable, "-m", "pycram.apps.cli"]
    env = dict(os.environ, MUJOCO_GL="egl", PYTHONPATH=str(REPO), COLUMNS="200")

    def run(*extra: str) -> str:
        out = subprocess.run(
            [*cli, "demo", "--item-at", "0", "--no-record", "--no-animation", "-q", "-o", str(tmp_path), *extra],
            capture_output=True,
            text=True,
            env=env,
            cwd=tmp_path,
            timeout=600,
        )
        assert out.returncode == 1, out.stderr[-2000:]
        return out.stdout[out.stdout.rindex("FAILURE") :]

    short, full = run(), run("--verbose")
    assert len(short.strip().split("\n")) <= 2 and len(short) <= 2 * SUMMARY_LINE + 20, short
    assert short.startswith("FAILURE: NoItemGrasped: could not grasp an item")
    third = "no item at (0.40, -1.15, 0.95)"  # the last of the three attempts
    assert third not in short and third in full
