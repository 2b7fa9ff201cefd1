"""The plan-facing motion vocabulary (/tmp/vocab.md) on the simulated PR2 and TIAGo.

Every test performs designators through ``perform`` under ``with robot:`` on a real
:class:`pycram.sim.World` -- the same test body for both robots (issue 7's claim that one plan
runs unchanged on both). The world of each robot is shared by the tests of this module; each test
establishes its own preconditions (tests may *set up* the world directly; the code under test
only uses designators). Every wait is on a fluent, a handle or a designator with a time-out.
"""

from __future__ import annotations

import math

import pytest

pytest.importorskip("mujoco")

from pycram.designator import LocationDesignator, MotionDesignator, MotionPropertyError, perform  # noqa: E402
from pycram.fluent import Fluent  # noqa: E402
from pycram.language import State, pursue  # noqa: E402
from pycram.process_module import ProcessModule, ProcessModuleFailure, ProcessModuleStatus  # noqa: E402
from pycram.runtime import sleep  # noqa: E402

T = 60.0  # generous time-out of one wait [s of simulated time]
SLOT_1 = (0.1, -1.15)  # an item spot in front of cooker #2 (the demo's position 1) [m]
PLACE = (-0.72, 1.9)  # the place spot on cooker #1 [m]
START = (0.8, 0.6, 0.0)


def motion(**properties):
    return perform(MotionDesignator(**properties))


def item_centre(world, xy):
    """Centre [m] of the mug standing on the counter at ``xy``."""
    half = next(i for i in world.scene.items if i.name == "mug").half_height
    return [xy[0], xy[1], world.environment.support_height(*xy) + half]


def put_mug(world, xy):
    """Test set-up: the mug stands at ``xy`` (released from any gripper)."""
    outcome = world.move_item("mug", item_centre(world, xy)).wait(T)
    assert outcome is not None and outcome.succeeded, outcome


def go_to_start(robot):
    motion(type="setting_arm_configuration", arm="right", configuration="carry")
    motion(type="moving", pose=START)


def distance(a, b):
    return math.hypot(a.x - b.x, a.y - b.y)


def wait_value(predicate, fluents, timeout=T):
    """Wait until ``predicate()`` is true; re-evaluated whenever one of ``fluents`` pulses."""
    network = Fluent(lambda: True if predicate() else None)
    for fluent in fluents:
        fluent.add_child(network)
    return network.wait_for(timeout)


# --------------------------------------------------------------------------- load


def test_load_builds_the_robot_with_its_modules(robot):
    from pycram import robots
    from pycram.robots.common.sim_modules import SimRobot

    assert isinstance(robot, SimRobot)
    assert robot.world.robot == robot.name
    expected = {"navigation", "base_stop", "head", "torso", "sensors", "perception", "arm_right", "gripper_right"}
    if "left" in robot.description.ARMS:  # the PR2 and the TIAGo Pro have two arms
        expected |= {"arm_left", "gripper_left"}
    assert set(robot.process_modules) == expected
    with pytest.raises(ValueError, match="available: .*pr2, tiago"):
        robots.load("r2d2", robot.world)
    other = "tiago" if robot.name == "pr2" else "pr2"
    with pytest.raises(ValueError, match="needs a world"):
        robots.load(other, robot.world)


def test_reasoning_reaches_the_prospection_of_the_robots_belief_through_the_active_robot(robot):
    from pycram.robot import current_prospection
    from pycram.world.prospection import Prospection

    p = current_prospection()
    assert isinstance(p, Prospection) and p is robot.world.prospection(robot.belief)
    assert p is not robot.world.prospection()  # the simulator's truth is not the robot's
    assert p.believed is not None and p.believed.belief is robot.belief
    assert not p.in_collision(robot.world.base_pose.get_value())


def test_arm_requests_go_to_the_right_module(robot):
    """Thesis ch. 4.2.2: PR2 (and TIAGo Pro) dispatch on the arm; TIAGo serves any arm with its
    only one."""

    def module_for(**properties):
        return ProcessModule.resolve(MotionDesignator(**properties))

    two_armed = "left" in robot.description.ARMS  # the PR2 and the TIAGo Pro
    for name, physical in (("left", "left"), ("0", "left"), ("right", "right"), ("1", "right")):
        arm = physical if two_armed else "right"
        assert module_for(type="reaching", arm=name, target=[0, 0, 1]).name == f"arm_{arm}"
        assert module_for(type="setting_gripper", gripper=name, position=1).name == f"gripper_{arm}"
    assert module_for(type="cancelling_movement").name == "base_stop"
    assert module_for(type="moving", pose=START).name == "navigation"
    with pytest.raises(Exception, match="no arm 'middle'; available"):
        module_for(type="reaching", arm="middle", target=[0, 0, 1])


# --------------------------------------------------------------------------- vocabulary


def test_subscriptions_make_user_fluents_follow_the_sensors(robot):
    world = robot.world
    pose, opening = Fluent(name="pose"), Fluent(name="opening")
    assert motion(type="subscribing_pose", fl=pose) is pose
    motion(type="subscribing_gripper", gripper="1", fl=opening)  # thesis name of the right one
    assert pose.get_value() is not None and opening.get_value() is not None
    # every simulation update pulses the user's fluent
    pulses = pose.pulsed()
    assert pulses.wait_for(1.0)
    # it follows the base while driving ...
    here = world.base_pose.get_value()
    goal = (here.x + 0.3, here.y, here.yaw)
    near_goal = wait_value(lambda: abs(pose.get_value().x - goal[0]) < 0.03, [pose], timeout=0.0)
    assert not near_goal
    reached = motion(type="moving", pose=goal)
    assert distance(pose.get_value(), reached) < 0.01
    # ... and the gripper opening
    motion(type="setting_gripper", gripper="right", position=0)
    assert opening.get_value() < 0.01
    measured = motion(type="setting_gripper", gripper="right", position=1)
    assert abs(opening.get_value() - measured) < 0.005
    assert opening.get_value() > 0.08
    motion(type="moving", pose=START)


def test_torso_gripper_arm_and_head_motions(robot):
    world, d = robot.world, robot.description
    torso = d.TORSO["joint"]
    motion(type="setting_torso", position="down")
    assert abs(world.joint_states.get_value().position[torso] - d.TORSO_POSITIONS["down"]) < 0.01
    motion(type="setting_torso", position=0.1)
    assert abs(world.joint_states.get_value().position[torso] - 0.1) < 0.01
    motion(type="setting_torso", position="up")
    assert abs(world.joint_states.get_value().position[torso] - d.TORSO_POSITIONS["up"]) < 0.01

    half = motion(type="setting_gripper", gripper="1", position=0.5, max_effort=30)
    assert abs(half - 0.5 * d.GRIPPERS["right"]["max_opening"]) < 0.01

    for arm in ("left", "right", "0", "1"):
        for configuration in ("park", "pre_grasp", "carry", "carry_top"):
            motion(type="setting_arm_configuration", arm=arm, configuration=configuration)
            physical = d.ARM_ALIASES[arm]
            joints = d.ARMS[physical]["joints"]
            measured = [world.joint_states.get_value().position[j] for j in joints]
            wanted = d.ARM_CONFIGURATIONS[physical][configuration]
            assert max(abs(a - b) for a, b in zip(measured, wanted)) < 0.02, (arm, configuration)
    carry = list(d.ARM_CONFIGURATIONS["right"]["carry"])
    motion(type="setting_arm_joints", arm="right", positions=carry)
    with pytest.raises(MotionPropertyError, match="'configuration'.* must be 'carry', 'carry_top', 'park'"):
        motion(type="setting_arm_configuration", arm="right", configuration="wave")  # checked first
    with pytest.raises(ProcessModuleFailure, match="7 joints"):
        motion(type="setting_arm_joints", arm="right", positions=[0.0, 0.1])

    base = world.base_pose.get_value()
    ahead = [base.x + 1.5 * math.cos(base.yaw), base.y + 1.5 * math.sin(base.yaw), 0.5]
    angle = motion(type="pointing_head", coordinates=ahead, frame="map")
    assert angle < math.radians(1.5)


def test_non_waited_head_pointing_tracks_while_driving_and_detecting_sees_the_mug(robot):
    world = robot.world
    put_mug(world, SLOT_1)
    mug = item_centre(world, SLOT_1)
    go_to_start(robot)
    handle = motion(type="pointing_head", coordinates=mug, frame="map", wait=False)
    assert handle.wait(5.0) is None  # returns at once; the head keeps tracking
    # drive to a pose facing the mug (TIAGo's head cannot look backwards)
    x, y = START[0], START[1] - 0.4
    motion(type="moving", pose=(x, y, math.atan2(mug[1] - y, mug[0] - x)))
    seen = motion(type="detecting", object="mug")
    assert [item.type for item in seen] == ["mug"]
    assert seen[0].name.startswith("mug-")  # a belief's name, not the simulator's
    assert math.dist(seen[0].pose[:2], mug[:2]) < 0.04
    assert [item.type for item in motion(type="detecting")].count("mug") == 1
    assert motion(type="detecting", object="teapot") == []


def test_location_to_reach_and_full_grasp_sequence(robot):
    """The demo's grasp (open, drive to the to_reach pose, pre_grasp, grasp, close, lift, carry)."""
    world, d = robot.world, robot.description
    put_mug(world, SLOT_1)
    go_to_start(robot)
    target = item_centre(world, SLOT_1)
    opening = Fluent(name="opening")
    motion(type="subscribing_gripper", gripper="right", fl=opening)
    motion(type="setting_torso", position="up")
    motion(type="setting_gripper", gripper="right", position=1)
    base = LocationDesignator([("to_reach", target), ("arm", "right")]).reference()
    assert abs(base.yaw - (-math.pi / 2)) < 0.35  # faces the back counter (roughly squarely)
    assert base.arm == d.ARM_ALIASES["right"] and base.grasp == "side"
    assert 0.4 < math.dist((base.x, base.y), target[:2]) < 1.0
    reached = motion(type="moving", pose=base, frame="map")
    assert distance(reached, base) < 0.02
    for phase in ("pre_grasp", "grasp"):
        tool = motion(type="reaching", arm="right", target=target, phase=phase)
        back, up = d.APPROACH_OFFSETS[phase]
        wanted = (
            target[0] - back * math.cos(base.yaw),
            target[1] - back * math.sin(base.yaw),
            target[2] + up,
        )  # approach along the base's heading
        assert math.dist(tool.position, wanted) < 0.025, phase
    closed = motion(type="setting_gripper", gripper="right", position=0)
    assert closed > 0.01 and opening.get_value() > 0.01
    assert world.gripper_states[d.ARMS["right"]["gripper"]].get_value().holding == "mug"
    motion(type="reaching", arm="right", target=target, phase="lift")
    motion(type="setting_arm_configuration", arm="right", configuration="carry")
    assert opening.get_value() > 0.01  # still holding the mug
    assert world.item_poses.get_value()["mug"].position[2] > target[2] + 0.05
    # the alternatives of the location designator stand further back / closer
    first = LocationDesignator([("to_reach", target), ("arm", "right")])
    second = first.next_solution().reference()
    assert math.dist((second.x, second.y), (base.x, base.y)) >= 0.1 - 1e-9  # another place, no repeat
    # give the mug back to the counter and open the gripper
    put_mug(world, SLOT_1)
    motion(type="setting_gripper", gripper="right", position=1)
    motion(type="reaching", arm="right", target=target, phase="retreat")
    go_to_start(robot)


def test_place_spot_on_the_other_counter_is_reachable(robot):
    world = robot.world
    target = item_centre(world, PLACE)
    go_to_start(robot)
    motion(type="setting_torso", position="up")
    base = LocationDesignator([("to_reach", target), ("arm", "right"), ("action", "place")]).reference()
    assert abs(abs(base.yaw) - math.pi) < 0.35  # faces the left counter
    motion(type="moving", pose=base)
    for phase in ("pre_place", "place", "retreat"):
        motion(type="reaching", arm="right", target=target, phase=phase)
    go_to_start(robot)


# --------------------------------------------------------------------------- stopping the base


def test_non_waited_drive_is_cancelled_by_cancelling_movement(robot):
    world = robot.world
    go_to_start(robot)
    start = world.base_pose.get_value()
    execution = motion(type="moving", pose=(START[0] + 1.5, START[1] + 1.5, 0.0), wait=False)
    moved = wait_value(lambda: distance(world.base_pose.get_value(), start) > 0.2, [world.base_pose], timeout=10.0)
    assert moved
    assert not execution.done
    stopped_at = motion(type="cancelling_movement")
    assert execution.status.get_value() is ProcessModuleStatus.CANCELLED
    navigation = robot.process_module("navigation")
    assert navigation.current is None and navigation.queue_length == 0
    sleep(0.5)  # the base must stay where it stopped
    assert distance(world.base_pose.get_value(), stopped_at) < 0.03
    assert distance(world.base_pose.get_value(), start) < 1.5
    # the base is usable again afterwards; cancelling with nothing moving is harmless
    motion(type="cancelling_movement")
    motion(type="moving", pose=START)


def test_evaporating_a_running_drive_stops_the_base(robot):
    world = robot.world
    go_to_start(robot)
    start = world.base_pose.get_value()
    goal = (START[0] + 1.5, START[1] + 1.5, 0.0)
    state = pursue(lambda: motion(type="moving", pose=goal), lambda: sleep(1.0))
    assert state.get_value() is State.SUCCEEDED
    navigation = robot.process_module("navigation")
    assert navigation.status.get_value() is ProcessModuleStatus.CANCELLED
    here = world.base_pose.get_value()
    # it had moved (a differential drive may still be turning towards the goal) and stopped short
    turned = abs(math.remainder(here.yaw - start.yaw, 2 * math.pi))
    assert distance(here, start) > 0.05 or turned > 0.1
    assert distance(here, start) < 1.0
    sleep(0.5)
    assert distance(world.base_pose.get_value(), here) < 0.05
    motion(type="moving", pose=START)


def test_evaporating_a_queued_drive_leaves_the_running_one_alone(robot):
    go_to_start(robot)
    goal = (START[0] + 1.0, START[1] + 1.0, 0.0)
    running = ProcessModule.perform(MotionDesignator(type="moving", pose=goal, wait=False))
    navigation = robot.process_module("navigation")
    # a second drive waits in the queue and is evaporated there: its cancel hook must not
    # stop the drive that is running for another caller
    state = pursue(lambda: motion(type="moving", pose=START), lambda: (navigation.queued >= 1).wait_for())
    assert state.get_value() is State.SUCCEEDED
    reached = running.wait()
    assert math.hypot(reached.x - goal[0], reached.y - goal[1]) < 0.05
    motion(type="moving", pose=START)


# --------------------------------------------------------------------------- failures


def test_unreachable_reaching_fails_with_a_clear_error(robot):
    world = robot.world
    go_to_start(robot)
    far = [START[0] + 2.5, START[1], 1.0]
    with pytest.raises(ProcessModuleFailure, match="unreachable") as info:
        motion(type="reaching", arm="right", target=far, phase="grasp")
    assert "reach with the right arm" in str(info.value)
    assert robot.process_module("arm_right").status.get_value() is ProcessModuleStatus.FAILED
    motion(type="setting_arm_configuration", arm="right", configuration="carry")
    with pytest.raises(MotionPropertyError, match="'phase'.*must be .*'grasp'.*got 'wiggle'"):
        motion(type="reaching", arm="right", target=far, phase="wiggle")
    assert world.running


class _PoseTrack(Fluent):
    """Records every published base pose (in the simulation thread) while `active`."""

    def __init__(self, source: Fluent) -> None:
        super().__init__(None)
        self.source, self.samples, self.active = source, [], True
        source.add_child(self)

    def pulse(self) -> None:
        if self.active:
            self.samples.append(self.source.get_value())
        super().pulse()


def _obstacle_ahead(robot, distance: float) -> str:
    """Test set-up: the robot at START, an obstacle box `distance` [m] ahead; its name."""
    go_to_start(robot)
    outcome = robot.world.place_obstacle(START[0] + distance, START[1]).wait(T)
    assert outcome is not None and outcome.succeeded
    return outcome.value


def test_moving_goes_around_an_obstacle_on_the_straight_line(robot):
    world = robot.world
    obstacle = _obstacle_ahead(robot, 1.0)
    watcher = _PoseTrack(world.base_pose)
    samples = watcher.samples
    try:
        reached = motion(type="moving", pose=(START[0] + 2.0, START[1], 0.0))
        assert reached.distance_to(world.base_pose.get_value()) < 0.02
        assert abs(reached.x - (START[0] + 2.0)) < 0.02 and abs(reached.y - START[1]) < 0.02
        # it left the straight line to pass the obstacle (0.15 m half width + the base)
        assert max(abs(p.y - START[1]) for p in samples) > 0.3
    finally:
        watcher.active = False
        world.remove_obstacle(obstacle).wait(T)
    motion(type="moving", pose=START)


def test_moving_to_an_occupied_goal_fails_with_a_navigation_failure(robot):
    from pycram.world.navigation import NavigationFailure

    world = robot.world
    obstacle = _obstacle_ahead(robot, 2.0)
    before = world.base_pose.get_value()
    try:
        with pytest.raises(ProcessModuleFailure) as info:
            motion(type="moving", pose=(START[0] + 2.0, START[1], 0.0))
        assert isinstance(info.value.cause, NavigationFailure)
        assert info.value.cause.reason == "no_path"
        message = str(info.value)
        assert "drive to (x=2.800" in message and "goal_in_collision" in message
        assert world.base_pose.get_value().distance_to(before) < 0.01  # it did not set off
    finally:
        world.remove_obstacle(obstacle).wait(T)
    motion(type="moving", pose=START)
