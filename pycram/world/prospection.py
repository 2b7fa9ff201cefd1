"""Prospection: ask "what if" about the world as it is now, without moving the robot.

A :class:`Prospection` answers three questions for the robot it belongs to:

- :meth:`Prospection.in_collision` -- would the robot, at a base pose (and in its current or a
  given joint configuration), collide with the environment?
- :meth:`Prospection.reachable` -- from a base pose, can an arm put its tool frame through a
  sequence of poses (pre-grasp, grasp, lift, ...) within its joint limits and without collision?
  The answer carries the joint solutions, or the reason why not.
- :meth:`Prospection.visible` -- with the head camera pointed at a target from a base pose, which
  fraction of the target would it see?

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
from typing import Any

__all__ = [
    "BasePose",
    "ToolPose",
    "Prospection",
    "Reachability",
    "Visibility",
    "REACH_FAILURES",
    "as_base_pose",
    "as_tool_pose",
]

#: Reasons why :meth:`Prospection.reachable` fails (``Reachability.reason``):
#: ``'out_of_reach'`` -- no arm configuration puts the tool at the pose, even ignoring joint limits;
#: ``'joint_limit'`` -- one does, but only outside the joint limits;
#: ``'collision'`` -- every solution found (or the base pose itself) collides with the environment.
REACH_FAILURES = ("out_of_reach", "joint_limit", "collision")


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


class Prospection(abc.ABC):
    """What-if questions about one robot in the current world (see the module's guarantees)."""

    @property
    @abc.abstractmethod
    def arms(self) -> tuple[str, ...]:
        """The arm names :meth:`reachable` accepts."""

    @abc.abstractmethod
    def in_collision(self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None) -> bool:
        """Would the robot at ``base_pose`` collide with the environment?

        The robot keeps its current joint positions except those in ``joint_configuration``
        (joint name -> position [rad or m]). Raises ``ValueError`` for an unknown joint (the
        message lists the valid ones) or a malformed pose.
        """

    @abc.abstractmethod
    def collisions(
        self, base_pose: Any, joint_configuration: Mapping[str, float] | None = None
    ) -> list[tuple[str, str]]:
        """Like :meth:`in_collision`, but the touching pairs (robot part, environment part)."""

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
