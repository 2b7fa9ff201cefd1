"""Ending a run on SIGINT (Ctrl-C) or SIGTERM: `StopSignals`, used by `pycram run` and `pycram demo`.

Inside `with StopSignals() as stop:` (main thread only; elsewhere it does nothing):

- the first SIGINT or SIGTERM is recorded in `stop` (`stop.signum`, `stop.reason`,
  `stop.exit_code`: 130 for SIGINT, 143 for SIGTERM, as a shell reports them) and sets
  `stop.event`; with `stop_main=True` it also stops what the main thread runs, so that a script
  stops where it is and its `finally` blocks and PyCRAM's clean-up run: in plain Python code it
  raises `Interrupted` (a `KeyboardInterrupt`) there, as Ctrl-C does by default; inside PyCRAM
  (waiting in an expression, or in the runtime's own bookkeeping, where an exception landing at
  an arbitrary point could leave a branch behind) it evaporates the main thread's task tree
  instead, which PyCRAM delivers as `Evaporated` at a safe point, after stopping every branch;
- a second one while the run is stopping ends the process at once with the first signal's exit
  code, after one line on stderr (`os._exit`: no clean-up, no traceback — and no thread that could
  crash while the interpreter shuts down).

On leaving the block the previous handlers are restored. Installing handlers is never done at
import time (the library has no import-time side effects).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any

__all__ = ["Interrupted", "StopSignals", "signal_reason", "exit_code_of"]

#: The signals that end a run, and how a person would call them.
_DESCRIPTIONS = {signal.SIGINT: "Ctrl-C (SIGINT)", signal.SIGTERM: "SIGTERM"}


def signal_reason(signum: int) -> str:
    """'interrupted by Ctrl-C (SIGINT)' / 'terminated by SIGTERM' for `signum`."""
    verb = "interrupted" if signum == signal.SIGINT else "terminated"
    return f"{verb} by {_DESCRIPTIONS.get(signal.Signals(signum), signal.Signals(signum).name)}"


def exit_code_of(signum: int) -> int:
    """The exit code a shell reports for a process ended by `signum` (128 + signum)."""
    return 128 + int(signum)


class Interrupted(KeyboardInterrupt):
    """A run was stopped by a signal: `signum`, `reason` (one line), `exit_code` (128 + signum)."""

    def __init__(self, signum: int) -> None:
        self.signum = int(signum)
        self.reason = signal_reason(signum)
        self.exit_code = exit_code_of(signum)
        super().__init__(self.reason)


class StopSignals:
    """Handle SIGINT and SIGTERM as a request to stop the run (see the module docstring).

    `on_second`: called (in the main thread, from the signal handler) before the process exits
    on a second signal, e.g. to restore the terminal; it must be quick.
    """

    def __init__(self, stop_main: bool = False, on_second: Callable[[], Any] | None = None) -> None:
        self.stop_main = stop_main
        self.on_second = on_second
        self.event = threading.Event()
        self.signum: int | None = None
        self._previous: dict[int, Any] = {}
        self._main_runner: Any = None
        self._evaporate_main = threading.Event()
        self._stopper: threading.Thread | None = None

    @property
    def requested(self) -> bool:
        """True once a stop signal arrived."""
        return self.event.is_set()

    @property
    def reason(self) -> str:
        """Why the run stops ('interrupted by Ctrl-C (SIGINT)'), or '' while no signal arrived."""
        return signal_reason(self.signum) if self.signum is not None else ""

    @property
    def exit_code(self) -> int:
        """130 (SIGINT) or 143 (SIGTERM) once a signal arrived, else 0."""
        return exit_code_of(self.signum) if self.signum is not None else 0

    def request(self, signum: int) -> None:
        """Record a stop request as if `signum` had arrived (the first one counts)."""
        if self.signum is None:
            self.signum = int(signum)
        self.event.set()

    def __enter__(self) -> StopSignals:
        if threading.current_thread() is not threading.main_thread():
            return self
        if self.stop_main:
            from pycram.core.runtime.evaporation import current_runner

            self._main_runner = current_runner()
            # Started now, not from the handler: a handler must not start threads (the main
            # thread may be inside `Thread.start` itself, holding the lock that needs).
            self._stopper = threading.Thread(target=self._stop_main_tasks, name="pycram-stop-signals", daemon=True)
            self._stopper.start()
        for signum in _DESCRIPTIONS:
            self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        previous, self._previous = self._previous, {}
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if self._stopper is not None:
            self._evaporate_main.set()  # ends the stopper (it evaporates nothing once we left)
            self._stopper.join()
            self._stopper = None

    def _stop_main_tasks(self) -> None:
        """The stopper thread: once asked, evaporate the main thread's task tree (from its root)."""
        self._evaporate_main.wait()
        if self._previous:  # still inside the block: a signal asked for it
            task = self._main_runner.task
            while task is not None and task.parent is not None:
                task = task.parent
            if task is not None:
                task.evaporate()

    def _in_plain_code(self) -> bool:
        """True when the main thread (running this handler) is in neither PyCRAM's waits nor
        its bookkeeping, nor protected from evaporation: an exception may land here."""
        from pycram.core.runtime.evaporation import _USER

        runner = self._main_runner
        return runner is None or runner.task is None or (runner._mode == _USER and not runner._protected)

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.signum is not None:  # a second signal while stopping: leave at once
            try:
                if self.on_second is not None:
                    self.on_second()
                sys.stdout.flush()
                sys.stderr.write(
                    f"\npycram: {signal_reason(signum)} again while stopping; exiting at once "
                    f"(pictures and trace may be incomplete)\n"
                )
                sys.stderr.flush()
            finally:
                os._exit(self.exit_code)
        self.request(signum)
        if self.stop_main:
            if self._in_plain_code():
                raise Interrupted(signum)
            self._evaporate_main.set()
