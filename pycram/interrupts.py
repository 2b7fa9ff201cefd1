"""Ending a run on SIGINT (Ctrl-C) or SIGTERM: `StopSignals`, used by `pycram run` and `pycram demo`.

Inside `with StopSignals() as stop:` (main thread only; elsewhere it does nothing):

- the first SIGINT or SIGTERM is recorded in `stop` (`stop.signum`, `stop.reason`,
  `stop.exit_code`: 130 for SIGINT, 143 for SIGTERM, as a shell reports them) and sets
  `stop.event`; with `raise_in_main=True` it also raises `Interrupted` (a `KeyboardInterrupt`)
  in the main thread, as Ctrl-C does by default, so that a script stops where it is and its
  `finally` blocks and PyCRAM's clean-up run;
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
from types import FrameType
from typing import Any, Callable

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

    def __init__(self, raise_in_main: bool = False, on_second: Callable[[], Any] | None = None) -> None:
        self.raise_in_main = raise_in_main
        self.on_second = on_second
        self.event = threading.Event()
        self.signum: int | None = None
        self._previous: dict[int, Any] = {}

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
        if threading.current_thread() is threading.main_thread():
            for signum in _DESCRIPTIONS:
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        previous, self._previous = self._previous, {}
        for signum, handler in previous.items():
            signal.signal(signum, handler)

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.signum is not None:  # a second signal while stopping: leave at once
            try:
                if self.on_second is not None:
                    self.on_second()
                sys.stdout.flush()
                sys.stderr.write(f"\npycram: {signal_reason(signum)} again while stopping; exiting at once "
                                 f"(pictures and trace may be incomplete)\n")
                sys.stderr.flush()
            finally:
                os._exit(self.exit_code)
        self.request(signum)
        if self.raise_in_main:
            raise Interrupted(signum)
