"""A kitchen built from primitives: two counters with cooker areas, walls, free floor.

The layout follows the thesis' demo (ch. 4): cooker #2 is on the counter along the back wall
(y < -1 m), cooker #1 on the counter along the left wall (x < -0.55 m); the floor between them is
free to drive on. All numbers in [m], map frame, z up. Counter tops are at `COUNTER_HEIGHT`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from . import collision

#: Height of the kitchen counters' tops [m].
COUNTER_HEIGHT = 0.9  # [m]


@dataclass(frozen=True)
class Box:
    """A static box: name, centre [m], half sizes [m], RGBA colour."""

    name: str
    center: tuple[float, float, float]
    half: tuple[float, float, float]
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class Cooker:
    """A cooker area (a burner disc on a counter top): name, centre on the top [m], radius [m]."""

    name: str
    center: tuple[float, float, float]
    radius: float


H = COUNTER_HEIGHT / 2.0
COUNTERS = (
    Box("counter_back", (0.2, -1.3, H), (1.2, 0.3, H), (0.82, 0.80, 0.76, 1)),
    Box("counter_left", (-0.85, 2.1, H), (0.3, 1.1, H), (0.82, 0.80, 0.76, 1)),
)
WALLS = (
    Box("wall_back", (0.9, -1.65, 1.1), (2.1, 0.05, 1.1), (0.93, 0.92, 0.88, 1)),
    Box("wall_left", (-1.2, 1.0, 1.1), (0.05, 2.7, 1.1), (0.93, 0.92, 0.88, 1)),
    Box("fridge", (1.75, -1.25, 0.9), (0.35, 0.35, 0.9), (0.75, 0.78, 0.8, 1)),
)
#: The kitchen's cookers (name, centre of the hob [m], radius [m]); the demo carries the item
#: from cooker #2 to cooker #1.
COOKERS = (
    Cooker("cooker #1", (-0.72, 1.9, COUNTER_HEIGHT), 0.11),
    Cooker("cooker #2", (0.1, -1.2, COUNTER_HEIGHT), 0.11),
)
#: The stove plates around the cookers (dark, flat).
STOVES = (
    Box("stove_1", (-0.8, 1.9, COUNTER_HEIGHT + 0.002), (0.25, 0.3, 0.002), (0.12, 0.12, 0.13, 1)),
    Box("stove_2", (0.1, -1.3, COUNTER_HEIGHT + 0.002), (0.3, 0.25, 0.002), (0.12, 0.12, 0.13, 1)),
)
#: Axis-aligned region of free floor (x_min, y_min, x_max, y_max) [m].
FREE_FLOOR = (-0.45, -0.9, 3.0, 3.5)

#: Where the fixed overview camera sits and what it looks at [m].
OVERVIEW_CAMERA = {"name": "overview", "position": (3.4, 3.6, 3.2), "target": (-0.1, 0.2, 0.5), "fovy": 60.0}

N_OBSTACLES = 3
OBSTACLE_PARKING = (20.0, 20.0, -5.0)  # [m] where unused obstacles wait (far away, below ground)


def look_at_quat(position: tuple[float, float, float], target: tuple[float, float, float]) -> list[float]:
    """Quaternion (w, x, y, z) of a MuJoCo camera at `position` looking at `target`, z up."""
    import numpy as np

    forward = np.asarray(target, float) - np.asarray(position, float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    mat = np.column_stack([right, up, -forward])  # camera x, y, z axes in the world
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat.flatten())
    return quat.tolist()


def _box(body: mujoco.MjsBody, box: Box, group: int | None) -> mujoco.MjsGeom:
    geom = body.add_geom(name=box.name, type=mujoco.mjtGeom.mjGEOM_BOX, pos=list(box.center),
                         size=list(box.half), rgba=list(box.rgba))
    if group is None:
        geom.contype = 0
        geom.conaffinity = 0
    else:
        collision.set_group(geom, group)
    return geom


def add_kitchen(spec: mujoco.MjSpec) -> None:
    """Add floor, lights, counters, cookers, walls, obstacles and the overview camera to `spec`."""
    world = spec.worldbody
    tex = spec.add_texture(name="floor_tex", type=mujoco.mjtTexture.mjTEXTURE_2D,
                           builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER, width=256, height=256,
                           rgb1=[0.62, 0.6, 0.55], rgb2=[0.52, 0.5, 0.46])
    mat = spec.add_material(name="floor_mat", texrepeat=[8, 8], reflectance=0.0)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    floor = world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[6, 6, 0.1],
                           pos=[1.0, 1.0, 0.0], material="floor_mat")
    collision.set_group(floor, collision.FLOOR)
    world.add_light(name="sun", pos=[1.0, 0.5, 4.0], dir=[-0.2, 0.1, -1.0], castshadow=False,
                    diffuse=[0.7, 0.7, 0.7], ambient=[0.25, 0.25, 0.25])
    kitchen = world.add_body(name="kitchen")
    for box in COUNTERS + WALLS:
        _box(kitchen, box, collision.ENVIRONMENT)
    for box in STOVES:
        _box(kitchen, box, None)
    for cooker in COOKERS:
        x, y, z = cooker.center
        g = kitchen.add_geom(name=cooker.name, type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                             pos=[x, y, z + 0.005], size=[cooker.radius, 0.002, 0],
                             rgba=[0.55, 0.08, 0.05, 1])
        g.contype = 0
        g.conaffinity = 0
        kitchen.add_site(name=cooker.name, pos=[x, y, z], size=[0.01, 0.01, 0.01], rgba=[0, 0, 0, 0])
    for i in range(N_OBSTACLES):
        body = world.add_body(name=f"obstacle_{i}", mocap=True, pos=list(OBSTACLE_PARKING))
        g = body.add_geom(name=f"obstacle_{i}", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.15, 0.15, 0.5],
                          pos=[0, 0, 0.5], rgba=[0.9, 0.5, 0.1, 1])
        collision.set_group(g, collision.ENVIRONMENT)
    cam = OVERVIEW_CAMERA
    world.add_camera(name=cam["name"], pos=list(cam["position"]), fovy=cam["fovy"],
                     quat=look_at_quat(cam["position"], cam["target"]))


def cooker_positions() -> dict[str, tuple[float, float, float]]:
    """Centre of each cooker area on its counter top [m], by name."""
    return {c.name: c.center for c in COOKERS}


def yaw_facing(from_xy: tuple[float, float], to_xy: tuple[float, float]) -> float:
    """Yaw [rad] of a base at `from_xy` facing `to_xy`."""
    return math.atan2(to_xy[1] - from_xy[1], to_xy[0] - from_xy[0])
