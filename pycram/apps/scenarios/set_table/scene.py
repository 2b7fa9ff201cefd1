"""The set-table scene in the apartment: where the objects start and where they belong.

`start_scene` draws, from a seed, where each object starts (`pycram.world.scenes.Placement`s:
open surfaces of `START_REGIONS`, some objects inside closed containers of `START_CONTAINERS`);
`anywhere_scene` draws the ``anywhere`` starts: the six breakfast types anywhere on the worktops
and inside the containers, wherever some standing pose of the robot reaches them (the task
suite's `draw_starts`); the same seed always gives the same scene. `place_settings` turns the place settings of
`SETTINGS` (relative to the table's edge at the seat) into points [m, map] where each object's
centre should stand. Both read the environment's description only, never a simulator.
"""

from __future__ import annotations

import math
import random
from typing import Any

from pycram.apps.scenarios.common.scene import NoStartSpot, draw_starts, open_surfaces, reachability, table_edge
from pycram.apps.scenarios.set_table.data import (
    ANYWHERE_OBJECTS,
    ANYWHERE_SOURCE_KINDS,
    OBJECTS,
    SCENE_DRAWS,
    SEAT,
    SETTINGS,
    START_CONTAINERS,
    START_REGIONS,
    START_SPACING,
)
from pycram.apps.scenarios.set_table.plan import PlaceSetting

__all__ = [
    "start_scene",
    "anywhere_scene",
    "anywhere_sources",
    "place_settings",
]


def place_settings(environment: Any, seat: str = SEAT, objects: tuple[str, ...] = OBJECTS) -> list[PlaceSetting]:
    """The place settings of `objects` at `seat` on the environment's table, as points [m, map]
    where each object's centre stands (from `SETTINGS`, relative to the table's edge)."""
    from pycram.world.objects import object_type

    table = environment.surface("table")
    x, y, yaw = environment.place(seat).pose
    fx, fy = math.cos(yaw), math.sin(yaw)  # the seat's heading: into the table
    rx, ry = fy, -fx  # to the right of the heading
    edge = table_edge(environment, seat)  # where the heading from the seat enters the table's bounds
    out = []
    for name in objects:
        if name not in SETTINGS:
            raise ValueError(f"no place setting for {name!r}; settings exist for {', '.join(SETTINGS)}")
        side, inward = SETTINGS[name]
        d = edge + inward
        out.append(
            PlaceSetting(
                name,
                (x + fx * d + rx * side, y + fy * d + ry * side, table.height + object_type(name).half_height),
                seat,
            )
        )
    return out


def start_scene(
    environment: Any, seed: int, objects: tuple[str, ...] = OBJECTS, in_containers: bool = True
) -> list[Any]:
    """Where `objects` start (`pycram.world.scenes.Placement`s), drawn from `seed`: a support of
    a kind the object is found on among `START_REGIONS`, a spot in its region clear of the
    others, a random yaw (boxes roughly square to the counter's edge: perception does not
    measure yaw). Then, with `in_containers` (not in the ``set-table-open`` scenario) and the
    probability of `START_CONTAINERS` (from a second random stream of the seed, so the
    open-surface spots stay those of a scene without containers), an object is moved inside a
    closed container instead (`Placement.container` names it). The same seed gives the same
    scene. When the spots drawn first leave no room for an object, the scene is drawn again
    from another stream of the seed (at most `SCENE_DRAWS` times)."""
    rng = random.Random(seed)
    for attempt in range(1, SCENE_DRAWS + 1):
        placed = _draw_scene(environment, seed, objects, in_containers, rng)
        if placed is not None:
            return placed
        rng = random.Random(seed * 7907 + 3 + attempt)  # the spots drawn first left no room: again
    raise RuntimeError(f"no free start spots for {', '.join(objects)} in {SCENE_DRAWS} draws (seed {seed})")


def _draw_scene(
    environment: Any, seed: int, objects: tuple[str, ...], in_containers: bool, rng: random.Random
) -> list[Any] | None:
    """One draw of `start_scene`'s placements from `rng`; None when an object found no spot."""
    inside = random.Random(seed * 7907 + 3)  # the draws of starts in containers
    drawn: list[Any] = []  # every object's spot on an open surface, as without containers
    placed: list[Any] = []
    for name in objects:
        candidate = _start_spot(environment, name, START_REGIONS[name], drawn, rng)
        if candidate is None:
            return None
        drawn.append(candidate)
        if in_containers and name in START_CONTAINERS:
            probability, containers = START_CONTAINERS[name]
            if inside.random() < probability:
                others = [p for p in placed if p.container is not None]
                candidate = _start_spot(environment, name, containers, others, inside) or candidate
        placed.append(candidate)
    return placed


def _start_spot(
    environment: Any,
    name: str,
    regions: dict[str, tuple[float, float, float, float]],
    placed: list[Any],
    rng: random.Random,
) -> Any:
    """A `Placement` of `name` on one of `regions` (support name -> region [m, map]), drawn from
    `rng`, at least `START_SPACING` from each of `placed`; None after 500 tries."""
    from pycram.world.objects import object_type
    from pycram.world.scenes import GAP, Placement

    otype = object_type(name)
    supports = list(regions)
    for _ in range(500):
        support = rng.choice(supports)
        surface = environment.surface(support)
        x0, y0, x1, y1 = regions[support]
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        if otype.shape == "box":
            yaw = rng.choice((0.0, math.pi / 2, math.pi, -math.pi / 2)) + rng.uniform(-0.15, 0.15)
        else:
            yaw = rng.uniform(-math.pi, math.pi)
        container = environment.container_of(support)
        candidate = Placement(
            name,
            name,
            support,
            None if container is None else container.name,
            (x, y, surface.height + otype.half_height + 0.001),
            yaw,
            otype.footprint_radius,
        )
        if not any(candidate.overlaps(other, GAP + START_SPACING) for other in placed):
            return candidate
    return None


def anywhere_sources(environment: Any, type_name: str) -> list[str]:
    """The surfaces an object of `type_name` may start on in the ``anywhere`` starts: the
    environment's open surfaces of `ANYWHERE_SOURCE_KINDS` (whole), then the insides of its
    containers of a kind the type is found on (`ObjectType.found_on`), in the description's
    order."""
    from pycram.world.objects import object_type

    found_on = object_type(type_name).found_on
    inside = [s.name for c in environment.containers for s in c.interior if s.kind in found_on]
    return open_surfaces(environment, ANYWHERE_SOURCE_KINDS) + inside


def anywhere_scene(environment: Any, seed: int, robot: str, objects: tuple[str, ...] = ANYWHERE_OBJECTS) -> list[Any]:
    """The ``anywhere`` starts of `seed` for `robot` (`pycram.world.scenes.Placement`s, each
    object named by its type): each of `objects` drawn uniformly over the union of its
    `anywhere_sources` (the whole worktops, drawers, fridge shelves, the cupboard; inside a
    container it starts closed: `Placement.container`), clear of the others, and kept only where
    some standing pose of `robot` grasps it among the objects drawn before while each of those
    stays graspable (the task suite's `draw_starts` with the reachability filter counting the
    other objects as the robot's location reasoning counts believed ones). The same seed, robot
    and environment give the same scene. When the objects drawn first leave no reachable room
    for the next one, the scene is drawn again from another stream of the seed (at most
    `SCENE_DRAWS` times); then `NoStartSpot` is raised."""
    from pycram.apps.scenarios.common.scene import check_types

    listed = check_types(objects, ANYWHERE_OBJECTS, "set-table-anywhere")
    sources = {t: anywhere_sources(environment, t) for t in listed}
    reach = reachability(robot, environment.name)
    failure: NoStartSpot | None = None
    for attempt in range(SCENE_DRAWS):
        stream = f"set-table-anywhere/{seed}" + (f"/{attempt}" if attempt else "")
        try:
            placed, _ = draw_starts(environment, stream, listed, sources, reach, among_placed=True)
        except NoStartSpot as error:
            failure = error
            continue
        return placed
    raise NoStartSpot(f"seed {seed}: no scene in {SCENE_DRAWS} draws; the last: {failure}")
