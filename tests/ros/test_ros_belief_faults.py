"""The bridge publishes what the simulated camera detects, its perception faults included: a
camera that misses every object leaves the belief empty, whatever is in front of it."""

from __future__ import annotations

import math

import pytest

from pycram.designator import MotionDesignator, NoSolutionError, ObjectDesignator, perform


def motion(**properties):
    return perform(MotionDesignator(**properties))


@pytest.fixture(scope="module")
def blind_robot(ros_master, transport):
    """The PR2 behind a bridge whose camera misses every object (``--miss-probability 1``)."""
    from pycram.backends.ros.launch import BridgeProcess
    from pycram.robots.common.ros_robot import make_ros_robot

    bridge = BridgeProcess("pr2", ros_master.uri, item_at=1, extra_args=("--miss-probability", "1"))
    try:
        robot = make_ros_robot("pr2", transport)
        with robot:
            yield robot
        robot.shutdown()
    finally:
        bridge.stop()


def test_a_camera_that_misses_everything_fills_no_belief(blind_robot):
    from pycram.apps.demos.kitchen_world import SLOTS

    x, y = SLOTS[1]
    here = blind_robot.state.base_pose.get_value()
    motion(type="moving", pose=(here.x, here.y, math.atan2(y - here.y, x - here.x)), frame="map")
    motion(type="setting_torso", position="up")
    motion(type="pointing_head", coordinates=[x, y, 0.95])
    assert motion(type="detecting") == []
    assert blind_robot.belief.present() == []
    assert blind_robot.belief.looks, "the look itself arrived (with its camera view)"
    with pytest.raises(NoSolutionError):
        ObjectDesignator(type="mug").reference()
