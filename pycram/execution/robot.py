"""Robots: one bundle of resolvers and process modules per robot, and which robot is active.

A plan never names a robot. It performs designators; *which* resolvers turn those designators
into solutions and *which* process modules execute them is decided by the active robot::

    with pr2:                       # or: use_robot(pr2)
        perform(MotionDesignator(type='moving', pose=p))

Guarantees
----------
- The active robot (and the active world, see :func:`use_world`) is process-global, not
  thread-local: every branch of a plan runs in its own thread and must see the same robot.
- ``with robot:`` nests: leaving the block restores whatever was active before, also on error.
- Resolution order for every kind of resolver is: the active robot's, then the active world's,
  then the thesis' global class-level lists (``MotionDesignator.resolvers``,
  ``ProcessModule.resolvers``, ...). A single-robot program that only uses the global lists keeps
  working unchanged.

Which resolvers are active lives one layer up, in :mod:`pycram.designators.resolvers` (designators
read it; this module sets the active robot there).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from pycram.designators.resolvers import (
    ResolverSet,
    activate_robot_resolvers,
    active_resolver_sets,
    active_robot_resolvers,
    current_prospection,
    current_world,
    use_world,
)

__all__ = [
    "ResolverSet",
    "Robot",
    "current_robot",
    "current_world",
    "current_prospection",
    "use_robot",
    "use_world",
    "active_resolver_sets",
]


class Robot(ResolverSet):
    """A robot: its designator resolvers plus its process modules and their resolvers.

    ``process_modules`` maps a component name (``'navigation'``, ``'head'``, ``'arm_left'``...)
    to a :class:`pycram.process_module.ProcessModule`; ``process_module_resolvers`` holds the
    thesis-style functions ``f(designator) -> ProcessModule | None`` that dispatch motion
    designators to those modules (typically on ``type`` and ``arm``).

    ``with robot:`` activates the robot for the whole process for the duration of the block and
    restores the previously active robot on exit (it nests). Activating a robot does not start or
    stop its process modules.
    """

    def __init__(self, name: str, process_modules: dict[str, Any] | None = None) -> None:
        super().__init__(name)
        self.process_modules: dict[str, Any] = dict(process_modules or {})
        self.process_module_resolvers: list[Callable[..., Any]] = []
        self._previous_stack: list[Robot | None] = []
        self._stack_lock = threading.Lock()

    def add_process_module(self, name: str, module: Any) -> Any:
        """Register ``module`` under ``name`` and return it (for one-line definitions)."""
        self.process_modules[name] = module
        return module

    def process_module(self, name: str) -> Any:
        """The process module registered under ``name``.

        Raises ``KeyError`` listing the available names when there is none.
        """
        try:
            return self.process_modules[name]
        except KeyError:
            raise KeyError(
                f"robot {self.name!r} has no process module {name!r}; available: {sorted(self.process_modules)}"
            ) from None

    def __enter__(self) -> Robot:
        previous = use_robot(self)
        with self._stack_lock:
            self._previous_stack.append(previous)
        return self

    def __exit__(self, *exc_info: Any) -> None:
        with self._stack_lock:
            previous = self._previous_stack.pop()
        use_robot(previous)


def use_robot(robot: Robot | None) -> Robot | None:
    """Make ``robot`` the active robot for the whole process (``None`` deactivates).

    Returns the previously active robot so callers can restore it. Prefer ``with robot:``.
    """
    if robot is not None and not isinstance(robot, Robot):
        raise TypeError(f"use_robot expects a Robot or None, got {robot!r}")
    previous = activate_robot_resolvers(robot)
    assert previous is None or isinstance(previous, Robot)
    return previous


def current_robot() -> Robot | None:
    """The active robot, or ``None`` when the thesis' global resolver lists are in use."""
    robot = active_robot_resolvers()
    assert robot is None or isinstance(robot, Robot)
    return robot
