"""Fixtures of the ROS tests: a real roscore on a free loopback port, real bridge processes.

rospy allows one node per process and cannot move it to another master, so the test process
talks to ONE master for the whole session (started here, on 127.0.0.1, stopped at the end);
each test module starts its own `pycram sim-ros-bridge` processes and stops them. Everything is
skipped, saying why, when ROS 1 is not installed (scripts/install_ros.sh installs it).
"""

from __future__ import annotations

import os
import shutil

import pytest


def _ros_missing() -> str | None:
    if shutil.which("roscore") is None:
        return "roscore not found (run scripts/install_ros.sh)"
    try:
        import actionlib  # noqa: F401
        import control_msgs.msg  # noqa: F401
        import rospy  # noqa: F401
    except ImportError as e:
        return f"ROS 1 Python packages not importable ({e}; run scripts/install_ros.sh)"
    return None


@pytest.fixture(scope="session")
def ros_master():
    """roscore on 127.0.0.1:<free port>; this process's ROS environment points at it."""
    reason = _ros_missing()
    if reason:
        pytest.skip(reason)
    from pycram.backends.ros.launch import RosMaster

    saved = {k: os.environ.get(k) for k in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOSTNAME")}
    master = RosMaster()
    os.environ.update(ROS_MASTER_URI=master.uri, ROS_IP="127.0.0.1", ROS_HOSTNAME="127.0.0.1")
    import rosgraph
    import rospy

    if rospy.core.is_initialized() and rosgraph.get_master_uri() != master.uri:
        master.stop()
        pytest.skip("this test process's ROS node already talks to another master")
    yield master
    master.stop()
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


@pytest.fixture(scope="session")
def transport(ros_master):
    """The test process's ROS 1 transport (its node lives for the session)."""
    from pycram.backends.ros.ros1 import ros1_transport

    return ros1_transport()


def _start_bridge(robot: str, master, item_at: int = 1):
    from pycram.backends.ros.launch import BridgeProcess

    return BridgeProcess(robot, master.uri, item_at=item_at)


@pytest.fixture
def start_bridge(ros_master):
    """``start_bridge(robot, item_at=1)`` -> a running bridge process, stopped after the test."""
    bridges = []

    def start(robot: str, item_at: int = 1):
        bridges.append(_start_bridge(robot, ros_master, item_at))
        return bridges[-1]

    yield start
    for bridge in bridges:
        bridge.stop()


def _robot_behind_bridge(robot_name: str, master, transport):
    """A bridge for `robot_name` (the demo's mug on slot 1) and the robot over ROS, active."""
    from pycram.robots.common.ros_robot import make_ros_robot

    bridge = _start_bridge(robot_name, master)
    try:
        robot = make_ros_robot(robot_name, transport)
        with robot:
            yield robot
        robot.shutdown()
    finally:
        bridge.stop()


@pytest.fixture(scope="module", params=["pr2", "tiago"])
def ros_robot(request, ros_master, transport):
    """A bridge for the robot of the parameter and the robot over ROS, active for the module."""
    yield from _robot_behind_bridge(request.param, ros_master, transport)


@pytest.fixture(scope="module")
def pr2_with_mug(ros_master, transport):
    """The PR2 behind a bridge with the demo's mug on slot 1, active for the module."""
    yield from _robot_behind_bridge("pr2", ros_master, transport)
