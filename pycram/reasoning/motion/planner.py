"""The motion-planner interface: collision-free joint-space paths for one arm in the believed world.

A :class:`MotionPlanner` answers "how does ``arm`` get from ``start`` to ``goal`` without touching
anything?" with a :class:`MotionPlan`: a path of joint configurations (start and goal included,
consecutive ones joined by straight joint-space segments that were checked collision-free at the
planner's resolution), or the reason why not (:data:`PLAN_FAILURES`).

The world is prospection's (:class:`pycram.world.prospection.Prospection`): the planner asks it
for the arm's joint limits and a :class:`~pycram.world.prospection.ConfigurationChecker`, never a
backend, so the same planner serves the simulator and the ROS robot. The OMPL implementation is
:class:`pycram.reasoning.motion.ompl_planner.OMPLPlanner`; timing a path within the joints'
limits is :func:`pycram.reasoning.motion.timing.time_parameterize`.

Conventions: joint positions in [rad] (revolute) or [m] (prismatic), in the order of
``MotionPlan.joints`` (the torso first when it is planned); times in [s].
"""

from __future__ import annotations

import abc
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from pycram.world.prospection import ConfigurationChecker, IKResult, JointLimits, Prospection

__all__ = ["MotionPlan", "MotionPlanner", "PLAN_FAILURES", "PoseMotionPlan", "plan_to_pose"]

#: Reasons why a plan fails (``MotionPlan.reason``):
#: ``'outside_limits'`` -- the start or goal lies outside the joints' position limits;
#: ``'start_in_collision'`` / ``'goal_in_collision'`` -- that configuration touches something
#: (the message names the pair);
#: ``'no_path'`` -- the planner found no path within its time limit (the message gives the time
#: spent).
PLAN_FAILURES = ("outside_limits", "start_in_collision", "goal_in_collision", "no_path")


@dataclass(frozen=True)
class MotionPlan:
    """A planned joint-space path, or why there is none; truthy iff planned.

    ``path``: configurations from start to goal (both included; empty on failure), joined by
    straight segments; ``planner``: what produced it (``'straight_line'`` when the direct
    segment was free, else the planner's name); ``planning_time`` [s, wall clock];
    ``checks``: configurations checked for collisions.
    """

    joints: tuple[str, ...]
    path: tuple[tuple[float, ...], ...] = ()
    reason: str | None = None
    message: str = ""
    planner: str = ""
    planning_time: float = 0.0
    checks: int = 0

    @property
    def ok(self) -> bool:
        return self.reason is None

    def __bool__(self) -> bool:
        return self.ok

    @property
    def length(self) -> float:
        """Joint-space length of the path (sum of the segments' Euclidean lengths) [rad or m]."""
        return sum(math.dist(a, b) for a, b in zip(self.path, self.path[1:]))


class MotionPlanner(abc.ABC):
    """Plans collision-free joint-space paths (see the module docstring).

    Subclasses implement :meth:`plan_with`, on a checker and limits; :meth:`plan` builds those
    from a prospection. A planner object holds settings only: it may be shared between threads.
    """

    @abc.abstractmethod
    def plan_with(
        self,
        checker: ConfigurationChecker,
        limits: JointLimits,
        start: Sequence[float],
        goal: Sequence[float],
        *,
        time_limit: float | None = None,
        seed: int = 0,
    ) -> MotionPlan:
        """A path from ``start`` to ``goal`` (positions in the order of ``limits.joints``, which must
        be ``checker.joints``) whose segments ``checker`` finds free. ``time_limit`` [s of wall
        time] (None: the planner's default) bounds the search; a planner should end its search
        by a deterministic budget first (`OMPLPlanner`: collision checks), so that the same
        ``seed`` and world give the same path on any machine and load.
        Raises ``ValueError`` when a configuration has the wrong length."""

    def plan(
        self,
        prospection: Prospection,
        arm: str,
        start: Sequence[float],
        goal: Sequence[float],
        base_pose: Any,
        joint_configuration: Mapping[str, float] | None = None,
        *,
        include_torso: bool = False,
        held_object: str | None = None,
        exempt_object: str | None = None,
        clearance: float = 0.0,
        object_clearance: float = 0.0,
        held_tilt: float | None = None,
        time_limit: float | None = None,
        seed: int = 0,
    ) -> MotionPlan:
        """Plan ``arm`` from ``start`` to ``goal`` with the robot at ``base_pose`` in prospection's
        world; the other joints as they are now or as in ``joint_configuration``. ``held_object``,
        ``exempt_object``, ``clearance`` and ``object_clearance`` [m] are those of
        :meth:`~pycram.world.prospection.Prospection.configuration_checker`; with
        ``include_torso`` the torso joint is planned too (first in the configurations). With
        ``held_tilt`` [rad] and a ``held_object``, no configuration of the path tilts the held
        object further from how it stands now than that, or than the goal tilts it
        (`ConfigurationChecker.max_held_lean`): carried upright, it stays so on the way."""
        limits = prospection.arm_joint_limits(arm, include_torso)
        with prospection.configuration_checker(
            arm,
            base_pose,
            joint_configuration,
            include_torso=include_torso,
            held_object=held_object,
            exempt_object=exempt_object,
            clearance=clearance,
            object_clearance=object_clearance,
        ) as checker:
            if held_tilt is not None and held_object is not None:
                checker.max_held_lean = max(held_tilt, checker.held_lean(goal) + 1e-3, checker.held_lean(start) + 1e-3)
            return self.plan_with(checker, limits, start, goal, time_limit=time_limit, seed=seed)


@dataclass(frozen=True)
class PoseMotionPlan:
    """Answer of :func:`plan_to_pose`: the IK answer for the pose and, if it was solved, the plan
    to the solution; truthy iff both succeeded."""

    ik: IKResult
    plan: MotionPlan | None

    def __bool__(self) -> bool:
        return bool(self.ik) and self.plan is not None and bool(self.plan)


def plan_to_pose(
    planner: MotionPlanner,
    prospection: Prospection,
    arm: str,
    start: Sequence[float],
    pose: Any,
    base_pose: Any,
    joint_configuration: Mapping[str, float] | None = None,
    *,
    held_object: str | None = None,
    exempt_object: str | None = None,
    clearance: float = 0.0,
    time_limit: float | None = None,
    seed: int = 0,
) -> PoseMotionPlan:
    """IK for the tool ``pose`` (seeded with ``start``, collision-free), then a plan from ``start``
    (the arm's joints, no torso) to the solution. The IK solution is checked with the same
    held/exempt objects as the path."""
    t0 = time.perf_counter()
    ik = prospection.solve_ik(
        arm,
        pose,
        base_pose,
        joint_configuration,
        seeds=[start],
        held_object=held_object,
        exempt_object=exempt_object,
        clearance=clearance,
    )
    if not ik:
        return PoseMotionPlan(ik, None)
    plan = planner.plan(
        prospection,
        arm,
        start,
        ik.positions,
        base_pose,
        joint_configuration,
        held_object=held_object,
        exempt_object=exempt_object,
        clearance=clearance,
        time_limit=None if time_limit is None else max(0.0, time_limit - (time.perf_counter() - t0)),
        seed=seed,
    )
    return PoseMotionPlan(ik, plan)
