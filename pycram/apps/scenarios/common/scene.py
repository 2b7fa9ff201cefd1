"""Scenes of the household task suite: start spots anywhere a robot reaches, where things belong,
and the seats at the table -- from the environment's description and a seed, by names only.

`draw_starts` draws where each object starts: a spot drawn uniformly from the union of the named
source surfaces, kept only where some standing pose of the robot grasps it
(`pycram.apps.scenarios.reachability.ReachabilityFilter`, a scene-generation filter the robot
never asks). `storage_containers` names the containers an object type is put away in
(`pycram.world.objects.ObjectType.stored_in`, best first). `table_edge` and `seat_point` say where
the table's edge is in front of a seat. Everything reads the environment's description (names of
surfaces, containers and places), never map coordinates, so the same scene code runs in the
apartment and in every generated apartment (``procedural:SEED``).
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from pycram.world.environment import Environment
from pycram.world.objects import object_type

__all__ = [
    "Goal",
    "TaskScene",
    "NoStartSpot",
    "reachability",
    "draw_starts",
    "open_surfaces",
    "storage_containers",
    "table_edge",
    "seat_point",
    "check_types",
    "put_away_scene",
]

#: Steps [m] and how many of them `table_edge` walks from a seat towards the table.
_EDGE_STEP, _EDGE_STEPS = 0.01, 400


class NoStartSpot(RuntimeError):
    """No free spot some standing pose of the robot reaches was drawn for an object (the source
    surfaces are full, or out of the robot's reach)."""


@dataclass(frozen=True)
class Goal:
    """Where one object should end: the object (`type`, and `name` in the simulator -- the judge's
    key) and, to be put away, the `containers` it belongs in (best first); to be served, the
    `seat` (a named place) and `point` [m, map]: where on the table in front of the seat, at the
    table's height."""

    type: str
    name: str
    containers: tuple[str, ...] = ()
    seat: str | None = None
    point: tuple[float, float, float] | None = None


@dataclass
class TaskScene:
    """A drawn scene: where each object starts (`pycram.world.scenes.Placement`s) and its `goals`;
    `checked` counts what the reachability filter said of the free spots drawn ((surface,
    reachable) -> count)."""

    placements: list[Any]
    goals: list[Goal]
    checked: dict[tuple[str, bool], int] = field(default_factory=dict)


_FILTERS: dict[tuple[str, str], Any] = {}


def reachability(robot: str, environment: str) -> Any:
    """The scene-generation filter of `robot` in the environment called `environment` (built once
    per process: about 1 s)."""
    from pycram.apps.scenarios.reachability import ReachabilityFilter

    key = (robot, environment)
    if key not in _FILTERS:
        _FILTERS[key] = ReachabilityFilter(robot, environment)
    return _FILTERS[key]


def open_surfaces(environment: Environment, kinds: Sequence[str]) -> list[str]:
    """The names of the environment's open surfaces (not inside a container) of `kinds`
    (`Surface.kind`: "counter", "cooker", "table", ...), in the description's order."""
    return [s.name for s in environment.surfaces if s.kind in kinds]


def draw_starts(
    environment: Environment,
    stream: str,
    types: Sequence[str],
    surfaces: Sequence[str] | Mapping[str, Sequence[str]],
    reach: Any = None,
    among_placed: bool = False,
) -> tuple[list[Any], dict[tuple[str, bool], int]]:
    """Start spots (`Placement`s, each object named by its type) for `types`, one after the
    other, drawn from `random.Random(stream)` uniformly over the union of `surfaces` (surface
    names -- open surfaces or insides of containers --, or per object type: type -> names), clear
    of the objects drawn before and -- with `reach` (a `ReachabilityFilter`) -- where some
    standing pose grasps the object; with `among_placed`, the filter counts the objects drawn
    before as the robot's location reasoning counts believed objects (`draw_spot`). The same
    stream gives the same spots. Raises `NoStartSpot` naming the object when none is found."""
    from pycram.apps.scenarios.reachability import draw_spot

    rng = random.Random(stream)
    placed: list[Any] = []
    checked: dict[tuple[str, bool], int] = {}
    for type_name in types:
        sources = surfaces[type_name] if isinstance(surfaces, Mapping) else surfaces
        spot, counts = draw_spot(rng, environment, type_name, sources, placed, reach, among_placed=among_placed)
        for key, n in counts.items():
            checked[key] = checked.get(key, 0) + n
        if spot is None:
            raise NoStartSpot(
                f"no free spot on {', '.join(sources)} of {environment.name} where the robot reaches a "
                f"{type_name} (beside {', '.join(p.name for p in placed) or 'nothing'}); try another seed"
            )
        placed.append(spot)
    return placed, checked


def storage_containers(environment: Environment, type_name: str) -> tuple[str, ...]:
    """The containers of `environment` an object of `type_name` is put away in, best first: by
    the kinds of `ObjectType.stored_in` in their order, of equal kind the container whose inside
    is highest first (reached from above with the least bending: a top drawer before a bottom
    one). Raises `ValueError` when the type is not put away or the environment has no such
    container."""
    otype = object_type(type_name)
    if not otype.stored_in:
        raise ValueError(f"a {type_name} is not put away anywhere (ObjectType.stored_in is empty)")
    found: list[str] = []
    for kind in otype.stored_in:
        of_kind = [c for c in environment.containers if any(s.kind == kind for s in c.interior)]
        of_kind.sort(key=lambda c: -max(s.height for s in c.interior))
        found += [c.name for c in of_kind if c.name not in found]
    if not found:
        raise ValueError(
            f"{environment.name} has no container for a {type_name} (inside of kind "
            f"{' or '.join(otype.stored_in)}); its containers: {', '.join(c.name for c in environment.containers)}"
        )
    return tuple(found)


def table_edge(environment: Environment, seat: str) -> float:
    """How far [m] the table's edge facing `seat` (a named place) is from the seat, along the
    seat's heading (0.0 when the heading misses the table's bounds)."""
    table = environment.surface("table")
    x, y, yaw = environment.place(seat).pose
    fx, fy = math.cos(yaw), math.sin(yaw)  # the seat's heading: into the table
    x0, y0, x1, y1 = table.bounds
    for step in range(1, _EDGE_STEPS):
        px, py = x + fx * _EDGE_STEP * step, y + fy * _EDGE_STEP * step
        if x0 <= px <= x1 and y0 <= py <= y1:
            return _EDGE_STEP * step
    return 0.0


def seat_point(environment: Environment, seat: str, inward: float = 0.0) -> tuple[float, float, float]:
    """The point [m, map] `inward` [m] in from the table's edge in front of `seat`, at the table's
    height."""
    x, y, yaw = environment.place(seat).pose
    d = table_edge(environment, seat) + inward
    return (x + math.cos(yaw) * d, y + math.sin(yaw) * d, environment.surface("table").height)


def check_types(types: Sequence[str], allowed: Sequence[str], scenario: str) -> tuple[str, ...]:
    """`types` as a tuple, checked: each one of `allowed` (object types the scenario knows), each
    at most once (the plan finds objects by type), at least one and at most ``len(allowed)``.
    Raises `ValueError` saying what is wrong and what to ask instead."""
    listed = tuple(str(t).strip() for t in types)
    if not listed:
        raise ValueError(f"{scenario}: no object asked for; choose from {', '.join(allowed)}")
    unknown = [t for t in listed if t not in allowed]
    if unknown:
        raise ValueError(
            f"{scenario}: unknown or unsupported object type(s) {', '.join(map(repr, unknown))}; "
            f"choose from {', '.join(allowed)}"
        )
    repeated = sorted({t for t in listed if listed.count(t) > 1})
    if repeated:
        raise ValueError(f"{scenario}: each object type at most once (the plan finds objects by type): {repeated}")
    return listed


def put_away_scene(
    environment: Environment,
    seed: int,
    robot: str,
    types: Sequence[str],
    allowed: Sequence[str],
    source_kinds: Sequence[str],
    scenario: str,
) -> TaskScene:
    """A scene of objects to be put away: `types` (checked against `allowed`) at spots drawn
    (from the stream ``SCENARIO/SEED``) uniformly over the environment's open surfaces of
    `source_kinds`, where some standing pose of `robot` grasps them; each object's goal lists
    the environment's containers its type is put away in (`storage_containers`). The same seed,
    robot and environment give the same scene."""
    listed = check_types(types, allowed, scenario)
    surfaces = open_surfaces(environment, source_kinds)
    placements, checked = draw_starts(
        environment, f"{scenario}/{seed}", listed, surfaces, reachability(robot, environment.name)
    )
    goals = [Goal(t, t, containers=storage_containers(environment, t)) for t in listed]
    return TaskScene(placements, goals, checked)
