"""Exceptions of the simulated world."""

from __future__ import annotations

from typing import Iterable


class SimulationError(Exception):
    """Base class of every error raised by `pycram.sim`."""


class UnknownNameError(SimulationError, KeyError):
    """A name (item, arm, gripper, camera, configuration ...) that does not exist.

    The message lists the valid choices.
    """

    def __init__(self, kind: str, name: object, choices: Iterable[str]) -> None:
        self.kind, self.name, self.choices = kind, name, sorted(choices)
        super().__init__(f"{kind} {name!r} does not exist. Available: {', '.join(self.choices)}")

    def __str__(self) -> str:  # KeyError would repr() the message
        return self.args[0]


class WorldClosedError(SimulationError):
    """The world has been closed (or its simulation thread died); no more commands are accepted."""


class CommandFailed(SimulationError):
    """A command ended without success; `outcome` tells why."""

    def __init__(self, outcome: object) -> None:
        self.outcome = outcome
        super().__init__(f"{getattr(outcome, 'reason', '?')}: {getattr(outcome, 'message', '')}")
