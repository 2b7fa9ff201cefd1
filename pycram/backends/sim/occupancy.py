"""The floor as the base sees it: occupancy grids rasterized from a scene, and the base footprint.

The environment's collision geometry (`Scene.environment_geoms`) is split once per scene into
*static* geoms (on bodies welded to the world) and *movable* ones (mocap obstacles, doors,
drawers). The static part is rasterized once; the movable part is rasterized from the current
state whenever it changed. A geom counts where it could touch the robot: between the floor
and `MAX_HEIGHT`; its outline on the floor is the convex hull of its vertices (boxes: corners,
meshes: mesh vertices, other shapes: their bounding box).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from pycram.world.navigation import Footprint, OccupancyGrid

from .scene import Scene

#: Geoms entirely above this height [m] or below `MIN_HEIGHT` do not block the base.
MAX_HEIGHT = 2.0
MIN_HEIGHT = 0.01
#: Grid cell size [m] and the margin [m] of the grid around the environment.
RESOLUTION = 0.05
MAP_MARGIN = 2.0
#: Height bands [m] of obstacles (see `FloorMap`).
BAND = 0.1
#: Directions along which outlines of many points are sampled (see `planar_extremes`).
EXTREME_DIRECTIONS = 64

#: (directions, digest of a mesh's vertices) -> the indices `local_vertices` keeps of them.
_EXTREMES: dict[tuple[int, bytes], np.ndarray] = {}

_UNIT_BOX = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)


def local_vertices(model: mujoco.MjModel, geom: int, directions: int = 0) -> np.ndarray:
    """Points (n x 3, geom frame [m]) whose convex hull is `geom`; with `directions` > 0, only
    the mesh vertices farthest along that many directions spread over the sphere (a polytope
    inscribed in the hull, for speed)."""
    gtype = model.geom_type[geom]
    if gtype == mujoco.mjtGeom.mjGEOM_MESH and model.geom_dataid[geom] >= 0:
        mesh = int(model.geom_dataid[geom])
        adr, num = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        local = np.asarray(model.mesh_vert[adr : adr + num], float)
        if directions and num > directions:
            key = (directions, hashlib.blake2b(local.tobytes(), digest_size=16).digest())
            chosen = _EXTREMES.get(key)
            if chosen is None:  # the same mesh in the next scene (a robot's links) is not searched again
                k = np.arange(directions) + 0.5  # a Fibonacci sphere
                z = 1.0 - 2.0 * k / directions
                phi = np.pi * (1.0 + 5**0.5) * k
                r = np.sqrt(1.0 - z * z)
                dirs = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
                chosen = _EXTREMES[key] = np.unique(np.argmax(local @ dirs.T, axis=0))
            local = local[chosen]
        return local
    if gtype == mujoco.mjtGeom.mjGEOM_BOX:
        return _UNIT_BOX * model.geom_size[geom]
    center, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]  # the bounding box
    return center + _UNIT_BOX * half


def geom_vertices(model: mujoco.MjModel, data: mujoco.MjData, geom: int, local: np.ndarray | None = None) -> np.ndarray:
    """Points (n x 3, map frame [m]) whose convex hull contains `geom` at its current pose
    (`local`: its points in the geom frame, when already known)."""
    if local is None:
        local = local_vertices(model, geom)
    rot = data.geom_xmat[geom].reshape(3, 3)
    return local @ rot.T + data.geom_xpos[geom]


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (k x 2) of planar `points` (n x 2), monotone chain."""
    pts = sorted(set(map(tuple, np.round(points, 6))))
    if len(pts) <= 2:
        return np.asarray(pts, float)

    def half(seq: list) -> list:
        out: list = []
        for p in seq:
            while (
                len(out) >= 2
                and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1]) - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0]))
                <= 0
            ):
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.asarray(lower[:-1] + upper[:-1], float)


def _fill_polygon(mask: np.ndarray, origin: tuple[float, float], res: float, hull: np.ndarray) -> None:
    """Mark the cells of `mask` whose centres lie inside the convex polygon `hull` (ccw)."""
    if len(hull) < 3:
        return
    rows, cols = mask.shape
    c0 = max(0, int(math.floor((hull[:, 0].min() - origin[0]) / res)))
    c1 = min(cols, int(math.ceil((hull[:, 0].max() - origin[0]) / res)) + 1)
    r0 = max(0, int(math.floor((hull[:, 1].min() - origin[1]) / res)))
    r1 = min(rows, int(math.ceil((hull[:, 1].max() - origin[1]) / res)) + 1)
    if r0 >= r1 or c0 >= c1:
        return
    xs = origin[0] + (np.arange(c0, c1) + 0.5) * res
    ys = origin[1] + (np.arange(r0, r1) + 0.5) * res
    X, Y = np.meshgrid(xs, ys)
    inside = np.ones_like(X, bool)
    for (x0, y0), (x1, y1) in zip(hull, np.roll(hull, -1, axis=0)):
        inside &= (x1 - x0) * (Y - y0) - (y1 - y0) * (X - x0) >= -1e-9
    mask[r0:r1, c0:c1] |= inside


@dataclass(frozen=True)
class FloorMap:
    """A scene's floor: the grid geometry, the static occupancy by height band and the movable
    geoms.

    Occupancy comes in bands by the height of the obstacles' tops (`BAND` steps): the part of
    the robot below an obstacle's top must keep off it, so a counter keeps the base away while
    the arms reach over it, and a wall keeps the whole robot away.
    """

    origin: tuple[float, float]
    resolution: float
    static: dict[float, np.ndarray]  # band top [m] -> cells under static geoms of that band
    movable_geoms: tuple[int, ...]
    #: what to compare to notice that a movable geom moved: mocap ids and joint qpos addresses
    mocap_ids: tuple[int, ...]
    qpos_addresses: tuple[int, ...]
    shape: tuple[int, int] = (0, 0)

    def bands(self, model: mujoco.MjModel, data: mujoco.MjData) -> dict[float, np.ndarray]:
        """Band top [m] -> occupied cells, static and movable (in the state of `data`,
        kinematics computed), lowest band first."""
        out = {top: mask.copy() for top, mask in self.static.items()}
        for g in self.movable_geoms:
            _add(out, self, model, data, g)
        return dict(sorted(out.items()))

    def grid(self, model: mujoco.MjModel, data: mujoco.MjData) -> OccupancyGrid:
        """The occupancy grid of the state in `data` (kinematics computed): all bands."""
        mask = np.zeros(self.shape, bool)
        for band in self.bands(model, data).values():
            mask |= band
        return OccupancyGrid(self.origin, self.resolution, mask)

    def movable_state(self, data: mujoco.MjData) -> np.ndarray:
        """The part of the state that moves movable geoms (to notice changes cheaply)."""
        return np.concatenate(
            [
                data.mocap_pos[list(self.mocap_ids)].ravel(),
                data.mocap_quat[list(self.mocap_ids)].ravel(),
                data.qpos[list(self.qpos_addresses)],
            ]
        )


def band_top(z: float) -> float:
    """The top [m] of the height band of an obstacle whose top is at `z` [m]."""
    return min(MAX_HEIGHT, math.ceil(z / BAND - 1e-9) * BAND)


def _add(
    bands: dict[float, np.ndarray], floor: FloorMap, model: mujoco.MjModel, data: mujoco.MjData, geom: int
) -> None:
    """Rasterize `geom` into the band of its top (if it can touch the robot at all)."""
    verts = geom_vertices(model, data, geom)
    if verts[:, 2].max() < MIN_HEIGHT or verts[:, 2].min() > MAX_HEIGHT:
        return
    mask = bands.setdefault(band_top(float(verts[:, 2].max())), np.zeros(floor.shape, bool))
    _fill_polygon(mask, floor.origin, floor.resolution, convex_hull(verts[:, :2]))


def _moves(model: mujoco.MjModel, body: int) -> bool:
    """Whether `body` can move: it (or an ancestor) is a mocap body or has joints."""
    while body > 0:
        if model.body_mocapid[body] >= 0 or model.body_jntnum[body] > 0:
            return True
        body = int(model.body_parentid[body])
    return False


def build_floor_map(
    scene: Scene, data: mujoco.MjData, resolution: float = RESOLUTION, margin: float = MAP_MARGIN
) -> FloorMap:
    """Rasterize the static environment of `scene` (state `data`, kinematics computed)."""
    model = scene.model
    env = sorted(scene.environment_geoms)
    movable = tuple(g for g in env if _moves(model, int(model.geom_bodyid[g])))
    static = [g for g in env if g not in movable]
    pts = [geom_vertices(model, data, g) for g in static]
    pts = [p for p in pts if p[:, 2].max() >= MIN_HEIGHT and p[:, 2].min() <= MAX_HEIGHT]
    allp = np.vstack(pts) if pts else np.zeros((1, 3))
    lo, hi = allp[:, :2].min(axis=0) - margin, allp[:, :2].max(axis=0) + margin
    origin = (float(lo[0]), float(lo[1]))
    shape = (int(math.ceil((hi[1] - lo[1]) / resolution)), int(math.ceil((hi[0] - lo[0]) / resolution)))
    floor = FloorMap(origin, resolution, {}, (), (), (), shape)
    for g in static:
        _add(floor.static, floor, model, data, g)
    mocaps: set[int] = set()
    qadr: set[int] = set()
    for g in movable:
        b = int(model.geom_bodyid[g])
        while b > 0:
            if model.body_mocapid[b] >= 0:
                mocaps.add(int(model.body_mocapid[b]))
            for j in range(int(model.body_jntadr[b]), int(model.body_jntadr[b] + model.body_jntnum[b])):
                qadr.update(
                    range(
                        int(model.jnt_qposadr[j]),
                        int(model.jnt_qposadr[j])
                        + (7 if model.jnt_type[j] == 0 else 4 if model.jnt_type[j] == 1 else 1),
                    )
                )
            b = int(model.body_parentid[b])
    return FloorMap(
        origin,
        resolution,
        dict(sorted(floor.static.items())),
        movable,
        tuple(sorted(mocaps)),
        tuple(sorted(qadr)),
        shape,
    )


def base_footprint(scene: Scene, data: mujoco.MjData) -> Footprint:
    """The outline of the robot's base collision geoms (description: `BASE['collision_links']`)
    on the floor, in the base frame: the convex hull of their vertices."""
    model = scene.model
    mount = scene.body(scene.description.ROOT_LINK)
    rot, pos = data.xmat[mount].reshape(3, 3), data.xpos[mount]
    pts = np.vstack([(geom_vertices(model, data, g) - pos) @ rot for g in sorted(scene.base_geoms)])
    hull = convex_hull(pts[:, :2])
    return Footprint(tuple((float(x), float(y)) for x, y in hull))


def planar_extremes(points: np.ndarray, directions: int = EXTREME_DIRECTIONS) -> np.ndarray:
    """The points of `points` (n x 2) farthest along each of `directions` evenly spread
    directions: the corners of a polygon inscribed in their convex hull, off by at most
    r (1 - cos(pi / directions)) at distance r (0.1 % with 64 directions)."""
    angles = np.arange(directions) * (2.0 * np.pi / directions)
    dirs = np.column_stack([np.cos(angles), np.sin(angles)])
    return points[np.unique(np.argmax(points @ dirs.T, axis=0))]


def robot_parts(scene: Scene, directions: int = 500) -> list[dict[int, np.ndarray]]:
    """The robot's collision geoms in parts whose outlines are taken separately -- the base
    with torso and head first, then each arm (the geoms below its first joint) -- each as
    geom -> local points (see `local_vertices`); computed once per scene."""
    model = scene.model
    arm_bodies = []
    for arm in scene.description.ARMS.values():
        root = int(model.jnt_bodyid[scene.joint_id(arm["joints"][0])])
        arm_bodies.append({b for b in range(model.nbody) if descends(model, b, root)})
    parts: list[dict[int, np.ndarray]] = [{} for _ in range(len(arm_bodies) + 1)]
    for g in sorted(scene.robot_geoms | scene.base_geoms):
        body = int(model.geom_bodyid[g])
        k = next((i + 1 for i, bodies in enumerate(arm_bodies) if body in bodies), 0)
        parts[k][g] = local_vertices(model, g, directions)
    return parts


def descends(model: mujoco.MjModel, body: int, ancestor: int) -> bool:
    """Whether `body` is `ancestor` or below it in the kinematic tree."""
    while body > 0:
        if body == ancestor:
            return True
        body = int(model.body_parentid[body])
    return False


def body_outline(
    scene: Scene, data: mujoco.MjData, below: float, parts: list[dict[int, np.ndarray]]
) -> list[Footprint]:
    """The outline on the floor, in the base frame, of the robot as it stands in `data`: one
    convex footprint per part of `robot_parts` (the base's first, always including the base
    geoms), counting only the parts of the geoms below `below` [m]."""
    return body_outlines(scene, data, [below], parts)[below]


def body_outlines(
    scene: Scene, data: mujoco.MjData, belows: Sequence[float], parts: list[dict[int, np.ndarray]]
) -> dict[float, list[Footprint]]:
    """`body_outline` for each height of `belows` [m], the same footprints at a fraction of the
    cost: each geom's points are placed once, and a part's outline is taken once for all the
    heights that keep the same points of each of its geoms."""
    model = scene.model
    mount = scene.body(scene.description.ROOT_LINK)
    rot, pos = data.xmat[mount].reshape(3, 3), data.xpos[mount]
    out: dict[float, list[Footprint]] = {below: [] for below in belows}
    heights = np.asarray(belows, float)
    for k, part in enumerate(parts):
        # each geom's points, and how many of them are below each height (all: the base's own)
        placed, counts = [], []
        for g, local in part.items():
            verts = geom_vertices(model, data, g, local)
            whole = k == 0 and g in scene.base_geoms
            placed.append((g, verts, whole))
            counts.append(
                np.full(len(heights), len(verts)) if whole else np.searchsorted(np.sort(verts[:, 2]), heights, "right")
            )
        kept_per_height = np.array(counts).T.tolist() if counts else [[] for _ in belows]
        extremes: dict[tuple[int, int], np.ndarray] = {}  # (geom, points kept) -> their extremes
        hulls: dict[tuple[int, ...], Footprint | None] = {}  # points kept per geom -> the outline
        for below, kept_list in zip(belows, kept_per_height):
            kept = tuple(kept_list)
            if kept not in hulls:
                pts = []
                for (g, verts, whole), n in zip(placed, kept):
                    if not n:
                        continue
                    ext = extremes.get((g, n))
                    if ext is None:
                        chosen = verts if whole else verts[verts[:, 2] <= below]
                        ext = extremes[(g, n)] = planar_extremes(((chosen - pos) @ rot)[:, :2])
                    pts.append(ext)
                hull = convex_hull(planar_extremes(np.vstack(pts))) if pts else np.zeros((0, 2))
                hulls[kept] = Footprint(tuple((float(x), float(y)) for x, y in hull)) if len(hull) >= 3 else None
            footprint = hulls[kept]
            if footprint is not None:
                out[below].append(footprint)
    return out
