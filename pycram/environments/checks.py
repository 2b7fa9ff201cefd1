"""Checks of an environment description: can a robot base drive to every place, can it stand
near every surface and container, does any furniture overlap?

Pure data (numpy and the navigation planner of `pycram.world.navigation`), no simulator: the
floor is rasterized from the description (`Environment.floor`, `Environment.obstacles`), and
base paths are planned for a round base of `radius` [m] with the same `PathPlanner` the robots
drive with. Used by the tests of generated apartments and by `pycram.environments.from_file`
(which logs what a loaded kitchen lacks).

    from pycram.environments import load
    from pycram.environments.checks import environment_problems
    assert environment_problems(load("procedural:3")) == []
"""

from __future__ import annotations

import collections
import math

import numpy as np

from pycram.world.environment import Box, Environment, Surface
from pycram.world.navigation import Footprint, NoPathError, OccupancyGrid, PathPlanner

__all__ = [
    "BASE_RADIUS",
    "REACH",
    "floor_grid",
    "drivability_problems",
    "reach_problems",
    "overlapping_furniture",
    "height_problems",
    "environment_problems",
    "piece_of",
]

#: The base the checks drive: a circle around the PR2's square base (0.67 m wide), [m].
BASE_RADIUS = 0.47
#: A surface or a handle counts as within reach when a reachable base pose's centre is at most
#: this far [m] from it (horizontally).
REACH = 1.0
#: Surfaces objects are put on lie between these heights [m].
HEIGHTS = (0.08, 1.5)


def floor_grid(env: Environment, resolution: float = 0.05, margin: float = 0.5) -> OccupancyGrid:
    """The floor of `env` as an occupancy grid of cells of `resolution` [m]: a cell is occupied
    when it lies off every floor rectangle (its centre) or touches the footprint of an obstacle
    (`Environment.obstacles`: walls, furniture reaching down to the floor, closed containers).
    The grid covers `Environment.plan_bounds` and `margin` [m] around it."""
    x0, y0, x1, y1 = env.plan_bounds
    ox, oy = x0 - margin, y0 - margin
    cols = int(math.ceil((x1 + margin - ox) / resolution))
    rows = int(math.ceil((y1 + margin - oy) / resolution))
    xs = ox + (np.arange(cols) + 0.5) * resolution
    ys = oy + (np.arange(rows) + 0.5) * resolution
    on_floor = np.zeros((rows, cols), bool)
    for fx0, fy0, fx1, fy1 in env.floor:
        on_floor |= ((ys >= fy0) & (ys <= fy1))[:, None] & ((xs >= fx0) & (xs <= fx1))[None, :]
    occupied = ~on_floor
    for box in env.obstacles():
        bx0, by0, bx1, by1 = box.footprint
        c0, c1 = int(math.floor((bx0 - ox) / resolution)), int(math.floor((bx1 - ox) / resolution))
        r0, r1 = int(math.floor((by0 - oy) / resolution)), int(math.floor((by1 - oy) / resolution))
        occupied[max(r0, 0) : max(r1 + 1, 0), max(c0, 0) : max(c1 + 1, 0)] = True
    return OccupancyGrid((ox, oy), resolution, occupied)


def _planner(env: Environment, radius: float, resolution: float) -> PathPlanner:
    return PathPlanner(floor_grid(env, resolution), Footprint.circle(radius))


def drivability_problems(env: Environment, radius: float = BASE_RADIUS, resolution: float = 0.05) -> list[str]:
    """What keeps a round base of `radius` [m] from driving from the place ``start`` to every
    other place of `env` (planned with `PathPlanner`); empty when it reaches them all."""
    planner = _planner(env, radius, resolution)
    start = env.start_pose
    problems = []
    if not planner.pose_free(*start):
        problems.append(f"the place 'start' {start} is not free floor for a base of radius {radius} m")
        return problems
    for place in env.places:
        if place.name == "start":
            continue
        try:
            planner.plan(start, place.pose)
        except NoPathError as e:
            problems.append(f"place {place.name!r} {place.pose}: {e}")
    return problems


def _reachable_cells(planner: PathPlanner, start: tuple[float, float, float]) -> np.ndarray:
    """The cells a round base reaches from `start`: connected free cells (8-neighbours)."""
    free = ~planner.lethal
    seen = np.zeros_like(free)
    r, c = planner.grid.cell(start[0], start[1])
    if not planner.grid.inside(r, c) or not free[r, c]:
        return seen
    seen[r, c] = True
    queue = collections.deque([(r, c)])
    rows, cols = free.shape
    while queue:
        r, c = queue.popleft()
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if 0 <= rr < rows and 0 <= cc < cols and free[rr, cc] and not seen[rr, cc]:
                    seen[rr, cc] = True
                    queue.append((rr, cc))
    return seen


def _distance_to(surface: Surface, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Horizontal distance [m] of the points (xs, ys) to the convex `surface` (0 inside)."""
    outside = np.full(xs.shape, -np.inf)
    for a, _, n in surface.edges():
        outside = np.maximum(outside, (xs - a[0]) * n[0] + (ys - a[1]) * n[1])
    return np.maximum(outside, 0.0)


def reach_problems(
    env: Environment, radius: float = BASE_RADIUS, reach: float = REACH, resolution: float = 0.05
) -> list[str]:
    """The open surfaces and container handles of `env` that no base pose reachable from
    ``start`` comes within `reach` [m] of (a surface: of its nearest edge; a container: of its
    handle); empty when a robot can stand near each."""
    planner = _planner(env, radius, resolution)
    reachable = _reachable_cells(planner, env.start_pose)
    rows, cols = np.nonzero(reachable)
    g = planner.grid
    xs = g.origin[0] + (cols + 0.5) * g.resolution
    ys = g.origin[1] + (rows + 0.5) * g.resolution
    problems = []
    if xs.size == 0:
        return ["no floor is reachable from 'start'"]
    for surface in env.surfaces:
        if surface.kind == "cooker":
            continue  # cookers lie on a counter, which is checked
        if float(_distance_to(surface, xs, ys).min()) > reach:
            problems.append(f"surface {surface.name!r}: no reachable base pose within {reach} m")
    for container in env.containers:
        hx, hy, _ = container.handle
        if float(np.hypot(xs - hx, ys - hy).min()) > reach:
            problems.append(f"container {container.name!r}: no reachable base pose within {reach} m of its handle")
    return problems


def piece_of(name: str) -> str:
    """The piece of furniture a part named `name` belongs to: its first word, with a number
    that follows it ("table leg 2" -> "table", "chair 2 back" -> "chair 2", "drawer 1" -> "drawer 1")."""
    words = name.split()
    if len(words) > 1 and words[1].isdigit():
        return " ".join(words[:2])
    return words[0] if words else name


def _overlap(a: Box, b: Box, tolerance: float) -> bool:
    return all(abs(a.center[i] - b.center[i]) < a.half[i] + b.half[i] - tolerance for i in range(3))


def overlapping_furniture(env: Environment, tolerance: float = 1e-4) -> list[tuple[str, str]]:
    """Pairs of parts of different pieces of furniture (`piece_of`) whose boxes overlap by more
    than `tolerance` [m] in every direction: colliding static boxes and the container bodies
    (closed). Parts of one piece may touch and overlap (a cabinet's top on its sides)."""
    boxes = [b for b in env.static if b.collides] + [c.body for c in env.containers]
    out = []
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            if piece_of(a.name) != piece_of(b.name) and _overlap(a, b, tolerance):
                out.append((a.name, b.name))
    return out


def height_problems(env: Environment, heights: tuple[float, float] = HEIGHTS) -> list[str]:
    """Surfaces of `env` (open ones and those inside containers) outside `heights` [m]."""
    low, high = heights
    return [
        f"surface {s.name!r} is {s.height:.3f} m high (outside {low}-{high} m)"
        for s in env.all_surfaces()
        if not low <= s.height <= high
    ]


def environment_problems(env: Environment, radius: float = BASE_RADIUS) -> list[str]:
    """Everything the checks of this module find wrong with `env` (empty: none): places not
    reachable from ``start``, surfaces and containers out of reach, overlapping furniture,
    surfaces too low or too high."""
    problems = drivability_problems(env, radius) + reach_problems(env, radius)
    problems += [f"{a!r} overlaps {b!r}" for a, b in overlapping_furniture(env)]
    return problems + height_problems(env)
