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

Every lookup asks the registry when it is made: the entry points are read again
(`importlib.metadata`, ~15 ms) whenever ``sys.path`` or one of its directories changed since the
last read -- a robot package installed, or put on the path, while a process runs is found by the
next lookup -- and are cached otherwise. `RegisteredRobots` is a sequence of the names that
reads them so (``pycram.robots.ROBOT_NAMES`` is one). Each description is imported, validated
and cached on first use (`robot_description`), so a malformed description fails the first time
it is asked for, with a `RobotDescriptionError` that names the key; a cached description is
dropped when its robot's package, or the file it comes from, is no longer the registered one.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import sys
import threading
from collections.abc import Iterable, Iterator, Sequence
from typing import overload

from .errors import UnknownNameError
from .robot_description import RobotDescription, RobotDescriptionError

__all__ = [
    "ENTRY_POINT_GROUP",
    "DEFAULT_ROBOT",
    "UnknownRobotError",
    "RegisteredRobots",
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


#: Guards the caches below (lookups come from plan threads and the simulation thread alike).
_lock = threading.RLock()
#: The last read of the entry points: (`_path_key` then, {robot name: package}).
_read: tuple[tuple[tuple[str, int | None], ...], dict[str, str]] | None = None
#: Validated descriptions: robot name -> (package, the description module's file, description).
_descriptions: dict[str, tuple[str, str | None, RobotDescription]] = {}


def _path_key() -> tuple[tuple[str, int | None], ...]:
    """``sys.path`` with each directory's modification time [ns] (None: missing): it changes when
    a distribution is installed into, or a path put on, the import path (a few microseconds)."""
    key = []
    for entry in sys.path:
        try:
            mtime: int | None = os.stat(entry or os.curdir).st_mtime_ns
        except (OSError, TypeError, ValueError):
            mtime = None
        key.append((str(entry), mtime))
    return tuple(key)


def _read_entry_points() -> dict[str, str]:
    """``{robot name: package}`` of the entry points on the import path now."""
    packages: dict[str, str] = {}
    for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        if packages.get(entry.name, entry.value) != entry.value:
            raise RuntimeError(
                f"robot {entry.name!r} is registered twice ({ENTRY_POINT_GROUP!r} entry points): "
                f"{packages[entry.name]!r} and {entry.value!r}"
            )
        packages[entry.name] = entry.value
    return packages


def _description_file(package: str) -> str | None:
    """The file the description module of `package` is (or would be) imported from."""
    try:
        spec = importlib.util.find_spec(f"{package}.description")
    except Exception:  # the package cannot be imported now: its cached description is dropped
        return None
    return spec.origin if spec is not None else None


def _packages() -> dict[str, str]:
    """``{robot name: package}`` of the registered entry points, read again when the import path
    changed since the last read (`_path_key`); descriptions of robots whose package or
    description file changed meanwhile are dropped."""
    global _read
    key = _path_key()
    with _lock:
        if _read is not None and _read[0] == key:
            return _read[1]
        packages = _read_entry_points()
        _read = (key, packages)
        for name, (package, origin, _) in list(_descriptions.items()):
            if packages.get(name) != package or _description_file(package) != origin:
                del _descriptions[name]
        return packages


def robot_names() -> tuple[str, ...]:
    """The names of the registered robots, sorted."""
    return tuple(sorted(_packages()))


def robot_choices(names: Iterable[str] | None = None) -> str:
    """Robot names for a message -- the registered robots, or `names`: ``'pr2'``,
    ``'pr2' or 'tiago'``, ``'a', 'b' or 'c'``."""
    quoted = [repr(n) for n in (robot_names() if names is None else names)]
    return " or ".join([", ".join(quoted[:-1]), quoted[-1]]) if len(quoted) > 1 else "".join(quoted)


def robot_package(name: str) -> str:
    """The package of the robot `name` (e.g. ``'pycram.robots.pr2'``); `UnknownRobotError`
    lists the registered robots."""
    try:
        return _packages()[name]
    except (KeyError, TypeError):
        raise UnknownRobotError(name) from None


def _description(name: str) -> RobotDescription:
    package = robot_package(name)
    with _lock:
        cached = _descriptions.get(name)
    if cached is not None and cached[0] == package:
        return cached[2]
    module = importlib.import_module(f"{package}.description")
    description = RobotDescription.from_module(module)
    if description.NAME != name:
        raise RobotDescriptionError(
            name, "NAME", f"NAME is {description.NAME!r} but the robot is registered as {name!r}"
        )
    with _lock:
        _descriptions[name] = (package, getattr(module, "__file__", None), description)
    return description


def robot_description(name: str) -> RobotDescription:
    """The validated description of the robot `name` (imported and checked once, then cached
    while the robot's registration stays the same).
    Raises `UnknownRobotError` for an unregistered name, `RobotDescriptionError` for a
    description that does not fit the schema."""
    if not isinstance(name, str) or name not in _packages():
        raise UnknownRobotError(name)
    return _description(name)


class RegisteredRobots(Sequence[str]):
    """The names of the registered robots, sorted (`robot_names`), read from the registry each time
    the sequence is used -- iterated, indexed, measured or asked ``name in`` -- so that a robot
    registered after it was made is in it. ``tuple(names)`` is the registry's names now."""

    @overload
    def __getitem__(self, index: int) -> str: ...

    @overload
    def __getitem__(self, index: slice) -> tuple[str, ...]: ...

    def __getitem__(self, index: int | slice) -> str | tuple[str, ...]:
        return robot_names()[index]

    def __len__(self) -> int:
        return len(robot_names())

    def __iter__(self) -> Iterator[str]:
        return iter(robot_names())

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in _packages()

    def __repr__(self) -> str:
        return repr(robot_names())
