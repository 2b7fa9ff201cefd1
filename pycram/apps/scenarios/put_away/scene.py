"""The put-away scene: the groceries anywhere on the kitchen's worktops where the robot reaches
them, each to go into the containers its type is put away in (milk: the fridge; cereal: the
cupboard)."""

from __future__ import annotations

from collections.abc import Sequence

from pycram.apps.scenarios.common.scene import TaskScene, put_away_scene
from pycram.apps.scenarios.put_away.data import ALLOWED, OBJECTS, SOURCE_KINDS
from pycram.world.environment import Environment

__all__ = ["start_scene"]


def start_scene(environment: Environment, seed: int, robot: str, objects: Sequence[str] | None = None) -> TaskScene:
    """The scene of `seed` for `robot`: `objects` (default `OBJECTS`; any of `ALLOWED`) at spots
    drawn uniformly over the kitchen's worktops (the counters, the cabinet top, the cookers),
    where some standing pose of `robot` grasps them, each to go into the containers its type is
    put away in (`put_away_scene`). Raises `ValueError` for an unknown object type."""
    return put_away_scene(
        environment, seed, robot, OBJECTS if objects is None else objects, ALLOWED, SOURCE_KINDS, "put-away"
    )
