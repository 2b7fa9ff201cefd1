"""The thesis demo's task -- fetch the mug at cooker #2, put it on cooker #1 -- in actions.

The thesis wrote it with motion designators and coordinates (`pycram demo`); with the action
library the robot perceives the mug, chooses where to stand, which arm and which grasp, and
recovers from failed grasps on its own. Run: `python examples/fetch_and_place_actions.py [tiago]`.
"""

import sys

from pycram import robots
from pycram.actions import MoveTorso, ParkArms, Transport
from pycram.designator import LocationDesignator, ObjectDesignator, perform
from pycram.sim import World

robot_name = sys.argv[1] if len(sys.argv) > 1 else "pr2"
with World(robot_name) as world:  # the thesis kitchen, with its mug at cooker #2
    with robots.load(robot_name, world) as robot:
        perform(ParkArms())
        perform(MoveTorso("up"))
        mug = perform(
            Transport(ObjectDesignator(type="mug"), LocationDesignator([("on", "cooker #1"), ("for", "mug")]))
        )
        print(f"the {robot_name} put the mug down at {mug.pose[0]:.2f}, {mug.pose[1]:.2f} on {mug.properties['on']}")
    robot.shutdown()
