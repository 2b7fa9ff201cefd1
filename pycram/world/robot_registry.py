"""The robot registry: which robots exist, their packages, and their validated descriptions.

Robots are Python entry points of the group ``pycram.robots`` (`ENTRY_POINT_GROUP`): the entry
point's name is the robot's name, its value the robot's package, e.g. in ``pyproject.toml``::

    [project.entry-points."pycram.robots"]
    pr2 = "pycram.robots.pr2"

so another distribution adds a robot by declaring one more entry point; nothing else in PyCRAM
names a robot. A robot package holds

- ``description.py``: the robot's description as pure data (UPPERCASE constants, no imports),
  whose schema is :class:`pycram.world.robot_description.RobotDescription`;
- ``robot.py``: ``make_robot(world)``, the robot of a simulated world with its resolvers and
  process modules.

The entry points are read once per process (`importlib.metadata`); each description is imported,
validated and cached on first use (`robot_description`), so a malformed description fails the
first time it is asked for, with a `RobotDescriptionError` that names the key.
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata

from .errors import UnknownNameError
from .robot_description import RobotDescription, RobotDescriptionError

__all__ = [
    "ENTRY_POINT_GROUP",
    "DEFAULT_ROBOT",
    "UnknownRobotError",
    "robot_names",
    "robot_choices",
    "robot_package",
    "robot_description",
]

#: The entry point group robots are registered in (name: robot, value: its package).
ENTRY_POINT_GROUP = "pycram.robots"
#: The robot a world, a demo or an experiment gets when none is named (the thesis' PR2).
DEFAULT_ROBOT = "pr2"


class UnknownRobotError(UnknownNameError, ValueError):
    """A robot name that is not registered; the message lists the registered robots. Both a
    `KeyError` (an unknown name, like the other `UnknownNameError`s) and a `ValueError` (a bad
    argument)."""

    def __init__(self, name: object) -> None:
        super().__init__("robot", name, robot_names())


@functools.cache
def _packages() -> dict[str, str]:
    """``{robot name: package}`` of the registered entry points."""
    packages: dict[str, str] = {}
    for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        if packages.get(entry.name, entry.value) != entry.value:
            raise RuntimeError(
                f"robot {entry.name!r} is registered twice ({ENTRY_POINT_GROUP!r} entry points): "
                f"{packages[entry.name]!r} and {entry.value!r}"
            )
        packages[entry.name] = entry.value
    return packages


def robot_names() -> tuple[str, ...]:
    """The names of the registered robots, sorted."""
    return tuple(sorted(_packages()))


def robot_choices() -> str:
    """The registered robots for a message: ``'pr2'``, ``'pr2' or 'tiago'``, ``'a', 'b' or 'c'``."""
    quoted = [repr(n) for n in robot_names()]
    return " or ".join([", ".join(quoted[:-1]), quoted[-1]]) if len(quoted) > 1 else "".join(quoted)


def robot_package(name: str) -> str:
    """The package of the robot `name` (e.g. ``'pycram.robots.pr2'``); `UnknownRobotError`
    lists the registered robots."""
    try:
        return _packages()[name]
    except (KeyError, TypeError):
        raise UnknownRobotError(name) from None


@functools.cache
def _description(name: str) -> RobotDescription:
    module = importlib.import_module(f"{robot_package(name)}.description")
    description = RobotDescription.from_module(module)
    if description.NAME != name:
        raise RobotDescriptionError(
            name, "NAME", f"NAME is {description.NAME!r} but the robot is registered as {name!r}"
        )
    return description


def robot_description(name: str) -> RobotDescription:
    """The validated description of the robot `name` (imported and checked once, then cached).
    Raises `UnknownRobotError` for an unregistered name, `RobotDescriptionError` for a
    description that does not fit the schema."""
    if not isinstance(name, str) or name not in _packages():
        raise UnknownRobotError(name)
    return _description(name)
