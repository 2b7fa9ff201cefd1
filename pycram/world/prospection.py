"""Prospection: ask "what if" about the world as it is now, without moving the robot.

A :class:`Prospection` answers three questions for the robot it belongs to:

- :meth:`Prospection.in_collision` -- would the robot, at a base pose (and in its current or a
  given joint configuration), collide with the environment?
- :meth:`Prospection.reachable` -- from a base pose, can an arm put its tool frame through a
  sequence of poses (pre-grasp, grasp, lift, ...) within its joint limits and without collision?
  The answer carries the joint solutions, or the reason why not.
- :meth:`Prospection.visible` -- with the head camera pointed at a target from a base pose, which
  fraction of the target would it see?

and, for arm motion planning (:mod:`pycram.reasoning.motion`), three more:

- :meth:`Prospection.arm_joint_limits` -- an arm's joints (the torso first when asked) with their
  position, velocity and acceleration limits;
- :meth:`Prospection.configuration_checker` -- a :class:`ConfigurationChecker` that tells, fast
  (tens of microseconds a question), whether an arm joint configuration at a base pose is free of
  collisions with the environment, the objects, the robot's other parts, with a held object moving
  with the hand and the object being grasped exempt at the gripper;
- :meth:`Prospection.solve_ik` -- an arm configuration that puts the tool frame at a pose, within
  the joint limits and (optionally) free of collisions: an :class:`IKResult`.

Implementations that do not plan arm motion need not provide these: the defaults raise
``NotImplementedError`` naming the implementation.

Guarantees every implementation gives
-------------------------------------
- **The world as it is now**: each answer reflects the state of the world at (or shortly before)
  the call: objects moved, furniture opened, obstacles placed, the robot's current joints.
- **Nothing moves**: asking never changes the running world (no command is sent, no simulator
  state is touched).
- **Thread-safe**: any number of threads may ask at once; the same question about the same world
  state gets the same answer from every thread.
- Deterministic: no answer depends on the thread, on earlier questions or on wall time.

Conventions: map frame, positions [m], yaw [rad] (counter-clockwise about z), quaternions
(w, x, y, z). A base pose is anything with ``x``, ``y``, ``yaw`` attributes or an (x, y, yaw)
tuple; an end-effector pose is anything with ``position`` and ``orientation`` attributes or a
(position, orientation) pair (orientation ``None``: position only).

This module is backend-neutral (stdlib only). The simulator's implementation is
``pycram.backends.sim.prospection.SimProspection``; reasoning code gets the active one from
:func:`pycram.robot.current_prospection` and never imports a backend.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import TracebackType
from typing import Any

__all__ = [
    "BasePose",
    "ToolPose",
    "Prospection",
    "Reachability",
    "Visibility",
    "REACH_FAILURES",
    "JointLimits",
    "ConfigurationChecker",
    "IKResult",
    "IK_FAILURES",
    "as_base_pose",
    "as_tool_pose",
]

#: Reasons why :meth:`Prospection.reachable` fails (``Reachability.reason``):
#: ``'out_of_reach'`` -- no arm configuration puts the tool at the pose, even ignoring joint limits;
#: ``'joint_limit'`` -- one does, but only outside the joint limits;
#: ``'collision'`` -- every solution found (or the base pose itself) collides with the environment.
REACH_FAILURES = ("out_of_reach", "joint_limit", "collision")

#: Reasons why :meth:`Prospection.solve_ik` fails (``IKResult.reason``):
#: ``'no_solution'`` -- no seed converged to the pose within the tolerances and the joint limits;
#: ``'collision'`` -- solutions were found, but every one collides (with ``avoid_collisions``).
IK_FAILURES = ("no_solution", "collision")


@dataclass(frozen=True)
class BasePose:
    """A base pose in the map frame: x [m], y [m], yaw [rad]."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class ToolPose:
    """An end-effector pose in the map frame: position [m], orientation (w, x, y, z) or None
    (any orientation)."""

    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float] | None = None


def as_base_pose(pose: Any) -> BasePose:
    """``pose`` (an object with x, y, yaw or an (x, y, yaw) sequence) as a :class:`BasePose`.

    Raises ``ValueError`` naming the value when it is neither, or not finite.
    """
    try:
        if hasattr(pose, "yaw"):
            x, y, yaw = float(pose.x), float(pose.y), float(pose.yaw)
        else:
            x, y, yaw = (float(v) for v in pose)
    except (TypeError, ValueError, AttributeError):
        raise ValueError(f"a base pose is (x [m], y [m], yaw [rad]) or has x, y, yaw; got {pose!r}") from None
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise ValueError(f"base pose must be finite, got {pose!r}")
    return BasePose(x, y, yaw)


def as_tool_pose(pose: Any) -> ToolPose:
    """``pose`` (an object with position/orientation, a (position, orientation) pair, or a bare
    3D position) as a :class:`ToolPose`. Raises ``ValueError`` naming the value otherwise."""
    try:
        if hasattr(pose, "position"):
            position, orientation = pose.position, getattr(pose, "orientation", None)
        elif len(pose) == 2:
            position, orientation = pose
        else:
            position, orientation = pose, None
        p = tuple(float(v) for v in position)
        q = None if orientation is None else tuple(float(v) for v in orientation)
        if len(p) != 3 or (q is not None and len(q) != 4):
            raise ValueError
    except (TypeError, ValueError):
        raise ValueError(
            "a tool pose is (position (x, y, z) [m], orientation (w, x, y, z) or None) "
            f"or has position/orientation; got {pose!r}"
        ) from None
    if not all(math.isfinite(v) for v in p + (q or ())):
        raise ValueError(f"tool pose must be finite, got {pose!r}")
    if q is not None:
        n = math.sqrt(sum(v * v for v in q))
        if n < 1e-9:
            raise ValueError(f"tool orientation must be a non-zero quaternion, got {pose!r}")
        q = tuple(v / n for v in q)
    return ToolPose(p, q)  # type: ignore[arg-type]


@dataclass(frozen=True)
class Reachability:
    """Answer of :meth:`Prospection.reachable`; truthy iff every pose is reachable.

    ``solutions``: one tuple of arm joint positions [rad or m] per reachable pose, in the order
    of the poses (joint order of the robot description's arm), up to the first failing pose.
    ``reason`` (one of :data:`REACH_FAILURES`) and ``failed_index`` (index of the first pose
    that failed, -1 for the base pose itself) are set on failure; ``message`` says more
    (distance, joint, contact).
    """

    arm: str
    solutions: tuple[tuple[float, ...], ...] = ()
    reason: str | None = None
    failed_index: int | None = None
    message: str = ""

    @property
    def ok(self) -> bool:
        return self.reason is None

    def __bool__(self) -> bool:
        return self.ok


@dataclass(frozen=True)
class Visibility:
    """Answer of :meth:`Prospection.visible`.

    ``fraction``: share of the target's sample points the head camera sees (0..1);
    ``visible``: ``fraction >= threshold`` of the query; ``occluders``: names of what hides the
    other points (most points first), empty when nothing does; ``in_view``: share of the
    points inside the camera's field of view (the rest count as not seen).
    """

    fraction: float
    visible: bool
    in_view: float = 1.0
    occluders: tuple[str, ...] = field(default_factory=tuple)

    def __bool__(self) -> bool:
        return self.visible


@dataclass(frozen=True)
class JointLimits:
    """The joints of an arm (the torso first when it is included) and their limits, index by index.

    ``lower``/``upper``: position limits [rad or m] (``-inf``/``inf`` for a continuous joint);
    ``velocity``: speed limits [rad/s or m/s] (> 0); ``acceleration``: acceleration limits
    [rad/s^2 or m/s^2] (> 0). All tuples have the length of ``joints``.
    """

    joints: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity: tuple[float, ...]
    acceleration: tuple[float, ...]

    def __post_init__(self) -> None:
        n = len(self.joints)
        for name in ("lower", "upper", "velocity", "acceleration"):
            if len(getattr(self, name)) != n:
                raise ValueError(f"JointLimits.{name} has {len(getattr(self, name))} values for {n} joints")
        if any(v <= 0 for v in self.velocity + self.acceleration):
            raise ValueError("velocity and acceleration limits must be positive")
        if any(lo > hi for lo, hi in zip(self.lower, self.upper)):
            raise ValueError("a lower position limit exceeds its upper limit")

    @property
    def continuous(self) -> tuple[bool, ...]:
        """Per joint: True when it has no position limits (a continuous revolute joint)."""
        return tuple(math.isinf(lo) and math.isinf(hi) for lo, hi in zip(self.lower, self.upper))

    def within(self, q: Sequence[float], tolerance: float = 1e-6) -> bool:
        """Whether ``q`` (one position per joint) lies within the position limits (+- tolerance)."""
        return len(q) == len(self.joints) and all(
            lo - tolerance <= v <= hi + tolerance for v, lo, hi in zip(q, self.lower, self.upper)
        )


class ConfigurationChecker(abc.ABC):
    """Collision questions about one arm's joint configurations in one fixed setting (base pose,
    other joints, held and exempt objects), made by :meth:`Prospection.configuration_checker`.

    A configuration is a sequence of positions [rad or m] in the order of :attr:`joints`. The
    world is the one of the moment the checker was made; asking never changes it. A checker holds
    scratch data of its own: use it from one thread at a time, and :meth:`close` it (or use it as
    a context manager) when done. :attr:`checks` counts the configurations checked so far.
    """

    #: The joints of a configuration, in order (the torso first when included).
    joints: tuple[str, ...] = ()
    #: Configurations checked so far (by :meth:`is_free`, :meth:`contacts`, :meth:`motion_free` and
    #: :meth:`first_touching`).
    checks: int = 0
    #: With a held object: how far [rad] the direction that points up through it when the checker
    #: was made may lean from the vertical in a free configuration (:meth:`held_lean`); the
    #: default, infinity, lets it turn any way.
    max_held_lean: float = math.inf

    @abc.abstractmethod
    def is_free(self, q: Sequence[float]) -> bool:
        """True iff the robot with the arm at ``q`` touches nothing (environment, objects, its own
        other parts), counting contacts closer than the checker's clearance."""

    @abc.abstractmethod
    def contacts(self, q: Sequence[float]) -> list[tuple[str, str]]:
        """The distinct touching pairs (robot part or held object, obstacle) with the arm at ``q``."""

    def held_lean(self, q: Sequence[float]) -> float:
        """How far [rad] the direction that pointed up through the held object when the checker
        was made leans from the vertical with the arm at ``q`` (0 without a held object)."""
        return 0.0

    def motion_free(self, q0: Sequence[float], q1: Sequence[float], resolution: float = 0.02) -> bool:
        """True iff every configuration on the straight joint-space segment from ``q0`` to ``q1``,
        sampled no more than ``resolution`` [rad or m, largest joint step] apart (both ends
        included), is free."""
        return self.first_touching(q0, q1, resolution) is None

    def first_touching(self, q0: Sequence[float], q1: Sequence[float], resolution: float = 0.02) -> list[float] | None:
        """The first configuration from ``q0`` on the straight segment to ``q1`` (sampled as
        :meth:`motion_free` does) that is not free, or None when all are."""
        steps = max(1, math.ceil(max((abs(b - a) for a, b in zip(q0, q1)), default=0.0) / resolution))
        for i in range(steps + 1):
            s = i / steps
            q = [a + s * (b - a) for a, b in zip(q0, q1)]
            if not self.is_free(q):
                return q
        return None

    def close(self) -> None:  # noqa: B027 - optional hook: implementations release their data here
        """Release the checker's scratch data; it must not be used afterwards."""

    def __enter__(self) -> ConfigurationChecker:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


@dataclass(frozen=True)
class IKResult:
    """Answer of :meth:`Prospection.solve_ik`; truthy iff a solution was found.

    ``joints``: the solved joints in order; ``positions``: their positions [rad or m] (empty on
    failure); ``position_error`` [m] and ``orientation_error`` [rad]: the remaining tool-frame
    errors of the solution (of the best attempt on failure); ``reason`` (one of
    :data:`IK_FAILURES`) and ``message`` say why not; ``iterations``: solver iterations spent.
    """

    arm: str
    joints: tuple[str, ...]
    positions: tuple[float, ...] = ()
    position_error: float = math.inf
    orientation_error: float = math.inf
    reason: str | None = None
    message: str = ""
    iterations: int = 0

    @property
    def ok(self) -> bool:
        return self.reason is None

    def __bool__(self) -> bool:
        return self.ok


class Prospection(abc.ABC):
    """What-if questions about one robot in the current world (see the module's guarantees)."""

    @property
    @abc.abstractmethod
    def arms(self) -> tuple[str, ...]:
        """The arm names :meth:`reachable` accepts."""

    @abc.abstractmethod
    def in_collision(
        self,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        carried: Sequence[str] = (),
        objects: bool = False,
    ) -> bool:
        """Would the robot at ``base_pose`` collide with the environment (and, with ``objects``,
        with an object of the world)?

        The robot keeps its current joint positions except those in ``joint_configuration``
        (joint name -> position [rad or m]). The objects named in ``carried`` (objects the robot
        holds) move with the base from where they are now -- rigidly, as the base drives with
        them -- and count as parts of the robot. Raises ``ValueError`` for an unknown joint or
        object (the message lists the valid ones) or a malformed pose.
        """

    @abc.abstractmethod
    def collisions(
        self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None
    ) -> list[tuple[str, str]]:
        """Like :meth:`in_collision`, but the touching pairs (robot part, environment part)."""

    def drivable(
        self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None, carried: Sequence[str] = ()
    ) -> bool:
        """Would navigation take ``base_pose`` as a goal, the robot arriving in
        ``joint_configuration`` with the objects ``carried`` -- judged with navigation's own model
        of the floor and of the robot's footprint and clearance, in this prospection's world?
        A backend without such a model answers True (the caller's own checks decide)."""
        return True

    @abc.abstractmethod
    def reachable(
        self, arm: str, poses: Sequence[Any], base_pose: Any, joint_configuration: Mapping[str, float] | None = None
    ) -> Reachability:
        """Can ``arm`` put its tool frame at each of ``poses`` in turn, from ``base_pose``?

        Inverse kinematics for the sequence (each solution seeds the next, so the arm moves
        little between poses), each solution checked within the joint limits and against
        collisions of the whole robot with the environment (not with the items). The base, the
        torso and the other joints stay as they are now (or as in ``joint_configuration``).
        Raises ``ValueError`` for an unknown arm (listing the valid ones) or an empty sequence.
        """

    @abc.abstractmethod
    def visible(
        self,
        target: Any,
        base_pose: Any,
        threshold: float = 0.5,
        joint_configuration: Mapping[str, float] | None = None,
    ) -> Visibility:
        """How much of ``target`` does the head camera see from ``base_pose``, pointed at it?

        ``target`` is the name of an object in the world or a point (x, y, z) [m]. The head
        turns (within its joint limits) to look at the target's centre; the rest of the robot
        keeps its configuration. ``visible`` is ``fraction >= threshold``. Raises ``ValueError``
        for an unknown object (listing the known ones).
        """

    # ---------------------------------------------------------------- arm motion planning
    # Optional: implementations that do not plan arm motion keep these defaults.

    def arm_joint_limits(self, arm: str, include_torso: bool = False) -> JointLimits:
        """The joints of ``arm`` (in the robot description's order; the torso joint first with
        ``include_torso``) and their position, velocity and acceleration limits.

        Raises ``ValueError`` for an unknown arm (listing the valid ones), ``NotImplementedError``
        when this prospection does not support arm motion planning.
        """
        raise NotImplementedError(f"{type(self).__name__} does not provide arm_joint_limits (arm motion planning)")

    def configuration_checker(
        self,
        arm: str,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        *,
        include_torso: bool = False,
        held_object: str | None = None,
        exempt_object: str | None = None,
        clearance: float = 0.0,
        object_clearance: float = 0.0,
        self_collision: bool = True,
    ) -> ConfigurationChecker:
        """A :class:`ConfigurationChecker` for ``arm`` (joints as in :meth:`arm_joint_limits`) with
        the robot at ``base_pose``, its other joints as they are now (or as in
        ``joint_configuration``).

        Obstacles: the environment, the objects of the world, and (``self_collision``) the robot's
        parts that do not move with the arm. ``held_object`` (an object's name) moves rigidly with
        the hand as it is held now and counts as part of the arm; ``exempt_object`` may touch the
        gripper (the object being grasped) but nothing else of the arm. A pair counts as touching
        when closer than ``clearance`` [m] (negative: that much penetration is tolerated); the arm
        and an object of the world (not the held one) when closer than ``object_clearance`` [m] if
        that is larger (objects are where they were measured, a few cm off: a plan keeps away).
        The robot's own parts may overlap each other as deep as the implementation's models of
        them do in ordinary configurations (the simulator's: 15 mm, link meshes collide as their
        convex hulls) before that counts. A configuration that tilts the held object further than
        the checker's `ConfigurationChecker.max_held_lean` (set it after making the checker) is
        not free either.

        Raises ``ValueError`` for an unknown arm, joint or object (listing the valid ones),
        ``NotImplementedError`` when this prospection does not support arm motion planning.
        """
        raise NotImplementedError(f"{type(self).__name__} does not provide configuration_checker (arm motion planning)")

    def arm_configuration_free(
        self,
        arm: str,
        q: Sequence[float],
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        **options: Any,
    ) -> bool:
        """Whether ``arm`` at ``q`` is free of collisions (one question; for many, make one
        :meth:`configuration_checker` and ask it). ``options`` are those of
        :meth:`configuration_checker`."""
        with self.configuration_checker(arm, base_pose, joint_configuration, **options) as checker:
            return checker.is_free(q)

    def tool_pose(self, arm: str, base_pose: Any, joint_configuration: Mapping[str, float] | None = None) -> ToolPose:
        """Where the tool frame of ``arm`` is (map frame: position [m], orientation (w, x, y, z))
        with the robot at ``base_pose`` and its joints as they are but those in
        ``joint_configuration``. Raises ``ValueError`` for an unknown arm or joint,
        ``NotImplementedError`` when this prospection does not support it."""
        raise NotImplementedError(f"{type(self).__name__} does not provide tool_pose")

    def solve_ik(
        self,
        arm: str,
        pose: Any,
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        *,
        seeds: Sequence[Sequence[float]] = (),
        avoid_collisions: bool = True,
        held_object: str | None = None,
        exempt_object: str | None = None,
        clearance: float = 0.0,
        position_tolerance: float = 0.001,
        orientation_tolerance: float = 0.01,
    ) -> IKResult:
        """Arm joint positions (order of :meth:`arm_joint_limits` without the torso) that put the
        tool frame of ``arm`` at ``pose`` (a tool pose: position [m], orientation (w, x, y, z) or
        None for any) with the robot at ``base_pose``, within the joint limits and the tolerances
        (position [m], orientation [rad]).

        Tries the given ``seeds`` first, then the arm's current configuration, its named
        configurations and a few random ones (deterministic). With ``avoid_collisions`` the
        solution is also free of collisions, as :meth:`configuration_checker` judges with
        ``held_object``, ``exempt_object`` and ``clearance``. Raises ``ValueError`` for an
        unknown arm or a malformed pose, ``NotImplementedError`` when this prospection does not
        support it.
        """
        raise NotImplementedError(f"{type(self).__name__} does not provide solve_ik (arm motion planning)")
