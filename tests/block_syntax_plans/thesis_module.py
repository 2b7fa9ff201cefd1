"""Thesis listings (ch. 3.2.2, 3.2.3, 4.2.3) at module level, written in the thesis' block syntax.

Run in script mode (`run_script`, `python -m pycram thesis_module.py`) and import-hook mode by
tests/test_block_syntax_thesis.py. `s1`, `s2`, ... of the thesis are real statements here; the
outcomes land in RESULTS (printed as JSON when run as a script).
"""

import json
import math
import sys
import threading

from robot_stub import MotionDesignator, Pose, Robot

from pycram.fluent import macros, Fluent, whenever, Behavior
from pycram.language import macros, failure_handling, par, seq, State, try_in_order, try_all, pursue
from pycram.runtime import sleep

RESULTS = {}
TIMEOUT = 10.0


class Boom(Exception):
    pass


def fail(label):
    raise Boom(label)


# -- 3.2.2 fluents and fluent networks (the waits are branches of a `par`, the change another) --

f = Fluent(1)
first_value = f.get_value()  # returns 1
f.set_value(2)  # sets the value to 2
second_value = f.get_value()  # returns 2

goal_reached = Fluent()
with par as s:
    goal_reached.wait_for()  # blocks if the value is None, no effect otherwise
    goal_reached.set_value(True)
goal_state = s.get_value().name

f = Fluent(9)
with par as s:
    (f / 3 < 1).wait_for()
    f.set_value(2)
division_state = s.get_value().name

f = Fluent(9)
fluent_net = Fluent(lambda: f.get_value() / 3)
f.add_child(fluent_net)
with par as s:
    (fluent_net < 1).wait_for()
    f.set_value(1.5)
RESULTS["fluents"] = (first_value, second_value, goal_state, division_state, s.get_value().name)


# -- 3.2.2 whenever ------------------------------------------------------------------------------

loc = Fluent()
targets = [(1, 0), (2, 0), (3, 0)]
moves = []


def move(location):
    if not moves or moves[-1] != location:
        moves.append(location)


def update_location(location):
    loc.set_value(location)


update_location(targets[0])
with whenever(loc):
    move(loc.get_value())
    if len(moves) == len(targets):
        break
    update_location(targets[len(moves)])
RESULTS["whenever"] = list(moves)

# `whenever(loc.pulsed(...))`: locations arrive from another thread, like a ROS subscriber
# callback. A location published before the pulse fluent exists is missed (as on a real topic),
# so the publisher repeats each one until the plan has moved there.
loc = Fluent()
moves = []
moved = Fluent(0)


def publisher():
    for i, target in enumerate(targets, 1):
        for _ in range(int(TIMEOUT / 0.05)):
            update_location(target)
            if (moved >= i).wait_for(timeout=0.05):
                break


threading.Thread(target=publisher, daemon=True).start()
with whenever(loc.pulsed(Behavior.ONCE)):
    # execute once more if missed pulses occur
    move(loc.get_value())
    moved.set_value(len(moves))
    if len(moves) == len(targets):
        break
RESULTS["whenever_pulsed"] = list(moves)



def follow(loc, targets):
    """`with whenever` inside a function: `return` leaves the loop (and the function), as the
    thesis says ("it will not stop unless it is canceled by a return statement")."""
    moves = []
    loc.set_value(targets[0])
    with whenever(loc):
        moves.append(loc.get_value())
        if len(moves) == len(targets):
            return moves
        loc.set_value(targets[len(moves)])


RESULTS["whenever_return"] = follow(Fluent(), targets)

# -- 3.2.3 sequential execution ------------------------------------------------------------------

trace = []
with seq(errors) as s:
    trace.append("s1")
    trace.append("s2")
RESULTS["seq_ok"] = (s.get_value().name, list(trace), len(errors))

trace = []
with seq(errors) as s:
    fail("s1")
    trace.append("s2")
RESULTS["seq_fail"] = (s.get_value().name, list(trace), [str(e) for e in errors])

del errors
trace = []
with try_in_order(errors) as s:
    fail("s1")
    trace.append("s2")
RESULTS["try_in_order"] = (s.get_value().name, list(trace), [str(e) for e in errors])

# -- 3.2.3 parallel execution --------------------------------------------------------------------

del errors
done = []
with par(errors) as s:
    done.append("s1")
    done.append("s2")
RESULTS["par_ok"] = (s.get_value().name, sorted(done), len(errors))

threads = {}
with par(errors) as s:
    if True:
        threads["s1"] = threading.get_ident()
        threads["s2"] = threading.get_ident()
    threads["s3"] = threading.get_ident()
RESULTS["par_if_true"] = (
    s.get_value().name,
    threads["s1"] == threads["s2"],
    threads["s1"] != threads["s3"],
)

order = []
with par(errors) as s:
    with seq as state:
        order.append("s1")
        order.append("s2")
    order.append("s3")
RESULTS["par_seq"] = (s.get_value().name, state.get_value().name, order.index("s1") < order.index("s2"), sorted(order))

del errors
seen_failed = []
with par(errors) as s:
    fail("s1")
    while True:
        if s.get_value() == State.FAILED:
            seen_failed.append(True)
            break
    done.append("s2")
RESULTS["par_state_loop"] = (s.get_value().name, [str(e) for e in errors])

del errors
with par(errors) as s:
    fail("s1")
    while True:
        if s.get_value():
            break

    done.append("s2")
RESULTS["par_state_loop_truthy"] = (s.get_value().name, [str(e) for e in errors])

del errors
with try_all(errors) as s:
    fail("s1")
    done.append("s2")
RESULTS["try_all"] = (s.get_value().name, [str(e) for e in errors])

del errors
never = Fluent()
with pursue(errors) as s:
    done.append("s1")
    never.wait_for()
RESULTS["pursue"] = (s.get_value().name, len(errors))

# -- 3.2.3 error handling ------------------------------------------------------------------------

attempts = 0
with failure_handling(5):
    try:
        attempts += 1
        if attempts < 3:
            fail("c")
    except Exception as e:
        retry()
RESULTS["failure_handling_5"] = attempts

attempts = 0
try:
    with failure_handling(5):
        try:
            attempts += 1
            fail("c")
        except Exception as e:
            retry()  # once the 5 retries are used up, re-raises e
    error = None
except Boom as e:
    error = str(e)
RESULTS["failure_handling_5_exhausted"] = (attempts, error)

attempts = 0
with failure_handling():
    try:
        attempts += 1
        if attempts < 20:
            fail("c")
    except Exception as e:
        retry()
RESULTS["failure_handling_unlimited"] = attempts

# -- 4.2.3 the demo (language parts; the robot is a stub) -------------------------------------------

robot = Robot()
ProcessModule = robot.process_module()
pose = robot.pose
r_gripper_state = robot.r_gripper_state


def reset_robot():
    with par as state:
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '0'), ('position', 1)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '0'), ('positions', [0.0] * 7)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '1'), ('positions', [0.0] * 7)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_torso'), ('position', 0.3)]))

    state.wait_for()
    RESULTS["reset_state"] = state.get_value().name
    goal = Pose()
    goal.orientation.w = 1.0
    ProcessModule.perform(MotionDesignator([('type', 'moving'), ('pose', goal), ('frame', 'map')]))


def grab_item():
    ProcessModule.perform(MotionDesignator([('type', 'moving'), ('pose', goal), ('frame', 'map')]))
    robot.holding = abs(goal.position.x - 0.4) < 1e-9  # the item stands at x = 0.4
    ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 0)]))
    if r_gripper_state.get_value() < 0.01:
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
        raise Boom(f"nothing to grab at x={goal.position.x}")


def put_item_back():  # the thesis asks the user: input('Put the item into the right gripper ...')
    robot.holding = True


def place_item():
    ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
    robot.holding = False


reset_robot()
RESULTS["reset_kinds"] = robot.kinds()

goal = Pose()
look_goal = Pose()
demo_done = Fluent()
head_stopped = Fluent()
head_targets = []
grab_attempts = []
fh_attempts = 0

with par as s:
    with whenever(pose.pulsed()):
        ProcessModule.perform(MotionDesignator([('type', 'pointing_head'), ('coordinates', [look_goal.position.x, look_goal.position.y, look_goal.position.z]), ('wait', False), ('frame', 'map')]))
        head_targets.append((look_goal.position.x, look_goal.position.y, look_goal.position.z))
        if demo_done.get_value():
            head_stopped.set_value(True)
            break
    with seq as s:
        with try_in_order as state:
            if True:
                goal.position.x = 0.1
                goal.position.y = -0.6
                goal.orientation.z = -0.700573543807
                goal.orientation.w = 0.713580205526

                look_goal.position.x = 0.1
                look_goal.position.y = -1.1
                look_goal.position.z = 0.8

                grab_attempts.append(goal.position.x)
                grab_item()
            if True:
                goal.position.x = -0.2
                goal.position.y = -0.6
                goal.orientation.z = -0.700573543807
                goal.orientation.w = 0.713580205526

                look_goal.position.x = -0.2
                look_goal.position.y = -1.1
                look_goal.position.z = 0.8

                grab_attempts.append(goal.position.x)
                grab_item()
            if True:
                goal.position.x = 0.4
                goal.position.y = -0.6
                goal.orientation.z = -0.700573543807
                goal.orientation.w = 0.713580205526

                look_goal.position.x = 0.4
                look_goal.position.y = -1.1
                look_goal.position.z = 0.8

                grab_attempts.append(goal.position.x)
                grab_item()

        if state.get_value() == State.FAILED:
            raise Boom('Could not grab any item.')

        goal.position.x = -0.1
        goal.position.y = 1.9
        goal.orientation.z = 0.9999981068
        goal.orientation.w = 0.00194586635055

        look_goal.position.x = -0.6
        look_goal.position.y = 1.9
        look_goal.position.z = 1.0

        with failure_handling:
            try:
                fh_attempts += 1
                if r_gripper_state.get_value() > 0.01:
                    ProcessModule.perform(MotionDesignator([('type', 'moving'), ('pose', goal), ('wait', False), ('frame', 'map')]))

                while True:
                    p = pose.get_value().pose.position

                    if r_gripper_state.get_value() < 0.01:  # if lost item
                        ProcessModule.perform(MotionDesignator([('type', 'cancelling_movement')]))
                        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
                        put_item_back()
                        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 0)]))
                        raise
                    elif math.hypot(goal.position.x - p.x, goal.position.y - p.y) < 0.1:
                        break

                    sleep(0.01)
            except:
                retry()

        place_item()
        demo_done.set_value(True)
        while not head_stopped.wait_for(timeout=0.05):  # until the head loop has seen it
            pose.pulse()

RESULTS["demo"] = {
    "par": s.get_value().name,
    "try_in_order": state.get_value().name,
    "grab_attempts": grab_attempts,
    "failure_handling_attempts": fh_attempts,
    "final_position": [p.x, p.y],
    "last_head_target": list(head_targets[-1]),
    "head_moves": len(head_targets),
    "kinds": robot.kinds(),
}

if __name__ == "__main__":
    sys.stdout.write(json.dumps(RESULTS, default=list) + "\n")
