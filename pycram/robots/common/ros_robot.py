"""A robot whose process modules talk ROS: :func:`make_ros_robot`.

The same motion vocabulary and resolvers as the simulated robot of the same name (the plan does
not know which backend runs it), with :mod:`pycram.backends.ros.modules` as process modules. The robot's
numbers (joint configurations, torso heights, reaching offsets) come from its validated
description (:func:`pycram.world.robot_registry.robot_description`); the names of its ROS
interfaces from :mod:`pycram.backends.ros.config`.

With the simulation extra installed (``mujoco``) the robot reasons as the simulated robot does:

- ``prospection`` -- the world it believes in (:mod:`pycram.robots.common.ros_prospection`:
  the environment's description, its belief, its joints and base pose from its topics);
- location designators (``to_reach``, ``to_see``, ``to_open``, ``on``, ``in``) resolved by the
  same location generator as the simulated robot's
  (:func:`~pycram.robots.common.sim_resolvers.make_location_generator`) over that prospection;
- arm motions planned in it and sent as joint trajectories
  (:mod:`pycram.robots.common.ros_arm_motion`).

Without it ``prospection`` is None, ``to_reach`` is answered from the description alone and arm
motions are sent as plain goals.
"""

from __future__ import annotations

import logging
from typing import Any

from pycram.backends.ros import modules as rm
from pycram.backends.ros.config import RosRobotConfig, robot_config
from pycram.backends.ros.transport import Transport
from pycram.execution.process_module import ProcessModule
from pycram.execution.robot import Robot
from pycram.robots.common.ros_arm_motion import RosPlannedArmModule
from pycram.robots.common.ros_prospection import ros_prospection
from pycram.robots.common.sim_modules import SensorModule, shutdown_modules
from pycram.robots.common.sim_resolvers import (
    make_location_generator,
    make_motion_resolver,
    make_to_reach_generator,
    physical_arm,
    physical_gripper,
)
from pycram.robots.common.sim_vocabulary import motion_types
from pycram.world.belief import BeliefState
from pycram.world.robot_registry import robot_description

__all__ = ["RosRobot", "make_ros_robot"]

logger = logging.getLogger(__name__)


class RosRobot(Robot):
    """A :class:`~pycram.robot.Robot` driven over ROS. ``state`` holds its sensor fluents
    (:class:`~pycram.backends.ros.modules.RosRobotState`); ``belief`` (a
    :class:`~pycram.world.belief.BeliefState` of the configured environment) what it perceived,
    filled by its ``detecting`` motion from the detections topic and read by its object resolver,
    as on the simulated robot; ``prospection`` the world it believes in
    (:func:`~pycram.robots.common.ros_prospection.ros_prospection`; None without ``mujoco``).
    :meth:`shutdown` ends subscriptions and takes the modules offline (idempotent)."""

    def __init__(
        self, name: str, transport: Transport, config: RosRobotConfig, state: rm.RosRobotState, description: Any
    ) -> None:
        super().__init__(name)
        self.transport, self.config, self.state, self.description = transport, config, state, description
        #: What this robot believes is in the world: filled by its perception module, read by its
        #: object resolver.
        self.belief = BeliefState(state.environment)
        self.object_resolvers.append(self.belief.resolver)
        #: Prospection of the world this robot believes in (see the module docstring), or None.
        self.prospection: Any = None

    def shutdown(self) -> None:
        shutdown_modules(self)
        for module in self.process_modules.values():
            if isinstance(module, rm.RosPerceptionModule):
                module.close()
        self.state.close()

    def __repr__(self) -> str:
        return f"RosRobot({self.name!r})"


def make_ros_robot(
    name: str,
    transport: Transport | None = None,
    config: RosRobotConfig | None = None,
    wait_for_state: float = 10.0,
    reasoning: bool = True,
) -> RosRobot:
    """The robot ``name`` (a registered robot with a ROS configuration) over ROS, modules online.

    ``transport`` defaults to the process's ROS 1 transport (node initialised on first use),
    ``config`` to the robot's default ROS configuration (its ``environment`` names the map the
    robot reasons in). Waits at most ``wait_for_state`` [s, wall] for the first base pose and
    gripper openings; raises ``TimeoutError`` naming the topics when they do not arrive (no
    robot, or no bridge, on this master). ``reasoning``: give the robot its prospection,
    location reasoning and planned arm motions (see the module docstring; skipped with a
    warning when ``mujoco`` is missing); False: the description-only ``to_reach`` and plain arm
    goals.
    """
    config = config or robot_config(name)
    if config.robot != name:
        raise ValueError(f"ROS configuration of {config.robot!r} given for robot {name!r}")
    if transport is None:
        from pycram.backends.ros.ros1 import ros1_transport

        transport = ros1_transport()
    description = robot_description(name)
    state = rm.RosRobotState(transport, config)
    if not state.wait_ready(wait_for_state):
        state.close()
        raise TimeoutError(
            f"no data from robot {name!r} on {config.pose_topic} and "
            f"{config.joint_states_topic} within {wait_for_state:.1f} s: is the robot "
            f"(or `pycram sim-ros-bridge --robot {name}`) running on this ROS master?"
        )
    robot = RosRobot(name, transport, config, state, description)
    args = (transport, config, state)
    navigation = robot.add_process_module("navigation", rm.RosNavigationModule(*args))
    base_stop = robot.add_process_module("base_stop", rm.RosBaseStopModule(*args, navigation))
    head = robot.add_process_module("head", rm.RosHeadModule(*args))
    torso = robot.add_process_module("torso", rm.RosTorsoModule(*args))
    if reasoning:
        try:
            robot.prospection = ros_prospection(state, robot.belief)
        except ImportError as missing:
            logger.warning("the %s over ROS reasons without prospection: %s", name, missing)
    arms = {
        a: robot.add_process_module(
            f"arm_{a}",
            RosPlannedArmModule(*args, a, description, robot=robot)
            if robot.prospection is not None
            else rm.RosArmModule(*args, a),
        )
        for a in config.arms
    }
    grippers = {g: robot.add_process_module(f"gripper_{g}", rm.RosGripperModule(*args, g)) for g in config.grippers}
    sensors = robot.add_process_module("sensors", SensorModule(state))
    perception = robot.add_process_module("perception", rm.RosPerceptionModule(*args, robot.belief))

    robot.motion_types.update(motion_types(state, description))
    robot.motion_resolvers.append(make_motion_resolver(state, description))
    if robot.prospection is not None:
        prospection = robot.prospection
        robot.location_generators.append(
            make_location_generator(state, description, robot.belief, prospection=lambda: prospection)
        )
    else:
        robot.location_generators.append(make_to_reach_generator(state, description))

    by_type = {
        "moving": navigation,
        "cancelling_movement": base_stop,
        "pointing_head": head,
        "setting_torso": torso,
        "detecting": perception,
        "subscribing_pose": sensors,
        "subscribing_gripper": sensors,
    }

    def ros_process_modules(desig: Any) -> ProcessModule | None:
        """Choose the module by the designator's type (and physical arm / gripper)."""
        motion_type = desig.prop_value("type")
        if isinstance(motion_type, str) and motion_type in by_type:
            return by_type[motion_type]
        if motion_type == "setting_gripper" and desig.check_constraints(["gripper"]):
            return grippers[physical_gripper(description, desig.prop_value("gripper"))]
        if motion_type in ("setting_arm_configuration", "setting_arm_joints", "reaching") and desig.check_constraints(
            ["arm"]
        ):
            return arms[physical_arm(description, desig.prop_value("arm"))]
        return None

    robot.process_module_resolvers.append(ros_process_modules)
    return robot
