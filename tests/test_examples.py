"""Every script in examples/ runs as the README tells users to run it (`python -m pycram FILE`,
the same as `pycram run FILE` without recording), in a fresh interpreter, headless, and prints
(or logs) what it promises. A new example must be added to EXPECTED."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"

#: example (with arguments) -> lines its log must contain
EXPECTED = {
    "language_tour.py": ["driving: State.SUCCEEDED", "placed the item on try 3"],
    "first_plan_on_sim.py": ["saw the mug (mug-1) at (0.1", "holding the mug", "back at the start with the mug"],
    "first_plan_on_sim.py tiago": ["saw the mug (mug-1) at (0.1", "holding the mug", "back at the start with the mug"],
    "fetch_and_place_actions.py": ["the pr2 put the mug down at -0.7", "on cooker #1"],
    "fetch_and_place_actions.py tiago": ["the tiago put the mug down at -0.7", "on cooker #1"],
    "custom_robot.py": ["toy base: stopped at (0.", "toy base at (0.50, 0.50); the gripper closed at 0.03 m"],
}


def test_every_example_is_run():
    assert {name.split()[0] for name in EXPECTED} == {p.name for p in EXAMPLES.glob("*.py")}


@pytest.mark.parametrize("example", sorted(EXPECTED))
def test_example_runs(example, tmp_path):
    name, *args = example.split()
    env = dict(os.environ, PYTHONPATH=str(REPO), PYCRAM_RECORD="0")
    env.setdefault("MUJOCO_GL", "egl")
    out = subprocess.run(
        [sys.executable, "-m", "pycram", str(EXAMPLES / name), *args],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=300,
    )
    assert out.returncode == 0, f"stdout:\n{out.stdout}\nstderr:\n{out.stderr}"
    for line in EXPECTED[example]:
        assert line in out.stderr + out.stdout, out.stderr + out.stdout
