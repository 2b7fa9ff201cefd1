"""Putting a robot description into a MuJoCo scene: URDF, omnidirectional base, actuators,
grippers, head camera and tool sites.

The robot's validated description (:class:`pycram.world.robot_description.RobotDescription`,
from the robot registry) provides the names and numbers; this module only knows how to turn them
into MJCF elements.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from pycram.world.robot_description import RobotDescription, RobotDescriptionError
from pycram.world.robot_registry import RegisteredRobots, robot_description, robot_names

from . import collision
from .assets import urdf_text
from .composition import composed_urdf_text, paint_composed
from .errors import UnknownNameError

#: Names of the robots the simulator can load: the registered robots
#: (:func:`pycram.world.robot_registry.robot_names`), read from the registry whenever it is used.
ROBOTS: Sequence[str] = RegisteredRobots()

#: Names of the base joints added on the mount body.
BASE_JOINTS = ("base_x", "base_y", "base_yaw")
#: Name of the MuJoCo camera mounted on each robot's head.
HEAD_CAMERA = "head_camera"


#: Named arm configurations that are no IK seeds: ``carry_top`` (carrying an object held from the
#: top level) came later than the others; as a seed it let IK find arm poses deep over a counter
#: that the executed motion could not reach (measured: a cup 0.35 m deep on the counter, blocked
#: 6 cm short), so the seeds stay those the reachability checks were measured with.
NOT_IK_SEEDS = frozenset({"carry_top"})


def load_description(robot: str) -> RobotDescription:
    """The validated description of `robot`, a registered robot (`UnknownNameError` otherwise)."""
    if robot not in robot_names():
        raise UnknownNameError("robot", robot, robot_names())
    return robot_description(robot)


def tool_site(arm: str) -> str:
    """Name of the site at the tool frame of `arm`."""
    return f"{arm}_tool"


def pad_site(gripper: str, side: int) -> str:
    """Name of the site on finger pad `side` (0 or 1) of `gripper`."""
    return f"{gripper}_pad{side}"


def _camera_quat() -> list[float]:
    # camera looks along -z, up +y: map to link +x forward, +z up
    mat = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat.flatten())
    return quat.tolist()


def _remove_replaced_links(spec: mujoco.MjSpec, desc: RobotDescription, links: Any) -> None:
    """Delete the links `links` of the URDF (with everything below them: the model file's own
    gripper that `desc.GRIPPER_MODEL` replaces) and the equalities of their joints."""
    gone: set[str] = set()
    for name in links:
        body = spec.body(name)
        if body is None:
            raise RobotDescriptionError(
                desc.NAME, "GRIPPER_MODEL", f"GRIPPER_MODEL: 'replaces' names {name!r}, which is no link of {desc.URDF}"
            )
        stack = [body]
        while stack:
            b = stack.pop()
            gone.update(j.name for j in b.joints)
            stack.extend(b.bodies)
        spec.delete(body)
    for eq in list(spec.equalities):
        if eq.type == mujoco.mjtEq.mjEQ_JOINT and (eq.name1 in gone or eq.name2 in gone):
            spec.delete(eq)


def _add_parallel_gripper(spec: mujoco.MjSpec, desc: RobotDescription, g: dict[str, Any]) -> None:
    """Build the simple parallel gripper `g` (`desc.GRIPPER_MODEL`) onto each arm's mount link.

    `g["mount_link"]` is one link (a one-armed robot) or ``{gripper: link}``; the optional
    `g["mount_quat"]` (w, x, y, z) turns the gripper's frame (x: approach, y: opening) in the
    mount link's frame; the optional `g["replaces"]` names links of the URDF deleted first (with
    their subtrees: the model file's own gripper).
    """
    if g.get("replaces"):
        _remove_replaced_links(spec, desc, g["replaces"])
    mounts = g["mount_link"]
    px, py, pz = g["palm_size"]
    fx, fy, fz = g["finger_size"]
    quat = list(g.get("mount_quat", (1.0, 0.0, 0.0, 0.0)))
    turn = np.zeros(9)
    mujoco.mju_quat2Mat(turn, np.asarray(quat, float))
    palm_pos = (turn.reshape(3, 3) @ np.array([px, 0.0, 0.0])).tolist()
    for arm in desc.ARMS.values():
        gname = arm["gripper"]
        grip = desc.GRIPPERS[gname]
        mount = spec.body(mounts if isinstance(mounts, str) else mounts[gname])
        palm = mount.add_body(
            name=grip["palm_link"], pos=palm_pos, quat=quat, mass=g["mass"], inertia=[1e-3, 1e-3, 1e-3]
        )
        palm.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[px, py, pz], rgba=[0.25, 0.25, 0.28, 1])
        palm.add_body(name=arm["tool_link"], pos=[g["tool_offset"] - px, 0, 0], mass=0.001, inertia=[1e-6, 1e-6, 1e-6])
        names = (grip["joint"],) + tuple(grip["coupled_joints"])
        for side, (link, jname) in enumerate(zip(grip["finger_links"], names)):
            sign = 1.0 if side == 0 else -1.0
            finger = palm.add_body(name=link, pos=[px + fx, sign * fy, 0], mass=0.05, inertia=[2e-5, 2e-5, 2e-5])
            finger.add_joint(
                name=jname,
                type=mujoco.mjtJoint.mjJNT_SLIDE,
                axis=[0, sign, 0],
                range=list(grip["joint_range"]),
                limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                # a stiff closed limit: squeezing a bowl's 8 mm rim, the fingers were pushed 16 mm
                # past it (soft default limit), crossed over and locked onto the rim -- the gripper
                # could no longer open to let go
                solref_limit=[0.004, 1.0],
            )
            finger.add_geom(
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[fx, fy, fz],
                rgba=[0.35, 0.35, 0.4, 1],
                friction=[1.5, 0.01, 0.001],
                condim=4,
            )


def build_robot_spec(desc: RobotDescription) -> mujoco.MjSpec:
    """The robot's own spec: URDF (or, for a description with a ``COMPOSITION``, the arm's URDF
    composed with a base, torso and head: `pycram.backends.sim.composition`) with collision
    groups, gravity compensation, camera and sites."""
    if desc.COMPOSITION is None:
        spec = mujoco.MjSpec.from_string(urdf_text(desc.URDF))
    else:
        spec = mujoco.MjSpec.from_string(composed_urdf_text(desc))
        paint_composed(spec)
    if desc.GRIPPER_MODEL is not None:
        _add_parallel_gripper(spec, desc, desc.GRIPPER_MODEL)
    for geom in spec.geoms:
        if geom.contype or geom.conaffinity:
            collision.set_group(geom, collision.ROBOT)
    # joints that follow another one (URDF mimic) are driven by the equality, not their limits:
    # some mimic factors of the PR2 URDF point out of the follower's own range
    followers = {eq.name1 for eq in spec.equalities if eq.type == mujoco.mjtEq.mjEQ_JOINT}
    for joint in spec.joints:
        if joint.name in followers:
            joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    for body in spec.bodies:
        body.gravcomp = 1.0
    fingers = followers | {j for g in desc.GRIPPERS.values() for j in (g["joint"], *g["coupled_joints"])}
    for joint in spec.joints:
        light = joint.name in fingers
        joint.armature = 0.002 if light else 0.05
        joint.damping = [0.02 if light else 1.0, 0.0, 0.0]
        joint.frictionloss = 0.0
    spec.body(desc.HEAD["camera_link"]).add_camera(name=HEAD_CAMERA, quat=_camera_quat(), fovy=desc.HEAD["fovy"])
    for arm, a in desc.ARMS.items():
        spec.body(a["tool_link"]).add_site(name=tool_site(arm), size=[0.005, 0, 0], rgba=[0, 1, 0, 0])
    for gname, g in desc.GRIPPERS.items():
        for side, link in enumerate(g["pad_links"]):
            spec.body(link).add_site(name=pad_site(gname, side), size=[0.004, 0, 0], rgba=[1, 0, 0, 0])
    return spec


def _position_actuator(spec: mujoco.MjSpec, joint: str, kp: float, kv: float, force: float) -> None:
    act = spec.add_actuator(name=joint, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    act.set_to_position(kp=kp, kv=kv)
    act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    act.forcerange = [-force, force]


def add_robot(spec: mujoco.MjSpec, desc: RobotDescription) -> None:
    """Give the robot of `desc` (already in `spec`, see `build_robot_spec`) an omnidirectional base
    (slide x, slide y, hinge yaw on its root link) and add its actuators.

    Actuators are position servos named after their joints: `base_x`, `base_y`, `base_yaw`, the
    torso, head, arm joints and each gripper's driven finger joint. Their force limits make a
    blocked base or a closing gripper stall instead of pushing through.
    """
    mount = spec.body(desc.ROOT_LINK)
    mount.add_joint(name="base_x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0], damping=[50.0, 0, 0])
    mount.add_joint(name="base_y", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0], damping=[50.0, 0, 0])
    mount.add_joint(name="base_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=[20.0, 0, 0])
    # base servos: stiff but force-limited, so a counter or obstacle stops the robot
    _position_actuator(spec, "base_x", kp=4e4, kv=8e3, force=2500.0)
    _position_actuator(spec, "base_y", kp=4e4, kv=8e3, force=2500.0)
    _position_actuator(spec, "base_yaw", kp=6e3, kv=1.2e3, force=800.0)
    _position_actuator(spec, desc.TORSO["joint"], kp=3e4, kv=4e3, force=5e3)
    _position_actuator(spec, desc.HEAD["pan_joint"], kp=40.0, kv=4.0, force=20.0)
    _position_actuator(spec, desc.HEAD["tilt_joint"], kp=40.0, kv=4.0, force=20.0)
    gains = (600.0, 600.0, 300.0, 300.0, 100.0, 100.0, 60.0)
    for a in desc.ARMS.values():
        for joint, kp in zip(a["joints"], gains):
            _position_actuator(spec, joint, kp=kp, kv=kp / 8.0, force=200.0)
    for g in desc.GRIPPERS.values():
        revolute = g["effort_lever"] != 1.0
        # prismatic fingers (the TIAGo's) close at ~0.17 m/s (25 N / kv): at 2.5 m/s (kv 10) they
        # went 5 mm into a thin object per 2 ms step, and on a 1 cm spoon the contact flipped to its
        # top face -- a finger rode up onto the spoon and the gripper closed on nothing
        kp, kv = (20.0, 0.1) if revolute else (1500.0, 150.0)
        _position_actuator(spec, g["joint"], kp=kp, kv=kv, force=g["default_effort"] * g["effort_lever"])
        already = {eq.name1 for eq in spec.equalities if eq.type == mujoco.mjtEq.mjEQ_JOINT}
        for other in g["coupled_joints"]:
            if other in already:  # the URDF importer turned a mimic tag into an equality
                continue
            spec.add_equality(
                type=mujoco.mjtEq.mjEQ_JOINT,
                name1=other,
                name2=g["joint"],
                data=[0, 1, 0, 0, 0] + [0] * 7,
                solref=[0.005, 1.0],
            )
