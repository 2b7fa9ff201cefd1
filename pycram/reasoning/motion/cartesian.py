"""Straight tool motions: a joint-space path whose tool frame follows the line between two poses.

A grasp closes in on an object, a lift raises it, a retreat backs the hand out: motions that must
not sweep sideways. The straight line in *joint* space between two IK solutions does not keep the
tool on a line -- between the pre-grasp and the grasp pose of a PR2 side grasp 1 m out, it bowed
6.8 cm sideways and 2.5 cm up and the fingers knocked the cup over (measured: set-table-anywhere,
``procedural:3``, seed 1). :func:`plan_cartesian_line` follows the line instead, as MoveIt's
``computeCartesianPath`` does: tool poses every `CARTESIAN_STEP` along it (positions linear,
orientations slerped), each solved by IK seeded with the solution before, refused where a step
turns a joint more than `MAX_JOINT_STEP` (the arm flips or passes a singularity: between two
solutions the tool would leave the line), then checked collision-free segment by segment.

Conventions as in :mod:`pycram.reasoning.motion.planner`: positions [m, map], orientations
(w, x, y, z), joint positions [rad or m] in the arm's order (no torso).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from pycram.world.prospection import Prospection, as_tool_pose

from .ompl_planner import _shortcut
from .planner import MotionPlan

__all__ = ["CARTESIAN_STEP", "MAX_JOINT_STEP", "CARTESIAN_RESOLUTION", "LINE_TOLERANCE", "plan_cartesian_line", "slerp"]

#: Distance [m] between two tool poses solved along the line (the tool leaves the line between
#: them by the joint-space bow of this step: well under a millimetre).
CARTESIAN_STEP = 0.01
#: Largest change [rad or m] of any joint between two consecutive poses along the line: a larger
#: one is a flip of the arm (or a singularity), between whose ends the tool would leave the line.
MAX_JOINT_STEP = 0.25
#: Joint-space resolution [rad or m] at which each step's segment is checked for collisions.
CARTESIAN_RESOLUTION = 0.02
#: How far [m] the tool may leave the line between two kept configurations: the solved ones in
#: between are dropped where the joints' straight segment keeps the tool this close (the timed
#: arm stops at each configuration kept: Ruckig, `pycram.reasoning.motion.timing`).
LINE_TOLERANCE = 0.005


def slerp(q0: Sequence[float], q1: Sequence[float], s: float) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) a fraction ``s`` (0..1) of the way from ``q0`` to ``q1``
    along the shorter arc."""
    a, b = np.asarray(q0, float), np.asarray(q1, float)
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    dot = float(a @ b)
    if dot < 0.0:
        b, dot = -b, -dot
    if dot > 0.9995:  # nearly the same: linear, normalised
        out = a + s * (b - a)
    else:
        theta = math.acos(dot)
        out = (math.sin((1.0 - s) * theta) * a + math.sin(s * theta) * b) / math.sin(theta)
    out = out / np.linalg.norm(out)
    return (float(out[0]), float(out[1]), float(out[2]), float(out[3]))


def plan_cartesian_line(
    prospection: Prospection,
    arm: str,
    start: Sequence[float],
    goal: Any,
    base_pose: Any,
    *,
    held_object: str | None = None,
    exempt_object: str | None = None,
    clearances: Sequence[tuple[float, float]] = ((0.0, 0.0),),
    position_tolerance: float = 0.001,
    step: float = CARTESIAN_STEP,
    max_joint_step: float = MAX_JOINT_STEP,
) -> MotionPlan:
    """A path for ``arm`` from the joints ``start`` whose tool frame moves along the straight line
    to the tool pose ``goal`` (position [m], orientation (w, x, y, z) or None: the orientation
    at ``start`` all the way), with the robot at ``base_pose`` in prospection's world.

    Guarantees of a plan (truthy, ``planner`` ``'cartesian_line'``): the tool stays within
    `LINE_TOLERANCE` [m] of the line (checked every `step` [m]; its configurations put it within
    ``position_tolerance`` of it) and ends at ``goal``; no joint turns more than
    ``max_joint_step`` per `step` of the way; every segment is free as
    :meth:`~pycram.world.prospection.Prospection.configuration_checker` judges with
    ``held_object``, ``exempt_object`` and the first of ``clearances`` ((clearance,
    object_clearance) [m] pairs, tried in turn) with which it is. Else the reason:
    ``'no_path'`` (IK failed, the arm flips, or the arm touches something along the line; the
    message says where and names the pair) or ``'start_in_collision'``. Raises ``ValueError``
    for an unknown arm or a malformed pose, ``NotImplementedError`` when prospection has no IK
    or forward kinematics."""
    t0 = time.perf_counter()
    limits = prospection.arm_joint_limits(arm)
    joints = limits.joints
    q0 = [float(v) for v in start]
    if len(q0) != len(joints):
        raise ValueError(f"start needs {len(joints)} positions ({', '.join(joints)}), got {len(q0)}")
    target = as_tool_pose(goal)
    here = prospection.tool_pose(arm, base_pose, dict(zip(joints, q0, strict=True)))
    p0, p1 = np.asarray(here.position, float), np.asarray(target.position, float)
    o0 = here.orientation
    o1 = target.orientation if target.orientation is not None else o0

    def failed(reason: str, message: str) -> MotionPlan:
        return MotionPlan(joints, (), reason, message, "cartesian_line", time.perf_counter() - t0)

    n = max(1, math.ceil(float(np.linalg.norm(p1 - p0)) / step))
    path = [q0]
    for i in range(1, n + 1):
        s = i / n
        position = tuple(float(v) for v in p0 + s * (p1 - p0))
        orientation = None if o0 is None or o1 is None else slerp(o0, o1, s)
        ik = prospection.solve_ik(
            arm,
            (position, orientation),
            base_pose,
            seeds=[path[-1]],
            avoid_collisions=False,
            position_tolerance=position_tolerance,
        )
        where = f"{s * 100:.0f} % of the way ({', '.join(f'{v:.3f}' for v in position)})"
        if not ik:
            return failed("no_path", f"no IK solution on the line at {where}: {ik.reason}")
        q = [float(v) for v in ik.positions]
        jump = max(abs(a - b) for a, b in zip(q, path[-1], strict=True))
        if jump > max_joint_step:
            return failed("no_path", f"the arm flips on the line at {where} (a joint turns {jump:.2f})")
        path.append(q)
    path = _simplified(prospection, arm, base_pose, joints, path, p0, p1)
    result = failed("no_path", "no clearance to try")
    for clearance, object_clearance in clearances:
        with prospection.configuration_checker(
            arm,
            base_pose,
            held_object=held_object,
            exempt_object=exempt_object,
            clearance=clearance,
            object_clearance=object_clearance,
        ) as checker:
            touching = _touches(checker, path)
            if touching is None:
                return MotionPlan(
                    joints,
                    tuple(tuple(q) for q in path),
                    None,
                    "",
                    "cartesian_line",
                    time.perf_counter() - t0,
                    checker.checks,
                )
        result = failed(*touching)
    return result


def _touches(checker: Any, path: list[list[float]]) -> tuple[str, str] | None:
    """(reason, message) where a segment of ``path`` is not free for ``checker``, or None."""
    if not checker.is_free(path[0]):
        return "start_in_collision", f"the start touches {_pair(checker.contacts(path[0]))}"
    n = len(path) - 1
    for i, (a, b) in enumerate(zip(path, path[1:]), start=1):
        bad = checker.first_touching(a, b, CARTESIAN_RESOLUTION)
        if bad is not None:
            return "no_path", f"the line touches {_pair(checker.contacts(bad))} at {i / n * 100:.0f} % of the way"
    return None


def _pair(contacts: list[tuple[str, str]]) -> str:
    return f"{contacts[0][1]} with {contacts[0][0]}" if contacts else "something"


def _simplified(
    prospection: Prospection,
    arm: str,
    base_pose: Any,
    joints: Sequence[str],
    path: list[list[float]],
    p0: np.ndarray,
    p1: np.ndarray,
) -> list[list[float]]:
    """``path`` (configurations solved on the line from ``p0`` to ``p1`` [m], evenly spaced) with
    those dropped that the joints' straight segment between their neighbours kept replaces
    without taking the tool more than `LINE_TOLERANCE` off the line: from each kept one, on to
    the farthest one so joined (the tool checked where each dropped one was)."""
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    if length < 1e-9 or len(path) <= 2:
        return path

    def off_line(q: Sequence[float]) -> float:
        p = np.asarray(prospection.tool_pose(arm, base_pose, dict(zip(joints, q, strict=True))).position, float)
        along = float(np.clip((p - p0) @ axis / length**2, 0.0, 1.0))
        return float(np.linalg.norm(p - (p0 + along * axis)))

    def joined(i: int, j: int) -> bool:
        a, b = path[i], path[j]
        return all(
            off_line([x + (k - i) / (j - i) * (y - x) for x, y in zip(a, b, strict=True)]) <= LINE_TOLERANCE
            for k in range(i + 1, j)
        )

    return [path[k] for k in _shortcut(0, len(path) - 1, joined)]
