"""The simulated PR2 as a :class:`pycram.robot.Robot`: resolvers and process modules (thesis ch. 4.2).

Two arms and two grippers, each with its own process module (the thesis' ``Pr2ArmL`` /
``Pr2ArmR``); requests name them ``'left'`` / ``'right'`` (or the thesis' ``'0'`` / ``'1'``).
All numbers come from :mod:`pycram.robots.pr2.description` (validated by the robot registry);
the modules and resolvers are those every simulated robot gets
(:func:`pycram.robots.common.sim_robot.make_sim_robot`).

Process modules (``robot.process_module(name)``): ``navigation``, ``base_stop``, ``head``,
``torso``, ``arm_left``, ``arm_right``, ``gripper_left``, ``gripper_right``, ``sensors``,
``perception``.
"""

from __future__ import annotations

from typing import Any

from pycram.robots.common.sim_modules import SimRobot
from pycram.robots.common.sim_robot import make_sim_robot
from pycram.world.robot_registry import robot_description

__all__ = ["make_robot"]

#: The validated description (the registry's, shared with the simulated world).
description = robot_description("pr2")


def make_robot(world: Any) -> SimRobot:
    """The PR2 of ``world`` (a :class:`pycram.sim.World` built for ``'pr2'``), modules online."""
    return make_sim_robot(world, description)
