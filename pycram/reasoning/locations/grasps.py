"""Tool poses of a grasp: the grasp or place sequence and the tool orientations it uses.

`grasp_sequence` gives the tool poses (position [m], orientation as a quaternion (w, x, y, z),
map frame) of the phases of a grasp (pre_grasp, grasp, lift) or a placing (pre_place, place,
retreat) at a point, each phase offset by the robot's ``APPROACH_OFFSETS`` (its description,
`RobotGeometry.approach_offsets`). The quaternion helpers turn a heading [rad] into the tool's
orientation: horizontal, horizontal with the fingers opening vertically, or pointing down.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .robot_geometry import RobotGeometry

__all__ = ["PHASES", "grasp_sequence"]

#: Grasp phases of ``to_reach`` by action.
PHASES = {"grasp": ("pre_grasp", "grasp", "lift"), "place": ("pre_place", "place", "retreat")}


def _quat_yaw(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def _quat_yaw_rolled(yaw: float) -> tuple[float, float, float, float]:
    """Tool x along `yaw`, turned 90 deg about itself: the fingers open vertically."""
    c, s, r = math.cos(yaw / 2), math.sin(yaw / 2), math.sqrt(0.5)
    return (c * r, c * r, s * r, s * r)


def _quat_down(yaw: float) -> tuple[float, float, float, float]:
    """Tool x pointing down, tool y across `yaw` (rotation about z by yaw, then about y by 90 deg)."""
    cz, sz, c, s = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(math.pi / 4), math.sin(math.pi / 4)
    return (cz * c, -sz * s, cz * s, sz * c)


def grasp_sequence(
    geometry: RobotGeometry, point: Sequence[float], heading: float, approach: str, action: str = "grasp"
) -> list[tuple[tuple[float, float, float], tuple]]:
    """Tool poses (position [m], orientation (w, x, y, z)) of the grasp or place sequence at
    `point`: the tool points along `heading` [rad] (horizontal approaches) or down (``'top'``),
    each phase offset by the robot's ``APPROACH_OFFSETS`` (back along the approach, up)."""
    x, y, z = point
    out = []
    for phase in PHASES[action]:
        back, up = geometry.approach_offsets.get(phase, (0.0, 0.0))
        if approach == "top":
            out.append(((x, y, z + back + up), _quat_down(heading)))
        else:
            c, s = math.cos(heading), math.sin(heading)
            out.append(((x - c * back, y - s * back, z + up), _quat_yaw(heading)))
    return out
