"""An action of the action library over ROS: ``Search`` finds the demo's mug with the ROS
robot's perception and belief alone (real roscore, real bridge process)."""

from __future__ import annotations

import math

import pytest

from pycram.designator import ObjectDesignator, perform


@pytest.fixture(scope="module")
def robot(ros_master, transport):
    """The PR2 behind a bridge with the demo's mug on slot 1, active for the module."""
    from pycram.ros.launch import BridgeProcess
    from pycram.ros.robot import make_ros_robot

    bridge = BridgeProcess("pr2", ros_master.uri, item_at=1)
    try:
        ros_robot = make_ros_robot("pr2", transport)
        with ros_robot:
            yield ros_robot
        ros_robot.shutdown()
    finally:
        bridge.stop()


def test_search_finds_the_mug_over_ros(robot):
    from pycram.actions import Search
    from pycram.demos.kitchen_world import SLOTS

    assert robot.belief.present() == []
    found = perform(Search(ObjectDesignator(type="mug")))
    x, y = SLOTS[1]
    assert found.type == "mug" and found in robot.belief.present()
    assert math.hypot(found.pose[0] - x, found.pose[1] - y) < 0.05, found
    assert ObjectDesignator(type="mug").reference() is found
