"""What a location designator may point at, reduced to what reasoning needs.

A target is an object designator (resolved with ``reference()``), a believed or perceived object
(anything with a ``pose``/``position`` and a ``type``), a named place, surface or container of the
environment, or a pose (a point (x, y, z) [m], or a base pose with x, y, yaw). `as_target`
turns each into a `Target`; nothing else is accepted (a ``ValueError`` says what was given).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pycram.world.environment import Container, Environment, Place, Surface
from pycram.world.objects import ObjectType, object_type

__all__ = ["Target", "as_target", "KnownObject"]


@dataclass(frozen=True)
class Target:
    """A thing to reach, see, put something on or open.

    `position` [m, map]: the object's centre (or the point); `type` its object type when known;
    `name` the name the world knows it by (for visibility), `yaw` [rad] its turn about z;
    `kind`: "object", "point", "place", "surface" or "container"; `thing` the environment part
    for surfaces and containers; `orientation` (w, x, y, z) an object's orientation as measured,
    when it is known (None: standing upright, turned by `yaw`; grasp planning,
    `pycram.reasoning.grasps`, reads it).
    """

    position: tuple[float, float, float]
    kind: str
    name: str | None = None
    type: ObjectType | None = None
    yaw: float = 0.0
    thing: Any = None
    orientation: tuple[float, float, float, float] | None = None

    def describe(self) -> str:
        if self.kind == "object":
            return f"{self.name or self.type.name if self.type else 'object'}"
        if self.kind in ("place", "surface", "container"):
            return f"{self.kind} {self.name!r}"
        return "(" + ", ".join(f"{v:.2f}" for v in self.position) + ")"


@dataclass(frozen=True)
class KnownObject:
    """An object reasoning knows of (from belief or perception): name, type, centre [m], yaw
    [rad], footprint `radius` [m] and `half_height` [m] (from its type when not given)."""

    name: str
    type: str
    position: tuple[float, float, float]
    yaw: float = 0.0
    radius: float | None = None
    half_height: float | None = None

    def __post_init__(self) -> None:
        if self.radius is None or self.half_height is None:
            otype = object_type(self.type)
            if self.radius is None:
                object.__setattr__(self, "radius", otype.footprint_radius)
            if self.half_height is None:
                object.__setattr__(self, "half_height", otype.half_height)


def _yaw_of(orientation: Any) -> float:
    try:
        w, x, y, z = (float(v) for v in orientation)
    except (TypeError, ValueError):
        return 0.0
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _quaternion(value: Any) -> tuple[float, float, float, float] | None:
    try:
        q = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return None
    if len(q) != 4 or not all(math.isfinite(v) for v in q) or not any(q):
        return None
    return (q[0], q[1], q[2], q[3])


def _point(value: Any) -> tuple[float, float, float] | None:
    try:
        p = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return None
    return p if len(p) == 3 and all(math.isfinite(v) for v in p) else None


def _object_like(value: Any) -> Target | None:
    otype = getattr(value, "type", None)
    pose = getattr(value, "pose", None)
    holder = pose if pose is not None and hasattr(pose, "position") else value
    position = _point(getattr(holder, "position", None))
    if position is None and pose is not None:  # a believed object: its pose is its centre
        position = _point(pose)
    if position is None or otype is None:
        return None
    if isinstance(otype, str):
        try:
            otype = object_type(otype)
        except KeyError:
            otype = None
    elif not isinstance(otype, ObjectType):
        otype = None
    yaw = getattr(value, "yaw", None)
    measured = getattr(holder, "orientation", None)
    if measured is None and holder is not value:
        measured = getattr(value, "orientation", None)
    if yaw is None:
        yaw = _yaw_of(measured)
    orientation = _quaternion(measured)
    return Target(position, "object", getattr(value, "name", None), otype, float(yaw), orientation=orientation)


def as_target(value: Any, environment: Environment | None = None, known_objects: Sequence[KnownObject] = ()) -> Target:
    """`value` as a `Target` (see the module docstring).

    A string names, in this order, a place, a surface or a container of `environment`, or one of
    `known_objects` (by name, else the first of that object type). Raises ``ValueError`` naming the
    value and what a target may be.
    """
    if isinstance(value, Target):
        return value
    if hasattr(value, "reference") and callable(value.reference):  # a designator
        value = value.reference()
    if isinstance(value, Surface):
        return Target(value.centroid, "surface", value.name, thing=value)
    if isinstance(value, Container):
        return Target(value.handle, "container", value.name, thing=value)
    if isinstance(value, str):
        if environment is not None:
            things: Sequence[Place | Surface | Container]
            for things in (environment.places, environment.all_surfaces(), environment.containers):
                for thing in things:
                    if thing.name == value:
                        return (
                            Target(
                                (thing.pose[0], thing.pose[1], 0.0), "place", thing.name, yaw=thing.pose[2], thing=thing
                            )
                            if isinstance(thing, Place)
                            else as_target(thing, environment)
                        )
        for known in known_objects:
            if known.name == value:
                return as_target(known, environment)
        for known in known_objects:  # an object type: the first known object of that type
            if known.type == value:
                return as_target(known, environment)
        names = (
            (
                [p.name for p in environment.places]
                + [s.name for s in environment.all_surfaces()]
                + [c.name for c in environment.containers]
            )
            if environment is not None
            else []
        )
        raise ValueError(
            f"unknown target {value!r}: not a place, surface or container of "
            f"{environment.name if environment else 'the environment'} nor a known object; "
            f"known: {sorted(names + [k.name for k in known_objects])}"
        )
    found = _object_like(value)
    if found is not None:
        return found
    point = _point(value)
    if point is not None:
        return Target(point, "point")
    if all(hasattr(value, a) for a in ("x", "y", "yaw")):
        return Target((float(value.x), float(value.y), 0.0), "place", yaw=float(value.yaw))
    raise ValueError(
        f"a location target is an object (with a pose and a type), an object designator, "
        f"a named place/surface/container or a point (x, y, z) [m]; got {value!r}"
    )
