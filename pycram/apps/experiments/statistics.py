"""How sure a success rate is: Wilson score intervals, and whether two rates differ by more than
the noise.

A success rate measured on n seeds is an estimate; its 95 % confidence interval says where the
true rate lies (for 195 of 200 it is 94.3-98.9 %). Two rates differ "by more than the noise" when
the 95 % confidence interval of their difference excludes 0. Intervals:

* one rate: the Wilson score interval (E. B. Wilson, 1927), which stays inside [0, 1] and keeps
  its coverage near 0 and 1, where the plain normal interval fails (100 % of 20 runs does not
  mean "exactly 100 %");
* a difference of two independent rates: Newcombe's hybrid score interval (method 10 of
  R. G. Newcombe, Statistics in Medicine 17, 1998), built from the two Wilson intervals.

Standard library only; rates and bounds are fractions in [0, 1].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Z_95", "wilson_interval", "Difference", "compare_rates"]

#: The standard normal quantile of a two-sided 95 % interval.
Z_95 = 1.959963984540054


def wilson_interval(successes: int, runs: int, z: float = Z_95) -> tuple[float, float]:
    """The Wilson score interval (low, high) of the success rate ``successes / runs`` at the
    confidence of ``z`` (default 95 %). ``(0.0, 1.0)`` without runs: nothing is known.

    Raises ``ValueError`` for negative counts or more successes than runs.
    """
    if runs < 0 or successes < 0 or successes > runs:
        raise ValueError(f"need 0 <= successes <= runs, got {successes} of {runs}")
    if runs == 0:
        return 0.0, 1.0
    p = successes / runs
    denominator = 1.0 + z * z / runs
    centre = (p + z * z / (2 * runs)) / denominator
    half = z * math.sqrt(p * (1.0 - p) / runs + z * z / (4 * runs * runs)) / denominator
    # exact at the ends (rounding must not put 1.0 outside its own interval)
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == runs else min(1.0, centre + half)
    return low, high


@dataclass(frozen=True)
class Difference:
    """Rate ``a`` minus rate ``b`` (fractions) with its 95 % confidence interval ``[low, high]``;
    ``beyond_noise`` when the interval excludes 0."""

    a: float
    b: float
    low: float
    high: float

    @property
    def difference(self) -> float:
        """``a - b``."""
        return self.a - self.b

    @property
    def beyond_noise(self) -> bool:
        """Whether the difference is larger than the noise: its interval excludes 0."""
        return self.low > 0.0 or self.high < 0.0

    def describe(self) -> str:
        """``+4.5 pp (95 % CI -1.2 to +10.3 pp): within the noise`` (pp: percentage points)."""
        verdict = "larger than the noise" if self.beyond_noise else "within the noise"
        return (
            f"{100 * self.difference:+.1f} pp (95 % CI {100 * self.low:+.1f} to {100 * self.high:+.1f} pp): {verdict}"
        )


def compare_rates(successes_a: int, runs_a: int, successes_b: int, runs_b: int, z: float = Z_95) -> Difference:
    """Rate a (``successes_a / runs_a``) minus rate b, with Newcombe's hybrid score interval
    (from the two rates' Wilson intervals). The runs of a and b must be independent (other
    seeds, or the same seeds on other code: each run is its own draw)."""
    pa = successes_a / runs_a if runs_a else 0.0
    pb = successes_b / runs_b if runs_b else 0.0
    la, ua = wilson_interval(successes_a, runs_a, z)
    lb, ub = wilson_interval(successes_b, runs_b, z)
    d = pa - pb
    low = d - math.sqrt((pa - la) ** 2 + (ub - pb) ** 2)
    high = d + math.sqrt((ua - pa) ** 2 + (pb - lb) ** 2)
    return Difference(pa, pb, max(-1.0, low), min(1.0, high))
