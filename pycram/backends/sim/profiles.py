"""Time parametrisation of straight-line motions with velocity and acceleration limits."""

from __future__ import annotations

import math


class Trapezoid:
    """A rest-to-rest trapezoidal (or triangular) velocity profile over a distance [m or rad]."""

    def __init__(self, distance: float, vmax: float, amax: float) -> None:
        self.distance = abs(distance)
        self.vmax, self.amax = vmax, amax
        t_acc = vmax / amax
        if self.distance < vmax * t_acc:  # triangular
            self.t_acc = math.sqrt(self.distance / amax)
            self.v_peak = amax * self.t_acc
            self.t_flat = 0.0
        else:
            self.t_acc = t_acc
            self.v_peak = vmax
            self.t_flat = (self.distance - vmax * t_acc) / vmax
        self.duration = 2.0 * self.t_acc + self.t_flat

    def position(self, t: float) -> float:
        """Distance covered after `t` [s] (0 before start, `distance` after the end)."""
        if t <= 0.0:
            return 0.0
        if t >= self.duration:
            return self.distance
        a, ta, tf = self.amax, self.t_acc, self.t_flat
        if t < ta:
            return 0.5 * a * t * t
        d_acc = 0.5 * a * ta * ta
        if t < ta + tf:
            return d_acc + self.v_peak * (t - ta)
        td = t - ta - tf
        return d_acc + self.v_peak * tf + self.v_peak * td - 0.5 * a * td * td

    def fraction(self, t: float, duration: float) -> float:
        """Fraction in [0, 1] of this profile stretched to last `duration` [s], at time `t` [s]."""
        if self.distance == 0.0 or duration <= 0.0:
            return 1.0
        return self.position(t * self.duration / duration) / self.distance


def smoothstep(s: float) -> float:
    """Cubic ease-in/ease-out of s in [0, 1] (zero velocity at both ends)."""
    s = min(max(s, 0.0), 1.0)
    return s * s * (3.0 - 2.0 * s)
