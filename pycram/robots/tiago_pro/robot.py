"""The simulated TIAGo Pro as a :class:`pycram.robot.Robot`: resolvers and process modules.

Two arms and two grippers, each with its own process module; requests name them ``'left'`` /
``'right'`` (or the thesis' ``'0'`` / ``'1'``), as for the PR2, so a plan written for the PR2
runs unchanged. All numbers come from :mod:`pycram.robots.tiago_pro.description` (validated by
the robot registry); the modules and resolvers are those every simulated robot gets
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
description = robot_description("tiago-pro")


def make_robot(world: Any) -> SimRobot:
    """The TIAGo Pro of ``world`` (a :class:`pycram.sim.World` built for ``'tiago-pro'``), modules
    online."""
    return make_sim_robot(world, description)
