"""The robot description schema and the robot registry: validation messages and lookups."""

from __future__ import annotations

import importlib

import pytest

from pycram.world.errors import UnknownNameError
from pycram.world.robot_description import RobotDescription, RobotDescriptionError
from pycram.world.robot_registry import (
    UnknownRobotError,
    robot_description,
    robot_names,
    robot_package,
)


def _data(robot: str = "pr2") -> dict:
    module = importlib.import_module(f"{robot_package(robot)}.description")
    return {k: v for k, v in vars(module).items() if k.isupper() and not k.startswith("_")}


def test_the_registry_lists_the_robots_of_the_entry_points():
    assert robot_names() == ("pr2", "tiago", "tiago-pro")
    assert robot_package("pr2") == "pycram.robots.pr2"
    assert robot_package("tiago") == "pycram.robots.tiago"


@pytest.mark.parametrize("robot", ["pr2", "tiago"])
def test_each_registered_description_validates_and_mirrors_its_module(robot):
    description = robot_description(robot)
    assert isinstance(description, RobotDescription)
    assert description is robot_description(robot)  # validated once, cached
    assert description.NAME == robot
    for key, value in _data(robot).items():
        if key == "HEAD" and "camera_link" not in value:  # read from the URDF: a copy, with it
            assert description.HEAD == {**value, "camera_link": description.HEAD["camera_link"]}
            continue
        assert getattr(description, key) is value  # the module's own objects
    with pytest.raises(AttributeError):
        description.NAME = "r2d2"  # type: ignore[misc]


def test_optional_keys_take_their_defaults():
    data = _data("pr2")
    for key in ("DEFAULT_ARM", "ARM_ALIASES", "DOOR_PUSH", "GRASP_CONTACT_MARGIN", "FINGERTIP_REACH", "ROS"):
        data.pop(key)
    description = RobotDescription.from_mapping(data)
    assert description.DEFAULT_ARM == "right"  # the first arm
    assert description.ARM_ALIASES == {"right": "right", "left": "left"}
    assert description.DOOR_PUSH is None and description.GRIPPER_MODEL is None and description.ROS is None
    assert description.DOOR_PULL_LIMIT is None and description.DOOR_GRIP_OPENING is None
    assert description.GRASP_CONTACT_MARGIN == 0.0 and description.FINGERTIP_REACH == 0.0
    assert robot_description("tiago").GRIPPER_MODEL is not None


def test_a_missing_key_is_named_with_the_robot_and_the_required_keys():
    data = _data("tiago")
    del data["URDF"]
    with pytest.raises(RobotDescriptionError, match=r"robot description of 'tiago': missing key 'URDF'") as info:
        RobotDescription.from_mapping(data, source="pycram.robots.tiago.description")
    assert "(in pycram.robots.tiago.description)" in str(info.value)
    assert "required keys: NAME, URDF, ROOT_LINK, BASE" in str(info.value)
    assert (info.value.robot, info.value.key) == ("tiago", "URDF")
    assert isinstance(info.value, ValueError)


def test_an_unknown_key_is_named_with_the_valid_keys():
    data = {**_data("pr2"), "ARM_JOINT_SUFFIXES": ("shoulder_pan_joint",)}
    with pytest.raises(
        RobotDescriptionError, match=r"robot description of 'pr2': unknown key 'ARM_JOINT_SUFFIXES'"
    ) as info:
        RobotDescription.from_mapping(data)
    message = str(info.value)
    assert "valid keys: NAME, URDF, ROOT_LINK" in message
    for key in RobotDescription.keys():
        assert key in message
    assert info.value.key == "ARM_JOINT_SUFFIXES"


def test_malformed_arms_and_grippers_are_named():
    data = _data("pr2")
    arms = {**data["ARMS"], "right": {**data["ARMS"]["right"], "gripper": "middle"}}
    with pytest.raises(
        RobotDescriptionError, match=r"ARMS: arm 'right': gripper 'middle' is none of the grippers: right, left"
    ):
        RobotDescription.from_mapping({**data, "ARMS": arms})
    arms = {**data["ARMS"], "left": {"joints": data["ARMS"]["left"]["joints"], "tool_link": "l_gripper_tool_frame"}}
    with pytest.raises(
        RobotDescriptionError, match=r"arm 'left' lacks 'gripper'; keys of an arm: joints, tool_link, gripper"
    ):
        RobotDescription.from_mapping({**data, "ARMS": arms})
    grippers = {**data["GRIPPERS"], "left": {**data["GRIPPERS"]["left"], "stroke": 0.1}}
    with pytest.raises(
        RobotDescriptionError, match=r"GRIPPERS: gripper 'left' has the unknown key 'stroke'; valid: joint,"
    ):
        RobotDescription.from_mapping({**data, "GRIPPERS": grippers})
    with pytest.raises(RobotDescriptionError, match=r"DEFAULT_ARM: 'middle' is no arm; arms: right, left"):
        RobotDescription.from_mapping({**data, "DEFAULT_ARM": "middle"})


def test_an_unknown_robot_name_lists_the_registered_robots():
    with pytest.raises(UnknownRobotError, match=r"robot 'r2d2' does not exist. Available: pr2, tiago"):
        robot_description("r2d2")
    with pytest.raises(UnknownNameError, match="Available: pr2, tiago"):
        robot_package("r2d2")
    with pytest.raises(ValueError, match="Available: pr2, tiago"):
        robot_description("r2d2")
