"""An arm's joints and their limits in the simulator: positions from the compiled model, velocities
from the robot's URDF, accelerations from a documented default.

MuJoCo keeps a joint's position range but drops the URDF's ``<limit velocity=...>``, so the
velocities are read from the URDF text the model was compiled from (`assets.urdf_text`). URDFs
carry no acceleration limits; :data:`DEFAULT_ACCELERATION` fills them in per joint kind. A joint
without a velocity in its URDF gets :data:`DEFAULT_VELOCITY`.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET

import mujoco

from pycram.world.prospection import JointLimits

from .assets import urdf_text
from .scene import Scene

__all__ = ["DEFAULT_ACCELERATION", "DEFAULT_VELOCITY", "arm_joint_names", "joint_limits", "urdf_velocities"]

#: Acceleration limits per joint kind (the URDF has none): ``'hinge'`` [rad/s^2], ``'slide'``
#: [m/s^2]. About what the simulated position servos follow without lagging by more than a
#: centimetre at the tool (the base's angular acceleration is 1.5 rad/s^2 too).
DEFAULT_ACCELERATION = {"hinge": 1.5, "slide": 0.1}
#: Velocity limits per joint kind when the URDF gives none: ``'hinge'`` [rad/s], ``'slide'`` [m/s].
DEFAULT_VELOCITY = {"hinge": 1.0, "slide": 0.05}


@functools.cache
def urdf_velocities(urdf: str) -> dict[str, float]:
    """Joint name -> velocity limit [rad/s or m/s] of every joint of the URDF ``urdf`` (a path
    relative to the robot data directory) that states one."""
    root = ET.fromstring(urdf_text(urdf))
    out: dict[str, float] = {}
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        name = joint.get("name")
        if limit is not None and name and limit.get("velocity"):
            velocity = float(limit.get("velocity", "0"))
            if velocity > 0:
                out[name] = velocity
    return out


def arm_joint_names(scene: Scene, arm: str, include_torso: bool = False) -> tuple[str, ...]:
    """The joints of ``arm`` in the description's order, the torso joint first with
    ``include_torso``. Raises ``ValueError`` for an unknown arm, listing the valid ones."""
    desc = scene.description
    if arm not in desc.ARMS:
        raise ValueError(f"unknown arm {arm!r} of {scene.robot}; valid arms: {list(desc.ARMS)}")
    joints = tuple(desc.ARMS[arm]["joints"])
    return ((desc.TORSO["joint"],) + joints) if include_torso else joints


def joint_limits(scene: Scene, arm: str, include_torso: bool = False) -> JointLimits:
    """The :class:`~pycram.world.prospection.JointLimits` of ``arm`` (see the module docstring)."""
    names = arm_joint_names(scene, arm, include_torso)
    m = scene.model
    velocities = urdf_velocities(scene.description.URDF)
    lower, upper, velocity, acceleration = [], [], [], []
    for name in names:
        jid = scene.joint_id(name)
        kind = "slide" if m.jnt_type[jid] == mujoco.mjtJoint.mjJNT_SLIDE else "hinge"
        if m.jnt_limited[jid]:
            lower.append(float(m.jnt_range[jid, 0]))
            upper.append(float(m.jnt_range[jid, 1]))
        else:
            lower.append(-math.inf)
            upper.append(math.inf)
        velocity.append(velocities.get(name, DEFAULT_VELOCITY[kind]))
        acceleration.append(DEFAULT_ACCELERATION[kind])
    return JointLimits(names, tuple(lower), tuple(upper), tuple(velocity), tuple(acceleration))
