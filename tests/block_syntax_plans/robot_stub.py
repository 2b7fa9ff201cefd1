"""A stand-in for the thesis' ROS robot, for the block-syntax tests (no block syntax here).

`ProcessModule.perform(MotionDesignator([...]))` records each motion (thread-safe) and updates
the fluents `pose` and `r_gripper_state` the way the thesis' subscribers did. The item can be
grabbed only at x == 0.4 and is dropped once on the first drive to cooker #1.
"""

from __future__ import annotations

import threading
from types import SimpleNamespace
from typing import Any

from pycram.fluent import Fluent


class Pose:
    """geometry_msgs/Pose look-alike."""

    def __init__(self) -> None:
        self.position = SimpleNamespace(x=0.0, y=0.0, z=0.0)
        self.orientation = SimpleNamespace(x=0.0, y=0.0, z=0.0, w=0.0)


class MotionDesignator:
    """Key-value motion description, as in the thesis."""

    def __init__(self, properties: list[tuple[str, Any]]) -> None:
        self.properties = dict(properties)


class Robot:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.performed: list[dict[str, Any]] = []
        self.pose = Fluent(name="pose")
        self.r_gripper_state = Fluent(0.08, name="r_gripper_state")
        self.holding = False
        self.drop_on_next_drive = True

    def perform(self, designator: MotionDesignator) -> None:
        props = designator.properties
        with self.lock:
            self.performed.append(dict(props))
        kind = props["type"]
        if kind == "moving":
            goal = props["pose"]
            if self.holding and self.drop_on_next_drive and goal.position.y > 1.0:
                self.drop_on_next_drive = False
                self.holding = False
                self.r_gripper_state.set_value(0.0)  # the item fell out; the base did not arrive
                return
            self.pose.set_value(SimpleNamespace(pose=SimpleNamespace(position=SimpleNamespace(x=goal.position.x, y=goal.position.y))))
        elif kind == "setting_gripper" and props["gripper"] == "1":
            if props["position"] == 0:  # close
                self.r_gripper_state.set_value(0.05 if self.holding else 0.0)
            else:
                self.r_gripper_state.set_value(0.08)

    def kinds(self) -> list[str]:
        with self.lock:
            return [p["type"] for p in self.performed]

    def process_module(self) -> SimpleNamespace:
        """An object with the thesis' `ProcessModule.perform(designator)` for this robot."""
        return SimpleNamespace(perform=self.perform)
