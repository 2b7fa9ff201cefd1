"""The clear-table scene: the objects anywhere on the table where the robot reaches them, each
to go into the containers its type is put away in."""

from __future__ import annotations

from collections.abc import Sequence

from pycram.apps.scenarios.clear_table.data import ALLOWED, OBJECTS, SOURCE_KINDS
from pycram.apps.scenarios.common.scene import TaskScene, put_away_scene
from pycram.world.environment import Environment

__all__ = ["start_scene"]


def start_scene(environment: Environment, seed: int, robot: str, objects: Sequence[str] | None = None) -> TaskScene:
    """The scene of `seed` for `robot`: `objects` (default `OBJECTS`; any of `ALLOWED`) at spots
    drawn uniformly over the whole table, where some standing pose of `robot` grasps them, each
    to go into the containers its type is put away in (`put_away_scene`). Raises `ValueError`
    for an unknown object type."""
    return put_away_scene(
        environment, seed, robot, OBJECTS if objects is None else objects, ALLOWED, SOURCE_KINDS, "clear-table"
    )
