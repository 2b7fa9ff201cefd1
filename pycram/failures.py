"""Failures with meaning, after CRAM's taxonomy: what went wrong, about which designator, why.

Plans catch these by kind (``except ObjectNotFound``); each carries the designator it is about
and the reason as data. Stdlib only.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

__all__ = ["ObjectNotFound", "PerceptionFailure", "PlanFailure"]


class PlanFailure(Exception):
    """Base class of the failures plans raise and handle. ``designator``: what it is about."""

    def __init__(self, message: str, designator: Any = None) -> None:
        super().__init__(message)
        self.designator = designator


class PerceptionFailure(PlanFailure):
    """Perception did not deliver what the plan needed."""


class ObjectNotFound(PerceptionFailure):
    """A search did not find an object matching ``designator``; ``looked`` names every place it
    looked at (in order) and ``skipped`` the places it could not look into, with the reason."""

    def __init__(self, designator: Any, looked: Sequence[str], skipped: Sequence[tuple[str, str]] = ()) -> None:
        self.looked = list(looked)
        self.skipped = list(skipped)
        message = f"no object matching {designator!r} found; looked at: {', '.join(self.looked) or 'nothing'}"
        if self.skipped:
            message += "; could not look into: " + ", ".join(f"{p} ({why})" for p, why in self.skipped)
        super().__init__(message, designator)
