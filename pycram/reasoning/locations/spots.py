"""The ``on`` and ``in`` vocabularies: free spots on a surface or inside a container.

``('on', s)`` [``('near', o)``, ``('for', type/object)``] is answered with `Spot`s on surface
``s`` where an object of that type fits without touching the known objects; ``('in', c)`` [same
options] with `Spot`s on the interior surfaces of container ``c`` -- a drawer's as the robot
believes it open (``container_states``): moved out, only the part out from under the furniture
(none while it is closed). Spots lie on a grid of
`SPOT_RESOLUTION` [m], keep `SPOT_GAP` [m] from other objects and `SPOT_EDGE_MARGIN` [m] from the
surface's edge, come nearest ``near`` (or the surface's centre; behind a door, out at the front:
`FRONT_CENTRING`) first and keep `SPACING` apart on
each surface; several surfaces (the shelves of a fridge, one above the other) take turns: each
one's best spot, then each one's second, ...
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from pycram.world.environment import Container, Surface
from pycram.world.objects import ObjectType, object_type

from .search import SPACING, CandidateSearch, _Tally
from .solutions import Spot
from .targets import KnownObject, as_target

__all__ = ["SpotVocabulary", "SPOT_RESOLUTION", "SPOT_GAP", "SPOT_EDGE_MARGIN", "DEFAULT_OBJECT"]

#: Spots on surfaces: grid cell [m].
SPOT_RESOLUTION = 0.02
#: Inside a container behind a door, spots are ranked by how far out towards the opening they
#: lie [m], plus this times their distance from the surface's centre [m] (centred among equals).
FRONT_CENTRING = 0.2
#: Free space [m] between a spot's object and the other objects.
SPOT_GAP = 0.02
#: Free space [m] between a spot's object and the surface's edge.
SPOT_EDGE_MARGIN = 0.03
#: Footprint radius [m] and half height [m] assumed for ``('on', s)`` without ``('for', ...)``.
DEFAULT_OBJECT = (0.05, 0.0)


class SpotVocabulary(CandidateSearch):
    """Answers ``on`` and ``in`` (see the module docstring)."""

    # ------------------------------------------------------------------ on / in
    def on(self, desig: Any) -> Iterator[Spot]:
        env = self.environment()
        value = desig.prop_value("on")
        surface = value if isinstance(value, Surface) else env.surface(value)
        return self._spots(desig, [surface], None)

    def inside(self, desig: Any) -> Iterator[Spot]:
        env = self.environment()
        value = desig.prop_value("in")
        container = value if isinstance(value, Container) else env.container(value)
        if not container.interior:
            raise self._fail(desig, f"{container.name!r} has no surfaces inside")
        if container.kind != "drawer":  # behind a door: the spots nearest the opening first
            front = container.opening_direction
            return self._spots(desig, list(container.interior), container.name, front)
        # a drawer's inside as it is believed open: out from under the furniture, reachable from above
        q = float(self.container_states().get(container.name, 0.0))
        exposed = container.opened_interior(q)  # spots keep their margin from the cut edge too
        half = self._object_size(desig.prop_value("for"), list(self.known_objects()))[1]
        if not any(s.clearance >= 2 * half + 0.01 for s in container.interior):
            return self._spots(desig, list(container.interior), container.name)  # says it does not fit
        if not exposed:
            raise self._fail(
                desig,
                f"{container.name!r} is closed as far as the robot knows (open {q:.2f} m): nothing "
                "inside is reachable from above -- open it first (Open, then look or resolve again)",
            )
        return self._spots(desig, list(exposed), container.name)

    def _object_size(self, value: Any, known: Sequence[KnownObject]) -> tuple[float, float, str, str | None]:
        """(footprint radius [m], half height [m], description, name) of the object to put down."""
        if value is None:
            return DEFAULT_OBJECT[0], DEFAULT_OBJECT[1], "an object", None
        if isinstance(value, ObjectType):
            return value.footprint_radius, value.half_height, f"a {value.name}", None
        if isinstance(value, str):
            for k in known:
                if k.name == value:
                    assert k.radius is not None and k.half_height is not None  # set by KnownObject.__post_init__
                    return float(k.radius), float(k.half_height), f"the {k.name}", k.name
            t = object_type(value)
            return t.footprint_radius, t.half_height, f"a {t.name}", None
        target = as_target(value, None, known)
        if target.type is None:
            raise ValueError(f"('for', {value!r}): need an object type, a known object or an object with a type")
        return target.type.footprint_radius, target.type.half_height, target.describe(), target.name

    def _spots(
        self, desig: Any, surfaces: list[Surface], container: str | None, front: tuple[float, float] | None = None
    ) -> Iterator[Spot]:
        """Spots on `surfaces` (see the module docstring); without ``near``, those farthest along
        ``front`` (a unit vector: a door's opening direction, towards the room) come first, else
        those nearest each surface's centre."""
        known = list(self.known_objects())
        radius, half, what, own = self._object_size(desig.prop_value("for"), known)
        near = desig.prop_value("near")
        near_xy = None if near is None else self._target(near).position[:2]
        fitting = [s for s in surfaces if s.clearance >= 2 * half + 0.01]
        if not fitting:
            raise self._fail(
                desig,
                f"{what} ({2 * half:.2f} m tall) fits on none of "
                f"{[s.name for s in surfaces]} (clearance "
                f"{', '.join(f'{s.clearance:.2f} m' for s in surfaces)})",
            )
        candidates = []
        tally = _Tally()
        for surface in fitting:
            x0, y0, x1, y1 = surface.bounds
            xs = np.arange(x0 + SPOT_RESOLUTION / 2, x1, SPOT_RESOLUTION)
            ys = np.arange(y0 + SPOT_RESOLUTION / 2, y1, SPOT_RESOLUTION)
            gx, gy = np.meshgrid(xs, ys)
            inside = np.ones(gx.shape, bool)
            for (ax, ay), _, n in surface.edges():
                inside &= (gx - ax) * -n[0] + (gy - ay) * -n[1] >= radius + SPOT_EDGE_MARGIN
            tally.tried += int(gx.size)
            tally.reasons["too close to the edge"] += int((~inside).sum())
            free = inside.copy()
            z = surface.height + half
            for k in known:
                if k.name == own:
                    continue
                assert k.radius is not None and k.half_height is not None  # set by KnownObject.__post_init__
                kz0, kz1 = k.position[2] - k.half_height, k.position[2] + k.half_height
                if kz1 <= surface.height - 0.01 or kz0 >= surface.height + 2 * half + 0.01:
                    continue
                blocked = np.hypot(gx - k.position[0], gy - k.position[1]) < radius + k.radius + SPOT_GAP
                tally.details.setdefault("occupied", Counter())[k.name] += int((blocked & free).sum())
                tally.reasons["occupied"] += int((blocked & free).sum())
                free &= ~blocked
            if near_xy is not None:
                cost = np.hypot(gx - near_xy[0], gy - near_xy[1])
            else:
                cx, cy, _ = surface.centroid
                cost = np.hypot(gx - cx, gy - cy)
                if front is not None:  # out at the front (reachable past the door), centred second
                    cost = -(gx * front[0] + gy * front[1]) + FRONT_CENTRING * cost
            for i in np.flatnonzero(free.ravel()):
                candidates.append((float(cost.ravel()[i]), float(gx.ravel()[i]), float(gy.ravel()[i]), z, surface.name))
        candidates.sort()
        if not candidates:
            raise self._fail(
                desig,
                f"no free spot for {what} (footprint radius {radius:.2f} m) on "
                f"{', '.join(s.name for s in fitting)}: {tally.summary()}",
            )

        def spots() -> Iterator[Spot]:
            # per surface, best first, `SPACING` apart; then the surfaces take turns (the fridge's
            # shelves: each one's best spot before any shelf's second -- a place that tries the
            # first few spots tried only the bottom shelf, out of reach)
            given: dict[str, list[tuple[float, float, float, float]]] = {}
            cells: dict[tuple[str, int, int], list[tuple[float, float]]] = {}  # spots by SPACING cell
            for cost, x, y, z, name in candidates:
                i, j = int(math.floor(x / SPACING)), int(math.floor(y / SPACING))
                near = (p for di in (-1, 0, 1) for dj in (-1, 0, 1) for p in cells.get((name, i + di, j + dj), ()))
                if any(math.hypot(x - gx_, y - gy_) < SPACING for gx_, gy_ in near):
                    continue
                cells.setdefault((name, i, j), []).append((x, y))
                given.setdefault(name, []).append((x, y, z, cost))
            turns = sorted(
                (rank, cost, x, y, z, name)
                for name, spots_on in given.items()
                for rank, (x, y, z, cost) in enumerate(spots_on)
            )
            for _, cost, x, y, z, name in turns:
                yield Spot(x, y, z, name, container, None if own else _type_name(desig.prop_value("for")), cost)

        return spots()


def _type_name(value: Any) -> str | None:
    if isinstance(value, ObjectType):
        return value.name
    return value if isinstance(value, str) else None
