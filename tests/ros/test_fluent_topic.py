"""A sensor topic drives a fluent network and wakes a waiter (no bridge: a test publisher)."""

from __future__ import annotations

import threading

from pycram.fluent import Fluent


def test_pose_topic_drives_a_fluent_network_and_wakes_wait_for(transport):
    import rospy
    from geometry_msgs.msg import PoseWithCovarianceStamped

    from pycram.backends.ros.config import robot_config
    from pycram.backends.ros.modules import RosRobotState

    config = robot_config("pr2").replace(pose_topic="/test/fluent_pose", joint_states_topic="/test/fluent_joints")
    state = RosRobotState(transport, config)
    publisher = rospy.Publisher(config.pose_topic, PoseWithCovarianceStamped, queue_size=1, latch=True)
    far_enough = Fluent(
        lambda: True if state.base_pose.get_value() is not None and state.base_pose.get_value().x > 1.0 else None
    )
    state.base_pose.add_child(far_enough)
    woke = threading.Event()
    waiter = threading.Thread(target=lambda: far_enough.wait_for(30.0) and woke.set(), daemon=True)
    waiter.start()
    try:
        message = PoseWithCovarianceStamped()
        message.pose.pose.orientation.w = 1.0
        message.pose.pose.position.x = 0.5
        publisher.publish(message)  # latched: delivered once the subscriber has connected
        assert state.base_pose.wait_for(10.0)
        assert state.base_pose.get_value().x == 0.5
        assert not woke.is_set()  # 0.5 m does not satisfy the network
        message.pose.pose.position.x = 1.5
        publisher.publish(message)
        assert woke.wait(10.0), "the waiter did not wake on the topic's update"
        assert state.base_pose.get_value().x == 1.5
    finally:
        waiter.join(35.0)
        publisher.unregister()
        state.close()
