"""A first plan of your own on a simulated robot: find the mug, pick it up, carry it away.

    pycram run examples/first_plan_on_sim.py            # on the PR2
    pycram run examples/first_plan_on_sim.py tiago      # the same plan on the one-armed TIAGo

(On a machine without a display, set MUJOCO_GL=egl.) The plan only performs motion designators
(docs/motions.md lists them all) and reads fluents; it never touches the simulator. It exits
with 0 when the robot is back at its start holding the mug.
"""

import logging
import math
import sys

from pycram import robots
from pycram.designator import LocationDesignator, MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.language import State, par, pursue
from pycram.sim import World

logging.basicConfig(level=logging.INFO, format="%(message)s")
log = logging.getLogger("first plan")

START = (0.8, 0.6, 0.0)  # where the robot starts: x [m], y [m], yaw [rad] in the map frame
BACK_COUNTER = (0.2, -1.2, 0.9)  # a point on the back counter, where mugs usually stand [m]
EMPTY = 0.01  # the gripper holds nothing when it closes further than this [m]


class MugNotFound(Exception):
    pass


class MugLost(Exception):
    pass


def motion(**properties):
    """Perform a motion designator on the active robot; return what its process module returns."""
    return perform(MotionDesignator(**properties))


def fetch_the_mug():
    opening = Fluent(name="opening")  # follows the gripper's opening [m] from now on
    motion(type="subscribing_gripper", gripper="right", fl=opening)

    errors = []
    with par(errors) as ready:  # get ready: three parts of the robot move at once
        motion(type="setting_torso", position="up")
        motion(type="setting_gripper", gripper="right", position=1)
        motion(type="setting_arm_configuration", arm="right", configuration="carry")
    if ready.get_value() is State.FAILED:
        raise errors[0]

    # look at the back counter: turn towards it, point the head, ask perception
    x, y, _ = START
    motion(type="moving", pose=(x, y, math.atan2(BACK_COUNTER[1] - y, BACK_COUNTER[0] - x)))
    motion(type="pointing_head", coordinates=BACK_COUNTER)
    seen = motion(type="detecting", object="mug")
    if not seen:
        raise MugNotFound("no mug on the back counter")
    mug = seen[0].pose  # its centre (x, y, z) [m] as measured by the camera
    log.info("saw the %s (%s) at (%.2f, %.2f, %.2f)", seen[0].type, seen[0].name, *mug)

    # grasp it: a base pose to reach it from (a location designator), then the arm
    motion(type="moving", pose=LocationDesignator([("to_reach", mug)]).reference())
    motion(type="reaching", arm="right", target=mug, phase="pre_grasp")
    motion(type="reaching", arm="right", target=mug, phase="grasp")
    motion(type="setting_gripper", gripper="right", position=0)
    if opening.get_value() < EMPTY:
        raise MugNotFound("the gripper closed on nothing")
    motion(type="reaching", arm="right", target=mug, phase="lift")
    motion(type="setting_arm_configuration", arm="right", configuration="carry")
    log.info("holding the mug: the gripper is %.1f cm open", 100 * opening.get_value())

    # carry it back, with a monitor that stops the drive if the mug is lost on the way
    mug_lost = opening < EMPTY
    with pursue(errors) as carried:
        motion(type="moving", pose=START)
        mug_lost.wait_for()
    if mug_lost.get_value():
        raise MugLost("the mug slipped out of the gripper")
    if carried.get_value() is State.FAILED:
        raise errors[-1]  # e.g. the drive collided with something
    log.info("back at the start with the mug")


if __name__ == "__main__":
    robot_name = sys.argv[1] if len(sys.argv) > 1 else "pr2"
    with World(robot_name) as world:  # the kitchen with the robot and a mug, simulated
        robot = robots.load(robot_name, world)  # its process modules and resolvers
        try:
            with robot:  # designators performed in this block go to this robot
                fetch_the_mug()
        finally:
            robot.shutdown()
        log.info("simulated time: %.1f s", world.sim_time.get_value())
