"""What the robot holds: an object in a gripper (`Held`: the believed object, the arm, the
gripper and the grasp) and, per robot, what its grippers hold as far as its actions know
(`held_objects`, arm -> `Held`).

`PickUp` records the object it picked up here, `Place` removes it when it lets go (and when the
gripper is measured empty). Whether the object is still in hand is measured, not taken from
this record: the gripper's opening below `Held.held_opening` [m] means it holds nothing.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Any

from pycram.execution.robot import current_robot
from pycram.world.belief import PerceivedObject
from pycram.world.objects import Grasp

__all__ = ["Held", "held_objects", "HELD_FRACTION"]

#: The gripper holds the object when its opening is at least this fraction of the grasp's opening.
HELD_FRACTION = 0.5


@dataclass
class Held:
    """An object in a gripper: the believed `object`, the `arm` and `gripper`, and the `grasp`."""

    object: PerceivedObject
    arm: str
    gripper: str
    grasp: Grasp

    @property
    def held_opening(self) -> float:
        """Below this measured opening [m] the gripper holds nothing."""
        return HELD_FRACTION * self.grasp.opening


_holding: weakref.WeakKeyDictionary[Any, dict[str, Held]] = weakref.WeakKeyDictionary()


def held_objects() -> dict[str, Held]:
    """What the active robot's grippers hold, as far as its actions know (arm -> `Held`)."""
    return _holding.setdefault(current_robot(), {})
