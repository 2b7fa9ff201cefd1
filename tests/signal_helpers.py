"""Helpers of the signal tests: a `pycram` command in a subprocess whose output is read line by
line, so that a test can send a signal once the run has reached a known point (a line it
printed), with a time-out — never after a guessed delay."""

from __future__ import annotations

import os
import queue
import re
import subprocess
import sys
import threading
from pathlib import Path


class Command:
    """`python -m pycram ARGS` with `$PYCRAM_DB_URL` set to `db`; stdout and stderr are read
    by threads of their own (both kept whole in `stdout` / `stderr`)."""

    def __init__(self, args: list[str], db: str, cwd: Path) -> None:
        env = dict(
            os.environ,
            PYCRAM_DB_URL=db,
            PYTHONUNBUFFERED="1",
            COLUMNS="200",
            MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"),
        )
        self.process = subprocess.Popen(
            [sys.executable, "-m", "pycram", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            cwd=cwd,
        )
        self._lines: queue.SimpleQueue[str | None] = queue.SimpleQueue()
        self._out: list[str] = []
        self._err: list[str] = []
        self._readers = [
            threading.Thread(target=self._read, args=(self.process.stdout, self._out), daemon=True),
            threading.Thread(target=self._read, args=(self.process.stderr, self._err), daemon=True),
        ]
        for reader in self._readers:
            reader.start()

    def _read(self, stream, lines: list[str]) -> None:
        for line in stream:
            lines.append(line)
            self._lines.put(line)
        self._lines.put(None)

    def wait_for_line(self, pattern: str, timeout: float = 120.0) -> str:
        """The first line (of either stream) from now on matching `pattern`; fails after
        `timeout` [s] or when the process ended without printing it."""
        ended = 0
        while True:
            try:
                line = self._lines.get(timeout=timeout)
            except queue.Empty:
                self.process.kill()
                raise AssertionError(f"no line matching {pattern!r} within {timeout} s:\n{self.output}") from None
            if line is None:
                ended += 1
                if ended == 2:
                    raise AssertionError(f"the process ended without a line matching {pattern!r}:\n{self.output}")
                continue
            if re.search(pattern, line):
                return line

    def send(self, signum: int) -> None:
        self.process.send_signal(signum)

    def wait(self, timeout: float = 120.0) -> int:
        """Wait for the process to exit (killing it after `timeout` [s]); its exit code."""
        try:
            code = self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            raise AssertionError(f"the process did not exit within {timeout} s:\n{self.output}") from None
        for reader in self._readers:
            reader.join(10.0)
        return code

    @property
    def stdout(self) -> str:
        return "".join(self._out)

    @property
    def stderr(self) -> str:
        return "".join(self._err)

    @property
    def output(self) -> str:
        return f"--- stdout\n{self.stdout}\n--- stderr\n{self.stderr}"
