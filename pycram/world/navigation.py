"""Base navigation on an occupancy grid: footprints, inflation, A* and path shortening.

Backend-neutral (numpy only). A backend rasterizes its environment into an
:class:`OccupancyGrid` and describes the robot's :class:`Footprint`; :class:`PathPlanner` then
plans collision-free base paths between poses.

How a path is planned
---------------------
1. The straight line from start to goal is taken when the footprint, turning uniformly from the
   start yaw to the goal yaw along it, touches nothing (today's short, straight drives stay
   exactly what they were).
2. Otherwise A* (8-connected, octile heuristic, so optimal on the grid) searches the cells where
   at least the footprint's inscribed circle (plus ``clearance``) fits; cells where only some
   headings fit cost more, so paths keep their distance from furniture where they can.
3. The A* cell path gets headings (a uniform turn by path length, or turning at the start, or
   at the end, whichever is free; where the footprint does not fit at the profile's heading,
   the nearest heading that fits) and is shortened greedily: from each waypoint a far later
   waypoint reachable on a straight, footprint-checked segment is taken (found by bisection).
   Every segment of the result is footprint-checked at ``resolution``/2 spacing. Cells where
   the footprint fits at no heading are blocked and A* searches again.

Obstacles may come in layers, each kept off by its own outline of the robot (the sim backend
uses height bands: the base alone keeps off a counter the arms reach over, the robot with its
arms keeps off walls and tall boxes). A backend may add an exact check of poses
(``exact_check``): where only the convex outline of an arm is in the way it decides, and it
validates the final path every `EXACT_STEP` -- wherever an obstacle of a layer is within reach
of an outline (poses farther than every outline's radius from every obstacle are free by
construction).

A differential drive (`pycram.world.base_kinematics`) cannot step sideways: every straight
segment above is then checked, and returned, as a chain of turns on the spot and straight
drives along the heading (forwards, a short way backwards, or arriving at / leaving a pose
straight along its heading); intermediate waypoints face along the way the robot goes
(forwards or backwards, whichever the robot faces more), and it turns only where its way turns.

A* on a grid was chosen over sampling planners (RRT, PRM) because a 2D omnidirectional base in a
room has a small grid (10^4..10^5 cells), A* is complete and deterministic on it (the same
question gives the same path, which tests and traces rely on), and "no path exists" is a
definite answer rather than a time-out.

Failures: :class:`NoPathError` (a :class:`NavigationFailure`) with ``reason`` ``'no_path'``,
``'goal_in_collision'`` or ``'outside_map'``.
"""

from __future__ import annotations

import hashlib
import heapq
import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from pycram.execution.failures import GoalUnreachable, NavigationFailure

from .base_kinematics import POSITION_EPS, BaseKinematics, arc_point, arc_radius, move_options
from .prospection import BasePose, as_base_pose

__all__ = [
    "Footprint",
    "NavigationFailure",
    "NoPathError",
    "OccupancyGrid",
    "PathPlanner",
    "dilate",
    "squared_distances",
]

SQRT2 = math.sqrt(2.0)
#: A robot that already touches something may move this far [m] from its start unchecked, to
#: get clear (e.g. after a drive stopped on contact).
ESCAPE_RADIUS = 0.15
#: A differential drive that touches something gets clear only along its heading: poses turned
#: more than this [rad] from its start are checked.
ESCAPE_TURN = 0.05
#: A* searches per plan: after each, cells where the footprint fits at no heading are blocked.
MAX_SEARCHES = 8
#: Spacing [m] of the backend's exact checks along a path, and the half width [cells] of the
#: square blocked around a spot where one failed.
EXACT_STEP = 0.1
EXACT_BLOCK_CELLS = 3
#: A differential drive turns on the spot, sweeping its arms round: its turns are checked
#: wherever the outermost point of its outlines has moved this far [m] (measured: an arm turning
#: 0.52 rad past a milk carton on the counter touched it over less than 0.05 rad, between two
#: checks 2.5 cm of sweep apart, and knocked it over).
EXACT_TURN_STEP = 0.01
#: A differential drive's search over headings (`PathPlanner._lattice`, when the cell search
#: finds no path for it): headings per turn, the length [m] of a straight step, the extra cost of
#: a step backwards, how near the goal [m] a straight connection is tried, and how many poses it
#: expands before it gives up.
LATTICE_HEADINGS = 16
LATTICE_STEP = 0.1
LATTICE_REVERSE_COST = 3.0
LATTICE_SHOT = 1.0
#: Length [m] of the lattice's arcs (each turns by one heading).
LATTICE_ARC = 0.2
LATTICE_EXPANSIONS = 60000
#: Weight of A*'s distance heuristic: above 1 it expands far fewer cells, for a path at most
#: this factor longer than the cheapest on the grid (before shortening: `_shorten` straightens
#: it wherever the straight line is free).
HEURISTIC_WEIGHT = 1.5

PoseCheck = Callable[[float, float, float], bool]


class NoPathError(GoalUnreachable):
    """No collision-free path exists (a `pycram.failures.GoalUnreachable`). ``reason``:
    ``'no_path'`` (start and goal are not connected
    on the free floor), ``'goal_in_collision'`` (the robot does not fit at the goal pose) or
    ``'outside_map'`` (start or goal is off the map). ``start``/``goal`` are the poses asked."""

    def __init__(self, reason: str, message: str, start: BasePose | None = None, goal: BasePose | None = None) -> None:
        super().__init__(f"{reason}: {message}")
        self.reason = reason
        self.start, self.goal = start, goal


@dataclass(frozen=True)
class OccupancyGrid:
    """Occupied floor cells: ``occupied[row, col]`` covers the square of side ``resolution`` [m]
    whose centre is ``(origin[0] + (col + 0.5) * resolution, origin[1] + (row + 0.5) *
    resolution)`` in the map frame. A cell is occupied when its centre lies under an obstacle
    that the base could touch."""

    origin: tuple[float, float]
    resolution: float
    occupied: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape

    def cell(self, x: float, y: float) -> tuple[int, int]:
        """(row, col) of the cell containing map point (x, y) [m] (may be outside the grid)."""
        return (
            int(math.floor((y - self.origin[1]) / self.resolution)),
            int(math.floor((x - self.origin[0]) / self.resolution)),
        )

    def center(self, row: int, col: int) -> tuple[float, float]:
        """Map point [m] at the centre of cell (row, col)."""
        r = self.resolution
        return (self.origin[0] + (col + 0.5) * r, self.origin[1] + (row + 0.5) * r)

    def inside(self, row: int, col: int) -> bool:
        return 0 <= row < self.occupied.shape[0] and 0 <= col < self.occupied.shape[1]


@dataclass(frozen=True)
class Footprint:
    """The base's outline on the floor: a convex polygon in the base frame (x ahead, y left) [m],
    counter-clockwise."""

    vertices: tuple[tuple[float, float], ...]

    @classmethod
    def circle(cls, radius: float, sides: int = 16) -> Footprint:
        """A regular polygon circumscribing a circle of ``radius`` [m]."""
        r = radius / math.cos(math.pi / sides)
        return cls(
            tuple(
                (r * math.cos(2 * math.pi * (i + 0.5) / sides), r * math.sin(2 * math.pi * (i + 0.5) / sides))
                for i in range(sides)
            )
        )

    @classmethod
    def rectangle(cls, x_min: float, y_min: float, x_max: float, y_max: float) -> Footprint:
        return cls(((x_min, y_min), (x_max, y_min), (x_max, y_max), (x_min, y_max)))

    @property
    def circumscribed_radius(self) -> float:
        """Largest distance [m] of the outline from the base origin."""
        return max(math.hypot(x, y) for x, y in self.vertices)

    @property
    def inscribed_radius(self) -> float:
        """Radius [m] of the largest circle about the base origin inside the outline."""
        return min(-d for d in self._edge_offsets())

    def _edges(self) -> tuple[np.ndarray, np.ndarray]:
        """Outward unit normals (n x 2) and offsets (n): a point p is inside iff n.p <= c for all."""
        v = np.asarray(self.vertices, float)
        e = np.roll(v, -1, axis=0) - v
        normals = np.column_stack([e[:, 1], -e[:, 0]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        return normals, np.einsum("ij,ij->i", normals, v)

    def _edge_offsets(self) -> np.ndarray:
        normals, c = self._edges()
        return -c


def dilate(mask: np.ndarray, radius_cells: float) -> np.ndarray:
    """``mask`` grown by a disk of ``radius_cells``: the cells whose centre is within that
    distance [cells] of a set cell's centre (a new array; thread-safe)."""
    if int(math.floor(radius_cells)) <= 0 or not mask.any():
        return mask.copy()
    return _within(mask, radius_cells)


def _within(mask: np.ndarray, radius_cells: float) -> np.ndarray:
    """The cells within ``radius_cells`` of a set cell of ``mask`` (none when it is negative)."""
    if radius_cells < 0:
        return np.zeros_like(mask, dtype=bool)
    return squared_distances(mask, radius_cells) <= radius_cells * radius_cells


#: Masks whose squared distances `squared_distances` keeps (the least recently used go first).
DISTANCE_CACHE_SIZE = 16
_distance_cache: OrderedDict[bytes, tuple[int, np.ndarray]] = OrderedDict()
_distance_lock = threading.Lock()


def squared_distances(mask: np.ndarray, reach: float) -> np.ndarray:
    """The squared distance [cells^2] from each cell's centre to the nearest set cell's centre of
    the 2D boolean ``mask``: exact wherever it is at most ``reach``^2; any larger value only says
    "farther than ``reach``". Read-only (shared).

    The last `DISTANCE_CACHE_SIZE` masks' answers are kept (by content), so growing the same
    obstacles by several radii -- a planner's inflation layers, the next planner of an unchanged
    room -- computes them once: O(reach x cells) with numpy."""
    need = max(0, int(math.ceil(reach)))
    key = np.asarray(mask.shape, np.int64).tobytes() + hashlib.blake2b(mask.tobytes(), digest_size=16).digest()
    with _distance_lock:
        cached = _distance_cache.get(key)
        if cached is not None and cached[0] >= need:
            _distance_cache.move_to_end(key)
            return cached[1]
    if cached is not None:  # asked farther than before: at least twice as far, so this is rare
        need = max(need, 2 * cached[0])
    distances = _squared_distances(np.asarray(mask, bool), need)
    distances.setflags(write=False)
    with _distance_lock:
        _distance_cache[key] = (need, distances)
        _distance_cache.move_to_end(key)
        while len(_distance_cache) > DISTANCE_CACHE_SIZE:
            _distance_cache.popitem(last=False)
    return distances


def _squared_distances(mask: np.ndarray, reach: int) -> np.ndarray:
    """`squared_distances` computed: each row's distance to its nearest set cell (both
    directions, by running maxima of indices), then the minimum over rows up to ``reach`` away
    of that distance squared plus the rows' offset squared. Values above ``reach``^2 are capped
    at (``reach`` + 1)^2."""
    rows, cols = mask.shape
    far = reach + 1
    index = np.arange(cols, dtype=np.int64)
    left = np.maximum.accumulate(np.where(mask, index, -(cols + far)), axis=1)
    right = np.minimum.accumulate(np.where(mask, index, 2 * cols + far)[:, ::-1], axis=1)[:, ::-1]
    across = np.minimum(np.minimum(index - left, right - index), far)
    across = across * across
    out = np.full(mask.shape, far * far, dtype=np.int64)
    for dr in range(-min(reach, rows - 1), min(reach, rows - 1) + 1):
        target = out[max(0, dr) : rows - max(0, -dr)]
        np.minimum(target, across[max(0, -dr) : rows - max(0, dr)] + dr * dr, out=target)
    return out


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _merged(start: BasePose, moves: list[BasePose], max_reverse: float) -> list[BasePose]:
    """`moves` (each a turn on the spot or a straight drive from the one before, the first from
    `start`) without moves that go nowhere, with consecutive turns the same way round (less
    than half a turn together), and consecutive drives the same way along one heading, merged
    into one (backwards only up to `max_reverse` [m] together)."""
    out: list[BasePose] = []
    for move in moves:
        last = out[-1] if out else start
        if _same_place(last, move) and abs(_wrap(move.yaw - last.yaw)) < 1e-9:
            continue
        if out:
            before, last = (out[-2] if len(out) > 1 else start), out[-1]
            if _same_place(before, last) and _same_place(last, move):
                t1, t2 = _wrap(last.yaw - before.yaw), _wrap(move.yaw - last.yaw)
                if t1 * t2 > 0 and abs(t1) + abs(t2) < math.pi - 1e-6:
                    out[-1] = move
                    continue
            elif not _same_place(before, last) and not _same_place(last, move):
                yaw = last.yaw
                same_heading = abs(_wrap(yaw - before.yaw)) < 1e-9 and abs(_wrap(move.yaw - yaw)) < 1e-9
                d1 = (last.x - before.x) * math.cos(yaw) + (last.y - before.y) * math.sin(yaw)
                d2 = (move.x - last.x) * math.cos(yaw) + (move.y - last.y) * math.sin(yaw)
                if same_heading and d1 * d2 > 0 and (d1 > 0 or -(d1 + d2) <= max_reverse + 1e-9):
                    out[-1] = move
                    continue
        out.append(move)
    return out


def _same_place(a: BasePose, b: BasePose) -> bool:
    return math.hypot(a.x - b.x, a.y - b.y) < POSITION_EPS


def _along(yaw: float, direction: float) -> float:
    """`direction` or its opposite, whichever is nearer `yaw` (driving forwards or backwards)."""
    back = _wrap(direction + math.pi)
    return direction if abs(_wrap(direction - yaw)) <= abs(_wrap(back - yaw)) else back


class _Layer:
    """Occupied cells that one outline must keep off (e.g. counters: the base; walls and boxes:
    the whole robot as it stands). The outline is one convex footprint or several (their
    union, e.g. the base and each arm); the first contains the base origin."""

    def __init__(
        self, mask: np.ndarray, outline: Footprint | Sequence[Footprint], grid: OccupancyGrid, margin: float
    ) -> None:
        parts = [outline] if isinstance(outline, Footprint) else list(outline)
        self.mask = mask
        self.edges = [part._edges() for part in parts]
        self.inscribed = parts[0].inscribed_radius
        self.circumscribed = max(part.circumscribed_radius for part in parts)
        self.grid = grid
        self.reach = self.circumscribed + margin

    def hits(self, xs: np.ndarray, ys: np.ndarray, yaws: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
        """Per pose: does the outline's first part (around the base), grown by `margin`, cover
        an occupied cell; does another part?"""
        base, other = np.zeros(len(xs), bool), np.zeros(len(xs), bool)
        reach, g = self.reach, self.grid
        # the occupied cells within reach of the poses' bounding box: a window of the mask
        (ox, oy), res = g.origin, g.resolution
        c0 = max(0, int((float(xs.min()) - reach - ox) / res))
        c1 = min(self.mask.shape[1], int((float(xs.max()) + reach - ox) / res) + 1)
        r0 = max(0, int((float(ys.min()) - reach - oy) / res))
        r1 = min(self.mask.shape[0], int((float(ys.max()) + reach - oy) / res) + 1)
        if c0 >= c1 or r0 >= r1:
            return base, other
        rows, cols = np.nonzero(self.mask[r0:r1, c0:c1])
        if rows.size == 0:
            return base, other
        occ = np.column_stack([ox + (cols + c0 + 0.5) * res, oy + (rows + r0 + 0.5) * res])
        dx = occ[None, :, 0] - xs[:, None]  # poses x occupied cells
        dy = occ[None, :, 1] - ys[:, None]
        pose, cell = np.nonzero(dx * dx + dy * dy <= reach * reach)
        if pose.size == 0:
            return base, other
        c, s = np.cos(yaws[pose]), np.sin(yaws[pose])
        px, py = dx[pose, cell], dy[pose, cell]
        bx, by = c * px + s * py, -s * px + c * py  # into the base frame
        for k, (normals, offsets) in enumerate(self.edges):
            d = np.outer(bx, normals[:, 0]) + np.outer(by, normals[:, 1]) - offsets
            (base if k == 0 else other)[pose[np.all(d <= margin, axis=1)]] = True
        return base, other


@dataclass(frozen=True)
class _Query:
    """What one `PathPlanner.plan` call checks with: the start to move off unchecked (or None)
    and the backend's exact check (or None)."""

    escape: BasePose | None
    exact: PoseCheck | None


class PathPlanner:
    """Plans base paths on ``grid`` for a robot with ``footprint``, keeping ``clearance`` [m].

    ``layers``: more occupied masks (same shape as the grid), each with the outline that must
    keep off it (a footprint, or several whose union it is, the first around the base origin)
    -- e.g. walls that the whole robot, arms included, must pass, while the base alone must
    keep off the counters the arms reach over. ``grid`` (attribute) is the
    union of all. Construction inflates the grid (a few ms); :meth:`plan` is then a pure function of its
    arguments (thread-safe, deterministic). ``cost_weight`` is the extra cost per cell [m/m]
    of passing where the footprint fits only at some headings. ``kinematics``: how the base
    moves (default omnidirectional); for a differential drive every segment of a plan is a
    chain of turns on the spot and straight drives (`pycram.world.base_kinematics`), and
    :meth:`plan` returns those primitives, so that each step of the result is one a
    differential drive makes.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        footprint: Footprint,
        clearance: float = 0.03,
        cost_weight: float = 2.0,
        layers: Sequence[tuple[np.ndarray, Footprint | Sequence[Footprint]]] = (),
        kinematics: BaseKinematics | None = None,
    ) -> None:
        self.kinematics = kinematics or BaseKinematics()
        res = grid.resolution
        # a cell is marked when its centre is under an obstacle: the obstacle may reach half a
        # cell diagonal further, so checks add that to the clearance
        self._margin = clearance + res * SQRT2 / 2.0
        self._layers = [_Layer(grid.occupied, footprint, grid, self._margin)]
        self._layers += [_Layer(mask, fp, grid, self._margin) for mask, fp in layers if mask.any()]
        occupied = grid.occupied.copy()
        for mask, _ in layers:
            occupied |= mask
        self.grid = OccupancyGrid(grid.origin, res, occupied)
        self.footprint, self.clearance, self.cost_weight = footprint, clearance, cost_weight
        half = res * SQRT2 / 2.0
        self.lethal = np.zeros_like(occupied)
        self.caution = np.zeros_like(occupied)
        self._sure_hit = np.zeros_like(occupied)
        sure_not_free = np.zeros_like(occupied)
        for layer in self._layers:
            m = layer.mask
            if not m.any():
                continue
            # the largest radius first: one distance map serves all four
            reach = (layer.circumscribed + self._margin + half) / res
            sure_not_free |= _within(m, reach)
            self.lethal |= _within(m, (layer.inscribed + self._margin) / res)
            self.caution |= _within(m, (layer.circumscribed + self._margin) / res)
            # for single poses anywhere in a cell (up to half a diagonal from its centre)
            self._sure_hit |= _within(m, (layer.inscribed + self._margin - half) / res)
        self._sure_free = ~sure_not_free
        self._turn_radius = max(layer.circumscribed for layer in self._layers)

    # ------------------------------------------------------------------ checks
    def pose_free(self, x: float, y: float, yaw: float, exact_check: PoseCheck | None = None) -> bool:
        """Does the footprint at (x, y, yaw), grown by the clearance, stay off occupied cells?
        Off-map poses count as free (nothing is known there)."""
        return self._free(np.array([x], float), np.array([y], float), np.array([yaw], float), exact_check)

    def _free(self, xs: np.ndarray, ys: np.ndarray, yaws: np.ndarray, exact_check: PoseCheck | None = None) -> bool:
        """Whether every pose (xs[i], ys[i], yaws[i]) is free (see `pose_free`)."""
        g = self.grid
        rows = np.floor((ys - g.origin[1]) / g.resolution).astype(int)
        cols = np.floor((xs - g.origin[0]) / g.resolution).astype(int)
        inside = (rows >= 0) & (rows < g.shape[0]) & (cols >= 0) & (cols < g.shape[1])
        r, c = rows[inside], cols[inside]
        if self._sure_hit[r, c].any():
            return False
        unsure = np.nonzero(inside)[0][~self._sure_free[r, c]]
        if unsure.size == 0:
            return True
        xs, ys, yaws = xs[unsure], ys[unsure], yaws[unsure]
        hit = np.zeros(len(xs), bool)
        for layer in self._layers:
            base, other = layer.hits(xs, ys, yaws, self._margin)
            if base.any():
                return False
            hit |= other
        if exact_check is None:
            return not hit.any()
        # the outlines of the other parts (arms) are convex hulls, larger than the arms: where
        # only they are in the way, the backend's exact check decides
        return all(exact_check(float(xs[i]), float(ys[i]), float(yaws[i])) for i in np.nonzero(hit)[0])

    def _surely_free(self, x: float, y: float) -> bool:
        """Whether the robot at (x, y), at any heading and in any outline of its layers, is
        farther than the clearance from every occupied cell (then no exact check is needed)."""
        g = self.grid
        r = int(math.floor((y - g.origin[1]) / g.resolution))
        c = int(math.floor((x - g.origin[0]) / g.resolution))
        return 0 <= r < g.shape[0] and 0 <= c < g.shape[1] and bool(self._sure_free[r, c])

    def segment_free(
        self, a: BasePose, b: BasePose, escape: BasePose | None = None, exact_check: PoseCheck | None = None
    ) -> bool:
        """Can the base move from ``a`` to ``b`` touching nothing? Omnidirectional: the straight
        drive, turning uniformly; differential: one of the chains of turns and straight drives
        of `pycram.world.base_kinematics.move_options`. Poses within `ESCAPE_RADIUS` of
        ``escape`` are not checked."""
        return self._free_chain(a, b, escape, exact_check) is not None

    def _free_chain(
        self, a: BasePose, b: BasePose, escape: BasePose | None, exact_check: PoseCheck | None
    ) -> list[BasePose] | None:
        """The first chain of `move_options` from ``a`` to ``b`` whose every straight step is
        free (``a`` excluded, ``b`` last), or None."""
        for chain in move_options(a, b, self.kinematics):
            prev, free = a, True
            for pose in chain:
                if not self._straight_free(prev, pose, escape, exact_check):
                    free = False
                    break
                prev = pose
            if free:
                return chain
        return None

    def _straight_free(
        self, a: BasePose, b: BasePose, escape: BasePose | None = None, exact_check: PoseCheck | None = None
    ) -> bool:
        """Is the straight drive from ``a`` to ``b`` (turning uniformly) free everywhere?"""
        dist = math.hypot(b.x - a.x, b.y - a.y)
        dyaw = _wrap(b.yaw - a.yaw)
        # sample so that neither the centre nor a corner moves more than half a cell per step
        step = 0.5 * self.grid.resolution
        turn_step = step if self.kinematics.holonomic else EXACT_TURN_STEP  # it turns on the spot
        n = max(1, int(math.ceil(max(dist / step, abs(dyaw) * self._turn_radius / turn_step))))
        s = np.linspace(0.0, 1.0, n + 1)
        xs, ys, yaws = self._along_move(a, b, s)
        if escape is not None:
            keep = np.hypot(xs - escape.x, ys - escape.y) >= ESCAPE_RADIUS
            if not self.kinematics.holonomic:  # a differential drive escapes straight: its turns are checked
                keep |= np.abs((yaws - escape.yaw + np.pi) % (2.0 * np.pi) - np.pi) > ESCAPE_TURN
            xs, ys, yaws = xs[keep], ys[keep], yaws[keep]
        return self._free(xs, ys, yaws, exact_check)

    def _along_move(self, a: BasePose, b: BasePose, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The poses (xs, ys, yaws) at fractions `s` of the move from ``a`` to ``b``: the straight
        line turning uniformly, or for a differential drive the arc between them (`arc_radius`;
        `arc_point` over arrays)."""
        dyaw = _wrap(b.yaw - a.yaw)
        yaws = a.yaw + s * dyaw
        rho = None if self.kinematics.holonomic else arc_radius(a, b)
        if rho is None:
            return a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), yaws
        return a.x + rho * (np.sin(yaws) - math.sin(a.yaw)), a.y - rho * (np.cos(yaws) - math.cos(a.yaw)), yaws

    def _primitives(
        self, start: BasePose, waypoints: list[BasePose], escape: BasePose | None, exact_check: PoseCheck | None
    ) -> list[BasePose] | None:
        """`waypoints` with each segment replaced by its first free chain of moves (the same
        list for an omnidirectional base), or None when a segment has none. A differential
        drive keeps at an intermediate waypoint the heading it arrives with where it can (it
        turns once there, towards the next one, not twice)."""
        if self.kinematics.holonomic:
            return list(waypoints)
        out: list[BasePose] = []
        prev = start
        for i, w in enumerate(waypoints):
            chain = self._free_chain(prev, w, escape, exact_check)
            if chain is None:
                return None
            if i < len(waypoints) - 1 and len(chain) > 1 and _same_place(chain[-1], chain[-2]):
                chain = chain[:-1]  # no turn to the waypoint's heading: the next segment turns
            out += chain
            prev = chain[-1]
        return out

    # ------------------------------------------------------------------ planning
    def plan(self, start: object, goal: object, exact_check: PoseCheck | None = None) -> list[BasePose]:
        """Waypoints from ``start`` to ``goal`` (start excluded, goal last), each reached by a
        straight, footprint-checked drive from the one before. Raises :class:`NoPathError`.

        ``exact_check(x, y, yaw) -> bool`` (optional, from the backend: e.g. the whole robot in
        its current configuration against the 3D environment) must also hold at the goal and
        every `EXACT_STEP` along the path; where it fails, A* searches again around that spot.
        """
        a, b = as_base_pose(start), as_base_pose(goal)
        g = self.grid
        if not self.pose_free(b.x, b.y, b.yaw, exact_check):
            raise NoPathError(
                "goal_in_collision",
                f"the robot does not fit at the goal (x={b.x:.2f}, y={b.y:.2f}, yaw={b.yaw:.2f})",
                a,
                b,
            )
        escape = None if self.pose_free(a.x, a.y, a.yaw, exact_check) else a
        ctx = _Query(escape, exact_check)
        if self.path_free(a, [b], exact_check):
            return self._primitives(a, [b], escape, exact_check) or [b]
        sc, gc = g.cell(a.x, a.y), g.cell(b.x, b.y)
        for name, cell, pose in (("start", sc, a), ("goal", gc, b)):
            if not g.inside(*cell):
                raise NoPathError(
                    "outside_map", f"the {name} (x={pose.x:.2f}, y={pose.y:.2f}) is off the map of the floor", a, b
                )
        try:
            return self._grid_search(a, b, sc, gc, ctx)
        except NoPathError as exc:
            if self.kinematics.holonomic or exc.reason != "no_path":
                raise
            path = self._lattice(a, b, ctx)  # a differential drive: search headings too
            if path is None:
                raise
            return path

    def _grid_search(
        self, a: BasePose, b: BasePose, sc: tuple[int, int], gc: tuple[int, int], ctx: _Query
    ) -> list[BasePose]:
        """A* over the cells, headings along the cell path, shortening (steps 2-3 of the module
        docstring). Raises `NoPathError`."""
        g, escape, exact_check = self.grid, ctx.escape, ctx.exact
        bad: set[tuple[int, int]] = set()
        for _attempt in range(MAX_SEARCHES):
            cells = self._astar(sc, gc, bad, escape is None)
            if cells is None:
                raise NoPathError(
                    "no_path",
                    f"no collision-free path from (x={a.x:.2f}, y={a.y:.2f}) to (x={b.x:.2f}, y={b.y:.2f})",
                    a,
                    b,
                )
            path, misfits = self._shorten(a, b, cells, ctx)
            if not misfits:
                moves = self._primitives(a, path, escape, exact_check)
                if moves is None:  # a differential drive cannot make a step of it
                    raise NoPathError("no_path", "no path with the turns a differential drive can make", a, b)
                path = moves
                hit = self._exact_hit(a, path, escape, exact_check)
                if hit is None:
                    return path
                r, c = g.cell(*hit)  # the robot touches something there: keep its centre away
                k = EXACT_BLOCK_CELLS
                misfits = {
                    (rr, cc)
                    for rr in range(r - k, r + k + 1)
                    for cc in range(c - k, c + k + 1)
                    if g.inside(rr, cc) and (rr, cc) not in (sc, gc)
                }
            bad |= misfits  # the footprint fits there at no heading (or cannot turn there)
        raise NoPathError("no_path", "no path where the robot fits at the headings it needs", a, b)

    def _lattice(self, a: BasePose, b: BasePose, ctx: _Query) -> list[BasePose] | None:
        """A differential drive's path from ``a`` to ``b`` by A* over poses (x, y and one of
        `LATTICE_HEADINGS` headings): steps of `LATTICE_STEP` and arcs of `LATTICE_ARC` (turning
        by one heading), forwards or backwards (backwards costing `LATTICE_REVERSE_COST` times
        more), and turns on the spot by one heading; from
        every pose within `LATTICE_SHOT` of the goal, the moves of `move_options` straight to
        it are tried. Each step is checked as `segment_free` checks. Finds the way out of a
        corner that needs backing up before turning, which the cell search cannot (it knows no
        headings). None when `LATTICE_EXPANSIONS` poses are expanded without reaching the goal."""
        n, res = LATTICE_HEADINGS, LATTICE_STEP
        unit = 2.0 * math.pi / n
        turn_cost = self._turn_radius * unit
        escape, exact = ctx.escape, ctx.exact

        def key(p: BasePose, h: int) -> tuple[int, int, int]:
            return (round(p.x / res), round(p.y / res), h % n)

        h0 = round(a.yaw / unit)
        first = a  # straight steps keep a pose's own heading; turns go to the lattice's
        k0 = key(first, h0)
        best: dict[tuple[int, int, int], float] = {k0: 0.0}
        parent: dict[tuple[int, int, int], tuple[int, int, int]] = {}  # the start has none
        poses: dict[tuple[int, int, int], tuple[BasePose, int]] = {k0: (first, h0)}
        heap = [(math.hypot(b.x - a.x, b.y - a.y), 0.0, k0)]
        expanded = 0
        while heap and expanded < LATTICE_EXPANSIONS:
            _f, cost, k = heapq.heappop(heap)
            if cost > best[k]:
                continue
            expanded += 1
            pose, h = poses[k]
            if math.hypot(b.x - pose.x, b.y - pose.y) <= LATTICE_SHOT:
                shot = self._free_chain(pose, b, escape, exact)
                if shot is not None:
                    back: list[BasePose] = []
                    node = k
                    while node in parent:
                        back.append(poses[node][0])
                        node = parent[node]
                    return _merged(a, back[::-1] + shot, self.kinematics.max_reverse)
            yaw = pose.yaw
            dx, dy = LATTICE_STEP * math.cos(yaw), LATTICE_STEP * math.sin(yaw)
            steps = [
                (BasePose(pose.x + dx, pose.y + dy, yaw), h, LATTICE_STEP),
                (BasePose(pose.x - dx, pose.y - dy, yaw), h, LATTICE_STEP * LATTICE_REVERSE_COST),
                (BasePose(pose.x, pose.y, (h + 1) * unit), h + 1, turn_cost),
                (BasePose(pose.x, pose.y, (h - 1) * unit), h - 1, turn_cost),
            ]
            for turn in (1, -1):  # arcs: one heading over `LATTICE_ARC` of way, forwards and back
                for way, weight in ((LATTICE_ARC, 1.0), (-LATTICE_ARC, LATTICE_REVERSE_COST)):
                    end = (h + turn) * unit
                    rho = way / (end - yaw)
                    arc = BasePose(*arc_point(pose.x, pose.y, yaw, rho, end), end)
                    steps.append((arc, h + turn, LATTICE_ARC * weight))
            for nxt, nh, step_cost in steps:
                nk = key(nxt, nh)
                ncost = cost + step_cost
                if ncost >= best.get(nk, math.inf):
                    continue
                if not self._straight_free(pose, nxt, escape, exact):
                    continue
                best[nk], parent[nk], poses[nk] = ncost, k, (nxt, nh)
                heapq.heappush(heap, (ncost + math.hypot(b.x - nxt.x, b.y - nxt.y), ncost, nk))
        return None

    def path_free(self, start: BasePose, waypoints: list[BasePose], exact_check: PoseCheck | None = None) -> bool:
        """Is driving from ``start`` through ``waypoints`` free (footprint, and ``exact_check``)?
        For a differential drive, each segment by one of its chains of moves."""
        escape = None if self.pose_free(start.x, start.y, start.yaw, exact_check) else start
        moves = self._primitives(start, waypoints, escape, exact_check)
        if moves is None:  # a differential drive: no free chain (its chains are checked)
            return False
        if self.kinematics.holonomic:
            prev = start
            for w in moves:
                if not self._straight_free(prev, w, escape, exact_check):
                    return False
                prev = w
        return self._exact_hit(start, moves, escape, exact_check) is None

    def _exact_hit(
        self, start: BasePose, waypoints: list[BasePose], escape: BasePose | None, exact_check: PoseCheck | None
    ) -> tuple[float, float] | None:
        """The first (x, y) along the path where ``exact_check`` fails, or None."""
        if exact_check is None:
            return None
        prev = start
        for w in waypoints:
            dist = math.hypot(w.x - prev.x, w.y - prev.y)
            dyaw = _wrap(w.yaw - prev.yaw)
            step = EXACT_STEP if self.kinematics.holonomic else EXACT_TURN_STEP
            n = max(1, int(math.ceil(max(dist / EXACT_STEP, abs(dyaw) * self._turn_radius / step))))
            xs, ys, yaws = self._along_move(prev, w, np.arange(1, n + 1) / n)
            for x, y, yaw in zip(xs.tolist(), ys.tolist(), yaws.tolist()):
                if self._escaping(escape, x, y, yaw):
                    continue
                if self._surely_free(x, y):  # no layer's obstacle within any outline's reach
                    continue
                if not exact_check(x, y, yaw):
                    return (x, y)
            prev = w
        return None

    def _escaping(self, escape: BasePose | None, x: float, y: float, yaw: float) -> bool:
        """Whether the pose (x, y, yaw) is part of getting clear from `escape` (unchecked): within
        `ESCAPE_RADIUS` of it, and for a differential drive also within `ESCAPE_TURN` of its
        heading (it backs off or drives on straight; a turn on the spot would sweep whatever
        it touches)."""
        if escape is None or math.hypot(x - escape.x, y - escape.y) >= ESCAPE_RADIUS:
            return False
        return self.kinematics.holonomic or abs(_wrap(yaw - escape.yaw)) <= ESCAPE_TURN

    def _astar(
        self, sc: tuple[int, int], gc: tuple[int, int], bad: set[tuple[int, int]], start_free: bool
    ) -> list[tuple[int, int]] | None:
        rows, cols = self.lethal.shape
        passable = ~self.lethal
        if not start_free:
            # the robot already touches something: let it move off through the cells nearby
            k = int(math.ceil(ESCAPE_RADIUS / self.grid.resolution))
            r, c = sc
            passable[max(0, r - k) : r + k + 1, max(0, c - k) : c + k + 1] = True
        for cell in bad:
            passable[cell] = False
        passable[sc] = passable[gc] = True
        free = passable.ravel().tolist()
        penalty = (self.caution & passable).ravel().tolist()
        w = self.cost_weight
        start, goal = sc[0] * cols + sc[1], gc[0] * cols + gc[1]
        gr, gcl = gc
        neighbours = (
            (1, 0, 1.0),
            (-1, 0, 1.0),
            (0, 1, 1.0),
            (0, -1, 1.0),
            (1, 1, SQRT2),
            (1, -1, SQRT2),
            (-1, 1, SQRT2),
            (-1, -1, SQRT2),
        )
        best = [math.inf] * (rows * cols)
        parent = [-1] * (rows * cols)
        best[start] = 0.0
        heap = [(0.0, 0.0, start)]
        push, pop = heapq.heappush, heapq.heappop
        while heap:
            _f, cost, node = pop(heap)
            if node == goal:
                out = []
                while node != start:
                    out.append(divmod(node, cols))
                    node = parent[node]
                out.append(sc)
                return out[::-1]
            if cost > best[node]:
                continue  # a stale entry: the node was reached more cheaply since
            r, c = divmod(node, cols)
            for dr, dc, step in neighbours:
                nr, nc = r + dr, c + dc
                if nr < 0 or nr >= rows or nc < 0 or nc >= cols:
                    continue
                n = nr * cols + nc
                if not free[n]:
                    continue
                if dr and dc and not (free[r * cols + nc] and free[nr * cols + c]):
                    continue  # no corner cutting
                ncost = cost + step * (1.0 + w * penalty[n])
                if ncost < best[n]:
                    best[n] = ncost
                    parent[n] = node
                    ddr, ddc = abs(nr - gr), abs(nc - gcl)
                    h = (ddr + ddc) + (SQRT2 - 2.0) * min(ddr, ddc)
                    push(heap, (ncost + HEURISTIC_WEIGHT * h, ncost, n))
        return None

    def _shorten(
        self, a: BasePose, b: BasePose, cells: list[tuple[int, int]], ctx: _Query
    ) -> tuple[list[BasePose], set[tuple[int, int]]]:
        """Poses along the cell path, shortened greedily, or the cells to block and search again.

        Headings: the first of these profiles in which every step of the cell path is free --
        turning uniformly along the path, turning at the start, turning at the end -- where at
        each cell the nearest heading (steps of pi/16) that fits replaces the profile's when that
        one does not fit. When none is free, the cells where the best profile failed are returned.
        """
        pts = [(a.x, a.y)] + [self.grid.center(r, c) for r, c in cells[1:-1]] + [(b.x, b.y)]
        lengths = [0.0]
        for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
            lengths.append(lengths[-1] + math.hypot(x1 - x0, y1 - y0))
        total = lengths[-1] or 1.0
        dyaw = _wrap(b.yaw - a.yaw)
        profiles: tuple[Callable[[float], float], ...] = (
            lambda s: a.yaw + dyaw * s,
            lambda s: a.yaw + dyaw,
            lambda s: a.yaw,
        )
        if not self.kinematics.holonomic:
            profiles = profiles[:1]  # a differential drive faces the way it goes (`_headed`)
        fewest: set[tuple[int, int]] | None = None
        for profile in profiles:
            poses, bad = self._headed(a, b, pts, lengths, total, cells, profile, ctx)
            if not bad:
                return self._greedy(poses, ctx), bad
            if fewest is None or len(bad) < len(fewest):
                fewest = bad
        return [], fewest or set()

    def _headed(
        self,
        a: BasePose,
        b: BasePose,
        pts: list[tuple[float, float]],
        lengths: list[float],
        total: float,
        cells: list[tuple[int, int]],
        profile: Callable[[float], float],
        ctx: _Query,
    ) -> tuple[list[BasePose], set[tuple[int, int]]]:
        poses = [a]
        bad: set[tuple[int, int]] = set()
        for i in range(1, len(pts) - 1):
            (x, y), yaw = pts[i], profile(lengths[i] / total)
            if not self.kinematics.holonomic:  # a differential drive faces the way it goes, or away
                yaw = _along(poses[-1].yaw, math.atan2(y - pts[i - 1][1], x - pts[i - 1][0]))
            fitting = self._fitting_yaw(x, y, yaw, ctx)
            if fitting is None:
                bad.add(cells[i])
            poses.append(BasePose(x, y, yaw if fitting is None else fitting))
        poses.append(b)
        if not bad:
            for i in range(len(poses) - 1):  # every raw step must be free (turns included)
                if not self.segment_free(poses[i], poses[i + 1], ctx.escape, ctx.exact):
                    bad.update(cells[j] for j in (i, i + 1) if 0 < j < len(cells) - 1)
        return poses, bad

    def _greedy(self, poses: list[BasePose], ctx: _Query) -> list[BasePose]:
        """From each pose on, a far later pose reachable on a free straight segment: the last
        pose if it is, else one found by bisection (free, with the next one not free from
        there). Consecutive poses are known to be connected by free segments."""
        out: list[BasePose] = []
        i, n = 0, len(poses)
        while i < n - 1:
            lo, hi = i + 1, n - 1
            if self.segment_free(poses[i], poses[hi], ctx.escape, ctx.exact):
                lo = hi
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if self.segment_free(poses[i], poses[mid], ctx.escape, ctx.exact):
                    lo = mid
                else:
                    hi = mid
            out.append(poses[lo])
            i = lo
        return out

    def _fitting_yaw(self, x: float, y: float, yaw: float, ctx: _Query) -> float | None:
        """`yaw` if the footprint fits there at it, else the nearest heading (in steps of
        pi/16) that fits, else None."""
        if self._escaping(ctx.escape, x, y, yaw):
            return yaw
        for k in range(17):
            for sign in (1,) if k == 0 else (1, -1):
                candidate = yaw + sign * k * math.pi / 16
                if self.pose_free(x, y, candidate, ctx.exact):
                    return candidate
        return None
