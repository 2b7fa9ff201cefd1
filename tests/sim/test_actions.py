"""The action library (issue 16) on both robots in the apartment: each action alone, picking up
and placing, transporting, every recovery path forced by a fault, and the typed failures.

The plans know the world only through perception; the tests set the scene up with the
simulator and judge with its truth (`action_helpers`).
"""

from __future__ import annotations

import math

import pytest
from action_helpers import (
    COUNTER,
    TABLE,
    HiddenBehindRaisedArm,
    KnockOverOnceLetGo,
    MissingDetections,
    OnceHolding,
    apartment_with,
    holding,
    put,
    rests_upright_at,
    run_as_task,
    tasks_named,
)
from sim_helpers import ok, tilt

from pycram.actions import (
    ActionParameterError,
    Detect,
    Held,
    LookAt,
    MoveTorso,
    Navigate,
    ParkArms,
    PickUp,
    Place,
    Search,
    SetGripper,
    Transport,
    held_objects,
)
from pycram.actions.place import resting_problem
from pycram.designator import LocationDesignator, MotionDesignator, ObjectDesignator, perform
from pycram.failures import (
    GoalUnreachable,
    GraspFailed,
    GripperEmpty,
    ObjectNotFound,
    ObjectNotVisible,
    ObjectOutOfReach,
    ObjectSlipped,
    PlacingFailed,
    PlanFailure,
)
from pycram.process_module import ProcessModuleFailure
from pycram.world.objects import object_type

ROBOTS = ("pr2", "tiago")


def on(surface: str, type_name: str) -> LocationDesignator:
    return LocationDesignator([("on", surface), ("for", type_name)])


def ready() -> None:
    perform(ParkArms())
    perform(MoveTorso("up"))


# -- each action alone ----------------------------------------------------------------------------


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_navigate_to_a_pose_and_to_a_location(robot_name):
    with apartment_with(robot_name, {"cup": COUNTER}) as (world, robot):
        reached = perform(Navigate((3.0, 1.2, 0.0)))
        assert math.hypot(reached.x - 3.0, reached.y - 1.2) < 0.05
        table = world.environment.surface("table")
        reached = perform(Navigate(LocationDesignator([("to_see", "table")])))
        base = world.base_pose.get_value()
        assert math.hypot(base.x - reached.x, base.y - reached.y) < 0.05
        assert not table.contains(base.x, base.y, 0.3)


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_look_park_torso_gripper_and_detect(robot_name):
    with apartment_with(robot_name, {"cup": TABLE}, base_pose=(4.3, 0.9, math.pi / 2)) as (world, robot):
        ready()
        gripper = next(iter(robot.description.GRIPPERS))
        opening = perform(SetGripper(gripper, 1.0))
        assert opening > 0.05
        perform(LookAt("table"))
        seen = perform(Detect("cup"))
        assert [o.type for o in seen] == ["cup"]
        assert math.dist(seen[0].pose[:2], TABLE[1]) < 0.03
        with pytest.raises(ObjectNotVisible, match="milk"):
            perform(Detect("milk"))
        everything = perform(Detect())
        assert {o.type for o in everything} == {"cup"}


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_search_action_finds_an_object_out_of_view(robot_name):
    with apartment_with(robot_name, {"cup": COUNTER}, base_pose=(4.3, 0.9, -math.pi / 2)) as (world, robot):
        found = perform(Search(ObjectDesignator(type="cup")))
        assert found.type == "cup" and math.dist(found.pose[:2], COUNTER[1]) < 0.03


# -- picking up and placing -------------------------------------------------------------------------


#: Every object type and the approach it is picked up with (bowls and plates by the rim from
#: above, the spoon from above across its handle, the cereal box across its narrow side).
APPROACH_OF = {
    "cup": "side",
    "mug": "side",
    "bowl": "top",
    "plate": "top",
    "spoon": "top",
    "cereal": "-y",
    "milk": "-y",
}


def _pick_and_place_cases() -> list:
    return [
        pytest.param(robot_name, type_name, id=f"{type_name}-{robot_name}")
        for robot_name in ROBOTS
        for type_name in APPROACH_OF
    ]


def test_every_object_type_is_covered():
    from pycram.world.objects import OBJECT_TYPES

    assert set(APPROACH_OF) == set(OBJECT_TYPES)


@pytest.mark.parametrize(("robot_name", "type_name"), _pick_and_place_cases())
def test_pick_up_each_graspable_type_and_place_it_on_the_table(robot_name, type_name):
    # "Upright" is as it started: standing, or for the spoon lying flat (tilt < 20 deg).
    with apartment_with(robot_name, {type_name: COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type=type_name)))
        assert isinstance(held, Held) and held.object.type == type_name
        assert held.grasp.approach in (APPROACH_OF[type_name], "+y" if APPROACH_OF[type_name] == "-y" else "")
        assert holding(world) == {type_name}
        assert held_objects() == {held.arm: held}
        obj = perform(Place(held, "table"))
        assert rests_upright_at(world, type_name, "table", obj.pose[:2])
        assert holding(world) == set() and held_objects() == {}


@pytest.mark.parametrize(
    ("robot_name", "type_name", "yaw_deg"),
    [("pr2", "spoon", -60), ("tiago", "spoon", 45), ("pr2", "cereal", 30), ("tiago", "cereal", 160)],
)
def test_a_turned_spoon_or_cereal_box_is_grasped_as_perception_measured_its_turn(robot_name, type_name, yaw_deg):
    # the spoon across its handle, the box across its narrow side: both need the object's turn,
    # which perception measures from the top's longer axis
    yaw = math.radians(yaw_deg)
    with apartment_with(robot_name, {type_name: COUNTER}) as (world, robot):
        x, y = COUNTER[1]
        z = world.environment.surface("counter").height + object_type(type_name).half_height + 0.002
        ok(world.move_item(type_name, (x, y, z), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))))
        ready()
        held = perform(PickUp(ObjectDesignator(type=type_name)))
        assert holding(world) == {type_name}
        assert abs((held.object.yaw - yaw + math.pi / 2) % math.pi - math.pi / 2) < math.radians(10)
        obj = perform(Place(held, "table"))
        assert rests_upright_at(world, type_name, "table", obj.pose[:2])


@pytest.mark.parametrize("type_name", ["bowl", "plate"])
def test_bowls_and_plates_are_picked_up_by_the_rim_from_above_and_placed(type_name):
    with apartment_with("pr2", {type_name: COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type=type_name)))
        assert held.grasp.approach == "top" and holding(world) == {type_name}
        obj = perform(Place(held, "table"))
        assert rests_upright_at(world, type_name, "table", obj.pose[:2])


def test_the_one_armed_tiago_picks_a_bowl_by_the_rim():
    with apartment_with("tiago", {"bowl": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="bowl")))
        assert held.grasp.approach == "top" and holding(world) == {"bowl"}


@pytest.mark.parametrize("robot_name", ROBOTS)
@pytest.mark.parametrize("surface", ["counter", "cabinet top", "cooker #1"])
def test_place_on_each_surface_kind(robot_name, surface):
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup")))
        obj = perform(Place(held, surface))
        assert rests_upright_at(world, "cup", surface, obj.pose[:2])


def test_placing_at_a_location_designator_uses_its_spots():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup")))
        obj = perform(Place(held, on("table", "cup")))
        assert rests_upright_at(world, "cup", "table", obj.pose[:2])


def test_the_pr2_picks_with_the_arm_it_is_asked_for():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup"), arm="left"))
        assert held.arm == "left" and world.gripper_states["left"].get_value().holding == "cup"


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_transport_from_the_counter_to_the_table(robot_name):
    with apartment_with(robot_name, {"cup": COUNTER}) as (world, robot):
        ready()
        obj, task = run_as_task(lambda: perform(Transport(ObjectDesignator(type="cup"), "table")))
        assert rests_upright_at(world, "cup", "table", obj.pose[:2])
        names = [t.name for t in task.walk()]
        for step in ("perform transporting", "search_for", "perform picking_up", "perform placing"):
            assert step in names, names


# -- recovery, forced by faults ---------------------------------------------------------------------


def test_an_object_hidden_by_the_raised_arm_at_the_standing_pose_is_looked_at_with_the_arm_parked():
    # the belief's pose came from a partial view (a sliver of the carton, 3.5 cm off -- measured
    # in set-table seed 37); at the standing pose the TIAGo's gripper, raised to carry, hid the
    # carton from the head, and grasping on the old pose knocked the carton over
    with apartment_with("tiago", {"milk": ("counter", (1.206, 4.478))}) as (world, robot):
        ready()
        milk = perform(Search(ObjectDesignator(type="milk")))
        x, y, z = milk.pose
        milk.pose = (x - 0.035, y, z)
        milk.pose_fluent.set_value(milk.pose)
        with HiddenBehindRaisedArm(world, "milk") as camera:
            held, task = run_as_task(lambda: perform(PickUp(milk)))
        assert camera.hidden >= 1
        assert holding(world) == {"milk"} and held.object is milk
        # the look with the arm parked found the carton 3.5 cm from where the grasp was planned:
        # that attempt gave way to one planned for where it is
        attempts = tasks_named(task, "grasp milk-1")
        assert attempts[0].status.get_value().value == "failed" and "moved" in str(attempts[0].exception)
        assert attempts[-1].status.get_value().value == "succeeded"
        assert abs(milk.pose[0] - x) < 0.015
        assert tilt(world.item_poses.get_value()["milk"].orientation) < math.radians(20)


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_an_object_moved_after_perception_is_perceived_again_and_grasped(robot_name):
    with apartment_with(robot_name, {"cup": COUNTER}) as (world, robot):
        ready()
        cup = perform(Search(ObjectDesignator(type="cup")))
        put(world, "cup", "counter", (COUNTER[1][0] - 0.2, COUNTER[1][1]))  # a person moves it
        held, task = run_as_task(lambda: perform(PickUp(cup)))
        assert holding(world) == {"cup"} and held.object is cup
        attempts = tasks_named(task, "grasp cup-1")
        assert len(attempts) >= 2
        assert attempts[0].status.get_value().value == "failed" and "moved" in str(attempts[0].exception)
        assert attempts[-1].status.get_value().value == "succeeded"


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_an_object_taken_from_the_gripper_is_fetched_again(robot_name):
    with apartment_with(robot_name, {"cup": COUNTER}) as (world, robot):
        ready()
        original = world.item_poses.get_value()["cup"].position
        person = OnceHolding(world, "cup", lambda w: ok(w.take_item(item="cup", to=original)))
        obj, task = run_as_task(lambda: perform(Transport(ObjectDesignator(type="cup"), "table")))
        assert person.join() == "cup"
        assert rests_upright_at(world, "cup", "table", obj.pose[:2])
        rounds = tasks_named(task, "fetch and deliver")
        assert [r.status.get_value().value for r in rounds] == ["failed", "succeeded"]
        assert isinstance(rounds[0].exception, ObjectSlipped)


def test_a_standing_pose_that_cannot_be_reached_gives_way_to_the_next():
    with apartment_with("pr2", {"cup": TABLE}) as (world, robot):
        blocked, free = (3.0, 1.0, 0.0), (2.2, 1.0, 0.0)
        ok(world.place_obstacle(*blocked[:2]))
        poses = LocationDesignator([("named_for_test", "two poses")])
        robot.location_generators.append(lambda d: [blocked, free] if d.prop_value("named_for_test") else None)
        reached, task = run_as_task(lambda: perform(Navigate(poses)))
        assert math.hypot(reached.x - free[0], reached.y - free[1]) < 0.05
        drives = tasks_named(task, "drive to solution")
        assert [d.status.get_value().value for d in drives] == ["failed", "succeeded"]


def test_an_arm_blocked_on_its_way_up_to_drive_gets_up_all_the_same():
    """Where the TIAGo stands to push the cupboard shut, the arm's way up to ``carry_top`` meets
    the cupboard's open door, which the robot has not seen: the first try is blocked (it then
    looks, and the door is in its belief). The arm going up before a pick-up's drive gets there
    all the same: planned round the door now known, or after backing the base away (the faulted
    set-table run of seed 14 failed to pick up the bowl after closing the cupboard)."""
    from pycram.actions.pick_up import _arm_to_drive
    from pycram.robots.tiago.description import ARM_CONFIGURATIONS

    near_cupboard = (4.625, 4.025, 2.949)
    with apartment_with("tiago", {"bowl": COUNTER}, base_pose=near_cupboard) as (world, robot):
        ready()
        with pytest.raises(ProcessModuleFailure, match="blocked"):  # the case this test is for
            perform(MotionDesignator(type="setting_arm_configuration", arm="right", configuration="carry_top"))
        perform(ParkArms())
        run_as_task(lambda: _arm_to_drive("right", "carry_top"))
        joints = world.joint_states.get_value().position
        up = [joints[f"arm_{i}_joint"] for i in range(1, 8)]
        assert max(abs(a - b) for a, b in zip(up, ARM_CONFIGURATIONS["right"]["carry_top"], strict=True)) < 0.05


def test_a_drive_up_to_grasp_refused_with_the_arm_raised_is_driven_again_with_it_tucked():
    """Location reasoning checks a standing pose with the free arms tucked; a pick-up drives up
    with its arm raised to carry. Where that raised arm does not fit (the first drive fails, as
    navigation refuses a goal in collision), the arm is tucked and the base drives again."""
    from pycram.robots.common.sim_modules import NavigationFailed, NavigationModule
    from pycram.robots.pr2.description import ARM_CONFIGURATIONS

    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        module = robot.process_module("navigation")
        drive = module._execute
        arms_at_drives = []

        def refuse_the_first_drive_to_the_counter(designator):
            joints = world.joint_states.get_value().position
            right = [joints[j] for j in world.description.ARMS["right"]["joints"]]
            pose = designator.reference()["pose"]
            if pose.y > 3.5:  # up to the counter, not the start of the search
                arms_at_drives.append(right)
                if len(arms_at_drives) == 1:
                    raise NavigationFailed("drive", "no_path", "goal_in_collision: the robot does not fit at the goal")
            return drive(designator)

        assert isinstance(module, NavigationModule)
        module._execute = refuse_the_first_drive_to_the_counter
        held = perform(PickUp(ObjectDesignator(type="cup"), arm="right"))
        assert holding(world) == {"cup"} and held.arm == "right"
        first, again, *_ = arms_at_drives
        park = ARM_CONFIGURATIONS["right"]["park"]
        assert max(abs(a - b) for a, b in zip(first, park)) > 0.3  # raised the first time
        assert max(abs(a - b) for a, b in zip(again, park)) < 0.05  # tucked the second


# -- typed failures when recovery is impossible ------------------------------------------------------


@pytest.mark.parametrize(("type_name", "tells"), [("milk", "across"), ("cup", "across"), ("cereal", "across")])
def test_perception_tells_a_toppled_object_from_a_standing_one(type_name, tells):
    # milk and cereal by their measured height; the cup (as tall lying as standing) by its
    # footprint seen from above
    with apartment_with("pr2", {type_name: TABLE}) as (world, robot):
        ready()
        obj = perform(Search(ObjectDesignator(type=type_name)))
        assert resting_problem(obj) is None, obj.properties["size"]  # standing
        x, y = TABLE[1]
        lying = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # 90 deg about x
        kind = object_type(type_name)
        height = world.environment.surface("table").height
        lying_height = 2 * kind.size[1] if kind.shape == "box" else kind.lying_height
        ok(world.move_item(type_name, (x, y, height + lying_height / 2 + 0.002), lying))
        perform(LookAt(obj))
        perform(Detect(type_name))
        problem = resting_problem(obj)
        assert problem is not None and problem[0] == "toppled", (problem, obj.properties["size"])
        assert tells in problem[1]


def test_a_look_after_placing_that_misses_the_object_is_taken_again():
    # the first look after letting go misses the cup (a missed detection, as perception faults
    # make them): Place parks the arm, looks again and succeeds -- not PlacingFailed 'not seen'
    from pycram.backends.sim.perception import PerceptionFaults

    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup")))
        original, missed = world.detect, []

        def detect_missing_once(*args, **kwargs):
            if missed or "cup" in holding(world):
                return original(*args, **kwargs)
            saved, world.perception_faults = world.perception_faults, PerceptionFaults(miss_probability=1.0)
            try:
                handle = original(*args, **kwargs)
                report = ok(handle)
            finally:
                world.perception_faults = saved
            missed.append(report)
            return handle

        world.detect = detect_missing_once
        obj = perform(Place(held, "table"))
        assert missed and not any(d.type == "cup" for d in missed[0].detections)
        assert rests_upright_at(world, "cup", "table", obj.pose[:2]) and not obj.gone


def test_looks_after_placing_that_miss_the_object_twice_are_taken_again():
    # the first two looks after letting go miss the cup (missed detections): one missed look
    # is no proof of absence -- Place looks until the belief holds the cup gone, parks the arm
    # and looks again, and succeeds (it raised PlacingFailed 'not seen' after two misses)
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup")))

        def put_down() -> bool:  # let go and low on the table (contacts with a carried cup flicker:
            # "not held" alone was true for a look while driving, measured)
            return "cup" not in holding(world) and world.item_poses.get_value()["cup"].position[2] < 0.85

        with MissingDetections(world, 2, put_down) as camera:
            obj = perform(Place(held, "table"))
        assert camera.missed and not any(d.type == "cup" for r in camera.missed for d in r.detections)
        if camera.missed[0].view.expects_visible(obj.pose):
            # in plain view: a miss the belief counted -- looked again until gone, then again
            # with the arm parked (the third look sees the cup)
            assert len(camera.missed) == 2
        else:
            # the arm in its carry pose hid the cup from the first look (1 run in 3, measured):
            # no miss is counted, the cup stays believed where it was put down
            assert len(camera.missed) == 1
        assert rests_upright_at(world, "cup", "table", obj.pose[:2]) and not obj.gone and obj.misses == 0


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_an_action_looking_at_an_object_looks_again_after_a_missed_detection(robot_name):
    # what PickUp does on arriving at its standing pose and Place after letting go: a look that
    # misses the cup in plain view is taken again, and the cup is still believed there (one
    # look believed it gone, and PickUp searched for it all over again)
    from pycram.actions.handling import _look_again

    with apartment_with(robot_name, {"cup": COUNTER}) as (world, robot):
        ready()
        cup = perform(Search(ObjectDesignator(type="cup")))
        with MissingDetections(world, 1) as camera:
            seen = _look_again(cup)
        assert seen and len(camera.missed) == 1 and camera.looks == 2
        assert not cup.gone and cup.misses == 0
        with MissingDetections(world, 5) as camera:  # not there any more, as far as looks tell
            seen = _look_again(cup)
        assert not seen and cup.gone and camera.looks == robot.belief.misses_to_gone


def test_placing_raises_placing_failed_when_the_object_ends_toppled_over():
    # a person knocks the carton over as soon as the hand has let go and backed off: Place
    # must not report success (the post-condition looks at the measured height)
    with apartment_with("pr2", {"milk": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="milk")))
        person = KnockOverOnceLetGo(world, "milk", held.arm, "table")
        with pytest.raises(PlacingFailed, match="does not rest upright") as raised:
            perform(Place(held, "table"))
        assert raised.value.reason == "toppled"
        assert person.join() is True


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_placing_with_an_empty_gripper_raises_gripper_empty(robot_name):
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        with pytest.raises(GripperEmpty, match="no gripper holds"):
            perform(Place(ObjectDesignator(type="cup"), "counter"))


def test_an_object_taken_while_placing_raises_object_slipped():
    with apartment_with("tiago", {"cup": COUNTER}) as (world, robot):
        ready()
        held = perform(PickUp(ObjectDesignator(type="cup")))
        person = OnceHolding(world, "cup", lambda w: ok(w.take_item(item="cup")))
        with pytest.raises(ObjectSlipped, match="fell out|no longer"):
            perform(Place(held, "table"))
        person.join()
        # the gripper holds nothing any more, and the cup is not where it was picked up
        assert held_objects() == {} and held.object.gone


def test_an_object_taken_for_good_ends_the_transport_with_object_not_found():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        ready()
        person = OnceHolding(world, "cup", lambda w: ok(w.take_item(item="cup")))
        with pytest.raises(ObjectNotFound, match="looked at"):
            perform(Transport(ObjectDesignator(type="cup"), "table"))
        person.join()


def test_an_object_out_of_reach_raises_object_out_of_reach():
    with apartment_with("tiago", {"cup": ("counter", (1.0, 4.9))}) as (world, robot):  # deep on the counter
        ready()
        with pytest.raises(ObjectOutOfReach, match="no standing pose"):
            perform(PickUp(ObjectDesignator(type="cup")))


def test_a_grasp_the_type_does_not_have_raises_grasp_failed():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        # a cup has a side grasp and (for drawers) one from the top, no directional one
        with pytest.raises(GraspFailed, match=r"cannot execute a grasp \+x of a cup \(its grasps: side, top") as caught:
            perform(PickUp(ObjectDesignator(type="cup"), grasp="+x"))
        assert caught.value.reason == "no_executable_grasp"


def test_an_occupied_goal_raises_goal_unreachable():
    with apartment_with("tiago", {"cup": TABLE}) as (world, robot):
        ok(world.place_obstacle(3.0, 1.0))
        with pytest.raises(GoalUnreachable) as caught:
            perform(Navigate((3.0, 1.0, 0.0)))
        assert isinstance(caught.value, PlanFailure) and caught.value.reason in ("goal_in_collision", "no_path")


def test_bad_parameters_are_named():
    with apartment_with("pr2", {"cup": TABLE}) as (world, robot):
        with pytest.raises(ActionParameterError, match=r"picking_up: parameter 'arm'.*valid: .*left"):
            perform(PickUp(ObjectDesignator(type="cup"), arm="third"))
        with pytest.raises(ActionParameterError, match="placing: parameter 'target'"):
            perform(Place(ObjectDesignator(type="cup"), None))
        with pytest.raises(ActionParameterError, match="searching: parameter 'object'"):
            perform(Search(42))
