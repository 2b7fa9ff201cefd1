"""A robot whose process modules talk ROS: :func:`make_ros_robot`.

The same motion vocabulary and resolvers as the simulated robot of the same name (the plan does
not know which backend runs it), with :mod:`pycram.backends.ros.modules` as process modules. The robot's
numbers (joint configurations, torso heights, reaching offsets) come from its validated
description (:func:`pycram.world.robot_registry.robot_description`); the names of its ROS
interfaces from :mod:`pycram.backends.ros.config`.
"""

from __future__ import annotations

from typing import Any

from pycram.backends.ros import modules as rm
from pycram.backends.ros.config import RosRobotConfig, robot_config
from pycram.backends.ros.transport import Transport
from pycram.execution.process_module import ProcessModule
from pycram.execution.robot import Robot
from pycram.robots.common.sim_modules import SensorModule, shutdown_modules
from pycram.robots.common.sim_resolvers import (
    make_motion_resolver,
    make_to_reach_generator,
    physical_arm,
    physical_gripper,
)
from pycram.robots.common.sim_vocabulary import motion_types
from pycram.world.belief import BeliefState
from pycram.world.robot_registry import robot_description

__all__ = ["RosRobot", "make_ros_robot"]


class RosRobot(Robot):
    """A :class:`~pycram.robot.Robot` driven over ROS. ``state`` holds its sensor fluents
    (:class:`~pycram.backends.ros.modules.RosRobotState`); ``belief`` (a
    :class:`~pycram.world.belief.BeliefState` of the configured environment) what it perceived,
    filled by its ``detecting`` motion from the detections topic and read by its object resolver,
    as on the simulated robot. No prospection over ROS (``prospection`` is None).
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

    def shutdown(self) -> None:
        shutdown_modules(self)
        for module in self.process_modules.values():
            if isinstance(module, rm.RosPerceptionModule):
                module.close()
        self.state.close()

    def __repr__(self) -> str:
        return f"RosRobot({self.name!r})"


def make_ros_robot(
    name: str, transport: Transport | None = None, config: RosRobotConfig | None = None, wait_for_state: float = 10.0
) -> RosRobot:
    """The robot ``name`` (a registered robot with a ROS configuration) over ROS, modules online.

    ``transport`` defaults to the process's ROS 1 transport (node initialised on first use),
    ``config`` to the robot's default ROS configuration. Waits at most ``wait_for_state`` [s,
    wall] for the first base pose and gripper openings; raises ``TimeoutError`` naming the topics
    when they do not arrive (no robot, or no bridge, on this master).
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
    arms = {a: robot.add_process_module(f"arm_{a}", rm.RosArmModule(*args, a)) for a in config.arms}
    grippers = {g: robot.add_process_module(f"gripper_{g}", rm.RosGripperModule(*args, g)) for g in config.grippers}
    sensors = robot.add_process_module("sensors", SensorModule(state))
    perception = robot.add_process_module("perception", rm.RosPerceptionModule(*args, robot.belief))

    robot.motion_types.update(motion_types(state, description))
    robot.motion_resolvers.append(make_motion_resolver(state, description))
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
