"""Location reasoning judged by the simulator: the solutions really work.

- every ``to_reach`` solution tried lets the robot grasp the object (drive there, pre-grasp,
  grasp, close, lift: the object is held and lifted), for several random apartment scenes, both
  robots (two arms: PR2; one arm: TIAGo);
- ``to_see`` solutions show the object in the head camera's segmentation;
- ``on`` spots hold the object upright where it was put;
- ``NoSolutionError`` says which constraint ruled the candidates out.

Simulator truth (item poses, segmentation) is used only to judge; the reasoning gets the objects
as believed objects (name, type, pose).
"""

from __future__ import annotations

import math

import pytest

pytest.importorskip("mujoco")
prospection = pytest.importorskip("pycram.world.prospection")

import mujoco  # noqa: E402
from sim_helpers import settle, tilt  # noqa: E402

from pycram import robots  # noqa: E402
from pycram.designator import LocationDesignator, MotionDesignator, perform  # noqa: E402
from pycram.designators.core import NoSolutionError  # noqa: E402
from pycram.locations import KnownObject, Spot  # noqa: E402
from pycram.sim import World  # noqa: E402
from pycram.world.objects import object_type  # noqa: E402

T = 60.0
#: (robot, seed, object): scenes of `random_scene(apartment, ["cup", "milk", "bowl"], seed)` with
#: the object on the counter (0.22 m deep: seed 3; milk, a directional grasp: seed 13) or the
#: table (seed 9); the bowl, grasped at its rim from the top, on the counter (seeds 5, 8).
GRASPS = [
    ("pr2", 3, "cup"),
    ("pr2", 9, "cup"),
    ("pr2", 13, "milk"),
    ("tiago", 9, "cup"),
    ("tiago", 13, "milk"),
    ("pr2", 5, "bowl"),
    ("pr2", 8, "bowl"),
    ("tiago", 8, "bowl"),
]


def motion(**properties):
    return perform(MotionDesignator(**properties))


def believed(world, name):
    """The object `name` as the robot believes it (here: as it is, put into the active robot's
    belief as if perceived -- prospection knows only believed objects; a test judges with truth)."""
    from pycram.robot import current_robot
    from pycram.world.belief import PerceivedObject

    pose = world.item_poses.get_value()[name]
    w, x, y, z = pose.orientation
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    item = world.scene.item(name)
    current_robot().belief.add(PerceivedObject(name, item.type, tuple(pose.position)))
    return KnownObject(name, item.type, tuple(pose.position), yaw)


@pytest.fixture(params=["pr2", "tiago"])
def robot_name(request):
    return request.param


def make(robot_name, seed, objects=("cup", "milk", "bowl")):
    world = World(robot_name, environment="apartment", seed=seed, objects=list(objects))
    return world, robots.load(robot_name, world)


@pytest.mark.parametrize("robot_name,seed,name", GRASPS)
def test_to_reach_solutions_let_the_robot_grasp_the_object(robot_name, seed, name):
    world, robot = make(robot_name, seed)
    try:
        with robot:
            d = robot.description
            motion(type="setting_torso", position="up")
            target = believed(world, name)
            location = LocationDesignator([("to_reach", target)]).reference()
            assert location.arm in d.ARMS and location.grasp in [g.approach for g in object_type(name).grasps]
            gripper = d.ARMS[location.arm]["gripper"]
            motion(type="setting_gripper", gripper=gripper, position=1)
            # as the demo does: the arm is raised over the furniture before the base gets close
            motion(type="setting_arm_configuration", arm=location.arm, configuration="carry")
            reached = motion(type="moving", pose=location)
            assert math.hypot(reached.x - location.x, reached.y - location.y) < 0.03
            otype = object_type(name)
            grasp = next(g for g in otype.grasps if g.approach == location.grasp)
            x, y, z = target.position
            point = (x, y, z - otype.half_height + grasp.height)
            for index, phase in enumerate(("pre_grasp", "grasp", "lift")):
                if phase == "lift":
                    motion(type="setting_gripper", gripper=gripper, position=0)
                    assert world.gripper_states[gripper].get_value().holding == name
                if location.grasp == "top":  # the tool follows the validated poses, pointing down
                    position, orientation = location.tool_poses[index]
                    motion(
                        type="reaching",
                        arm=location.arm,
                        target=list(position),
                        orientation=list(orientation),
                        phase=phase,
                    )
                else:
                    motion(type="reaching", arm=location.arm, target=point, phase=phase)
            assert world.item_poses.get_value()[name].position[2] > z + 0.05
    finally:
        robot.shutdown()
        world.close()


@pytest.mark.parametrize("seed", [3, 4])
def test_a_grasp_held_from_above_is_solved_near_the_configuration_it_is_carried_in(seed):
    """The TIAGo Pro comes to a plate with its arm in ``carry_top`` and carries it there:
    location reasoning solves the grasp from there, so the lift's joints lie near it (from the
    side ``carry`` they came out with the wrist turned the other way round, 2.9 rad from it,
    and the way to ``carry_top`` swung a plate 0.55 m sideways into a milk carton)."""
    world, robot = make("tiago-pro", seed, objects=("plate",))
    try:
        with robot:
            motion(type="setting_torso", position="up")
            location = LocationDesignator([("to_reach", believed(world, "plate"))]).reference()
            assert location.grasp == "top"
            carry_top = robot.description.ARM_CONFIGURATIONS[location.arm]["carry_top"]
            lift = location.joints[-1]
            assert max(abs(a - b) for a, b in zip(lift, carry_top)) < 2.0
    finally:
        robot.shutdown()
        world.close()


def test_an_object_out_of_reach_says_so():
    world, robot = make("tiago", 1)  # the cup stands 0.46 m deep on the counter
    try:
        with robot:
            motion(type="setting_torso", position="up")
            with pytest.raises(NoSolutionError, match=r"\d+ candidates: .*unreachable for arm 'right'"):
                LocationDesignator([("to_reach", believed(world, "cup"))]).reference()
    finally:
        robot.shutdown()
        world.close()


def test_to_see_solutions_show_the_object_in_the_head_camera(robot_name):
    world, robot = make(robot_name, 1)
    try:
        with robot:
            motion(type="setting_torso", position="up")
            solutions = LocationDesignator([("to_see", believed(world, "cup"))]).solutions()
            for location, _ in zip(solutions, range(2)):
                assert location.visible >= 0.5
                motion(type="moving", pose=location)
                cup = world.item_poses.get_value()["cup"].position
                motion(type="pointing_head", coordinates=cup)
                outcome = world.request_segmentation().wait(T)
                assert outcome is not None and outcome.succeeded, outcome
                ids = outcome.value
                cup_geoms = {
                    g
                    for g in range(world.scene.model.ngeom)
                    if (mujoco.mj_id2name(world.scene.model, mujoco.mjtObj.mjOBJ_GEOM, g) or "").split(":")[0] == "cup"
                }
                pixels = int(sum((ids == g).sum() for g in cup_geoms))
                assert pixels >= 20, f"the cup covers only {pixels} pixels seen from {location}"
    finally:
        robot.shutdown()
        world.close()


def test_on_spots_hold_the_object_upright(robot_name):
    world, robot = make(robot_name, 1)  # milk and bowl stand on the table
    try:
        with robot:
            # the robot knows the objects on the table only by looking at them
            table = world.environment.surface("table")
            centre = (
                sum(p[0] for p in table.polygon) / len(table.polygon),
                sum(p[1] for p in table.polygon) / len(table.polygon),
                table.height,
            )
            motion(type="moving", pose=LocationDesignator([("to_see", centre)]).reference())
            motion(type="pointing_head", coordinates=centre)
            motion(type="detecting")
            assert {"milk", "bowl"} <= {obj.type for obj in robot.belief.objects()}
            spots = LocationDesignator([("on", "table"), ("for", "cup"), ("near", believed(world, "milk"))])
            for spot, _ in zip(spots.solutions(), range(3)):
                assert isinstance(spot, Spot) and spot.surface == "table"
                outcome = world.move_item("cup", spot.position).wait(T)
                assert outcome is not None and outcome.succeeded
                settle(world, 1.0)
                poses = world.item_poses.get_value()
                cup = poses["cup"]
                assert tilt(cup.orientation) < math.radians(5)
                assert math.dist(cup.position, spot.position) < 0.01
                for other in ("milk", "bowl"):  # nothing was pushed away
                    assert tilt(poses[other].orientation) < math.radians(5)
    finally:
        robot.shutdown()
        world.close()


def test_no_solution_error_names_the_ruling_constraint(robot_name):
    world, robot = make(robot_name, 0, objects=())
    try:
        with robot:
            # a point inside the closed drawer cabinet: nothing reaches it
            designator = LocationDesignator([("to_reach", (0.3, 2.9, 0.2))])
            with pytest.raises(NoSolutionError) as info:
                designator.reference()
            message = str(info.value)
            assert "candidates:" in message
            assert "unreachable for arm 'right'" in message or "in collision" in message, message
            # a container the object does not fit in
            with pytest.raises(NoSolutionError, match=r"cereal \(0.28 m tall\) fits on none of"):
                LocationDesignator([("in", "drawer 1"), ("for", "cereal")]).reference()
    finally:
        robot.shutdown()
        world.close()
