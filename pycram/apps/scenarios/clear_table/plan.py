"""The clear-table plan: every object from the table into one of the containers it belongs in,
then every container closed -- `pycram.apps.scenarios.common.plan.put_away`, robot-agnostic."""

from __future__ import annotations

from typing import Any

from pycram.apps.scenarios.common.plan import ErrandOutcome, put_away
from pycram.apps.scenarios.common.scene import Goal

__all__ = ["clear_table"]


def clear_table(goals: list[Goal], record: Any = None) -> list[ErrandOutcome]:
    """Put each object of `goals` into its first container (a drawer: the highest first; the
    next one after a failure there), close every container opened; one outcome per object."""
    return put_away(goals, record)
