"""Environments as data: static geometry, surfaces, containers, free floor and named places.

An environment module (`pycram.environments.<name>`) builds one `Environment` from these types;
robots, reasoning, plans and the simulator's scene builder read it. Nothing here knows about a
simulator. Conventions: map frame, z up, lengths in [m], angles in [rad], RGBA colours in [0, 1].
Polygons are convex and counter-clockwise (checked on construction).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Literal, Protocol, TypeVar

from .errors import UnknownNameError

#: A point or vector in the floor plane (x, y) [m].
XY = tuple[float, float]
#: A point or vector in space (x, y, z) [m].
Vec3 = tuple[float, float, float]
#: A colour: red, green, blue, alpha in [0, 1].
RGBA = tuple[float, float, float, float]
#: An axis-aligned rectangle on the floor: (x_min, y_min, x_max, y_max) [m].
Rect = tuple[float, float, float, float]

#: Surface kinds a robot stands in front of (their edges face the free floor).
FURNITURE_TOPS = ("counter", "table")


@dataclass(frozen=True)
class Box:
    """An axis-aligned static box: name, centre [m], half sizes [m], colour.

    `collides` False makes it decoration (seen, never touched: stove plates, labels).
    """

    name: str
    center: Vec3
    half: Vec3
    rgba: RGBA = (0.8, 0.8, 0.78, 1.0)
    collides: bool = True

    @property
    def footprint(self) -> Rect:
        """The box's shadow on the floor."""
        (x, y, _), (hx, hy, _) = self.center, self.half
        return (x - hx, y - hy, x + hx, y + hy)

    @property
    def z_range(self) -> tuple[float, float]:
        """Bottom and top height [m]."""
        return (self.center[2] - self.half[2], self.center[2] + self.half[2])


@dataclass(frozen=True)
class Surface:
    """A horizontal surface objects can rest on: a convex polygon at `height` [m].

    `kind` is one of "counter", "table", "cooker", "shelf", "drawer"; `clearance` [m] is the free
    height above it (inside a drawer or a cupboard), infinite for open surfaces.
    """

    name: str
    polygon: tuple[XY, ...]
    height: float
    kind: str = "counter"
    clearance: float = math.inf

    def __post_init__(self) -> None:
        if len(self.polygon) < 3:
            raise ValueError(f"surface {self.name!r}: a polygon needs at least 3 corners")
        for (a, b), (_, c) in zip(self._corner_pairs(), self._corner_pairs()[1:] + self._corner_pairs()[:1]):
            if (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) <= 0.0:
                raise ValueError(f"surface {self.name!r}: the polygon must be convex and counter-clockwise")

    def _corner_pairs(self) -> list[tuple[XY, XY]]:
        p = self.polygon
        return [(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]

    @classmethod
    def rectangle(
        cls, name: str, rect: Rect, height: float, kind: str = "counter", clearance: float = math.inf
    ) -> Surface:
        """A rectangular surface over `rect` (x_min, y_min, x_max, y_max)."""
        x0, y0, x1, y1 = rect
        return cls(name, ((x0, y0), (x1, y0), (x1, y1), (x0, y1)), height, kind, clearance)

    def edges(self) -> list[tuple[XY, XY, XY]]:
        """(start corner, end corner, outward unit normal) of every edge, counter-clockwise."""
        out = []
        for a, b in self._corner_pairs():
            dx, dy = b[0] - a[0], b[1] - a[1]
            n = math.hypot(dx, dy)
            out.append((a, b, (dy / n, -dx / n)))
        return out

    def edge_distance(self, x: float, y: float) -> float:
        """Signed distance [m] from (x, y) to the border: positive inside, negative outside."""
        return min((x - a[0]) * -n[0] + (y - a[1]) * -n[1] for a, _, n in self.edges())

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        """True when (x, y) lies inside, at least `margin` [m] away from every edge."""
        return self.edge_distance(x, y) >= margin - 1e-9

    @property
    def bounds(self) -> Rect:
        xs, ys = [p[0] for p in self.polygon], [p[1] for p in self.polygon]
        return (min(xs), min(ys), max(xs), max(ys))

    @property
    def centroid(self) -> Vec3:
        """The polygon's centre (mean of its corners) at the surface height [m]."""
        n = len(self.polygon)
        return (sum(p[0] for p in self.polygon) / n, sum(p[1] for p in self.polygon) / n, self.height)

    @property
    def area(self) -> float:
        """[m^2]"""
        return 0.5 * sum(a[0] * b[1] - b[0] * a[1] for a, b in self._corner_pairs())


@dataclass(frozen=True)
class Container:
    """An articulated piece of furniture: a drawer on a slide joint or a door on a hinge.

    `body` is the moving part when closed (the drawer's outer box, front included; the door
    panel). `handle` is the handle's grasp point when closed [m]. `opening_direction` is a unit
    vector on the floor: where a drawer slides out, or where the handle of a door moves first (the
    closed door's outward normal). `hinge` is the (x, y) of a door's vertical hinge axis. The joint
    position `q` is 0 when closed and within `limits` ([m] for a slide, [rad] for a hinge).
    `interior` are the surfaces inside, positioned as when closed (a drawer's bottom moves with it;
    a cupboard's shelves stay). Pulling must overcome `friction` [N or N m]; motion is damped by
    `damping` [N s/m or N m s/rad], so a container stays where it is left.
    """

    name: str
    kind: Literal["drawer", "door"]
    body: Box
    handle: Vec3
    opening_direction: XY
    limits: tuple[float, float]
    interior: tuple[Surface, ...] = ()
    hinge: XY | None = None
    damping: float = 20.0
    friction: float = 4.0
    wall: float = 0.015  # [m] panel thickness of a drawer's walls and bottom

    def __post_init__(self) -> None:
        if self.kind not in ("drawer", "door"):
            raise ValueError(f"container {self.name!r}: kind must be 'drawer' or 'door', not {self.kind!r}")
        if (self.kind == "door") != (self.hinge is not None):
            raise ValueError(f"container {self.name!r}: a door needs a hinge, a drawer has none")
        if abs(math.hypot(*self.opening_direction) - 1.0) > 1e-6:
            raise ValueError(f"container {self.name!r}: opening_direction must be a unit vector")

    @property
    def joint(self) -> Literal["slide", "hinge"]:
        """The joint type: "slide" for a drawer, "hinge" for a door."""
        return "slide" if self.kind == "drawer" else "hinge"

    @property
    def joint_name(self) -> str:
        return f"{self.name}:joint"

    @property
    def handle_site(self) -> str:
        """Name of the site at the handle's grasp point."""
        return f"{self.name}:handle"

    @property
    def hinge_sign(self) -> float:
        """+1 when the door opens counter-clockwise about +z (seen from above), else -1."""
        if self.hinge is None:
            return 1.0
        rx, ry = self.handle[0] - self.hinge[0], self.handle[1] - self.hinge[1]
        return 1.0 if -ry * self.opening_direction[0] + rx * self.opening_direction[1] > 0 else -1.0

    def along_slide(self, x: float, y: float) -> float:
        """How far [m] the floor point (x, y) lies along the opening direction (from the origin)."""
        return x * self.opening_direction[0] + y * self.opening_direction[1]

    @property
    def front(self) -> float:
        """Where the closed body ends along the opening direction [m, `along_slide`]: the
        furniture's front, beyond which a drawer's contents are out from under it."""
        return max(self.along_slide(x, y) for x, y in _rect_corners(self.body.footprint))

    @property
    def rim_height(self) -> float:
        """Height [m] of the top of a drawer's walls (its body's top)."""
        return self.body.z_range[1]

    def surface_holding(self, point: Sequence[float], q: float, above: float = 0.3) -> Surface | None:
        """The interior surface of this drawer, opened by `q` [m], that `point` (x, y, z) [m, map:
        an object's centre] rests on or in -- its footprint over the surface moved out by `q` and
        its height within `above` [m] of the surface and below its clearance. None for a door
        (its shelves do not move) and for a point in none of them."""
        if self.kind != "drawer":
            return None
        x, y, z = (float(v) for v in point[:3])
        dx, dy = self.opening_direction
        for surface in self.interior:
            if not surface.contains(x - dx * q, y - dy * q):
                continue
            if surface.height - 0.01 <= z <= surface.height + min(above, surface.clearance):
                return surface
        return None

    def opened_interior(self, q: float, margin: float = 0.0) -> tuple[Surface, ...]:
        """The interior surfaces that are open to above with the joint at `q` [m or rad]: a
        drawer's, moved out by `q` along the opening direction and cut at the furniture's
        `front` plus `margin` [m] (what lies behind is under the furniture); a door's shelves as
        they are (they do not move). Same names as `interior`; none when nothing is out."""
        if self.kind != "drawer":
            return self.interior
        dx, dy = self.opening_direction
        cut = self.front + margin
        out = []
        for surface in self.interior:
            moved = [(x + dx * q, y + dy * q) for x, y in surface.polygon]
            kept = _clip_half_plane(moved, lambda x, y: self.along_slide(x, y) - cut)
            if len(kept) >= 3 and _area(kept) > 1e-6:
                out.append(Surface(surface.name, tuple(kept), surface.height, surface.kind, surface.clearance))
        return tuple(out)

    def handle_position(self, q: float) -> Vec3:
        """Where the handle is when the joint is at `q` [m or rad] (the opening trajectory)."""
        hx, hy, hz = self.handle
        if self.kind == "drawer":
            return (hx + q * self.opening_direction[0], hy + q * self.opening_direction[1], hz)
        cx, cy = self.hinge  # type: ignore[misc]
        a = self.hinge_sign * q
        c, s = math.cos(a), math.sin(a)
        rx, ry = hx - cx, hy - cy
        return (cx + c * rx - s * ry, cy + s * rx + c * ry, hz)

    def _door_axes(self) -> tuple[XY, XY]:
        """A door's unit vectors when closed: along the panel from the hinge towards the free edge,
        and the outward normal (`opening_direction`)."""
        if self.hinge is None:
            raise ValueError(f"container {self.name!r} is a {self.kind}, not a door")
        nx, ny = self.opening_direction
        rx, ry = self.handle[0] - self.hinge[0], self.handle[1] - self.hinge[1]
        along = (-ny, nx) if -ny * rx + nx * ry > 0 else (ny, -nx)
        return along, (nx, ny)

    def _door_extent(self, axis: XY) -> tuple[float, float]:
        """(min, max) [m] of the closed panel's corners along `axis`, measured from the hinge."""
        assert self.hinge is not None  # callers check
        x0, y0, x1, y1 = self.body.footprint
        values = [
            (x - self.hinge[0]) * axis[0] + (y - self.hinge[1]) * axis[1]
            for x, y in ((x0, y0), (x0, y1), (x1, y0), (x1, y1))
        ]
        return min(values), max(values)

    @property
    def door_width(self) -> float:
        """A door's width [m]: from its hinge axis to its free edge."""
        return self._door_extent(self._door_axes()[0])[1]

    def door_face(self, q: float, distance: float, side: Literal["outside", "inside"]) -> tuple[XY, XY, XY]:
        """The point of a door's `side` face `distance` [m] from its hinge axis when the door is open
        by `q` [rad], with the face's unit vectors there: (point, along the panel towards the free
        edge, the face's normal pointing away from the panel). ``'outside'`` is the face with the
        handle, ``'inside'`` the one facing the interior when closed."""
        along0, normal0 = self._door_axes()
        inner, outer = self._door_extent(normal0)
        a = self.hinge_sign * q
        c, s = math.cos(a), math.sin(a)
        along = (c * along0[0] - s * along0[1], s * along0[0] + c * along0[1])
        normal = (c * normal0[0] - s * normal0[1], s * normal0[0] + c * normal0[1])
        if side == "inside":
            offset, normal = inner, (-normal[0], -normal[1])
        elif side == "outside":
            offset = outer
        else:
            raise ValueError(f"a door has the faces 'outside' and 'inside', not {side!r}")
        assert self.hinge is not None  # checked by _door_axes
        sign = 1.0 if side == "outside" else -1.0  # `offset` is along the outward normal
        point = (
            self.hinge[0] + distance * along[0] + sign * offset * normal[0],
            self.hinge[1] + distance * along[1] + sign * offset * normal[1],
        )
        return point, along, normal


@dataclass(frozen=True)
class Place:
    """A named base pose on the free floor: x [m], y [m], yaw [rad] (e.g. "start")."""

    name: str
    pose: tuple[float, float, float]


@dataclass(frozen=True)
class Camera:
    """A fixed camera: where it sits, what it looks at [m], vertical field of view [deg]."""

    name: str
    position: Vec3
    target: Vec3
    fovy: float = 60.0


@dataclass(frozen=True)
class Environment:
    """A whole environment. Look parts up by name with `surface`, `container`, `place`.

    `floor` are the rectangles of floor inside the walls; the free floor is the part of them
    that no furniture stands on (`is_free_floor`). `extent` is the rectangle the floor plane and
    top-down pictures cover.
    """

    name: str
    title: str
    static: tuple[Box, ...]
    surfaces: tuple[Surface, ...]
    containers: tuple[Container, ...]
    floor: tuple[Rect, ...]
    places: tuple[Place, ...]
    camera: Camera
    extent: Rect
    notes: str = ""

    def __post_init__(self) -> None:
        boxes = [b.name for b in self.static]
        parts = [s.name for s in self.all_surfaces()] + [c.name for c in self.containers]
        duplicates = sorted({n for names in (boxes, parts) for n in names if names.count(n) > 1})
        if duplicates:
            raise ValueError(f"environment {self.name!r}: names used twice: {duplicates}")
        if not any(p.name == "start" for p in self.places):
            raise ValueError(f"environment {self.name!r} needs a place named 'start'")

    # --- look-ups -----------------------------------------------------------------------
    def surface(self, name: str) -> Surface:
        """The surface (on the furniture or inside a container) called `name`."""
        return _find("surface", name, self.all_surfaces())

    def container(self, name: str) -> Container:
        return _find("container", name, self.containers)

    def place(self, name: str) -> Place:
        return _find("place", name, self.places)

    def static_box(self, name: str) -> Box:
        return _find("static box", name, self.static)

    def all_surfaces(self) -> list[Surface]:
        """The open surfaces, then the surfaces inside each container."""
        return list(self.surfaces) + [s for c in self.containers for s in c.interior]

    def container_of(self, surface: str) -> Container | None:
        """The container whose interior holds the surface `surface` (None for open surfaces)."""
        self.surface(surface)
        return next((c for c in self.containers if any(s.name == surface for s in c.interior)), None)

    def surfaces_of_kind(self, *kinds: str) -> list[Surface]:
        return [s for s in self.all_surfaces() if s.kind in kinds]

    @property
    def start_pose(self) -> tuple[float, float, float]:
        """The base pose of the place "start"."""
        return self.place("start").pose

    # --- geometry -----------------------------------------------------------------------
    @property
    def plan_bounds(self) -> Rect:
        """The rectangle around the floor and everything standing on it (walls included)."""
        rects = list(self.floor) + [b.footprint for b in self.static] + [c.body.footprint for c in self.containers]
        return (min(r[0] for r in rects), min(r[1] for r in rects), max(r[2] for r in rects), max(r[3] for r in rects))

    def obstacles(self) -> list[Box]:
        """Static boxes and closed container bodies that stand in the way of a driving base
        (they collide and reach down to less than 0.3 m above the floor)."""
        boxes = [b for b in self.static if b.collides] + [c.body for c in self.containers]
        return [b for b in boxes if b.z_range[0] < 0.3]

    def is_free_floor(self, x: float, y: float, margin: float = 0.0) -> bool:
        """True when (x, y) lies on the floor, at least `margin` [m] away from the walls of the
        floor rectangles' union and from every obstacle's footprint."""
        if not any(
            x0 + margin <= x <= x1 - margin and y0 + margin <= y <= y1 - margin for x0, y0, x1, y1 in self.floor
        ):
            return False
        for b in self.obstacles():
            x0, y0, x1, y1 = b.footprint
            if x0 - margin < x < x1 + margin and y0 - margin < y < y1 + margin:
                return False
        return True

    def support_height(self, x: float, y: float) -> float:
        """Height [m] of the highest open surface over (x, y); 0 (the floor) when there is none."""
        return max((s.height for s in self.surfaces if s.contains(x, y)), default=0.0)


class _Named(Protocol):
    @property
    def name(self) -> str: ...


_N = TypeVar("_N", bound=_Named)


def _find(kind: str, name: str, things: Iterable[_N]) -> _N:
    found = list(things)
    for t in found:
        if t.name == name:
            return t
    raise UnknownNameError(kind, name, [t.name for t in found])


def _rect_corners(rect: Rect) -> list[XY]:
    x0, y0, x1, y1 = rect
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def rect_around(center: XY, half: XY) -> Rect:
    """The rectangle of half sizes `half` around `center`."""
    return (center[0] - half[0], center[1] - half[1], center[0] + half[0], center[1] + half[1])


__all__ = [
    "Box",
    "Surface",
    "Container",
    "Place",
    "Camera",
    "Environment",
    "Rect",
    "XY",
    "Vec3",
    "RGBA",
    "FURNITURE_TOPS",
    "rect_around",
    "UnknownNameError",
]


def _clip_half_plane(polygon: Sequence[XY], side: Callable[[float, float], float]) -> list[XY]:
    """The part of the convex `polygon` where `side(x, y) >= 0` (`side` affine), counter-clockwise."""
    out: list[XY] = []
    n = len(polygon)
    for i in range(n):
        a, b = polygon[i], polygon[(i + 1) % n]
        sa, sb = side(*a), side(*b)
        if sa >= 0.0:
            out.append(a)
        if (sa >= 0.0) != (sb >= 0.0):
            t = sa / (sa - sb)
            out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
    deduplicated: list[XY] = []
    for p in out:
        if not deduplicated or math.dist(p, deduplicated[-1]) > 1e-9:
            deduplicated.append(p)
    if len(deduplicated) > 1 and math.dist(deduplicated[0], deduplicated[-1]) <= 1e-9:
        deduplicated.pop()
    return deduplicated


def _area(polygon: Sequence[XY]) -> float:
    """The area [m^2] of a simple polygon (positive when counter-clockwise)."""
    n = len(polygon)
    return 0.5 * sum(
        polygon[i][0] * polygon[(i + 1) % n][1] - polygon[(i + 1) % n][0] * polygon[i][1] for i in range(n)
    )
