"""The prospection of a robot over ROS: the world it believes in, from what it knows.

A robot driven over ROS has no simulator in its process, yet its reasoning asks the same
questions as the simulated robot's (is this base pose free, can the arm reach that, is the
object visible from here, which arm path is collision-free). :func:`ros_prospection` answers
them with a :class:`~pycram.backends.sim.prospection.SimProspection` over a
:class:`~pycram.backends.sim.believed_world.BelievedWorld` -- MuJoCo used as a geometry and
kinematics engine for reasoning, exactly as for the simulated robot -- built from:

- the **environment's description** (``state.environment``: the robot's map, from its ROS
  configuration's ``environment``);
- the robot's **belief** (its ``belief``: objects it perceived, container openings it measured;
  filled by its ``detecting`` motion from the detections topic);
- its **own sensed state** (:func:`sensed_robot`): the joint positions of the joint-states topic
  by name and the base pose of the pose topic (``RosRobotState.joint_states`` and
  ``base_pose``), stamped with the older of their stamps.

Nothing of the simulator behind a ``pycram sim-ros-bridge`` is read: the bridge is only the
robot's drivers. The same holds on a real robot whose URDF joint names are those of the robot's
description.

Layering: the ROS backend (:mod:`pycram.backends.ros`) never imports the simulator; this robots
module wires the two. ``mujoco`` is imported when a prospection is first made (the ``sim``
extra): without it :func:`ros_prospection` raises ``ImportError`` and the robot reasons without
prospection.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from pycram.world.types import Pose

if TYPE_CHECKING:
    from pycram.backends.ros.modules import RosRobotState
    from pycram.backends.sim.believed_world import SensedRobot
    from pycram.backends.sim.prospection import SimProspection

__all__ = ["sensed_robot", "ros_prospection", "tool_poses"]


def sensed_robot(state: RosRobotState) -> SensedRobot:
    """The robot as its ROS topics report it now: joint positions [rad or m] by name (the
    joint-states topic), the base pose (the pose topic, map frame) and the time [s, ROS time]
    of the older of the two. ``LookupError`` while either has not arrived yet."""
    from pycram.backends.sim.believed_world import SensedRobot

    joints, base = state.joint_states.get_value(), state.base_pose.get_value()
    if joints is None or base is None:
        missing = " and ".join(
            topic
            for topic, value in ((state.config.joint_states_topic, joints), (state.config.pose_topic, base))
            if value is None
        )
        raise LookupError(f"the {state.robot} has not been sensed yet: nothing on {missing}")
    stamp = state.stamp
    return SensedRobot(stamp if stamp > float("-inf") else 0.0, dict(joints), base)


def ros_prospection(state: RosRobotState, belief: Any) -> SimProspection:
    """The prospection of the robot whose ROS sensor fluents are ``state``, in the world its
    ``belief`` (a :class:`~pycram.world.belief.BeliefState` of ``state.environment``) describes
    (see the module docstring). Compiles the believed world's model on first use for the robot
    and environment (~0.1-0.5 s, then shared). ``ImportError`` without ``mujoco``."""
    from pycram.backends.sim.believed_world import BelievedWorld
    from pycram.backends.sim.prospection import SimProspection

    believed = BelievedWorld(state.robot, state.environment, belief, lambda: sensed_robot(state))
    return SimProspection(believed.scene, believed.snapshot, believed=believed)


def tool_poses(prospection: SimProspection) -> dict[str, Pose]:
    """Each arm's tool frame now (map frame; position [m], orientation (w, x, y, z)): forward
    kinematics of the sensed joints in ``prospection``'s believed world (what tf gives on a
    real robot). ``ValueError`` for a prospection without a believed world."""
    believed = prospection.believed
    if believed is None:
        raise ValueError("tool poses need a prospection of a believed world (ros_prospection)")
    return believed.tool_poses()
