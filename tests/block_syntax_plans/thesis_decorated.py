"""Thesis listings (ch. 3.2.2, 3.2.3, 4.2.3) inside functions decorated with `@plan`.

The same listings as thesis_module.py; here the block syntax is switched on per function. Each
function returns its outcome for tests/test_block_syntax_thesis.py.
"""

import math
import threading

from robot_stub import MotionDesignator, Pose, Robot

from pycram.fluent import Fluent, whenever, Behavior
from pycram.language import failure_handling, par, seq, State, try_in_order, try_all, pursue, plan
from pycram.runtime import sleep

TIMEOUT = 10.0


class Boom(Exception):
    pass


def fail(label):
    raise Boom(label)


@plan
def fluents():
    """3.2.2: the fluent listings; each wait is a branch of a `par`, the change another."""
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
    return {"fluents": (first_value, second_value, goal_state, division_state, s.get_value().name)}


@plan
def follow(loc, targets):
    """3.2.2: `return` inside `whenever` leaves the loop and the function."""
    moves = []
    loc.set_value(targets[0])
    with whenever(loc):
        moves.append(loc.get_value())
        if len(moves) == len(targets):
            return moves
        loc.set_value(targets[len(moves)])


@plan
def follow_pulsed(loc, targets):
    moves = []
    moved = Fluent(0)

    def publisher():
        for i, target in enumerate(targets, 1):
            for _ in range(int(TIMEOUT / 0.05)):
                loc.set_value(target)
                if (moved >= i).wait_for(timeout=0.05):
                    break

    threading.Thread(target=publisher, daemon=True).start()
    with whenever(loc.pulsed(Behavior.ONCE)):
        # execute once more if missed pulses occur
        if not moves or moves[-1] != loc.get_value():
            moves.append(loc.get_value())
        moved.set_value(len(moves))
        if len(moves) == len(targets):
            return moves


@plan
def sequential():
    out = {}
    trace = []
    with seq(errors) as s:
        trace.append("s1")
        trace.append("s2")
    out["seq_ok"] = (s.get_value().name, list(trace), len(errors))

    trace = []
    with seq(errors) as s:
        fail("s1")
        trace.append("s2")
    out["seq_fail"] = (s.get_value().name, list(trace), [str(e) for e in errors])

    trace = []
    errs = []
    with try_in_order(errs) as s:
        fail("s1")
        trace.append("s2")
    out["try_in_order"] = (s.get_value().name, list(trace), [str(e) for e in errs])
    return out


@plan
def parallel():
    out = {}
    done = []
    with par(errors) as s:
        done.append("s1")
        done.append("s2")
    out["par_ok"] = (s.get_value().name, sorted(done), len(errors))

    threads = {}
    with par(errors) as s:
        if True:
            threads["s1"] = threading.get_ident()
            threads["s2"] = threading.get_ident()
        threads["s3"] = threading.get_ident()
    out["par_if_true"] = (s.get_value().name, threads["s1"] == threads["s2"], threads["s1"] != threads["s3"])

    order = []
    with par(errors) as s:
        with seq as state:
            order.append("s1")
            order.append("s2")
        order.append("s3")
    out["par_seq"] = (s.get_value().name, state.get_value().name, order.index("s1") < order.index("s2"), sorted(order))

    e1 = []
    with par(e1) as s:
        fail("s1")
        while True:
            if s.get_value() == State.FAILED:
                break
        done.append("s2")
    out["par_state_loop"] = (s.get_value().name, [str(e) for e in e1])

    e2 = []
    with par(e2) as s:
        fail("s1")
        while True:
            if s.get_value():
                break

        done.append("s2")
    out["par_state_loop_truthy"] = (s.get_value().name, [str(e) for e in e2])

    e3 = []
    with try_all(e3) as s:
        fail("s1")
        done.append("s2")
    out["try_all"] = (s.get_value().name, [str(e) for e in e3])

    e4 = []
    never = Fluent()
    with pursue(e4) as s:
        done.append("s1")
        never.wait_for()
    out["pursue"] = (s.get_value().name, len(e4))
    return out


@plan
def error_handling():
    out = {}
    attempts = 0
    with failure_handling(5):
        try:
            attempts += 1
            if attempts < 3:
                fail("c")
        except Exception as e:
            retry()
    out["failure_handling_5"] = attempts

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
    out["failure_handling_5_exhausted"] = (attempts, error)

    attempts = 0
    with failure_handling():
        try:
            attempts += 1
            if attempts < 20:
                fail("c")
        except Exception as e:
            retry()
    out["failure_handling_unlimited"] = attempts
    return out


# -- 4.2.3 -----------------------------------------------------------------------------------------


class Demo:
    """The thesis demo's module-level state, one instance per run."""

    def __init__(self):
        self.robot = Robot()
        self.results = {}


@plan
def reset_robot(demo):
    ProcessModule = demo.robot.process_module()
    with par as state:
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '0'), ('position', 1)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '0'), ('positions', [0.0] * 7)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '1'), ('positions', [0.0] * 7)]))
        ProcessModule.perform(MotionDesignator([('type', 'setting_torso'), ('position', 0.3)]))

    state.wait_for()
    demo.results["reset_state"] = state.get_value().name
    goal = Pose()
    goal.orientation.w = 1.0
    ProcessModule.perform(MotionDesignator([('type', 'moving'), ('pose', goal), ('frame', 'map')]))


@plan
def run_demo(demo):
    robot = demo.robot
    ProcessModule = robot.process_module()
    pose = robot.pose
    r_gripper_state = robot.r_gripper_state

    def grab_item():
        ProcessModule.perform(MotionDesignator([('type', 'moving'), ('pose', goal), ('frame', 'map')]))
        robot.holding = abs(goal.position.x - 0.4) < 1e-9
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 0)]))
        if r_gripper_state.get_value() < 0.01:
            ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
            raise Boom(f"nothing to grab at x={goal.position.x}")

    def put_item_back():
        robot.holding = True

    def place_item():
        ProcessModule.perform(MotionDesignator([('type', 'setting_gripper'), ('gripper', '1'), ('position', 1)]))
        robot.holding = False

    reset_robot(demo)
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
                return
        with seq as s:
            with try_in_order as state:
                if True:
                    goal.position.x = 0.1
                    goal.position.y = -0.6
                    look_goal.position.x = 0.1
                    look_goal.position.y = -1.1
                    look_goal.position.z = 0.8
                    grab_attempts.append(goal.position.x)
                    grab_item()
                if True:
                    goal.position.x = -0.2
                    goal.position.y = -0.6
                    look_goal.position.x = -0.2
                    look_goal.position.y = -1.1
                    look_goal.position.z = 0.8
                    grab_attempts.append(goal.position.x)
                    grab_item()
                if True:
                    goal.position.x = 0.4
                    goal.position.y = -0.6
                    look_goal.position.x = 0.4
                    look_goal.position.y = -1.1
                    look_goal.position.z = 0.8
                    grab_attempts.append(goal.position.x)
                    grab_item()

            if state.get_value() == State.FAILED:
                raise Boom('Could not grab any item.')

            goal.position.x = -0.1
            goal.position.y = 1.9
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
            while not head_stopped.wait_for(timeout=0.05):
                pose.pulse()

    demo.results["demo"] = {
        "par": s.get_value().name,
        "try_in_order": state.get_value().name,
        "grab_attempts": grab_attempts,
        "failure_handling_attempts": fh_attempts,
        "final_position": [p.x, p.y],
        "last_head_target": list(head_targets[-1]),
        "head_moves": len(head_targets),
        "kinds": robot.kinds(),
    }
    return demo.results
