"""An experiment's local worker ends when its driver dies, however it dies (a ``kill -9``d driver
left its worker running its run to the end, a core taken for many minutes)."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not hasattr(os, "pidfd_open"), reason="waits on the worker with a pidfd (Linux)")

DRIVER = textwrap.dedent(
    """
    import multiprocessing, os, threading
    from concurrent.futures import ProcessPoolExecutor
    from pycram.apps.experiments.runner import _worker_init

    def report_and_wait():
        print(os.getpid(), flush=True)
        threading.Event().wait()  # a run that does not end on its own

    if __name__ == "__main__":
        pool = ProcessPoolExecutor(
            1, mp_context=multiprocessing.get_context("spawn"), initializer=_worker_init, initargs=(os.getpid(),)
        )
        pool.submit(report_and_wait)
        threading.Event().wait()
    """
)


def _ended_within(pid: int, seconds: float) -> bool:
    """Whether process `pid` (not a child of this one) ends within `seconds`: waits on its pidfd."""
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        readable, _, _ = select.select([fd], [], [], seconds)
        return bool(readable)
    finally:
        os.close(fd)


def test_a_worker_ends_when_its_driver_is_killed(tmp_path: Path) -> None:
    script = tmp_path / "driver.py"
    script.write_text(DRIVER)
    driver = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, cwd=tmp_path)
    worker = None
    try:
        assert driver.stdout is not None
        line = driver.stdout.readline()  # the worker's pid, once it runs its task
        assert line.strip().isdigit(), f"the worker did not report: {line!r}"
        worker = int(line)
        driver.kill()
        driver.wait(timeout=30)
        assert _ended_within(worker, 30), "the worker outlived its killed driver"
        worker = None
    finally:
        if driver.poll() is None:
            driver.kill()
            driver.wait()
        if worker is not None:
            try:
                os.kill(worker, signal.SIGKILL)
            except ProcessLookupError:
                pass
