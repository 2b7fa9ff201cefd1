"""Running `pycram` in a child process for the view's tests (a fresh process per run: the
view's hooks, logging handler and threads start and end with it)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def pycram_env() -> dict[str, str]:
    """The environment of a child `pycram`: headless rendering, this checkout first."""
    env = dict(os.environ)
    env.setdefault("MUJOCO_GL", "egl")
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    env["COLUMNS"] = "200"
    return env


def run_pycram(args: list[str], cwd: Path, timeout: float = 280.0) -> subprocess.CompletedProcess[str]:
    """`pycram ARGS` in `cwd`, to its end; its output is returned."""
    return subprocess.run(
        [sys.executable, "-m", "pycram.apps.cli", *args],
        cwd=cwd,
        env=pycram_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )
