"""Running `pycram` in a child process for the view's tests (a fresh process per run: the
view's hooks, logging handler and threads start and end with it)."""

from __future__ import annotations

import os
import signal
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


def interrupt(child: subprocess.Popen[str], timeout: float = 60.0) -> int:
    """Ctrl-C for a `pycram` child that keeps serving its view; its exit code. A child still
    running after `timeout` [s] is killed (its view server and workers end with it) and the test
    fails: it never outlives the test, holding a core."""
    if child.poll() is None:
        child.send_signal(signal.SIGINT)
    try:
        return child.wait(timeout)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()
        raise AssertionError(f"`pycram` did not stop within {timeout} s of Ctrl-C; killed") from None
