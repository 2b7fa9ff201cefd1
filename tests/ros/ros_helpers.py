"""Helpers of the ROS tests: judging runs with the simulator's truth, which the bridge publishes
on its simulator-only ``/pycram_sim/items`` topic (never given to the plans)."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from typing import Any


class ItemTruth:
    """The simulator's item poses from ``/pycram_sim/items`` (for judging only)."""

    def __init__(self, transport, config) -> None:
        self._cond = threading.Condition()
        self.count, self.poses, self.tilts, self.held = 0, {}, {}, {}
        self._subscription = transport.subscribe(f"{config.sim_namespace}/items", "pycram_msgs/ItemStates", self._on)

    def _on(self, message) -> None:
        with self._cond:
            self.poses = {i.name: (i.pose.position.x, i.pose.position.y, i.pose.position.z) for i in message.items}
            self.tilts = {  # [rad] between each item's z axis and the vertical
                i.name: math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (i.pose.orientation.x**2 + i.pose.orientation.y**2))))
                for i in message.items
            }
            self.held = {i.name: i.held_by for i in message.items if i.held_by}
            self.count += 1
            self._cond.notify_all()

    def fresh(self, timeout: float = 10.0) -> dict:
        """The item poses from a message that arrived after now (waits on a condition, at most
        ``timeout`` [s, wall])."""
        with self._cond:
            wanted = self.count + 2
            assert self._cond.wait_for(lambda: self.count >= wanted, timeout), "no item states from the bridge"
            return dict(self.poses)

    def close(self) -> None:
        self._subscription.close()


def on_surface(robot, truth, name: str, surface: str) -> bool:
    """True when the simulator has item ``name`` resting on ``surface`` (within 3 cm of its top)."""
    from pycram.world.objects import object_type

    x, y, z = truth.fresh()[name]
    top = robot.state.environment.surface(surface)
    return top.contains(x, y, 0.0) and abs(z - object_type(name).half_height - top.height) < 0.03


def robot_in_environment(
    master: Any,
    transport: Any,
    robot_name: str,
    environment: str,
    objects: tuple[str, ...],
    base_pose: tuple[float, float, float] | None = None,
) -> Iterator[tuple[Any, ItemTruth]]:
    """A bridge of ``environment`` with ``objects`` (``--object`` values) and ``robot_name`` at
    ``base_pose`` (None: the environment's start), the robot over ROS (configured for that
    environment) active, the plan's clock following the bridge's ``/clock``; yields (robot, the
    simulator's item truth) and stops everything afterwards."""
    from pycram.backends.ros.config import robot_config
    from pycram.backends.ros.launch import BridgeProcess
    from pycram.core.runtime.clock import set_clock
    from pycram.robots.common.ros_robot import make_ros_robot

    config = robot_config(robot_name).replace(environment=environment)
    extra = () if base_pose is None else ("--base-pose", ",".join(str(v) for v in base_pose))
    bridge = BridgeProcess(
        robot_name, master.uri, item_at=None, environment=environment, objects=objects, extra_args=extra
    )
    previous = set_clock(transport.sim_clock(config.clock_topic))
    truth = None
    try:
        robot = make_ros_robot(robot_name, transport, config)
        truth = ItemTruth(transport, config)
        with robot:
            yield robot, truth
        robot.shutdown()
    finally:
        if truth is not None:
            truth.close()
        set_clock(previous)
        bridge.stop()
