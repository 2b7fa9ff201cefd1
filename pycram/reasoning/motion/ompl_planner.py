"""Arm motion planning with OMPL: RRT-Connect in joint space, OMPL's path simplifier, then string
pulling.

:class:`OMPLPlanner` implements :class:`~pycram.reasoning.motion.planner.MotionPlanner`:

1. the start and goal are checked (limits, collisions): a typed failure names the touching pair;
2. **straight line first**: if the direct joint-space segment is free, the path is
   ``[start, goal]`` and OMPL is not run (most arm motions in open space);
3. otherwise RRT-Connect (`ompl.geometric.RRTConnect`) in the joints' box, every state and every
   motion checked by the prospection's :class:`~pycram.world.prospection.ConfigurationChecker` at
   the coarser ``search_resolution``; a continuous joint (a wrist's roll) may turn
   `CONTINUOUS_MARGIN` beyond its start and goal (a second search, if the first finds nothing
   within `FIRST_SEARCH_SHARE` of the budget, lets it turn by +-pi);
4. with ``simplify``, the path is shortened by OMPL's `PathSimplifier` (vertex reduction and rope
   shortcuts, not B-spline smoothing; checked at ``search_resolution``), then its vertices are
   joined by string pulling (from each kept vertex on to the farthest one a free segment reaches):
   the rope shortcuts keep the path taut along the obstacles, the pulling drops the vertices they
   add (the timing stops the arm at each);
5. **every vertex and segment is checked at** ``resolution``; a segment that fails there (it cuts
   a thin obstacle between two coarse checks) is planned around alone, RRT-Connect at the
   resolution between its ends (see :meth:`OMPLPlanner._finish`).

Guarantee: every segment of a returned path is free at ``resolution`` (configurations at most
that far apart, Euclidean over the joints, all free).

What made plans slow (``benchmarks/motion_planning.py``, PR2, the slowest 10 % of 200 queries
before 2026-11-27, all narrow passages beside the fridge, the cereal box and the drawer fronts,
not long joint-space distances): 51 % search, 40 % simplification at the search resolution
0.05, 4 % re-checks, and in a quarter of them a whole second search at the resolution after a
re-check failed. Now: the search and the simplifier check at 0.1 (half the checks), a failed
re-check costs a local repair, the wrist rolls stay near start and goal, and judging the contacts
of a check in collision takes half the time or less (``pycram.backends.sim.arm_checker``):
checks per plan 2115 -> 1194, at p95 8187 -> 4492.

Determinism: OMPL's random generators are seeded from ``ompl.util.RNG.setSeed(seed)`` before each
search's planner and simplifier are made, a search ends after a budget of collision *checks*
(``max_checks``; not of wall time, which depends on the machine and its load) and the shortcuts
run to convergence, so the same seed and world give the same path -- also in lock-step runs,
where a wall-time limit would make a run's outcome depend on the load. ``time_limit`` is only a
safety net far beyond the check budget (a plan it ends is not reproducible, and logs a warning).
``setSeed`` is process-global, so searches are serialised by a lock (a search takes milliseconds;
the checks hold Python's GIL anyway).

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
    "CONTINUOUS_MARGIN",
    "FIRST_SEARCH_SHARE",
    "ROPE_DELTA",
    "DEFAULT_MAX_CHECKS",
    "DEFAULT_RESOLUTION",
    "DEFAULT_SEARCH_RESOLUTION",
    "DEFAULT_TIME_LIMIT",
]

#: Largest joint-space step [rad or m, Euclidean over the joints] between two checked
#: configurations of a segment (0.02 rad moves a tool 0.9 m from the shoulder by <= 1.8 cm).
DEFAULT_RESOLUTION = 0.02
#: The coarser step [rad or m] RRT-Connect and the shortcuts check motions at; every segment of
#: the result is checked again at the resolution, and one that fails is repaired there (see
#: :meth:`OMPLPlanner._finish`). Measured on the PR2 (``benchmarks/motion_planning.py``, 200
#: queries, OMPL's default rope spacing): 0.1 needs a quarter fewer checks than 0.05 on average,
#: 30 % fewer at p95; 0.15 saves 10 % more, for longer paths that sweep more.
DEFAULT_SEARCH_RESOLUTION = 0.1
#: Collision checks a plan may spend searching (repairs included) before it fails with
#: ``'no_path'``: about 1 s on this machine (20-40 us a check), 7x a p95 PR2 plan's checks.
DEFAULT_MAX_CHECKS = 30_000
#: How far [rad] the first search lets a continuous joint (a wrist's or forearm's roll) turn
#: beyond its start and goal; the second search, if needed, lets it turn by +-pi (measured on the
#: PR2, 200 queries, OMPL's default rope spacing: 14 % fewer checks on average than +-pi, 29 %
#: fewer at p95, and 12 % shorter paths).
CONTINUOUS_MARGIN = math.pi / 2
#: The share of ``max_checks`` the first search may spend (the second gets the rest).
FIRST_SEARCH_SHARE = 2 / 3
#: Spacing [rad or m] of the points OMPL's rope shortcuts may start and end at along the path
#: (OMPL's default). Measured on the PR2, 200 queries: 1.5 needs a sixth fewer checks (a fifth at
#: p95) for paths about as taut (joint-space length 6.46 against 6.37 rad, the arm's bodies
#: travelling 0.80 against 0.78 m), but the ROS re-planning test's first path then hits the
#: unperceived box elsewhere, the box is measured from there, and the goal touches the believed
#: box (``tests/ros/test_ros_arm_planning.py``); 2.0 and more let the paths sweep wider (0.85 m
#: and more).
ROPE_DELTA = 1.0
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


def _interpolated_free(
    checker: ConfigurationChecker, a: Sequence[float], b: Sequence[float], step: float, ends: bool = True
) -> bool:
    """Every configuration on segment a-b, at most ``step`` apart (Euclidean), the ends included
    unless ``ends`` is False (they are known to be free)."""
    n = max(1, math.ceil(math.dist(a, b) / step))
    for i in _bisection_order(n):
        if not ends and (i == 0 or i == n):
            continue
        s = i / n
        if not checker.is_free([x + s * (y - x) for x, y in zip(a, b)]):
            return False
    return True


def _shortcut(first: int, last: int, free: Callable[[int, int], bool]) -> list[int]:
    """Indices of the vertices ``first..last`` of a path to keep: from each kept vertex, on to the
    farthest one that ``free(i, j)`` joins to it directly (string pulling; ``free(i, i + 1)`` is
    taken as given: those are the path's own segments)."""
    kept, i = [first], first
    while i < last:
        j = last
        while j > i + 1 and not free(i, j):
            j -= 1
        kept.append(j)
        i = j
    return kept


class OMPLPlanner(MotionPlanner):
    """RRT-Connect + OMPL's simplifier + string pulling (see the module docstring).

    ``resolution``: the checking step [rad or m] every returned segment is free at;
    ``search_resolution``: the coarser step [rad or m] of the search and the shortcuts;
    ``max_checks``: the plan's budget of collision checks; ``time_limit``: a safety net [s] of
    wall time (see the module docstring); ``range``: RRT-Connect's extension step [rad or m]
    (None: OMPL's default, a fifth of the space's extent); ``simplify``: whether to shorten the
    found path (without: the search's vertices, its edges checked at the resolution).
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

        # first a continuous joint within `CONTINUOUS_MARGIN` of the start and goal, within
        # `FIRST_SEARCH_SHARE` of the budget; then (no path, or one whose repair failed) free to
        # turn by +-pi, with another seed, within the rest
        path = None
        continuous = not all(math.isfinite(v) for v in (*limits.lower, *limits.upper))
        stages = (
            (CONTINUOUS_MARGIN if continuous else math.pi, checks0 + math.ceil(FIRST_SEARCH_SHARE * self.max_checks)),
            (math.pi, last_check),
        )
        for attempt, (margin, end) in enumerate(stages):
            if out_of_budget():
                break
            done = lambda end=end: out_of_budget() or checker.checks >= end  # noqa: E731
            raw = self._rrt_connect(
                checker, limits, q0, q1, done, seed + attempt, self.search_resolution, margin, self.simplify
            )
            if raw is not None:
                path = self._finish(checker, limits, raw, out_of_budget, seed + attempt, self.search_resolution)
                if path is not None:
                    break
        if time.perf_counter() >= deadline:
            _log.warning("a motion plan ran into its wall-time safety net: this run is not reproducible")
        if path is None:
            spent = time.perf_counter() - t0
            return result("no_path", f"RRT-Connect found no path in {checker.checks - checks0} checks ({spent:.3f} s)")
        return result(None, path=path, how="RRTConnect")

    def _finish(
        self,
        checker: ConfigurationChecker,
        limits: JointLimits,
        path: list[list[float]],
        done: Callable[[], bool],
        seed: int,
        search: float,
    ) -> list[list[float]] | None:
        """``path`` (the search's, simplified by OMPL at ``search``) with fewer vertices (with
        ``simplify``: string pulling, checked at ``search``) and free at the resolution: every
        vertex and segment is checked there; a segment that fails (it cuts a thin obstacle between
        the coarser checks, or ends at a vertex OMPL's rope shortcuts left on such an obstacle) is
        planned around alone, RRT-Connect at the resolution from its start to the next free vertex,
        within a tenth of ``max_checks``. None when such a repair finds no path (the caller then
        searches again)."""
        fine = self.resolution

        def pulled(path: list[list[float]], step: float) -> list[list[float]]:
            """The path's vertices joined by shortcuts (their ends not checked again)."""
            if not self.simplify:
                return path
            free = lambda i, j: _interpolated_free(checker, path[i], path[j], step, ends=False)  # noqa: E731
            return [path[i] for i in _shortcut(0, len(path) - 1, free)]

        path = pulled(path, search)
        out = [path[0]]  # the start: free
        i, last, repairs = 0, len(path) - 1, 0
        while i < last:
            if _interpolated_free(checker, out[-1], path[i + 1], fine):
                out.append(path[i + 1])
                i += 1
                continue
            j = i + 1
            while j < last and not checker.is_free(path[j]):  # the goal is free
                j += 1
            repairs += 1
            end = checker.checks + max(1, self.max_checks // 10)
            repair_done = lambda end=end: done() or checker.checks >= end  # noqa: E731
            # its vertices are the search's (free), its edges checked at the resolution
            detour = (
                None
                if done()
                else self._rrt_connect(checker, limits, out[-1], path[j], repair_done, seed + repairs, fine)
            )
            if detour is None:
                return None
            out.extend(pulled(detour, fine)[1:])
            i = j
        return out

    def _rrt_connect(
        self,
        checker: ConfigurationChecker,
        limits: JointLimits,
        q0: Sequence[float],
        q1: Sequence[float],
        done: Callable[[], bool],
        seed: int,
        resolution: float,
        margin: float = math.pi,
        simplify: bool = False,
    ) -> list[list[float]] | None:
        """RRT-Connect's path from ``q0`` to ``q1`` (states and motions checked at ``resolution``;
        a continuous joint within ``margin`` [rad] of the two), with ``simplify`` shortened by
        OMPL's ``PathSimplifier`` (vertex reduction and rope shortcuts, not B-splines, checked at
        ``resolution`` too -- but a rope shortcut's new vertices may lie between checks); None
        when ``done`` ends the search first."""
        import ompl.base as ob
        import ompl.geometric as og
        import ompl.util as ou

        n = len(q0)
        with _LOCK:  # the seed is process-global
            # OMPL reports re-seeding after the first plan as an error: the generators made before
            # keep their sequences. Each search makes its own planner and samplers after this
            # call, so the search is deterministic all the same.
            level = ou.getLogLevel()
            ou.setLogLevel(ou.LOG_NONE)
            try:
                ou.RNG.setSeed(int(seed) % 2_147_483_646 + 1)  # OMPL refuses the seed 0
            finally:
                ou.setLogLevel(level)
            space = ob.RealVectorStateSpace(n)
            bounds = ob.RealVectorBounds(n)
            for i, (lo, hi, a, b) in enumerate(zip(limits.lower, limits.upper, q0, q1)):
                bounds.setLow(i, lo if math.isfinite(lo) else min(a, b) - margin)
                bounds.setHigh(i, hi if math.isfinite(hi) else max(a, b) + margin)
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
            setup.solve(ob.PlannerTerminationCondition(done))
            if not setup.haveExactSolutionPath():
                return None
            path = setup.getSolutionPath()
            if simplify:
                simplifier = setup.getPathSimplifier()
                for _ in range(4):
                    before = path.getStateCount()
                    simplifier.reduceVertices(path)
                    simplifier.collapseCloseVertices(path)
                    simplifier.ropeShortcutPath(path, ROPE_DELTA)
                    if path.getStateCount() >= before:
                        break
            return [[s[i] for i in range(n)] for s in path.getStates()]
