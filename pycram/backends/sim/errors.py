"""Exceptions of the simulated world."""

from __future__ import annotations

from pycram.world.errors import UnknownNameError as WorldUnknownNameError


class SimulationError(Exception):
    """Base class of every error raised by `pycram.sim`."""


class UnknownNameError(SimulationError, WorldUnknownNameError):
    """A name (item, arm, gripper, camera, configuration ...) that does not exist.

    The message lists the valid choices.
    """


class WorldClosedError(SimulationError):
    """The world has been closed (or its simulation thread died); no more commands are accepted."""


class CommandFailed(SimulationError):
    """A command ended without success; `outcome` tells why."""

    def __init__(self, outcome: object) -> None:
        self.outcome = outcome
        super().__init__(f"{getattr(outcome, 'reason', '?')}: {getattr(outcome, 'message', '')}")
