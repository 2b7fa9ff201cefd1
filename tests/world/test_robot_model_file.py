"""What a robot description may leave to its URDF (pycram.world.robot_model_file): an arm's
joints from the link its chain starts at, a gripper's joints and range from the hand below it."""

from __future__ import annotations

import pytest

from pycram.world.robot_description import RobotDescription, RobotDescriptionError
from pycram.world.robot_model_file import ModelFileError, infer_from_model, read_urdf
from pycram.world.robot_registry import robot_description

pr2 = robot_description("pr2")
GRIPPER_FROM_FILE = ("joint", "coupled_joints", "joint_range")


def _pr2_from_file(root_link: str = "torso_lift_link") -> dict:
    """The PR2's description with its arms' joints and grippers' joints left to the URDF."""
    data = {k: getattr(pr2, k) for k in RobotDescription.keys()}
    data["ARMS"] = {
        arm: {"root_link": root_link, "tool_link": spec["tool_link"], "gripper": spec["gripper"]}
        for arm, spec in pr2.ARMS.items()
    }
    data["GRIPPERS"] = {
        g: {k: v for k, v in spec.items() if k not in GRIPPER_FROM_FILE} for g, spec in pr2.GRIPPERS.items()
    }
    return data


def test_arm_joints_are_the_movable_joints_from_the_root_link_to_the_tool():
    described = RobotDescription.from_mapping(_pr2_from_file())
    for arm in ("left", "right"):
        assert described.ARMS[arm]["joints"] == pr2.ARMS[arm]["joints"]  # as the PR2 states them


def test_a_gripper_is_its_one_driven_joint_its_mimics_and_its_limits():
    right = RobotDescription.from_mapping(_pr2_from_file()).GRIPPERS["right"]
    assert right["joint"] == pr2.GRIPPERS["right"]["joint"]
    assert set(pr2.GRIPPERS["right"]["coupled_joints"]) <= set(right["coupled_joints"])
    assert right["joint_range"] == pytest.approx(pr2.GRIPPERS["right"]["joint_range"], abs=1e-3)


def test_a_description_that_states_everything_is_not_changed():
    data = {k: getattr(pr2, k) for k in RobotDescription.keys()}
    assert infer_from_model(data, "pr2")["ARMS"] is pr2.ARMS


def test_a_root_link_not_above_the_tool_names_the_links_that_are():
    with pytest.raises(RobotDescriptionError, match=r"ARMS: arm '\w+': link 'head_pan_link' is not above .*r_forearm"):
        data = _pr2_from_file("head_pan_link")
        data["ARMS"] = {"right": data["ARMS"]["right"]}
        data["GRIPPERS"] = {"right": data["GRIPPERS"]["right"]}
        data["ARM_CONFIGURATIONS"] = {"right": pr2.ARM_CONFIGURATIONS["right"]}
        data["REACH_POINT_IN_BASE"] = {"right": pr2.REACH_POINT_IN_BASE["right"]}
        data["ARM_ALIASES"] = {"right": "right"}
        data["GRIPPER_ALIASES"] = {"right": "right"}
        RobotDescription.from_mapping(data)


def test_an_unknown_link_and_a_missing_file_are_named():
    with pytest.raises(RobotDescriptionError, match="has no link 'no_such_link'"):
        RobotDescription.from_mapping(_pr2_from_file("no_such_link"))
    with pytest.raises(ModelFileError, match="'robots/none.urdf' not found"):
        read_urdf("robots/none.urdf")


def test_a_robot_with_a_gripper_of_its_own_ends_its_chain_at_the_mount():
    tiago = robot_description("tiago")
    data = {k: getattr(tiago, k) for k in RobotDescription.keys()}
    data["ARMS"] = {"right": {"root_link": "torso_lift_link", "tool_link": "gripper_tool_link", "gripper": "right"}}
    assert RobotDescription.from_mapping(data).ARMS["right"]["joints"] == tiago.ARMS["right"]["joints"]


def test_the_camera_link_is_read_from_the_urdf_where_it_tells_and_named_where_it_does_not():
    from pycram.world.robot_model_file import camera_link
    from pycram.world.robot_registry import robot_description

    tiago = read_urdf("robots/tiago_description/robots/tiago_no_hand.urdf")
    # three cameras carry optical frames (xtion, its depth and its colour camera): the colour one
    assert camera_link(tiago, "head_2_joint") == "xtion_rgb_frame"
    pro = read_urdf("robots/tiago_pro_description/robots/tiago_pro.urdf")
    assert camera_link(pro, "head_2_joint") == "head_front_camera_link"  # no optical frames: by name
    # the descriptions that leave it out get the same link the simulator mounts its camera on
    assert robot_description("tiago").HEAD["camera_link"] == "xtion_rgb_frame"
    assert robot_description("tiago-pro").HEAD["camera_link"] == "head_front_camera_link"
    pr2 = read_urdf("robots/pr2_description/urdf/pr2.urdf")
    with pytest.raises(ModelFileError, match=r"cannot tell the camera.*high_def_frame.*state 'camera_link'"):
        camera_link(pr2, "head_tilt_joint")
    with pytest.raises(ModelFileError, match="no joint 'head_3_joint'"):
        camera_link(tiago, "head_3_joint")


def test_a_description_without_a_camera_link_whose_urdf_does_not_tell_names_the_key():
    from pycram.world.robot_description import RobotDescription, RobotDescriptionError
    from pycram.world.robot_registry import robot_description

    pr2 = robot_description("pr2")
    data = {k: getattr(pr2, k) for k in RobotDescription.keys()}
    data["HEAD"] = {k: v for k, v in pr2.HEAD.items() if k != "camera_link"}
    with pytest.raises(RobotDescriptionError, match=r"HEAD.*cannot tell the camera.*wide_stereo_link"):
        RobotDescription.from_mapping(data)
