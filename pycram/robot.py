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

This module has no dependency on the rest of pycram; designators and process modules read the
active robot from here.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import Any

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

logger = logging.getLogger(__name__)

_lock = threading.RLock()
_active_robot: Robot | None = None
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
    global _active_robot
    if robot is not None and not isinstance(robot, Robot):
        raise TypeError(f"use_robot expects a Robot or None, got {robot!r}")
    with _lock:
        previous, _active_robot = _active_robot, robot
    logger.debug("active robot: %r (was %r)", robot, previous)
    return previous


def current_robot() -> Robot | None:
    """The active robot, or ``None`` when the thesis' global resolver lists are in use."""
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
