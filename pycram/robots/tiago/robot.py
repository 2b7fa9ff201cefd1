"""The simulated TIAGo as a :class:`pycram.robot.Robot`: resolvers and process modules.

One arm and one gripper (physically named ``'right'`` in the description). Like the one-armed
robot of the thesis' ch. 4.2.2 discussion, its only arm module serves requests for either arm
(``'left'``, ``'right'``, ``'0'``, ``'1'``) and its only gripper module requests for either
gripper (the description's ``ARM_ALIASES`` / ``GRIPPER_ALIASES`` map them all to ``'right'``),
so a plan written for the two-armed PR2 runs unchanged. All numbers come from
:mod:`pycram.robots.tiago.description` (validated by the robot registry); the modules and
resolvers are those every simulated robot gets
(:func:`pycram.robots.common.sim_robot.make_sim_robot`).

Process modules (``robot.process_module(name)``): ``navigation``, ``base_stop``, ``head``,
``torso``, ``arm_right``, ``gripper_right``, ``sensors``, ``perception``.
"""

from __future__ import annotations

from typing import Any

from pycram.robots.common.sim_modules import SimRobot
from pycram.robots.common.sim_robot import make_sim_robot
from pycram.world.robot_registry import robot_description

__all__ = ["make_robot"]

#: The validated description (the registry's, shared with the simulated world).
description = robot_description("tiago")


def make_robot(world: Any) -> SimRobot:
    """The TIAGo of ``world`` (a :class:`pycram.sim.World` built for ``'tiago'``), modules online."""
    return make_sim_robot(world, description)
