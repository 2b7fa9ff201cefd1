"""Check c: the reach envelope of each arm, from the robot's own inverse kinematics.

Tool positions on a grid in front of the robot -- `X_RANGE` ahead, `Y_RANGE` to the left, `Z_RANGE`
above the floor [m, base frame], every `STEP` (full form) or `SHORT_STEP` (short form) -- are
asked of the active robot's prospection the way location reasoning asks it
(:meth:`pycram.world.prospection.Prospection.reachable`: IK for the tool pose within the joint
limits and without collision of the whole robot with the environment), with the base at
`pycram.apps.robot_check.scene.START` (open floor), the torso at its ``up`` position and the
other arms in their first named configuration. The tool points along the base's heading, fingers
opening sideways: the front grasp of the action library.

An arm fails the check when it reaches no point at `COUNTER_HEIGHT`: it could not pick anything
from a kitchen counter. Otherwise the row reports the fraction of the grid it reaches, the fraction
at counter height and the ranges the reachable points span.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "X_RANGE",
    "Y_RANGE",
    "Z_RANGE",
    "STEP",
    "SHORT_STEP",
    "COUNTER_HEIGHT",
    "ArmEnvelope",
    "grid",
    "reach_envelope",
]

#: Distances ahead of the base [m] of the grid (base frame x).
X_RANGE = (0.3, 0.9)
#: Distances to the left of the base [m] of the grid (base frame y).
Y_RANGE = (-0.5, 0.5)
#: Heights above the floor [m] of the grid.
Z_RANGE = (0.5, 1.3)
#: Grid spacing [m] of the full form.
STEP = 0.1
#: Grid spacing [m] of the short form.
SHORT_STEP = 0.2
#: Counter height [m]: an arm that reaches nothing at this height fails.
COUNTER_HEIGHT = 0.9


def _axis(low: float, high: float, step: float) -> list[float]:
    n = int(math.floor((high - low) / step + 1e-6))
    return [round(low + i * step, 6) for i in range(n + 1)]


def grid(step: float = STEP) -> list[tuple[float, float, float]]:
    """The grid's tool positions (x ahead, y left, z up) [m, base frame], every `step` [m]."""
    if not step > 0.0:
        raise ValueError(f"the grid step must be > 0 m, not {step!r}")
    return [(x, y, z) for x in _axis(*X_RANGE, step) for y in _axis(*Y_RANGE, step) for z in _axis(*Z_RANGE, step)]


@dataclass
class ArmEnvelope:
    """Which grid points (base frame [m]) one arm reaches, and why the others failed
    (`pycram.world.prospection.REACH_FAILURES` counted in `failures`)."""

    arm: str
    points: list[tuple[float, float, float]] = field(default_factory=list)
    reached: list[bool] = field(default_factory=list)
    failures: Counter = field(default_factory=Counter)

    @property
    def reachable(self) -> list[tuple[float, float, float]]:
        """The points the arm reaches."""
        return [p for p, ok in zip(self.points, self.reached, strict=True) if ok]

    @property
    def fraction(self) -> float:
        """The fraction of the grid the arm reaches."""
        return len(self.reachable) / len(self.points) if self.points else 0.0

    def at_height(self, z: float = COUNTER_HEIGHT) -> tuple[int, int]:
        """(points reached, points) at height `z` [m]."""
        level = [ok for p, ok in zip(self.points, self.reached, strict=True) if abs(p[2] - z) < 1e-6]
        return sum(level), len(level)

    def ranges(self) -> dict[str, tuple[float, float]] | None:
        """The span (min, max) [m] of the reachable points along x, y and z (None: none)."""
        points = self.reachable
        if not points:
            return None
        return {axis: (min(p[i] for p in points), max(p[i] for p in points)) for i, axis in enumerate("xyz")}

    def describe(self) -> str:
        """One line: fraction of the grid, at counter height, the reachable ranges."""
        reached, total = self.at_height()
        text = f"{len(self.reachable)}/{len(self.points)} ({self.fraction:.0%}) of the grid"
        text += f"; at {COUNTER_HEIGHT} m: {reached}/{total}"
        spans = self.ranges()
        if spans:
            text += "; reaches " + ", ".join(f"{a} {lo:+.1f}..{hi:+.1f}" for a, (lo, hi) in spans.items()) + " m"
        if self.failures:
            text += "; misses: " + ", ".join(f"{why} {n}" for why, n in self.failures.most_common())
        return text

    def as_dict(self) -> dict[str, Any]:
        """JSON-serialisable: the fraction, counter-height counts, ranges and the reachable points."""
        reached, total = self.at_height()
        return {
            "fraction": self.fraction,
            "at_counter_height": [reached, total],
            "ranges": self.ranges(),
            "failures": dict(self.failures),
            "reachable": self.reachable,
            "points": len(self.points),
        }


def reach_envelope(
    prospection: Any,
    description: Any,
    base_pose: tuple[float, float, float],
    step: float = STEP,
    arms: Sequence[str] | None = None,
) -> dict[str, ArmEnvelope]:
    """The envelope of each of `arms` (default: every arm of `description`; see the module
    docstring), asked of `prospection` with the base at `base_pose` (x [m], y [m], yaw [rad],
    map). Raises ``ValueError`` for an arm the description does not have."""
    unknown = [a for a in (arms or ()) if a not in description.ARMS]
    if unknown:
        raise ValueError(f"{description.NAME} has no arm {unknown[0]!r}; arms: {', '.join(description.ARMS)}")
    x0, y0, yaw = base_pose
    c, s = math.cos(yaw), math.sin(yaw)
    orientation = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    torso = description.TORSO_POSITIONS.get("up", description.TORSO["range"][1])
    points = grid(step)
    envelopes = {}
    for arm in arms or tuple(description.ARMS):
        configuration = {description.TORSO["joint"]: float(torso)}
        for other, spec in description.ARMS.items():
            if other != arm:
                first = next(iter(description.ARM_CONFIGURATIONS[other].values()))
                configuration.update(zip(spec["joints"], first, strict=True))
        envelope = ArmEnvelope(arm)
        for x, y, z in points:
            target = ((x0 + c * x - s * y, y0 + s * x + c * y, z), orientation)
            answer = prospection.reachable(arm, [target], (x0, y0, yaw), configuration)
            envelope.points.append((x, y, z))
            envelope.reached.append(bool(answer))
            if not answer:
                envelope.failures[answer.reason or "unknown"] += 1
        envelopes[arm] = envelope
    return envelopes
