"""Command handles: how a caller follows and stops a command running in the simulation thread."""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable
from typing import Any

from pycram.core.fluent import Fluent
from pycram.world.types import Outcome

from .errors import CommandFailed

_ids = itertools.count(1)


class CommandHandle:
    """A command submitted to a `World`.

    `result` is a Fluent whose value is None while the command runs and an `Outcome` once it has
    ended (succeeded, failed, cancelled, preempted by a newer command on the same part, or the
    world closed). Every method is thread-safe.
    """

    def __init__(self, name: str, canceller: Callable[[CommandHandle], None]) -> None:
        self.id = next(_ids)
        self.name = name
        self.result = Fluent(None, name=f"{name}#{self.id}.result")
        self._canceller = canceller

    @property
    def done(self) -> bool:
        """True once the command has ended."""
        return self.result.get_value() is not None

    @property
    def outcome(self) -> Outcome | None:
        """The outcome, or None while running (never blocks)."""
        return self.result.get_value()

    def cancel(self) -> None:
        """Ask the simulation to stop the command; it ends with reason "cancelled" (no-op if done)."""
        if not self.done:
            self._canceller(self)

    def wait(self, timeout: float | None = None) -> Outcome | None:
        """Block until the command ends or `timeout` [s of the active clock] passes.

        Returns the outcome, or None on time-out. Evaporable like every PyCRAM wait.
        """
        self.result.wait_for(timeout)
        return self.result.get_value()

    def wait_ok(self, timeout: float | None = None) -> Any:
        """Like `wait`, but return the outcome's value on success and raise `CommandFailed` otherwise
        (a time-out raises with reason "timeout")."""
        outcome = self.wait(timeout)
        if outcome is None:
            outcome = Outcome(False, "timeout", f"{self.name} did not end within {timeout} s")
        if not outcome.succeeded:
            raise CommandFailed(outcome)
        return outcome.value

    def _finish(self, outcome: Outcome) -> None:
        if self.result.get_value() is None:
            self.result.set_value(outcome)

    def __repr__(self) -> str:
        return f"<CommandHandle {self.name}#{self.id} {self.outcome!r}>"


def _wait_wall(handle: CommandHandle, timeout: float) -> None:
    """Wait for `handle` by wall time (for blocking conveniences that must not hang on sim time)."""
    deadline = time.monotonic() + timeout
    while not handle.done and time.monotonic() < deadline:
        handle.wait(0.05)  # wakes on completion or after 0.05 s of the active clock
