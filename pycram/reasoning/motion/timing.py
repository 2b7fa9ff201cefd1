"""Timing a joint-space path within the joints' velocity and acceleration limits (Ruckig).

:func:`time_parameterize` turns a planned path (configurations joined by straight segments) into
a :class:`TimedTrajectory`: samples (t [s], q) every ``period`` seconds.

Why Ruckig (PyPI ``ruckig``, community version) and not TOPP-RA: the path's straight segments are
what the planner checked for collisions, so the timed motion must stay on them. Ruckig times each
segment from rest to rest with *phase synchronisation* -- every joint's profile is the same profile
scaled, so the arm moves exactly along the segment -- time-optimally within the velocity,
acceleration and jerk limits, in microseconds, with no dependencies. TOPP-RA is time-optimal along
the whole path without stopping at vertices, but needs a path differentiable at its vertices: a
spline through them leaves the checked segments (and the package pulls in scipy and matplotlib).
Ruckig's own waypoint following (passing through vertices without stopping) is only in its
commercial version. The price: the arm stops briefly at each vertex -- a simplified path has few
(none besides start and goal for a straight line).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from pycram.world.prospection import JointLimits

__all__ = ["TimedTrajectory", "time_parameterize", "DEFAULT_JERK_RATIO"]

#: Jerk limit of each joint as a multiple of its acceleration limit [1/s]: full acceleration is
#: reached in 1/ratio seconds (0.1 s), smooth enough for position servos.
DEFAULT_JERK_RATIO = 10.0


@dataclass(frozen=True)
class TimedTrajectory:
    """Samples of a timed joint motion: ``times`` [s] from 0 (strictly increasing, the last one
    the duration), ``positions`` and ``velocities`` per sample in the order of ``joints``."""

    joints: tuple[str, ...]
    times: tuple[float, ...]
    positions: tuple[tuple[float, ...], ...]
    velocities: tuple[tuple[float, ...], ...]

    @property
    def duration(self) -> float:
        """The motion's duration [s]."""
        return self.times[-1] if self.times else 0.0

    def samples(self) -> list[tuple[float, tuple[float, ...]]]:
        """(t [s], q) pairs."""
        return list(zip(self.times, self.positions))


def time_parameterize(
    path: Sequence[Sequence[float]],
    limits: JointLimits,
    period: float = 0.02,
    velocity_scale: float = 1.0,
    acceleration_scale: float = 1.0,
    jerk_ratio: float = DEFAULT_JERK_RATIO,
) -> TimedTrajectory:
    """The fastest motion along ``path`` (straight segments between its configurations, at rest at
    each) within ``velocity_scale`` x and ``acceleration_scale`` x the joints' limits, sampled
    every ``period`` [s] (plus the end of the motion).

    Guarantees: every sample lies on the path's segments; between samples the velocity and
    acceleration stay within the scaled limits; starts and ends at rest at the path's ends. Raises
    ``ValueError`` for an empty path, configurations of the wrong length, or non-positive
    ``period`` or scales.
    """
    import ruckig

    n = len(limits.joints)
    if not path:
        raise ValueError("time_parameterize needs a path of at least one configuration")
    if any(len(q) != n for q in path):
        raise ValueError(f"every configuration needs {n} positions ({', '.join(limits.joints)})")
    if not (period > 0 and 0 < velocity_scale and 0 < acceleration_scale and jerk_ratio > 0):
        raise ValueError("period, scales and jerk_ratio must be positive")
    vmax = [v * velocity_scale for v in limits.velocity]
    amax = [a * acceleration_scale for a in limits.acceleration]
    jmax = [a * jerk_ratio for a in amax]
    otg = ruckig.Ruckig(n)
    trajectory = ruckig.Trajectory(n)
    segments: list[tuple[float, ruckig.Trajectory | None, Sequence[float]]] = []  # (t0, trajectory, end)
    t = 0.0
    for a, b in zip(path, path[1:]):
        if all(abs(x - y) < 1e-12 for x, y in zip(a, b)):
            continue
        inp = ruckig.InputParameter(n)
        inp.current_position, inp.target_position = list(a), list(b)
        inp.current_velocity = inp.current_acceleration = [0.0] * n
        inp.target_velocity = inp.target_acceleration = [0.0] * n
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = vmax, amax, jmax
        inp.synchronization = ruckig.Synchronization.Phase
        trajectory = ruckig.Trajectory(n)
        status = otg.calculate(inp, trajectory)
        if status not in (ruckig.Result.Working, ruckig.Result.Finished):
            raise ValueError(f"Ruckig could not time the segment {list(a)} -> {list(b)}: {status}")
        segments.append((t, trajectory, b))
        t += trajectory.duration
    times: list[float] = []
    positions: list[tuple[float, ...]] = []
    velocities: list[tuple[float, ...]] = []
    count = max(1, math.ceil(t / period - 1e-9)) if t > 0 else 0
    k = 0
    for i in range(count + 1):
        ti = min(i * period, t)
        if times and ti <= times[-1]:
            break
        while k + 1 < len(segments) and ti >= segments[k + 1][0]:
            k += 1
        if segments:
            t0, seg, _ = segments[k]
            assert seg is not None
            q, v, _acc = seg.at_time(min(ti - t0, seg.duration))
        else:
            q, v = list(path[0]), [0.0] * n
        times.append(ti)
        positions.append(tuple(float(x) for x in q))
        velocities.append(tuple(float(x) for x in v))
    if not times:
        times, positions, velocities = [0.0], [tuple(float(x) for x in path[0])], [(0.0,) * n]
    return TimedTrajectory(tuple(limits.joints), tuple(times), tuple(positions), tuple(velocities))
