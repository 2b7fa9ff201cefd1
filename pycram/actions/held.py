"""What the robot holds: an object in a gripper (`Held`: the believed object, the arm, the
gripper and the grasp) and, per robot, what its grippers hold as far as its actions know
(`held_objects`, arm -> `Held`).

`PickUp` records the object it picked up here, `Place` removes it when it lets go (and when the
gripper is measured empty). Whether the object is still in hand is measured, not taken from
this record: the gripper's opening below `Held.held_opening` [m] means it holds nothing. The
object turns with the hand: `fingers_yaw` reads the fingers' direction from a validated grasp
or place pose, `Held.hand_turn` how far the hand turned the object between the two.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import Any

from pycram.execution.robot import current_robot
from pycram.world.belief import PerceivedObject
from pycram.world.objects import Grasp

__all__ = ["Held", "held_objects", "HELD_FRACTION", "fingers_yaw"]

#: The gripper holds the object when its opening is at least this fraction of the grasp's opening.
HELD_FRACTION = 0.5


@dataclass
class Held:
    """An object in a gripper: the believed `object`, the `arm` and `gripper`, and the `grasp`;
    `hand_yaw` [rad, map] the direction the fingers opened along when they closed on it (None:
    not known): the object turns with the hand, so where it is put down with the fingers along
    another direction it is believed turned by the difference (`hand_turn`)."""

    object: PerceivedObject
    arm: str
    gripper: str
    grasp: Grasp
    hand_yaw: float | None = None

    def hand_turn(self, hand_yaw: float) -> float:
        """How far [rad, in [-pi, pi)] the held object turned about the vertical with the hand,
        its fingers now opening along `hand_yaw` [rad, map]; 0 when the grasp's is not known."""
        if self.hand_yaw is None:
            return 0.0
        return (hand_yaw - self.hand_yaw + math.pi) % (2 * math.pi) - math.pi

    @property
    def held_opening(self) -> float:
        """Below this measured opening [m] the gripper holds nothing."""
        return HELD_FRACTION * self.grasp.opening


def fingers_yaw(location: Any) -> float:
    """The direction [rad, map, in [-pi, pi)] the fingers open along at the grasp (or place) pose of
    `location` (a `pycram.reasoning.locations.BaseLocation`): from its validated tool
    orientation (the tool's y axis) when it has one, else across the base's heading (horizontal
    grasps reached along it)."""
    poses: Any = getattr(location, "tool_poses", ())
    if len(poses) > 1 and poses[1][1] is not None:
        w, x, y, z = (float(v) for v in poses[1][1])
        # the tool's y axis in the map frame: the second column of its rotation matrix
        return math.atan2(1 - 2 * (x * x + z * z), 2 * (x * y - w * z))
    return (float(location.yaw) + 1.5 * math.pi) % (2 * math.pi) - math.pi


_holding: weakref.WeakKeyDictionary[Any, dict[str, Held]] = weakref.WeakKeyDictionary()


def held_objects() -> dict[str, Held]:
    """What the active robot's grippers hold, as far as its actions know (arm -> `Held`)."""
    return _holding.setdefault(current_robot(), {})
