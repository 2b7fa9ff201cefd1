"""Turning an environment description (`pycram.world.environment.Environment`) into MuJoCo geometry.

Static boxes become geoms of one fixed body named "environment" (collision group ENVIRONMENT, or
no collision for decoration); cookers become dark red discs; every open surface gets a site at
its centre named after it. Each container becomes a body of its own: a drawer (bottom and four
walls) on a slide joint, or a door panel on a hinge, with a handle bar, a site at the handle's
grasp point, joint damping and friction loss (so it moves only when pulled hard enough and stays
where it is left), and an inactive joint equality that makes it "stuck" when activated. The
builder also adds the floor, a light, the overview camera, a top-down plan camera and parked
obstacles.
"""

from __future__ import annotations

import mujoco
import numpy as np

from pycram.world.environment import Box, Container, Environment

from . import collision

#: How many movable obstacles every scene holds for `World.place_obstacle` (parked when unused).
N_OBSTACLES = 3
#: Where unused obstacles wait [m]: far away, below the ground.
OBSTACLE_PARKING = (20.0, 20.0, -5.0)  # [m] where unused obstacles wait (far away, below ground)
_COOKER_RGBA = [0.55, 0.08, 0.05, 1]
_HANDLE_RGBA = [0.35, 0.35, 0.38, 1]
#: Drawer and door bodies are wood-like [kg/m^3].
_FURNITURE_DENSITY = 400.0
_HANDLE_STANDOFF = 0.04  # [m] between a front panel and its handle bar
#: An orthographic camera looking straight down on the whole environment (image up: +y).
PLAN_CAMERA = "plan"
PLAN_CAMERA_HEIGHT = 8.0  # [m]
#: Width / height of images of the plan camera.
PLAN_ASPECT = 4.0 / 3.0  # width / height of images of the plan camera


def stuck_equality(container: str) -> str:
    """Name of the (normally inactive) joint equality that holds `container` where it is."""
    return f"stuck:{container}"


def look_at_quat(position: tuple[float, float, float], target: tuple[float, float, float]) -> list[float]:
    """Quaternion (w, x, y, z) of a MuJoCo camera at `position` looking at `target`, z up."""
    forward = np.asarray(target, float) - np.asarray(position, float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-9:  # looking straight down: image up is +y
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    mat = np.column_stack([right, up, -forward])  # camera x, y, z axes in the world
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat.flatten())
    return quat.tolist()


def _geom(body: mujoco.MjsBody, name: str, pos, half, rgba, group: int | None, **kw) -> mujoco.MjsGeom:
    geom = body.add_geom(
        name=name, type=mujoco.mjtGeom.mjGEOM_BOX, pos=list(pos), size=list(half), rgba=list(rgba), **kw
    )
    if group is None:
        geom.contype = 0
        geom.conaffinity = 0
    else:
        collision.set_group(geom, group)
    return geom


def _static_box(body: mujoco.MjsBody, box: Box) -> None:
    _geom(body, box.name, box.center, box.half, box.rgba, collision.ENVIRONMENT if box.collides else None)


def add_environment(spec: mujoco.MjSpec, env: Environment) -> None:
    """Add floor, light, static geometry, surfaces, containers, obstacles and the overview camera."""
    world = spec.worldbody
    tex = spec.add_texture(
        name="floor_tex",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        width=256,
        height=256,
        rgb1=[0.62, 0.6, 0.55],
        rgb2=[0.52, 0.5, 0.46],
    )
    mat = spec.add_material(name="floor_mat", texrepeat=[8, 8], reflectance=0.0)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    x0, y0, x1, y1 = env.extent
    floor = world.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[(x1 - x0) / 2, (y1 - y0) / 2, 0.1],
        pos=[(x0 + x1) / 2, (y0 + y1) / 2, 0.0],
        material="floor_mat",
    )
    collision.set_group(floor, collision.FLOOR)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    world.add_light(
        name="sun",
        pos=[cx, cy - 0.5, 4.0],
        dir=[-0.2, 0.1, -1.0],
        castshadow=False,
        diffuse=[0.7, 0.7, 0.7],
        ambient=[0.25, 0.25, 0.25],
    )
    fixed = world.add_body(name="environment")
    for box in env.static:
        _static_box(fixed, box)
    for surface in env.surfaces:
        x, y, z = surface.centroid
        if surface.kind == "cooker":
            bx0, by0, bx1, by1 = surface.bounds
            g = fixed.add_geom(
                name=surface.name,
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                pos=[x, y, z + 0.005],
                size=[min(bx1 - bx0, by1 - by0) / 2, 0.002, 0],
                rgba=_COOKER_RGBA,
            )
            g.contype = 0
            g.conaffinity = 0
        fixed.add_site(name=surface.name, pos=[x, y, z], size=[0.01, 0.01, 0.01], rgba=[0, 0, 0, 0])
    for container in env.containers:
        _add_container(spec, container)
    for i in range(N_OBSTACLES):
        body = world.add_body(name=f"obstacle_{i}", mocap=True, pos=list(OBSTACLE_PARKING))
        g = body.add_geom(
            name=f"obstacle_{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[0.15, 0.15, 0.5],
            pos=[0, 0, 0.5],
            rgba=[0.9, 0.5, 0.1, 1],
        )
        collision.set_group(g, collision.ENVIRONMENT)
    cam = env.camera
    world.add_camera(name=cam.name, pos=list(cam.position), fovy=cam.fovy, quat=look_at_quat(cam.position, cam.target))
    px0, py0, px1, py1 = plan_view(env)
    top = world.add_camera(
        name=PLAN_CAMERA,
        pos=[(px0 + px1) / 2, (py0 + py1) / 2, PLAN_CAMERA_HEIGHT],
        fovy=py1 - py0,
        quat=look_at_quat((0, 0, 1), (0, 0, 0)),
    )
    top.proj = mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC


def plan_view(env: Environment, margin: float = 0.4) -> tuple[float, float, float, float]:
    """The floor rectangle (x_min, y_min, x_max, y_max) [m] the plan camera sees in a 4:3 image:
    the environment's `plan_bounds` with `margin`, widened to the image's aspect ratio."""
    x0, y0, x1, y1 = env.plan_bounds
    x0, y0, x1, y1 = x0 - margin, y0 - margin, x1 + margin, y1 + margin
    w, h = x1 - x0, y1 - y0
    if w < h * PLAN_ASPECT:
        x0, x1 = x0 - (h * PLAN_ASPECT - w) / 2, x1 + (h * PLAN_ASPECT - w) / 2
    else:
        y0, y1 = y0 - (w / PLAN_ASPECT - h) / 2, y1 + (w / PLAN_ASPECT - h) / 2
    return (x0, y0, x1, y1)


def _add_container(spec: mujoco.MjSpec, c: Container) -> None:
    box = c.body
    if c.kind == "drawer":
        origin = np.asarray(box.center, float)
    else:
        origin = np.array([c.hinge[0], c.hinge[1], box.center[2]])  # type: ignore[index]
    body = spec.worldbody.add_body(name=c.name, pos=origin.tolist())
    dx, dy = c.opening_direction
    joint = body.add_joint(
        name=c.joint_name,
        damping=c.damping,
        frictionloss=c.friction,
        armature=0.02,
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=list(c.limits),
    )
    if c.kind == "drawer":
        joint.type = mujoco.mjtJoint.mjJNT_SLIDE
        joint.axis = [dx, dy, 0.0]
    else:
        joint.type = mujoco.mjtJoint.mjJNT_HINGE
        joint.axis = [0.0, 0.0, c.hinge_sign]
    center = np.asarray(box.center, float) - origin  # the box in the body frame
    hx, hy, hz = box.half
    rgba, w = box.rgba, c.wall
    env = collision.ENVIRONMENT
    kw = {"density": _FURNITURE_DENSITY}
    if c.kind == "drawer":
        _geom(body, f"{c.name}:bottom", center + [0, 0, -hz + w / 2], (hx, hy, w / 2), rgba, env, **kw)
        for sx, sy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            front = (sx, sy) == (round(dx), round(dy))
            half = (w / 2, hy, hz) if sx else (hx, w / 2, hz)
            pos = center + [sx * (hx - w / 2), sy * (hy - w / 2), 0.0]
            name = f"{c.name}:front" if front else f"{c.name}:wall_{sx}_{sy}"
            _geom(body, name, pos, half, rgba, env, **kw)
    else:
        _geom(body, f"{c.name}:panel", center, box.half, rgba, env, **kw)
    # the handle: a bar held by two standoffs in front of the panel
    handle = np.asarray(c.handle, float) - origin
    normal = np.array([dx, dy, 0.0])
    along = np.array([0.0, 0.0, 1.0]) if c.kind == "door" else np.array([-dy, dx, 0.0])
    bar_half = 0.012 * (np.ones(3) - np.abs(along)) + 0.07 * np.abs(along)
    _geom(body, f"{c.name}:handle", handle, bar_half, _HANDLE_RGBA, env, density=2000.0)
    for side in (-1, 1):
        pos = handle + side * 0.055 * along - normal * _HANDLE_STANDOFF / 2
        half = 0.008 * (np.ones(3) - np.abs(normal)) + np.abs(normal) * _HANDLE_STANDOFF / 2
        _geom(body, f"{c.name}:handle_post{side:+d}", pos, half, _HANDLE_RGBA, env, density=2000.0)
    body.add_site(name=c.handle_site, pos=handle.tolist(), size=[0.012, 0.012, 0.012], rgba=[0, 0, 0, 0])
    eq = spec.add_equality(
        name=stuck_equality(c.name), type=mujoco.mjtEq.mjEQ_JOINT, objtype=mujoco.mjtObj.mjOBJ_JOINT, name1=c.joint_name
    )
    eq.active = False
    eq.solref = [0.005, 1.0]


__all__ = [
    "add_environment",
    "look_at_quat",
    "stuck_equality",
    "plan_view",
    "N_OBSTACLES",
    "OBSTACLE_PARKING",
    "PLAN_CAMERA",
    "PLAN_ASPECT",
]
