"""Every ROS process module against the simulator bridge (real roscore, real bridge process)."""

from __future__ import annotations

import math

import pytest

from pycram.designator import MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.process_module import ProcessModuleFailure


def motion(**properties):
    return perform(MotionDesignator(**properties))


def test_torso_moves_and_joint_states_follow(ros_robot):
    low, high = ros_robot.description.TORSO["range"]
    target = round(low + 0.5 * (high - low), 3)
    assert motion(type="setting_torso", position=target) == pytest.approx(target)
    joint = ros_robot.config.torso_joint
    settled = Fluent(lambda: True if abs(ros_robot.state.joint_states.get_value()[joint] - target) < 0.01 else None)
    ros_robot.state.joint_states.add_child(settled)
    assert settled.wait_for(10.0), ros_robot.state.joint_states.get_value()[joint]


def test_gripper_opens_and_closes_on_nothing(ros_robot):
    opened = motion(type="setting_gripper", gripper="right", position=1)
    closed = motion(type="setting_gripper", gripper="right", position=0)
    assert opened > 0.03 > closed
    # the opening topic follows the measured value
    opening = ros_robot.state.gripper_openings["right"]
    near = Fluent(lambda: True if abs(opening.get_value() - closed) < 0.005 else None)
    opening.add_child(near)
    assert near.wait_for(10.0)


def test_arm_configuration_reaches_its_joints(ros_robot):
    arm = next(iter(ros_robot.config.arms))
    positions = motion(type="setting_arm_configuration", arm="right", configuration="carry")
    expected = ros_robot.description.ARM_CONFIGURATIONS[arm]["carry"]
    assert positions == pytest.approx(tuple(expected))
    joints = ros_robot.config.arms[arm].joint_names
    there = Fluent(
        lambda: (
            True
            if all(abs(ros_robot.state.joint_states.get_value()[j] - p) < 0.05 for j, p in zip(joints, expected))
            else None
        )
    )
    ros_robot.state.joint_states.add_child(there)
    assert there.wait_for(10.0)


def test_head_points(ros_robot):
    assert motion(type="pointing_head", coordinates=[2.5, 0.6, 1.0]) is None


def test_reach_out_of_range_fails_with_the_simulators_reason(ros_robot):
    with pytest.raises(ProcessModuleFailure) as info:
        motion(type="reaching", arm="right", target=[0.8, 0.6, 4.0])
    cause = info.value.cause
    from pycram.backends.ros.transport import RosMotionFailed

    assert isinstance(cause, RosMotionFailed)
    assert cause.reason == "unreachable", cause
    assert "reach" in cause.action


def test_navigation_reaches_the_goal_and_pose_fluent_follows(ros_robot):
    pose = Fluent(name="test_pose")
    motion(type="subscribing_pose", fl=pose)
    start = pose.get_value()
    goal = (start.x + 0.3, start.y, start.yaw)
    reached = motion(type="moving", pose=goal, frame="map")
    assert math.hypot(reached.x - goal[0], reached.y - goal[1]) < 0.1
    close = Fluent(
        lambda: True if math.hypot(pose.get_value().x - goal[0], pose.get_value().y - goal[1]) < 0.1 else None
    )
    pose.add_child(close)
    assert close.wait_for(10.0)
    motion(type="moving", pose=(start.x, start.y, start.yaw), frame="map")


def test_gripper_subscription_follows_the_opening(ros_robot):
    opening = Fluent(name="test_opening")
    motion(type="subscribing_gripper", gripper="right", fl=opening)
    motion(type="setting_gripper", gripper="right", position=1)
    wide = Fluent(lambda: True if opening.get_value() > 0.03 else None)
    opening.add_child(wide)
    assert wide.wait_for(10.0)


def test_detecting_sees_the_mug(ros_robot):
    from pycram.apps.demos.kitchen_world import SLOTS

    x, y = SLOTS[1]
    here = ros_robot.state.base_pose.get_value()
    motion(type="moving", pose=(here.x, here.y, math.atan2(y - here.y, x - here.x)), frame="map")  # face it
    motion(type="setting_torso", position="up")
    motion(type="pointing_head", coordinates=[x, y, 0.95])
    seen = motion(type="detecting")
    assert [obj.type for obj in seen] == ["mug"], seen
    assert seen[0].pose[0] == pytest.approx(x, abs=0.05)
    assert seen[0] in ros_robot.belief.present()
    assert motion(type="detecting", object="no such thing") == []


def test_a_goal_in_another_frame_is_rejected_naming_the_frame(ros_robot, transport):
    goal = transport.message("move_base_msgs/MoveBaseGoal")
    goal.target_pose.header.frame_id = "odom"
    goal.target_pose.pose.orientation.w = 1.0
    handle = transport.action(ros_robot.config.move_base_action, "move_base_msgs/MoveBase").send(goal)
    assert handle.result.wait_for(10.0)
    outcome = handle.result.get_value()
    assert outcome.status == "rejected"
    assert outcome.text.startswith("invalid:") and "'odom'" in outcome.text


def test_tf_has_the_base_in_the_map_frame(ros_robot):
    import rospy
    import tf2_ros

    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    try:
        transform = buffer.lookup_transform(
            ros_robot.config.map_frame, ros_robot.config.base_frame, rospy.Time(0), rospy.Duration(10.0)
        )
        here = ros_robot.state.base_pose.get_value()
        assert transform.transform.translation.x == pytest.approx(here.x, abs=0.05)
        assert transform.transform.translation.y == pytest.approx(here.y, abs=0.05)
    finally:
        listener.unregister()
