"""Resolver sets: which designator resolvers are active, and in which order they are asked.

A plan never names a robot. It performs designators; *which* resolvers turn those designators
into solutions is decided by the active resolver sets: the active robot's (a
:class:`pycram.execution.robot.Robot` is a resolver set with process modules), then the active
world's, then the thesis' global class-level lists (``MotionDesignator.resolvers``, ...).

Guarantees
----------
- The active robot and world are process-global, not thread-local: every branch of a plan runs
  in its own thread and must see the same ones.
- Resolution order for every kind of resolver is: the active robot's, then the active world's,
  then the global lists. A single-robot program that only uses the global lists keeps working
  unchanged.

This module depends on nothing else of pycram; designators read the active resolvers from here,
and :mod:`pycram.execution.robot` sets the active robot through :func:`activate_robot_resolvers`.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import Any

__all__ = [
    "ResolverSet",
    "current_world",
    "current_prospection",
    "use_world",
    "active_resolver_sets",
    "activate_robot_resolvers",
    "active_robot_resolvers",
]

logger = logging.getLogger(__name__)

_lock = threading.RLock()
_active_robot: ResolverSet | None = None
_active_world: ResolverSet | None = None


class ResolverSet:
    """A named bundle of designator resolvers, location generators/validators and action plans.

    A :class:`Robot` is a resolver set with process modules. A simulated or modelled world may
    use a plain resolver set (or subclass it) to register what belongs to the *world* rather than
    to a robot, e.g. location generators for its furniture; activate it with :func:`use_world`.

    All lists are plain Python lists of functions, like the thesis' ``resolvers`` lists:

    - ``motion_resolvers``: ``f(designator) -> list`` of solutions, generators or generator
      functions (see :class:`pycram.designator.MotionDesignator`).
    - ``object_resolvers``: ``f(designator) -> iterable`` of candidate objects in a stable order.
    - ``location_generators``: ``f(designator) -> iterable of poses`` or ``None`` when the
      generator does not apply to this designator.
    - ``location_validators``: ``f(designator, pose) -> bool | None``; ``False`` rejects a pose,
      ``True`` or ``None`` (does not apply) accept it.
    - ``action_resolvers``: ``f(designator) -> plan | iterable of plans | None``; a plan is a
      function ``plan(designator)`` that :func:`pycram.designator.perform` runs as a task.

    ``motion_types`` maps a motion type's name to its
    :class:`~pycram.designators.motion_types.MotionType` (keys, units, valid values): the
    vocabulary motion designators are checked against before anything moves. Empty: nothing is
    checked.
    ``prospection`` is the :class:`pycram.world.prospection.Prospection` of the robot in its
    world (``None`` when there is none); reasoning reaches it through
    :func:`current_prospection`.
    """

    def __init__(self, name: str = "resolvers") -> None:
        self.name = name
        self.prospection: Any = None
        self.motion_resolvers: list[Callable[..., Any]] = []
        self.object_resolvers: list[Callable[..., Any]] = []
        self.location_generators: list[Callable[..., Any]] = []
        self.location_validators: list[Callable[..., Any]] = []
        self.action_resolvers: list[Callable[..., Any]] = []
        self.motion_types: dict[Any, Any] = {}

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"

    def __enter__(self) -> ResolverSet:
        self._previous_world = use_world(self)
        return self

    def __exit__(self, *exc_info: Any) -> None:
        use_world(self._previous_world)


def activate_robot_resolvers(robot: ResolverSet | None) -> ResolverSet | None:
    """Make ``robot`` the active robot's resolver set (``None`` deactivates); returns the previous.

    Called by :func:`pycram.execution.robot.use_robot`, which checks that ``robot`` is a robot.
    """
    global _active_robot
    with _lock:
        previous, _active_robot = _active_robot, robot
    logger.debug("active robot: %r (was %r)", robot, previous)
    return previous


def active_robot_resolvers() -> ResolverSet | None:
    """The active robot (as a resolver set), or ``None`` when none is active."""
    return _active_robot


def use_world(world: ResolverSet | None) -> ResolverSet | None:
    """Make ``world`` the active world resolver set (``None`` deactivates); returns the previous."""
    global _active_world
    if world is not None and not isinstance(world, ResolverSet):
        raise TypeError(f"use_world expects a ResolverSet or None, got {world!r}")
    with _lock:
        previous, _active_world = _active_world, world
    return previous


def current_world() -> ResolverSet | None:
    """The active world resolver set, or ``None``."""
    return _active_world


def current_prospection() -> Any:
    """The prospection of the active robot (else of the active world): the
    :class:`pycram.world.prospection.Prospection` that reasoning asks "what if".

    Raises ``LookupError`` naming what is active when neither has one.
    """
    for resolver_set in active_resolver_sets():
        if resolver_set.prospection is not None:
            return resolver_set.prospection
    raise LookupError(
        f"no prospection available: {describe_active_robot()}, active world "
        f"{_active_world!r}; activate a robot whose world supports prospection "
        f"(e.g. a simulated one)"
    )


def active_resolver_sets() -> list[ResolverSet]:
    """The active robot and world, in resolution order (robot first), skipping inactive ones."""
    with _lock:
        return [s for s in (_active_robot, _active_world) if s is not None]


def gather(attribute: str, global_list: Iterable[Any] = ()) -> list[Any]:
    """Snapshot of ``attribute`` of each active resolver set, followed by ``global_list``."""
    result: list[Any] = []
    for resolver_set in active_resolver_sets():
        result.extend(getattr(resolver_set, attribute, ()))
    result.extend(global_list)
    return result


def describe_active_robot() -> str:
    """Human-readable name of the active robot, for error messages."""
    robot = _active_robot
    if robot is None:
        return "no active robot (global resolver lists)"
    return f"active robot {robot.name!r}"
