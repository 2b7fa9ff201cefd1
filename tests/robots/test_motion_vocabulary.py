"""Bad motion designators get a clear error before anything moves (issue 12, points 4 and 6).

The simulated robots declare their motion vocabulary as data (``robot.motion_types``); a
designator with a missing, misspelled or invalid key, an unknown type, a non-finite value or a
goal outside the environment is refused with an error naming the type, the key and the valid
choices -- in the caller's thread, before a process module is asked to move. Each test runs on a
real :class:`pycram.sim.World`; waits are bounded by simulated time.
"""

from __future__ import annotations

import math

import pytest

pytest.importorskip("mujoco")

from pycram.designator import (  # noqa: E402
    GoalOutsideEnvironment,
    LocationDesignator,
    MotionDesignator,
    MotionPropertyError,
    NoSolutionError,
    PropertyError,
    ResolverError,
    perform,
)
from pycram.designators.motion_types import vocabulary_table  # noqa: E402
from pycram.language import pursue  # noqa: E402
from pycram.process_module import NoProcessModuleError, ProcessModuleStatus, UnknownMotionTypeError  # noqa: E402
from pycram.robot import current_robot  # noqa: E402
from pycram.runtime import sleep  # noqa: E402

T = 60.0  # [s of simulated time]
START = (0.8, 0.6, 0.0)


def refused(error_type, **properties):
    """Perform a motion that must be refused at once: return the error; assert nothing moved
    and no process module was asked (all still idle, nothing queued)."""
    robot = current_robot()
    before = robot.world.base_pose.get_value()
    statuses = {name: m.status.get_value() for name, m in robot.process_modules.items()}
    outcome = {}

    def attempt():
        try:
            perform(MotionDesignator(**properties))
        except Exception as e:  # noqa: BLE001 - inspected below
            outcome["error"] = e

    pursue(attempt, lambda: sleep(T))  # bounded: a hang (today's NaN drive) fails the test
    error = outcome.get("error")
    assert isinstance(error, error_type), f"expected {error_type.__name__}, got {error!r}"
    after = robot.world.base_pose.get_value()
    assert math.hypot(after.x - before.x, after.y - before.y) < 1e-3
    assert {n: m.status.get_value() for n, m in robot.process_modules.items()} == statuses
    assert all(m.queue_length == 0 for m in robot.process_modules.values())
    return error


# --------------------------------------------------------------------------- keys and types


def test_misspelled_key_names_key_type_and_valid_keys(robot):
    error = refused(MotionPropertyError, type="moving", pos=(1.0, 0.5, 0.0))
    message = str(error)
    assert "type 'moving'" in message and "unknown key 'pos'" in message
    assert "did you mean 'pose'?" in message
    assert "valid keys of 'moving': pose (required), frame, wait" in message
    assert error.key == "pos" and error.motion_type == "moving"
    assert {"pose", "frame", "wait"} <= set(error.valid_keys)
    assert isinstance(error, PropertyError)


def test_missing_required_key_names_it(robot):
    error = refused(MotionPropertyError, type="setting_gripper", gripper="right")
    message = str(error)
    assert "type 'setting_gripper'" in message
    assert "missing the required key 'position' (fraction open: 0 closed, 1 fully open)" in message
    assert "gripper (required), position (required), max_effort, wait" in message
    error = refused(MotionPropertyError, type="moving")
    assert "missing the required key 'pose'" in str(error)


def test_invalid_value_lists_the_valid_values_of_this_robot(robot):
    configurations = sorted({c for per_arm in robot.description.ARM_CONFIGURATIONS.values() for c in per_arm})
    error = refused(MotionPropertyError, type="setting_arm_configuration", arm="right", configuration="wave")
    assert ", ".join(repr(c) for c in configurations) in str(error) and "got 'wave'" in str(error)
    error = refused(MotionPropertyError, type="setting_torso", position=2.0)
    low, high = robot.description.TORSO["range"]
    assert f"'down', 'up' or a number in [{low:g}, {high:g}]" in str(error)
    error = refused(MotionPropertyError, type="reaching", arm="middle", target=(0.1, -1.1, 1.0))
    assert "key 'arm'" in str(error) and "'left'" in str(error) and "'right'" in str(error)


def test_unknown_type_lists_the_known_types_of_the_active_robot(robot):
    error = refused(UnknownMotionTypeError, type="movign", pose=START)
    message = str(error)
    assert "unknown motion type 'movign'" in message and "did you mean 'moving'?" in message
    assert f"known motion types of active robot {robot.name!r}:" in message
    for known in ("moving", "reaching", "setting_gripper", "detecting", "pointing_head"):
        assert known in message and known in error.known_types
    assert isinstance(error, NoProcessModuleError)
    error = refused(MotionPropertyError, pose=START)
    assert "has no 'type'" in str(error) and "moving" in str(error)


def test_resolving_a_bad_designator_directly_gives_the_same_error(robot):
    with pytest.raises(MotionPropertyError, match="unknown key 'pos'"):
        MotionDesignator(type="moving", pos=START).reference()
    with pytest.raises(NoSolutionError, match="known motion types of active robot"):
        MotionDesignator(type="movign").reference()


def test_the_vocabulary_table_documents_every_type_and_key(robot):
    table = vocabulary_table(robot.motion_types)
    for name, motion_type in robot.motion_types.items():
        assert f"| `{name}` |" in table
        for key in motion_type.keys:
            assert f"| `{key.name}` |" in table
    assert "[rad]" in table and "[m]" in table and "'pre_grasp'" in table


# --------------------------------------------------------------------------- absurd goals


@pytest.mark.parametrize(
    "properties,key",
    [
        (dict(type="moving", pose=(math.nan, 0.5, 0.0)), "pose"),
        (dict(type="moving", pose=(1.0, math.inf, 0.0)), "pose"),
        (dict(type="pointing_head", coordinates=(1.0, math.nan, 1.0)), "coordinates"),
        (dict(type="reaching", arm="right", target=(math.inf, 0.0, 1.0)), "target"),
        (dict(type="setting_arm_joints", arm="right", positions=[math.nan] * 7), "positions"),
        (dict(type="setting_gripper", gripper="right", position=math.nan), "position"),
    ],
)
def test_non_finite_goals_are_refused_before_anything_moves(robot, properties, key):
    error = refused(MotionPropertyError, **properties)
    assert f"key {key!r}" in str(error) and ("finite" in str(error) or "number in" in str(error))
    assert error.key == key


@pytest.mark.parametrize(
    "pose,frame",
    [
        ((100.0, 0.0, 0.0), "map"),
        ((1e9, 1e9, 0.0), None),
        ((50.0, 0.0, 0.0), "base_footprint"),
        ((0.8, -1.3, 0.0), "map"),
    ],
)  # inside the back counter
def test_goals_outside_the_environment_are_refused(robot, pose, frame):
    properties = dict(type="moving", pose=pose)
    if frame is not None:
        properties["frame"] = frame
    error = refused(GoalOutsideEnvironment, **properties)
    assert "is outside the environment" in str(error)
    assert "x in [-0.45, 3] m, y in [-0.9, 3.5] m" in str(error)
    assert error.key == "pose"


def test_a_goal_on_the_free_floor_still_drives(robot):
    reached = perform(MotionDesignator(type="moving", pose=(1.2, 0.6, 0.0)))
    assert abs(reached.x - 1.2) < 0.03
    perform(MotionDesignator(type="moving", pose=START))
    assert robot.process_module("navigation").status.get_value() is ProcessModuleStatus.SUCCEEDED


def test_to_reach_outside_the_environment_says_why(robot):
    designator = LocationDesignator([("to_reach", (10, 10, 1))])
    with pytest.raises(NoSolutionError) as info:
        designator.reference()
    message = str(info.value)
    assert not isinstance(info.value, ResolverError)
    assert "(10.0, 10.0, 1.0) [m, map] is outside the environment" in message
    assert "no cell of the floor of thesis-kitchen lies within the layer 'reach'" in message
    assert info.value.designator is designator
    assert list(designator.solutions()) == []
    # a point on the counter still resolves to a base pose on the free floor (torso up, as a
    # plan raises it before reaching)
    perform(MotionDesignator(type="setting_torso", position="up"))
    pose = LocationDesignator([("to_reach", (0.1, -1.15, 0.95))]).reference()
    assert -0.45 <= pose.x <= 3.0 and -0.9 <= pose.y <= 3.5
