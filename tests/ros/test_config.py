"""ROS configuration as data, and the checks that need no ROS installation."""

from __future__ import annotations

import pytest

from pycram.backends.ros.config import ROBOT_CONFIGS, config_from_dict, robot_config
from pycram.backends.ros.launch import check_master_uri


def test_pr2_defaults_are_the_pr2s_real_interface_names():
    c = robot_config("pr2")
    assert c.move_base_action == "move_base"
    assert c.head_action == "/head_traj_controller/point_head_action"
    assert c.arms["right"].trajectory_action == "/r_arm_controller/follow_joint_trajectory"
    assert c.grippers["right"].action == "/r_gripper_controller/gripper_action"
    assert c.torso_action == "/torso_controller/position_joint_action"
    assert (c.pose_topic, c.joint_states_topic) == ("/amcl_pose", "/joint_states")
    assert c.arms["left"].joint_names[0] == "l_shoulder_pan_joint"


@pytest.mark.parametrize("robot", sorted(ROBOT_CONFIGS))
def test_configured_joints_are_the_descriptions_joints(robot):
    import importlib

    description = importlib.import_module(f"pycram.robots.{robot}.description")
    config = robot_config(robot)
    assert set(config.arms) == set(description.ARMS)
    for arm, interface in config.arms.items():
        assert interface.joint_names == tuple(description.ARMS[arm]["joints"])
    assert set(config.grippers) == set(description.GRIPPERS)
    assert config.torso_joint == description.TORSO["joint"]


def test_every_action_has_a_type_and_names_are_unique():
    for config in ROBOT_CONFIGS.values():
        actions = config.actions()
        assert len(actions) == 3 + 2 * len(config.arms) + len(config.grippers)


def test_config_from_dict_overrides_and_names_unknown_keys():
    config = config_from_dict({"robot": "pr2", "move_base_action": "/nav_pcontroller/move_base"})
    assert config.move_base_action == "/nav_pcontroller/move_base"  # the thesis' controller
    assert config.head_action == robot_config("pr2").head_action
    assert config_from_dict(config.to_dict()) == config
    with pytest.raises(ValueError, match="unknown ROS configuration keys \\['move_bas'\\]"):
        config_from_dict({"robot": "pr2", "move_bas": "x"})
    with pytest.raises(ValueError, match="available: pr2, tiago"):
        robot_config("r2d2")
    with pytest.raises(ValueError, match="torso_interface"):
        robot_config("pr2").replace(torso_interface="hydraulic")


def test_master_uri_must_be_on_loopback_unless_allowed():
    assert check_master_uri("http://127.0.0.1:11311") == "http://127.0.0.1:11311"
    with pytest.raises(ValueError, match="not on loopback"):
        check_master_uri("http://10.0.0.5:11311")
    assert check_master_uri("http://10.0.0.5:11311", allow_remote=True)
    with pytest.raises(ValueError, match="not set"):
        check_master_uri(None)
    with pytest.raises(ValueError, match="http://HOST:PORT"):
        check_master_uri("10.0.0.5")


def test_demo_refuses_an_unknown_backend():
    from pycram.apps.demos.kitchen import DemoOptions, run_demo

    with pytest.raises(ValueError, match="--backend must be 'sim' or 'ros', not 'ros2'"):
        run_demo(DemoOptions(backend="ros2", record=False))


def test_pycram_ros_imports_without_rospy():
    import subprocess
    import sys

    code = (
        "import sys; import pycram.ros, pycram.backends.ros.transport, pycram.backends.ros.config, "
        "pycram.backends.ros.launch; "
        "assert 'rospy' not in sys.modules, 'rospy imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_bridge_cli_refuses_an_unknown_robot_and_a_remote_master(monkeypatch, capsys):
    from pycram.apps.cli import main

    monkeypatch.setenv("ROS_MASTER_URI", "http://127.0.0.1:11311")
    assert main(["sim-ros-bridge", "--robot", "r2d2"]) == 2
    assert "--robot must be 'pr2' or 'tiago', not 'r2d2'" in " ".join(capsys.readouterr())
    monkeypatch.setenv("ROS_MASTER_URI", "http://10.1.2.3:11311")
    assert main(["sim-ros-bridge", "--robot", "pr2"]) == 2
    assert "not on loopback" in " ".join(capsys.readouterr())
    monkeypatch.delenv("ROS_MASTER_URI")
    assert main(["sim-ros-bridge"]) == 2
    assert "ROS_MASTER_URI is not set" in " ".join(capsys.readouterr())


def test_bridge_objects_and_base_pose_are_parsed_with_clear_errors():
    from pycram.apps.cli.ros import _base_pose, object_items

    cup, other, box = object_items(["cup@1.0,4.55", "cup@2,3", "cereal@4.1,1.8,0.9"])
    assert (cup.name, cup.type, cup.position) == ("cup", "cup", (1.0, 4.55, None))  # on the surface there
    assert other.name == "cup-2"
    assert box.position == (4.1, 1.8, 0.9)
    with pytest.raises(ValueError, match="TYPE one of .*cup"):
        object_items(["teapot@1,2"])
    with pytest.raises(ValueError, match="X,Y or X,Y,Z"):
        object_items(["cup@1"])
    with pytest.raises(ValueError, match="X,Y or X,Y,Z"):
        object_items(["cup@1,nan"])
    assert _base_pose("4.3,1.15,1.57") == (4.3, 1.15, 1.57)
    with pytest.raises(ValueError, match="X,Y,YAW"):
        _base_pose("4.3,1.15")
