"""The serve scene: the requested objects anywhere on the kitchen's worktops where the robot
reaches them, to be brought to the table at the seat."""

from __future__ import annotations

import random
from collections.abc import Sequence

from pycram.apps.scenarios.common.scene import (
    Goal,
    TaskScene,
    check_types,
    draw_starts,
    open_surfaces,
    reachability,
    seat_point,
)
from pycram.apps.scenarios.serve.data import COUNT, INWARD, SEAT, SERVABLE, SOURCE_KINDS
from pycram.world.environment import Environment

__all__ = ["requested", "start_scene"]


def requested(seed: int, objects: Sequence[str] | None = None, count: int = COUNT) -> tuple[str, ...]:
    """The object types asked for: `objects` when given (checked: each of `SERVABLE`, at most
    once), else `count` of `SERVABLE` drawn from `seed`. Raises `ValueError` for an unknown type,
    a repeated one, or a `count` below 1 or above ``len(SERVABLE)``."""
    if objects is not None:
        return check_types(objects, SERVABLE, "serve")
    if not isinstance(count, int) or not 1 <= count <= len(SERVABLE):
        raise ValueError(
            f"serve: cannot bring {count!r} objects; ask for 1 to {len(SERVABLE)} (one of each of "
            f"{', '.join(SERVABLE)})"
        )
    return tuple(random.Random(f"serve/{seed}/asked").sample(SERVABLE, count))


def start_scene(
    environment: Environment, seed: int, robot: str, objects: Sequence[str] | None = None, count: int = COUNT
) -> TaskScene:
    """The scene of `seed` for `robot`: the `requested` objects at spots drawn uniformly over the
    kitchen's worktops where some standing pose of `robot` grasps them; each goal is the point
    `INWARD` in from the table's edge in front of `SEAT`. The same seed, robot and environment
    give the same scene. Raises `ValueError` for bad requests (see `requested`)."""
    types = requested(seed, objects, count)
    surfaces = open_surfaces(environment, SOURCE_KINDS)
    reach = reachability(robot, environment.name)
    placements, checked = draw_starts(environment, f"serve/{seed}", types, surfaces, reach)
    point = seat_point(environment, SEAT, INWARD)
    goals = [Goal(t, t, seat=SEAT, point=point) for t in types]
    return TaskScene(placements, goals, checked)
