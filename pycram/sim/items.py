"""Graspable items: their specification and how they are added to a scene."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from . import collision


@dataclass(frozen=True)
class ItemSpec:
    """A free rigid item.

    `shape` is "box" (half sizes x, y, z) or "cylinder" (radius, half height); `position` is the
    centre [m] in the map frame (None for z: resting on the surface below, see
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

    @property
    def half_height(self) -> float:
        """Half the item's height [m]."""
        return self.size[2] if self.shape == "box" else self.size[1]

    def resting_position(self, support_height: float) -> tuple[float, float, float]:
        """Centre [m] with z resolved: when not given, the item stands on a surface at
        `support_height` [m] (1 mm above it)."""
        x, y, z = self.position
        return (x, y, support_height + self.half_height + 0.001 if z is None else z)


#: The default items: a pot-like mug at cooker #2 (the one the demo fetches) and a box on the
#: left counter away from cooker #1.
DEFAULT_ITEMS = (
    ItemSpec("mug", "mug", "cylinder", (0.03, 0.05), 0.25, (0.1, -1.15, None), (0.85, 0.2, 0.15, 1)),
    ItemSpec("box", "box", "box", (0.025, 0.035, 0.06), 0.2, (-0.78, 2.75, None), (0.2, 0.45, 0.85, 1)),
)


def add_item(spec: mujoco.MjSpec, item: ItemSpec, position: tuple[float, float, float]) -> None:
    """Add `item` at `position` [m] as a free body named `item.name` with one collision geom of
    the same name."""
    half_yaw = 0.5 * item.yaw
    body = spec.worldbody.add_body(name=item.name, pos=list(position),
                                   quat=[math.cos(half_yaw), 0.0, 0.0, math.sin(half_yaw)])
    body.add_freejoint(name=f"{item.name}_free")
    if item.shape == "box":
        gtype, size = mujoco.mjtGeom.mjGEOM_BOX, list(item.size)
    elif item.shape == "cylinder":
        gtype, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [item.size[0], item.size[1], 0.0]
    else:
        raise ValueError(f"item shape {item.shape!r} is not one of: box, cylinder")
    geom = body.add_geom(name=item.name, type=gtype, size=size, mass=item.mass, rgba=list(item.rgba),
                         friction=[1.2, 0.01, 0.001], condim=4)
    collision.set_group(geom, collision.ITEM)
