"""Arm motion planning with OMPL: RRT-Connect in joint space, then OMPL's path simplifier.

:class:`OMPLPlanner` implements :class:`~pycram.reasoning.motion.planner.MotionPlanner`:

1. the start and goal are checked (limits, collisions): a typed failure names the touching pair;
2. **straight line first**: if the direct joint-space segment is free, the path is
   ``[start, goal]`` and OMPL is not run (most arm motions in open space);
3. otherwise RRT-Connect (`ompl.geometric.RRTConnect`) in the joints' box (a continuous joint
   gets +-pi around its start and goal), every state and every motion checked by the
   prospection's :class:`~pycram.world.prospection.ConfigurationChecker` at the coarser
   ``search_resolution``;
4. the path is shortened by OMPL's `PathSimplifier` (vertex reduction and shortcuts, not
   B-spline smoothing, so the path keeps few vertices: the timing stops at each) and its segments
   are checked again at ``resolution``; if one fails, steps 3-4 run again at ``resolution``.

Guarantee: every segment of a returned path is free at ``resolution`` (configurations at most
that far apart, Euclidean over the joints, all free).

Determinism: OMPL's random generators are seeded from ``ompl.util.RNG.setSeed(seed)`` before the
planner and the simplifier are made, the search ends after a budget of collision *checks*
(``max_checks``; not of wall time, which depends on the machine and its load) and the simplifier
runs to convergence, so the same seed and world give the same path -- also in lock-step runs,
where a wall-time limit would make a run's outcome depend on the load. ``time_limit`` is only a
safety net far beyond the check budget (a plan it ends is not reproducible, and logs a warning).
``setSeed`` is process-global, so plans are serialised by a lock (a plan takes
milliseconds; the checks hold Python's GIL anyway).

OMPL (PyPI ``ompl``, the `sim` extra) is imported when the first planner is made.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Sequence

from pycram.world.prospection import ConfigurationChecker, JointLimits

from .planner import MotionPlan, MotionPlanner

__all__ = [
    "OMPLPlanner",
    "DEFAULT_MAX_CHECKS",
    "DEFAULT_RESOLUTION",
    "DEFAULT_SEARCH_RESOLUTION",
    "DEFAULT_TIME_LIMIT",
]

#: Largest joint-space step [rad or m, Euclidean over the joints] between two checked
#: configurations of a segment (0.02 rad moves a tool 0.9 m from the shoulder by <= 1.8 cm).
DEFAULT_RESOLUTION = 0.02
#: The coarser step [rad or m] RRT-Connect and the simplifier check motions at; the result is
#: re-checked at the resolution, and searched again at the resolution if a segment fails
#: (measured: 0 to 2 % of the plans; the search costs about half as many checks).
DEFAULT_SEARCH_RESOLUTION = 0.05
#: Collision checks RRT-Connect may spend (with the re-check) before the plan fails with
#: ``'no_path'``: about 1 s on this machine (20-40 us a check), 15x a p95 plan's checks.
DEFAULT_MAX_CHECKS = 30_000
#: Wall time [s] after which a search ends whatever its check budget (a safety net only).
DEFAULT_TIME_LIMIT = 10.0

_LOCK = threading.Lock()
_log = logging.getLogger(__name__)


def _bisection_order(n: int) -> list[int]:
    """0..n with the ends first, then midpoints of ever finer halves (a collision somewhere inside
    is found after few checks, as OMPL's motion validator does)."""
    order, seen = [0, n], {0, n}
    spans = [(0, n)]
    while spans:
        nxt = []
        for lo, hi in spans:
            if hi - lo > 1:
                mid = (lo + hi) // 2
                if mid not in seen:
                    seen.add(mid)
                    order.append(mid)
                nxt += [(lo, mid), (mid, hi)]
        spans = nxt
    return order


def _interpolated_free(checker: ConfigurationChecker, a: Sequence[float], b: Sequence[float], step: float) -> bool:
    """Every configuration on segment a-b, at most ``step`` apart (Euclidean), both ends included."""
    n = max(1, math.ceil(math.dist(a, b) / step))
    for i in _bisection_order(n):
        s = i / n
        if not checker.is_free([x + s * (y - x) for x, y in zip(a, b)]):
            return False
    return True


class OMPLPlanner(MotionPlanner):
    """RRT-Connect + simplification (see the module docstring).

    ``resolution``: the checking step [rad or m]; ``max_checks``: the search's budget of
    collision checks; ``time_limit``: a safety net [s] of wall time (see the module docstring);
    ``range``: RRT-Connect's extension step [rad or m] (None: OMPL's default, a fifth of the
    space's extent); ``simplify``: whether to shorten the found path.
    """

    def __init__(
        self,
        resolution: float = DEFAULT_RESOLUTION,
        time_limit: float = DEFAULT_TIME_LIMIT,
        range: float | None = None,
        simplify: bool = True,
        search_resolution: float = DEFAULT_SEARCH_RESOLUTION,
        max_checks: int = DEFAULT_MAX_CHECKS,
    ) -> None:
        if not (resolution > 0 and time_limit > 0 and search_resolution > 0 and max_checks > 0) or (
            range is not None and not range > 0
        ):
            raise ValueError("resolution, search_resolution, time_limit, max_checks and range must be positive")
        self.max_checks = int(max_checks)
        import ompl.util as ou  # noqa: F401 - fail here, not in the first plan, when OMPL is missing

        ou.setLogLevel(ou.LOG_WARN)
        self.resolution, self.time_limit, self.range, self.simplify = resolution, time_limit, range, simplify
        self.search_resolution = max(resolution, search_resolution)

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
        t0 = time.perf_counter()
        checks0 = checker.checks
        joints = limits.joints
        if tuple(checker.joints) != tuple(joints):
            raise ValueError(f"the checker's joints {checker.joints} are not the limits' {joints}")
        n = len(joints)
        q0, q1 = [float(v) for v in start], [float(v) for v in goal]
        if len(q0) != n or len(q1) != n:
            raise ValueError(f"start and goal need {n} positions ({', '.join(joints)}), got {len(q0)} and {len(q1)}")

        def result(
            reason: str | None, message: str = "", path: Sequence[Sequence[float]] = (), how: str = ""
        ) -> MotionPlan:
            return MotionPlan(
                joints,
                tuple(tuple(float(v) for v in q) for q in path),
                reason,
                message,
                how,
                time.perf_counter() - t0,
                checker.checks - checks0,
            )

        for what, q in (("start", q0), ("goal", q1)):
            if not limits.within(q, 1e-3):
                bad = next(
                    i
                    for i, (v, lo, hi) in enumerate(zip(q, limits.lower, limits.upper))
                    if not lo - 1e-3 <= v <= hi + 1e-3
                )
                return result(
                    "outside_limits",
                    f"{what}: {joints[bad]}={q[bad]:.3f} outside [{limits.lower[bad]:.3f}, {limits.upper[bad]:.3f}]",
                )
        # the simulated state may lie a hair outside its limits: plan from the nearest inside
        q0 = [min(max(v, lo), hi) for v, lo, hi in zip(q0, limits.lower, limits.upper)]
        q1 = [min(max(v, lo), hi) for v, lo, hi in zip(q1, limits.lower, limits.upper)]
        for what, q in (("start", q0), ("goal", q1)):
            contacts = checker.contacts(q)
            if contacts:
                part, other = contacts[0]
                return result(f"{what}_in_collision", f"the {what} configuration touches {other} with {part}")
        if _interpolated_free(checker, q0, q1, self.resolution):
            return result(None, path=[q0, q1], how="straight_line")
        deadline = t0 + (self.time_limit if time_limit is None else time_limit)
        last_check = checks0 + self.max_checks

        def out_of_budget() -> bool:
            return checker.checks >= last_check or time.perf_counter() >= deadline

        path = None
        for search in dict.fromkeys((self.search_resolution, self.resolution)):  # coarse, then fine
            if out_of_budget():
                break
            with _LOCK:
                path = self._rrt_connect(checker, limits, q0, q1, out_of_budget, seed, search)
            if path is None:
                break
            if all(_interpolated_free(checker, a, b, self.resolution) for a, b in zip(path, path[1:])):
                break
            path = None  # a segment cuts an obstacle between the coarse checks: search finely
        if time.perf_counter() >= deadline:
            _log.warning("a motion plan ran into its wall-time safety net: this run is not reproducible")
        if path is None:
            spent = time.perf_counter() - t0
            return result("no_path", f"RRT-Connect found no path in {checker.checks - checks0} checks ({spent:.3f} s)")
        return result(None, path=path, how="RRTConnect")

    def _rrt_connect(
        self,
        checker: ConfigurationChecker,
        limits: JointLimits,
        q0: list[float],
        q1: list[float],
        done: Callable[[], bool],
        seed: int,
        resolution: float,
    ) -> list[list[float]] | None:
        import ompl.base as ob
        import ompl.geometric as og
        import ompl.util as ou

        n = len(q0)
        # OMPL reports re-seeding after the first plan as an error: the generators made before keep
        # their sequences. Each plan makes its own (planner, samplers, simplifier) after this
        # call, so the plan is deterministic all the same.
        level = ou.getLogLevel()
        ou.setLogLevel(ou.LOG_NONE)
        try:
            ou.RNG.setSeed(int(seed) % 2_147_483_646 + 1)  # OMPL refuses the seed 0
        finally:
            ou.setLogLevel(level)
        space = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for i, (lo, hi, a, b) in enumerate(zip(limits.lower, limits.upper, q0, q1)):
            bounds.setLow(i, lo if math.isfinite(lo) else min(a, b) - math.pi)
            bounds.setHigh(i, hi if math.isfinite(hi) else max(a, b) + math.pi)
        space.setBounds(bounds)
        setup = og.SimpleSetup(space)
        is_free = checker.is_free
        setup.setStateValidityChecker(lambda s: is_free([s[i] for i in range(n)]))
        info = setup.getSpaceInformation()
        info.setStateValidityCheckingResolution(min(1.0, resolution / space.getMaximumExtent()))
        planner = og.RRTConnect(info)
        if self.range is not None:
            planner.setRange(self.range)
        setup.setPlanner(planner)
        start, goal = space.allocState(), space.allocState()
        for i in range(n):
            start[i], goal[i] = q0[i], q1[i]
        setup.setStartAndGoalStates(start, goal)
        status = setup.solve(ob.PlannerTerminationCondition(done))
        if not setup.haveExactSolutionPath():
            return None
        path = setup.getSolutionPath()
        if self.simplify:
            simplifier = setup.getPathSimplifier()
            for _ in range(4):
                before = path.getStateCount()
                simplifier.reduceVertices(path)
                simplifier.collapseCloseVertices(path)
                simplifier.ropeShortcutPath(path)
                if path.getStateCount() >= before:
                    break
        del status
        return [[s[i] for i in range(n)] for s in path.getStates()]
