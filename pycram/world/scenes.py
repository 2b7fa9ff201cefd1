"""Random scenes: where the requested objects start, drawn from a seed.

`random_scene(environment, ["cup", "bowl", ...], seed)` puts each object on a surface of a kind
its type is found on (counters, the table, shelves, inside drawers), upright, turned at random,
fully on the surface and never overlapping another object: two objects whose height ranges
overlap keep their footprint circles `gap` apart. The same seed always gives the same scene.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass

from .environment import Environment, Surface
from .objects import ObjectType, object_type

#: Objects keep this far [m] from a surface's edge (beyond their footprint radius).
EDGE_MARGIN = 0.03
#: Free space [m] between the footprint circles of two objects at overlapping heights.
GAP = 0.02
#: Vertical room [m] an object needs above itself inside a container.
HEAD_ROOM = 0.01


@dataclass(frozen=True)
class Placement:
    """Where one object of a scene starts.

    `position` is the object's centre [m] in the map frame (containers closed), `yaw` [rad] its
    turn about z, `support` the surface it stands on and `container` the container that surface
    is in (None for open surfaces). `radius` [m] is its footprint circle.
    """

    name: str
    type: str
    support: str
    container: str | None
    position: tuple[float, float, float]
    yaw: float
    radius: float

    @property
    def z_range(self) -> tuple[float, float]:
        """Bottom and top height [m]."""
        half = object_type(self.type).half_height
        return (self.position[2] - half, self.position[2] + half)

    def overlaps(self, other: Placement, gap: float = 0.0) -> bool:
        """True when the two objects' footprint circles come closer than `gap` [m] at heights
        both objects occupy (a conservative test: the objects lie inside their circles)."""
        (a0, a1), (b0, b1) = self.z_range, other.z_range
        if a1 <= b0 or b1 <= a0:
            return False
        dx, dy = self.position[0] - other.position[0], self.position[1] - other.position[1]
        return math.hypot(dx, dy) < self.radius + other.radius + gap - 1e-9


class PlacementError(ValueError):
    """No free spot was found for an object; the message names it and where it was tried."""


def object_names(types: Sequence[str]) -> list[str]:
    """Names of objects of `types`: the type name, then "<type> 2", "<type> 3" for repeats."""
    counts: dict[str, int] = {}
    names = []
    for t in types:
        counts[t] = counts.get(t, 0) + 1
        names.append(t if counts[t] == 1 else f"{t} {counts[t]}")
    return names


def supports_for(environment: Environment, otype: ObjectType, supports: Sequence[str] | None = None) -> list[Surface]:
    """The surfaces an object of `otype` may start on: of a kind it is found on, high enough
    inside (clearance) and wide enough for its footprint; restricted to `supports` when given."""
    candidates = [environment.surface(s) for s in supports] if supports is not None else environment.all_surfaces()
    out = []
    for s in candidates:
        if s.kind not in otype.found_on or s.clearance < otype.height + HEAD_ROOM:
            continue
        x0, y0, x1, y1 = s.bounds
        if min(x1 - x0, y1 - y0) < 2 * (otype.footprint_radius + EDGE_MARGIN):
            continue
        out.append(s)
    return out


def random_scene(
    environment: Environment,
    types: Sequence[str],
    seed: int,
    *,
    supports: Sequence[str] | None = None,
    attempts: int = 300,
) -> list[Placement]:
    """Place one object of each of `types` (object type names) at random, reproducibly from `seed`.

    Supports are chosen with probability proportional to their area; `supports` (surface names)
    restricts them. Raises `UnknownNameError` for an unknown type or surface, and
    `PlacementError` when an object finds no free spot in `attempts` tries.
    """
    rng = random.Random(seed)
    placed: list[Placement] = []
    for name, type_name in zip(object_names(types), types):
        otype = object_type(type_name)
        candidates = supports_for(environment, otype, supports)
        if not candidates:
            raise PlacementError(
                f"no surface of {environment.name!r} fits a {type_name!r} (found on "
                f"{', '.join(otype.found_on)}; {otype.height:.2f} m tall)"
            )
        placement = _place(environment, name, otype, candidates, placed, rng, attempts)
        if placement is None:
            raise PlacementError(
                f"no free spot for {name!r} after {attempts} tries on {', '.join(s.name for s in candidates)}"
            )
        placed.append(placement)
    return placed


def _place(
    environment: Environment,
    name: str,
    otype: ObjectType,
    candidates: list[Surface],
    placed: list[Placement],
    rng: random.Random,
    attempts: int,
) -> Placement | None:
    radius = otype.footprint_radius
    weights = [s.area for s in candidates]
    for _ in range(attempts):
        surface = rng.choices(candidates, weights)[0]
        x0, y0, x1, y1 = surface.bounds
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        yaw = rng.uniform(-math.pi, math.pi)
        if not surface.contains(x, y, radius + EDGE_MARGIN):
            continue
        container = environment.container_of(surface.name)
        candidate = Placement(
            name,
            otype.name,
            surface.name,
            None if container is None else container.name,
            (x, y, surface.height + otype.half_height + 0.001),
            yaw,
            radius,
        )
        if not any(candidate.overlaps(other, GAP) for other in placed):
            return candidate
    return None


__all__ = ["Placement", "PlacementError", "random_scene", "supports_for", "object_names", "GAP", "EDGE_MARGIN"]
