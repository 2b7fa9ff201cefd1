"""Value types of the simulated world: poses, command outcomes, perceived items.

Conventions: positions in [m] in the map frame (z up), yaw in [rad] (counter-clockwise about z),
quaternions as (w, x, y, z) (MuJoCo's order).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


@dataclass(frozen=True)
class Pose2D:
    """A base pose in the map frame: x [m], y [m], yaw [rad]."""

    x: float
    y: float
    yaw: float

    def distance_to(self, other: Pose2D) -> float:
        """Planar distance [m]."""
        return math.hypot(self.x - other.x, self.y - other.y)

    def yaw_error_to(self, other: Pose2D) -> float:
        """Absolute yaw difference [rad], wrapped to [0, pi]."""
        return abs(wrap_angle(self.yaw - other.yaw))


@dataclass(frozen=True)
class Pose:
    """A 3D pose in the map frame: position [m] and orientation quaternion (w, x, y, z)."""

    position: Vec3
    orientation: Quat = (1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Outcome:
    """How a command ended. `reason` is one of the `REASONS`; truthy iff the command succeeded."""

    succeeded: bool
    reason: str
    message: str = ""
    value: Any = None

    REASONS = (
        "succeeded",
        "blocked",
        "collision",
        "cancelled",
        "preempted",
        "unreachable",
        "timeout",
        "invalid",
        "closed",
        "error",
        "no_path",
    )

    def __bool__(self) -> bool:
        return self.succeeded


@dataclass(frozen=True)
class VisibleItem:
    """An item seen by the head camera: its name, type, pose and visible pixel count."""

    name: str
    type: str
    pose: Pose
    pixels: int = 0
    #: mean pixel (u: column, v: row) of the item in the head camera image [px]
    centroid: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class GripperState:
    """A gripper's measured state: opening [m], the item welded to it (or None) and the effort [N]
    its actuator currently applies at the finger tips (never above the commanded effort limit)."""

    opening: float
    holding: str | None = None
    effort: float = 0.0


@dataclass(frozen=True)
class JointStates:
    """Joint positions [m or rad] and velocities by joint name, at simulated time `stamp` [s]."""

    stamp: float
    position: dict[str, float] = field(default_factory=dict)
    velocity: dict[str, float] = field(default_factory=dict)


def wrap_angle(a: float) -> float:
    """Wrap an angle [rad] to [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def yaw_to_quat(yaw: float) -> Quat:
    """Quaternion (w, x, y, z) of a rotation by `yaw` [rad] about z."""
    return (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))


def matrix_to_quat(rotation: Any) -> Quat:
    """The unit quaternion (w, x, y, z, with w >= 0) of a 3x3 rotation matrix (nested sequences or
    an array; Shepperd's method)."""
    m = [[float(rotation[i][j]) for j in range(3)] for i in range(3)]
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    norm = math.sqrt(sum(v * v for v in q)) * (-1.0 if q[0] < 0.0 else 1.0)
    w, x, y, z = (v / norm for v in q)
    return (w, x, y, z)
