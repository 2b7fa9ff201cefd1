"""Graspable items: their specification and how they are added to a scene."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from pycram.world.objects import ObjectType, shape_parts

from . import collision


@dataclass(frozen=True)
class ItemSpec:
    """A free rigid item.

    `shape` is "box" (half sizes x, y, z), "cylinder" (radius, half height), or "bowl"/"plate"
    (radius, half height, wall thickness; see `pycram.world.objects.shape_parts`); `position` is
    the centre [m] in the map frame (None for z: resting on the surface below, see
    `resting_position`); `mass` in [kg]; `yaw` [rad] turns the item about the vertical.
    """

    name: str
    type: str
    shape: str
    size: tuple[float, ...]
    mass: float
    position: tuple[float, float, float | None]
    rgba: tuple[float, float, float, float] = (0.2, 0.35, 0.8, 1.0)
    yaw: float = 0.0

    @classmethod
    def of(
        cls, object_type: ObjectType, name: str, position: tuple[float, float, float | None], yaw: float = 0.0
    ) -> ItemSpec:
        """An item of `object_type` called `name` at `position` [m] turned by `yaw` [rad]."""
        t = object_type
        return cls(name, t.name, t.shape, t.size, t.mass, position, t.rgba, yaw)

    @property
    def half_height(self) -> float:
        """Half the item's height [m]."""
        return self.size[2] if self.shape == "box" else self.size[1]

    def resting_position(self, support_height: float) -> tuple[float, float, float]:
        """Centre [m] with z resolved: when not given, the item stands on a surface at
        `support_height` [m] (1 mm above it)."""
        x, y, z = self.position
        return (x, y, support_height + self.half_height + 0.001 if z is None else z)


#: The default items of the thesis kitchen: a pot-like mug at cooker #2 (the one the demo
#: fetches) and a box on the left counter away from cooker #1.
DEFAULT_ITEMS = (
    ItemSpec("mug", "mug", "cylinder", (0.03, 0.05), 0.25, (0.1, -1.15, None), (0.85, 0.2, 0.15, 1)),
    ItemSpec("box", "box", "box", (0.025, 0.035, 0.06), 0.2, (-0.78, 2.75, None), (0.2, 0.45, 0.85, 1)),
)


def part_geom_name(item: str, index: int) -> str:
    """Name of part `index` of `item`'s shape: the first part is named like the item."""
    return item if index == 0 else f"{item}:{index}"


def add_item(spec: mujoco.MjSpec, item: ItemSpec, position: tuple[float, float, float]) -> None:
    """Add `item` at `position` [m] as a free body named `item.name`, with one collision geom per
    part of its shape (the first named like the item); the parts share the item's mass."""
    half_yaw = 0.5 * item.yaw
    body = spec.worldbody.add_body(
        name=item.name, pos=list(position), quat=[math.cos(half_yaw), 0.0, 0.0, math.sin(half_yaw)]
    )
    body.add_freejoint(name=f"{item.name}_free")
    parts = shape_parts(item.shape, item.size)
    volumes = [_volume(p.kind, p.size) for p in parts]
    for i, (part, volume) in enumerate(zip(parts, volumes)):
        if part.kind == "box":
            gtype, size = mujoco.mjtGeom.mjGEOM_BOX, list(part.size)
        else:
            gtype, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [part.size[0], part.size[1], 0.0]
        geom = body.add_geom(
            name=part_geom_name(item.name, i),
            type=gtype,
            size=size,
            pos=list(part.pos),
            quat=[math.cos(part.yaw / 2), 0.0, 0.0, math.sin(part.yaw / 2)],
            mass=item.mass * volume / sum(volumes),
            rgba=list(item.rgba),
            friction=[1.2, 0.01, 0.001],
            condim=4,
        )
        collision.set_group(geom, collision.ITEM)


def _volume(kind: str, size: tuple[float, ...]) -> float:
    if kind == "box":
        return 8.0 * size[0] * size[1] * size[2]
    return 2.0 * math.pi * size[0] ** 2 * size[1]
