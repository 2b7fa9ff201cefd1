"""The simulated mobile Panda as a PyCRAM robot: every process module and resolver comes from its
description (`pycram.robots.common.sim_robot.make_sim_robot`)."""

from __future__ import annotations

from typing import Any

from pycram.robots.common.sim_robot import make_sim_robot
from pycram.world.robot_registry import robot_description

__all__ = ["make_robot"]


def make_robot(world: Any) -> Any:
    """The mobile Panda of ``world`` (a :class:`pycram.sim.World` built for ``'mobile-panda'``)."""
    return make_sim_robot(world, robot_description("mobile-panda"))
