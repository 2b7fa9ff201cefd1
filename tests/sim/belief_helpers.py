"""Helpers of the belief and perception tests: the apartment with one object of each type,
objects put on surfaces, containers opened by a person's push (test set-up only)."""

from __future__ import annotations

import math

from sim_helpers import ok

from pycram.sim import World
from pycram.world.objects import OBJECT_TYPES, object_type

TYPES = tuple(OBJECT_TYPES)
#: One surface of every kind in the apartment: (surface, spot [m], base pose, container to open).
SURFACES = {
    "counter": ("counter", (1.0, 4.65), (1.0, 3.6, math.pi / 2), None),
    "cooker": ("cooker #1", (1.78, 4.7), (1.78, 3.6, math.pi / 2), None),
    "table": ("table", (4.3, 2.0), (4.3, 0.9, math.pi / 2), None),
    "shelf": ("fridge middle shelf", (3.05, 4.62), (3.05, 3.2, math.pi / 2), "fridge"),
    "drawer": ("drawer 2 inside", (0.3, 2.9), (1.45, 2.9, math.pi), "drawer 2"),
    "cupboard": ("cupboard shelf", (4.2, 4.65), (4.3, 3.5, math.pi / 2), "cupboard"),
}
OPENING_PUSH = {
    "fridge": ((0.0, -40.0, 0.0), 0.8),
    "drawer 2": ((40.0, 0.0, 0.0), 0.4),
    "drawer 3": ((40.0, 0.0, 0.0), 0.4),
    "cupboard": ((0.0, -20.0, 0.0), 0.6),
}


def apartment(base_pose, **kwargs) -> World:
    """The apartment with one object of each type, all taken aside (off the plan) to start."""
    world = World("pr2", environment="apartment", objects=list(TYPES), seed=1, base_pose=base_pose, **kwargs)
    for name in TYPES:
        ok(world.take_item(item=name))
    return world


def open_container(world: World, container: str) -> float:
    force, duration = OPENING_PUSH[container]
    ok(world.push_container(container, force, duration))
    t = world.sim_time.get_value() + 1.5  # it swings or slides on, damped, and stops
    assert (world.sim_time >= t).wait_for(10.0)
    q = world.container_states.get_value()[container]
    assert abs(q) > 0.2, f"{container} did not open: {q}"
    return q


def put(world: World, name: str, surface: str, xy, dx: float = 0.0) -> tuple[float, float, float]:
    """Stand object `name` at `xy` (+ `dx` along x) on `surface`; returns its true centre."""
    height = world.environment.surface(surface).height
    ok(world.move_item(name, (xy[0] + dx, xy[1], height + object_type(name).half_height + 0.002)))
    return world.item_poses.get_value()[name].position


def look(world: World, point) -> object:
    ok(world.point_head(point))
    return ok(world.detect())
