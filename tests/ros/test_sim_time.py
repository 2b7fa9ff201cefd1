"""The bridge in simulated time (issue 31, point 4): ``/clock`` and the sensor topics go out per
interval of *simulated* time, so the gripper state a ROS node sees is never older than two
sensor periods of simulated time -- also while two CPU-burning processes run beside it.

What is measured, in this process (a ROS node with ``use_sim_time``, as the plan's process is),
through the PyCRAM transport's subscriptions to ``/clock`` and ``/joint_states`` (where the
gripper openings are published), beside PyCRAM's ROS robot state (which acknowledges each sensor
instant it took in: the bridge keeps step with it), over a few seconds of simulated time while
the gripper is commanded open and closed:

* the staleness of the gripper state: at every message on either topic, the latest ``/clock``
  time received minus the stamp of the latest joint-state message received [s, simulated];
* the steps of ``/clock`` and of the joint-state stamps between successive messages received
  [s, simulated]: how much simulated time passed unseen. (With sensor topics on a wall-clock
  timer against a simulation running many times faster than real time -- the old bridge -- these
  steps are tenths of a simulated second, although the stamps match ``/clock``.)

Each must stay within two sensor periods of simulated time. The measurement begins after the
instant the bridge names on ``/pycram_sim/keeping_step`` (from there on it publishes an instant
only once the previous one was acknowledged); before, the simulation may run ahead of a client
it does not know of yet.
"""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field

import pytest

#: The bridge's sensor period [s of simulated time] (``--publish-rate`` 50 Hz, the default).
SENSOR_PERIOD = 1.0 / 50.0
BOUND = 2 * SENSOR_PERIOD
#: How long to measure [s of simulated time], and the wall bound on it [s].
WINDOW, WALL_LIMIT = 5.0, 120.0


@dataclass
class Staleness:
    """What a ROS node saw of the gripper, in simulated seconds (see the module docstring).

    Only messages stamped after ``after`` (the bridge's ``keeping_step`` time; None: not known
    yet) count; the window ends :data:`WINDOW` after the first ``/clock`` that counts."""

    after: float | None = None
    start: float | None = None
    latest_clock: float = float("-inf")
    latest_stamp: float = float("-inf")
    worst_staleness: float = 0.0
    worst_clock_step: float = 0.0
    worst_stamp_step: float = 0.0
    clock_messages: int = 0
    joint_messages: int = 0
    wall: list[float] = field(default_factory=list)  # when the window began and ended [s, monotonic]
    keeping_step: threading.Event = field(default_factory=threading.Event)
    done: threading.Event = field(default_factory=threading.Event)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def _counts(self, t: float) -> bool:
        return self.after is not None and t > self.after

    def _stale(self) -> None:
        if self._counts(self.latest_clock) and self._counts(self.latest_stamp):
            self.worst_staleness = max(self.worst_staleness, self.latest_clock - self.latest_stamp)

    def on_keeping_step(self, message) -> None:
        with self.lock:
            if self.after is None:
                self.after = message.clock.to_sec()
                self.keeping_step.set()

    def on_clock(self, message) -> None:
        t = message.clock.to_sec()
        with self.lock:
            if self.done.is_set() or not self._counts(t):
                return
            if self._counts(self.latest_clock):
                self.worst_clock_step = max(self.worst_clock_step, t - self.latest_clock)
            self.clock_messages += 1
            self.latest_clock = max(t, self.latest_clock)
            if self.start is None:
                self.start = t
                self.wall.append(time.monotonic())
            self._stale()
            if t >= self.start + WINDOW:
                self.wall.append(time.monotonic())
                self.done.set()

    def on_joints(self, message) -> None:
        stamp = message.header.stamp.to_sec()
        with self.lock:
            if self.done.is_set() or not self._counts(stamp):
                return
            if self._counts(self.latest_stamp):
                self.worst_stamp_step = max(self.worst_stamp_step, stamp - self.latest_stamp)
            self.joint_messages += 1
            self.latest_stamp = max(stamp, self.latest_stamp)
            self._stale()

    def summary(self) -> str:
        return (
            f"worst staleness {self.worst_staleness:.4f} s, worst /clock step {self.worst_clock_step:.4f} s, "
            f"worst joint-state step {self.worst_stamp_step:.4f} s (simulated; bound {BOUND:.3f} s) over "
            f"{self.clock_messages} /clock and {self.joint_messages} joint-state messages after "
            f"t={self.after} s"
            + (f", {WINDOW / (self.wall[1] - self.wall[0]):.1f}x real time" if len(self.wall) == 2 else "")
        )


def _measure(transport, config, gripper: str) -> Staleness:
    """Measure over :data:`WINDOW` simulated seconds while the gripper opens and closes, beside
    PyCRAM's ROS robot state (which takes the sensor topics in and acknowledges each instant)."""
    from pycram.backends.ros.modules import RosRobotState

    seen = Staleness()
    subscriptions = [
        transport.subscribe(f"{config.sim_namespace}/keeping_step", "rosgraph_msgs/Clock", seen.on_keeping_step),
        transport.subscribe(config.clock_topic, "rosgraph_msgs/Clock", seen.on_clock),
        transport.subscribe(config.joint_states_topic, "sensor_msgs/JointState", seen.on_joints),
    ]
    state = RosRobotState(transport, config)
    channel = transport.action(config.grippers[gripper].action, "control_msgs/GripperCommand")
    try:
        assert seen.keeping_step.wait(30.0), "the bridge did not say it keeps step with this process"
        opening = 0.08
        goals = 0
        while not seen.done.is_set() and goals < WALL_LIMIT / 2:
            goal = transport.message(
                "control_msgs/GripperCommandGoal",
                command=transport.message("control_msgs/GripperCommand", position=opening, max_effort=0.0),
            )
            handle = channel.send(goal)
            assert handle.result.wait_for(30.0), "a gripper goal did not end"  # wall clock (no sim clock here)
            goals += 1
            opening = 0.08 - opening
        assert seen.done.wait(WALL_LIMIT), f"no {WINDOW} s of simulated time: {seen.summary()}"
    finally:
        for subscription in subscriptions:
            subscription.close()
        state.close()
    return seen


def _burners(n: int) -> list[subprocess.Popen]:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]


def _check(start_bridge, transport, load: int) -> None:
    from pycram.backends.ros.config import robot_config

    config = robot_config("pr2")
    bridge = start_bridge("pr2", item_at=0)
    burners = _burners(load)
    try:
        seen = _measure(transport, config, "right")
    finally:
        for burner in burners:
            burner.kill()
            burner.wait(10)
    print(f"\n{load} CPU burners: {seen.summary()}")
    failure = f"{seen.summary()}\nthe bridge's output:\n{bridge.output()}"
    assert seen.worst_clock_step <= BOUND + 1e-6, failure
    assert seen.worst_stamp_step <= BOUND + 1e-6, failure
    assert seen.worst_staleness <= BOUND + 1e-6, failure
    assert seen.joint_messages >= 0.5 * WINDOW / SENSOR_PERIOD, failure


@pytest.mark.parametrize("load", [0, 2], ids=["idle", "two-cpu-burners"])
def test_gripper_state_over_ros_is_never_older_than_two_sensor_periods(start_bridge, transport, load):
    _check(start_bridge, transport, load)
