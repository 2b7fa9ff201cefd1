"""The simulated TIAGo as a :class:`pycram.robot.Robot`: resolvers and process modules.

One arm and one gripper (physically named ``'right'`` in the description). Like the one-armed
robot of the thesis' ch. 4.2.2 discussion, its only arm module serves requests for either arm
(``'left'``, ``'right'``, ``'0'``, ``'1'``) and its only gripper module requests for either
gripper, so a plan written for the two-armed PR2 runs unchanged. All numbers come from
:mod:`pycram.robots.tiago.description` (validated by the robot registry).

Process modules (``robot.process_module(name)``): ``navigation``, ``base_stop``, ``head``,
``torso``, ``arm_right``, ``gripper_right``, ``sensors``, ``perception``.
"""

from __future__ import annotations

from typing import Any

from pycram.execution.process_module import ProcessModule
from pycram.robots.common import sim_modules as sm
from pycram.robots.common.sim_resolvers import (
    make_location_generator,
    make_motion_resolver,
    physical_arm,
    physical_gripper,
)
from pycram.robots.common.sim_vocabulary import motion_types
from pycram.world.robot_registry import robot_description

__all__ = ["make_robot"]

#: The validated description (the registry's, shared with the simulated world).
description = robot_description("tiago")


def make_robot(world: Any) -> sm.SimRobot:
    """The TIAGo of ``world`` (a :class:`pycram.sim.World` built for ``'tiago'``), modules online."""
    if getattr(world, "robot", None) != description.NAME:
        raise ValueError(
            f"make_robot for {description.NAME!r} needs a world with a {description.NAME!r}, got {world!r}"
        )
    robot = sm.SimRobot(description.NAME, world, description)
    navigation = robot.add_process_module("navigation", sm.NavigationModule(world))
    base_stop = robot.add_process_module("base_stop", sm.BaseStopModule(world, navigation))
    head = robot.add_process_module("head", sm.HeadModule(world))
    torso = robot.add_process_module("torso", sm.TorsoModule(world))
    (arm_name,) = description.ARMS
    (gripper_name,) = description.GRIPPERS
    arm = robot.add_process_module(f"arm_{arm_name}", sm.ArmModule(world, arm_name, robot=robot))
    gripper = robot.add_process_module(f"gripper_{gripper_name}", sm.GripperModule(world, gripper_name))
    sensors = robot.add_process_module("sensors", sm.SensorModule(world))
    perception = robot.add_process_module("perception", sm.PerceptionModule(world, robot.belief))

    robot.motion_types.update(motion_types(world, description))
    robot.motion_resolvers.append(make_motion_resolver(world, description))
    robot.location_generators.append(make_location_generator(world, description, robot.belief))

    def available_process_modules(desig: Any) -> ProcessModule | None:
        """Thesis ch. 4.2.2: choose TIAGo's module by the designator's type; any arm or gripper
        request goes to its only arm or gripper (unknown names still fail clearly)."""
        if desig.check_constraints([("type", "moving")]):
            return navigation
        if desig.check_constraints([("type", "cancelling_movement")]):
            return base_stop
        if desig.check_constraints([("type", "pointing_head")]):
            return head
        if desig.check_constraints([("type", "setting_torso")]):
            return torso
        if desig.check_constraints([("type", "detecting")]):
            return perception
        if desig.check_constraints([("type", "subscribing_pose")]) or desig.check_constraints(
            [("type", "subscribing_gripper")]
        ):
            return sensors
        if desig.check_constraints([("type", "setting_gripper"), "gripper"]):
            physical_gripper(description, desig.prop_value("gripper"))  # validates the name
            return gripper
        if (
            desig.check_constraints([("type", "setting_arm_configuration"), "arm"])
            or desig.check_constraints([("type", "setting_arm_joints"), "arm"])
            or desig.check_constraints([("type", "reaching"), "arm"])
        ):
            physical_arm(description, desig.prop_value("arm"))  # validates the name
            return arm
        return None

    robot.process_module_resolvers.append(available_process_modules)
    return robot
