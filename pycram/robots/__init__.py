"""Per-robot packages: descriptions (data), simulated hardware settings, resolvers and process modules.

Which robots exist is the robot registry's business (:mod:`pycram.world.robot_registry`: the
``pycram.robots`` entry points); each robot package holds ``description.py`` (data) and
``robot.py`` (``make_robot(world)``; a package without one gets the robot every simulated robot
is, `make_sim_robot`). ``load(name, world)`` builds the :class:`pycram.robot.Robot`
of a simulated world; importing this package stays cheap (the robot modules, which need the
simulation, are imported by ``load``). :mod:`pycram.robots.common` holds what every robot
shares.

May import: every layer above (core to backends). Nothing but the apps imports a robot package.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from typing import Any

from pycram.world.robot_registry import RegisteredRobots, robot_package

__all__ = ["ROBOT_NAMES", "load"]

#: Robots with a simulated implementation: the registered robots, sorted -- read from the registry
#: whenever it is used (a `RegisteredRobots`), so a robot registered after this import is in it.
ROBOT_NAMES: Sequence[str] = RegisteredRobots()


def load(name: str, world: Any) -> Any:
    """The robot ``name`` (one of `ROBOT_NAMES`) of the simulated ``world``, as a
    :class:`pycram.robots.common.sim_modules.SimRobot` with all process modules online and its motion,
    process-module and location resolvers registered. Activate it with ``with robot:``; stop it
    with ``robot.shutdown()``. Raises ``ValueError`` for an unknown name (listing the robots
    registered now) or a world built for another robot.
    """
    if name not in ROBOT_NAMES:
        raise ValueError(f"unknown robot {name!r}; available: {', '.join(ROBOT_NAMES)}")
    robot_module = f"{robot_package(name)}.robot"
    try:
        module = importlib.import_module(robot_module)
    except ModuleNotFoundError as e:
        if e.name != robot_module:
            raise  # the package's robot.py exists and imports something missing: say so
        # a package with a description alone: the robot every simulated robot is
        from pycram.robots.common.sim_robot import make_sim_robot
        from pycram.world.robot_registry import robot_description

        return make_sim_robot(world, robot_description(name))
    return module.make_robot(world)
