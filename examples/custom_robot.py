"""A robot of your own: the extension points `Robot`, process modules and resolvers.

    pycram run examples/custom_robot.py

No simulator needed. The robot here has a toy base of our own (a process module that moves a
pose fluent in small steps of the active clock) and a gripper played by a test double from
`pycram.testing`. For real hardware, write process modules whose `_execute` sends the command
(a ROS action, a serial message, another simulator) and waits for it; everything else stays.

How a `perform(MotionDesignator(...))` reaches the hardware, and where you plug in:

1. the active robot's `motion_resolvers` turn the designator into a solution (here a dict
   with a 'cmd' key) -- `designator.reference()`;
2. its `process_module_resolvers` pick the process module for the designator;
3. that module's `_execute(designator)` runs the motion in the caller's task and returns a
   result; its `_cancel(designator)` stops the hardware when the caller is evaporated.

`location_generators` answer location designators such as `('to_reach', point)`.
"""

import logging
import math

from pycram.designator import LocationDesignator, MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.language import State, pursue
from pycram.process_module import ProcessModule
from pycram.robot import Robot
from pycram.runtime import sleep
from pycram.testing import ScriptedProcessModule

logging.basicConfig(level=logging.INFO, format="%(message)s")
log = logging.getLogger("custom robot")


class ToyBase(ProcessModule):
    """Drives a pretend base: ``{'cmd': 'drive', 'goal': (x, y)}`` moves ``pose`` towards the
    goal at ``speed`` [m/s] in steps of ``STEP`` [s]. Returns the reached (x, y) [m]."""

    STEP = 0.02  # [s]

    def __init__(self, speed: float = 2.0) -> None:
        super().__init__("toy_base")
        self.pose = Fluent((0.0, 0.0), name="toy_base.pose")  # plans may watch it
        self.speed = speed
        self.stopped_at = None

    def _execute(self, designator):
        solution = designator.reference()  # what the motion resolver made of the designator
        goal_x, goal_y = solution["goal"]
        while True:
            x, y = self.pose.get_value()
            distance = math.hypot(goal_x - x, goal_y - y)
            if distance < 1e-6:
                return x, y
            step = self.speed * self.STEP / distance
            self.pose.set_value((goal_x, goal_y) if step >= 1.0 else (x + step * (goal_x - x), y + step * (goal_y - y)))
            sleep(self.STEP)  # evaporable: a pursue or with_timeout can stop the drive here

    def _cancel(self, designator):
        # runs when the performing task was evaporated: stop the motors here
        self.stopped_at = self.pose.get_value()
        log.info("toy base: stopped at (%.2f, %.2f)", *self.stopped_at)


def toy_motions(designator):
    """Motion resolver: the designator -> a list of solutions its process module understands."""
    if designator.check_constraints([("type", "moving"), "pose"]):
        x, y, _yaw = designator.prop_value("pose")
        return [{"cmd": "drive", "goal": (float(x), float(y))}]
    if designator.check_constraints([("type", "setting_gripper"), "position"]):
        return [{"cmd": "grip", "opening": 0.08 * float(designator.prop_value("position"))}]
    return []


def toy_places(designator):
    """Location generator: base poses 0.5 m in front of a point to reach (None: not mine)."""
    if not designator.check_constraints(["to_reach"]):
        return None
    x, y, _z = designator.prop_value("to_reach")
    return [(x - 0.5, y, 0.0), (x, y - 0.5, math.pi / 2)]


def make_toy_robot() -> Robot:
    robot = Robot("toy")
    base = robot.add_process_module("base", ToyBase())
    # a test double: returns the scripted "measured openings" [m], one per execution
    gripper = robot.add_process_module("gripper", ScriptedProcessModule("gripper", script=[0.08, 0.03]))

    def process_module_for(designator):
        """Process-module resolver: which module executes this designator (None: not mine)."""
        if designator.check_constraints([("type", "moving")]):
            return base
        if designator.check_constraints([("type", "setting_gripper")]):
            return gripper
        return None

    robot.motion_resolvers.append(toy_motions)
    robot.process_module_resolvers.append(process_module_for)
    robot.location_generators.append(toy_places)
    return robot


def motion(**properties):
    return perform(MotionDesignator(**properties))


def fetch(point):
    """A plan in the same vocabulary as the simulated robots' (docs/motions.md)."""
    motion(type="setting_gripper", gripper="right", position=1)
    motion(type="moving", pose=LocationDesignator([("to_reach", point)]).reference())
    return motion(type="setting_gripper", gripper="right", position=0)


if __name__ == "__main__":
    robot = make_toy_robot()
    with robot:  # designators performed in this block go to the toy robot
        # a drive that takes too long is evaporated by the pursue: the cancel hook stops the base
        errors = []
        state = pursue(lambda: motion(type="moving", pose=(100.0, 0.0, 0.0)), lambda: sleep(0.2), errors=errors)
        assert state.get_value() is State.SUCCEEDED and robot.process_module("base").stopped_at is not None

        opening = fetch((1.0, 0.5, 0.9))
        log.info(
            "toy base at (%.2f, %.2f); the gripper closed at %.2f m",
            *robot.process_module("base").pose.get_value(),
            opening,
        )
        assert robot.process_module("base").pose.get_value() == (0.5, 0.5)
        assert [d.prop_value("position") for d in robot.process_module("gripper").executed] == [1, 0]
