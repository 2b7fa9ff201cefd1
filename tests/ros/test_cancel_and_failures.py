"""Evaporating a drive cancels its move_base goal; a vanished bridge fails goals by name, fast."""

from __future__ import annotations

import math
import threading

import pytest

from pycram.designator import MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.language import pursue
from pycram.process_module import ProcessModuleFailure, ProcessModuleStatus


def motion(**properties):
    return perform(MotionDesignator(**properties))


def _moved_from(fluent: Fluent, start, distance: float) -> Fluent:
    network = Fluent(
        lambda: True if math.hypot(fluent.get_value().x - start.x, fluent.get_value().y - start.y) > distance else None
    )
    fluent.add_child(network)
    return network


@pytest.fixture
def pr2_over_ros(start_bridge, transport):
    """A bridge of this test's own and the PR2 over ROS (the test may kill the bridge)."""
    from pycram.robots.common.ros_robot import make_ros_robot

    bridge = start_bridge("pr2")
    robot = make_ros_robot("pr2", transport)
    with robot:
        yield robot, bridge
    robot.shutdown()


def test_evaporating_a_drive_cancels_the_move_base_goal_and_the_base_stops(pr2_over_ros, transport):
    robot, _ = pr2_over_ros
    config = robot.config
    results = Fluent(None, name="move_base results")
    subscription = transport.subscribe(
        f"{config.move_base_action}/result",
        "move_base_msgs/MoveBaseActionResult",
        lambda message: results.set_value(message.status.status),
    )
    sim_time = Fluent(None, name="sim time")
    clock = transport.subscribe(
        config.clock_topic, "rosgraph_msgs/Clock", lambda message: sim_time.set_value(message.clock.to_sec())
    )
    try:
        start = robot.state.base_pose.get_value()
        goal = (start.x + 2.0, start.y, start.yaw)
        moved = _moved_from(robot.state.base_pose, start, 0.2)
        pursue(lambda: motion(type="moving", pose=goal, frame="map"), lambda: moved.wait_for(30.0))

        navigation = robot.process_module("navigation")
        assert navigation.status.get_value() is ProcessModuleStatus.CANCELLED
        assert results.wait_for(10.0)
        preempted = Fluent(lambda: True if results.get_value() == 2 else None)  # actionlib PREEMPTED
        results.add_child(preempted)
        assert preempted.wait_for(10.0), f"move_base result status {results.get_value()}"
        # the base comes to rest: within 5 s of simulated time there is a second over which it
        # moves less than 1 cm (pose and clock arrive on separate topics, published at a wall-time
        # rate while the simulation runs faster: a pose read right after a clock message can be a
        # batch old, so no single window is judged)
        assert sim_time.wait_for(10.0)

        def after(seconds: float) -> Fluent:
            t0 = sim_time.get_value()
            later = Fluent(lambda: True if sim_time.get_value() > t0 + seconds else None)
            sim_time.add_child(later)
            return later

        movements = []
        for _ in range(5):
            before = robot.state.base_pose.get_value()
            assert after(1.0).wait_for(10.0)
            now = robot.state.base_pose.get_value()
            movements.append(math.hypot(now.x - before.x, now.y - before.y))
            if movements[-1] < 0.01:
                break
        assert movements[-1] < 0.01, f"the base still moved after the cancel: {movements} m per second"
        assert math.hypot(now.x - goal[0], now.y - goal[1]) > 0.5  # it stopped on the way
    finally:
        subscription.close()
        clock.close()


def test_bridge_killed_mid_drive_fails_with_action_server_lost(pr2_over_ros, transport):
    from pycram.backends.ros.transport import ActionServerLost, ActionServerUnavailable

    robot, bridge = pr2_over_ros
    start = robot.state.base_pose.get_value()
    moved = _moved_from(robot.state.base_pose, start, 0.2)
    outcome: dict = {}

    def drive() -> None:
        with robot:
            try:
                motion(type="moving", pose=(start.x + 2.0, start.y, start.yaw), frame="map")
                outcome["result"] = "succeeded"
            except BaseException as error:
                outcome["error"] = error

    driver = threading.Thread(target=drive, name="test-drive", daemon=True)
    driver.start()
    assert moved.wait_for(30.0)
    bridge.kill()
    driver.join(transport.server_timeout + 15.0)  # a bound, not a speed target: never a hang
    assert not driver.is_alive(), "the drive hangs on a dead action server"
    error = outcome.get("error")
    assert isinstance(error, ProcessModuleFailure), outcome
    assert isinstance(error.cause, ActionServerLost), error.cause
    assert error.cause.reason == "lost" and error.cause.action == robot.config.move_base_action
    assert "vanished" in str(error.cause)

    # with no server at all, a new goal is refused by name within the connect time-out
    saved, transport.connect_timeout = transport.connect_timeout, 1.0
    try:
        with pytest.raises(ProcessModuleFailure) as info:
            motion(type="setting_torso", position="up")
        assert isinstance(info.value.cause, ActionServerUnavailable)
        assert robot.config.torso_action in str(info.value.cause)
    finally:
        transport.connect_timeout = saved
