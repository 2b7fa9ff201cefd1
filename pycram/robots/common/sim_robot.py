"""Any robot of a simulated world as a :class:`pycram.robot.Robot`, built from its description alone
(thesis ch. 4.2).

`make_sim_robot(world, description)` gives a validated
:class:`pycram.world.robot_description.RobotDescription` its process modules -- one arm module per
arm of ``ARMS`` (the thesis' ``Pr2ArmL`` / ``Pr2ArmR``), one gripper module per gripper of
``GRIPPERS``, and ``navigation``, ``base_stop``, ``head``, ``torso``, ``sensors``,
``perception`` -- and registers the robot's motion, location and process-module resolvers. The
process-module resolver chooses a module by the designator's type; a request for an arm or a
gripper is served by the physical arm or gripper its name stands for (``ARM_ALIASES`` /
``GRIPPER_ALIASES``: the thesis' ``'0'`` / ``'1'``, or on a one-armed robot ``'left'`` and
``'right'`` alike), and an unknown name fails naming the valid ones.

Process modules (``robot.process_module(name)``): ``navigation``, ``base_stop``, ``head``,
``torso``, ``arm_<arm>`` per arm, ``gripper_<gripper>`` per gripper, ``sensors``,
``perception``. Each robot package's ``robot.py`` is a thin ``make_robot(world)`` over this.
"""

from __future__ import annotations

from typing import Any

from pycram.execution.process_module import ProcessModule
from pycram.world.robot_description import RobotDescription

from . import sim_modules as sm
from .sim_resolvers import make_location_generator, make_motion_resolver, physical_arm, physical_gripper
from .sim_vocabulary import motion_types

__all__ = ["make_sim_robot"]

#: Designator types served by a module of their own (not an arm's or a gripper's), by module name.
_MODULE_OF_TYPE = {
    "moving": "navigation",
    "cancelling_movement": "base_stop",
    "pointing_head": "head",
    "setting_torso": "torso",
    "detecting": "perception",
    "subscribing_pose": "sensors",
    "subscribing_gripper": "sensors",
}
#: Designator types served by the module of the arm they name (their ``arm`` property).
_ARM_TYPES = ("setting_arm_configuration", "setting_arm_joints", "reaching")


def make_sim_robot(world: Any, description: RobotDescription) -> sm.SimRobot:
    """The robot of `description` in the simulated `world` (a :class:`pycram.sim.World` built for
    ``description.NAME``), with all its process modules online and its resolvers registered.

    Raises ``ValueError`` if `world` was built for another robot.
    """
    if getattr(world, "robot", None) != description.NAME:
        raise ValueError(
            f"make_robot for {description.NAME!r} needs a world with a {description.NAME!r}, got {world!r}"
        )
    robot = sm.SimRobot(description.NAME, world, description)
    # the order of the modules is the order they come online (kept as it was per robot)
    navigation = robot.add_process_module("navigation", sm.NavigationModule(world))
    modules: dict[str, ProcessModule] = {
        "navigation": navigation,
        "base_stop": robot.add_process_module("base_stop", sm.BaseStopModule(world, navigation)),
        "head": robot.add_process_module("head", sm.HeadModule(world)),
        "torso": robot.add_process_module("torso", sm.TorsoModule(world)),
    }
    arms = {
        arm: robot.add_process_module(f"arm_{arm}", sm.ArmModule(world, arm, robot=robot)) for arm in description.ARMS
    }
    grippers = {g: robot.add_process_module(f"gripper_{g}", sm.GripperModule(world, g)) for g in description.GRIPPERS}
    modules["sensors"] = robot.add_process_module("sensors", sm.SensorModule(world))
    modules["perception"] = robot.add_process_module("perception", sm.PerceptionModule(world, robot.belief))

    robot.motion_types.update(motion_types(world, description))
    robot.motion_resolvers.append(make_motion_resolver(world, description))
    robot.location_generators.append(make_location_generator(world, description, robot.belief))

    def available_process_modules(desig: Any) -> ProcessModule | None:
        """Thesis ch. 4.2.2: choose the robot's module by the designator's type (and arm or
        gripper; a name the robot does not know raises ``ValueError`` naming the valid ones)."""
        for motion_type, module in _MODULE_OF_TYPE.items():
            if desig.check_constraints([("type", motion_type)]):
                return modules[module]
        if desig.check_constraints([("type", "setting_gripper"), "gripper"]):
            return grippers[physical_gripper(description, desig.prop_value("gripper"))]
        for motion_type in _ARM_TYPES:
            if desig.check_constraints([("type", motion_type), "arm"]):
                return arms[physical_arm(description, desig.prop_value("arm"))]
        return None

    robot.process_module_resolvers.append(available_process_modules)
    return robot
