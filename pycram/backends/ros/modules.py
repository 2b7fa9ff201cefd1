"""Process modules over ROS: the same motion vocabulary as the simulated robots, sent as goals.

Each module executes the *solution* of its motion designator (the dictionaries of
:mod:`pycram.robots.common.sim_resolvers`, with a ``'cmd'`` key) by sending one goal on the robot's
action named in its :class:`~pycram.backends.ros.config.RosRobotConfig`, through a
:class:`~pycram.backends.ros.transport.Transport` -- never through ``rospy`` directly -- and waiting,
evaporably, on the goal's ``result`` fluent.

Guarantees
----------
- Same results as the simulated modules: the reached ``Pose2D`` (navigation), the reached tool
  ``Pose`` (reach), the measured opening [m] (gripper), the believed objects seen
  (``PerceivedObject``, perception; the robot's belief is updated as in-process).
- A failed goal raises :class:`~pycram.backends.ros.transport.RosMotionFailed` naming the command, the
  action and the robot's reason (the simulator's outcome reason behind the bridge:
  ``collision``, ``unreachable``, ...). A goal that does not end within its time-out [s of the
  active clock] is cancelled and fails with reason ``'timeout'``.
- A server that vanishes mid-goal: :class:`~pycram.backends.ros.transport.ActionServerLost` within the
  transport's ``server_timeout`` [s of wall time]; no server at all:
  :class:`~pycram.backends.ros.transport.ActionServerUnavailable` within its ``connect_timeout``.
- Evaporating the caller cancels the goal on the server (``_cancel``): an evaporated drive
  cancels the ``move_base`` goal and the base stops.
- When a drive or a gripper command returns, the sensor fluents (base pose, gripper openings)
  already show the robot after it: the module waits for a message sampled after the goal ended.
  Such waits on the robot's own messages are bounded in wall time, so a stopped simulation
  clock (a dead bridge) cannot hang them.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Sequence
from typing import Any

from pycram.backends.ros.config import RosRobotConfig
from pycram.backends.ros.detections import report_of
from pycram.backends.ros.transport import (
    ActionServerLost,
    GoalHandle,
    GoalOutcome,
    Publication,
    RosMotionFailed,
    Transport,
)
from pycram.core.fluent import Fluent
from pycram.execution.module_support import (
    cancel_running_handle,
    check_command,
    format_pose2d,
    format_values,
    seen_objects,
)
from pycram.execution.process_module import ProcessModule
from pycram.world.belief import BeliefState, BeliefUpdate
from pycram.world.types import Pose, Pose2D

__all__ = [
    "MessageCounter",
    "path_goal",
    "RosRobotState",
    "RosProcessModule",
    "RosNavigationModule",
    "RosBaseStopModule",
    "RosHeadModule",
    "RosTorsoModule",
    "RosArmModule",
    "RosGripperModule",
    "RosPerceptionModule",
]

logger = logging.getLogger(__name__)

#: Duration given to a joint trajectory's single point [s] (the controller interpolates).
ARM_MOTION_DURATION = 2.0


def yaw_of(orientation: Any) -> float:
    """Yaw [rad] of a ``geometry_msgs/Quaternion``."""
    q = orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class MessageCounter:
    """Counts the messages of one topic and keeps the latest; :meth:`wait_for_count` waits for
    a later one, bounded in wall time -- whatever clock the plan runs on (a simulation clock
    stops with the simulator, a wall bound does not)."""

    def __init__(self) -> None:
        self.count = 0
        self.latest: Any = None
        self._cond = threading.Condition()

    def tick(self, message: Any = None) -> None:
        with self._cond:
            self.count += 1
            self.latest = message
            self._cond.notify_all()

    def wait_for_count(self, count: int, timeout: float) -> bool:
        """Wait until ``count`` messages arrived (at most ``timeout`` [s, wall], in slices of
        0.1 s so an evaporation of the caller lands promptly). True if they did."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while self.count < count:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._cond.wait(min(remaining, 0.1))
        return True


class RosRobotState:
    """The robot's sensors over ROS, as fluents (thesis: ``subscribe_pose``/``subscribe_gripper``).

    ``base_pose`` (``Pose2D``, map frame, from the pose topic), ``joint_states`` (``{name:
    position}`` [rad or m]), ``joint_velocities`` (``{name: velocity}`` [rad/s or m/s]; empty
    when the robot publishes no velocities), ``gripper_openings[g]`` [m] (sum of the gripper's
    opening joints). Each is set
    in the middleware's thread at the topic's rate. Also serves as the "world" the motion
    resolvers read the base pose from. ``stamp`` is the (ROS) time [s] of the newest sensor
    instant taken in: the older of the latest pose and joint-state stamps.

    Keeping step with a simulator: it also follows ``config.clock_topic`` and acknowledges each
    sensor instant it has taken in completely -- base pose, joint states *and* ``/clock`` at
    that time, each in its fluents or clock -- by publishing the instant's stamp on
    ``config.sensor_ack_topic`` (a ``rosgraph_msgs/Clock``; nobody listens on a real robot).
    ``pycram sim-ros-bridge`` publishes the next instant only then, so the simulation never
    runs ahead of this process by more than one sensor period. A message repeating the instant
    last acknowledged (the bridge resends an instant nobody acknowledged) is acknowledged again;
    a stamp older than the last one on its topic (a restarted simulator) forgets every instant
    taken in so far. :meth:`close` ends the acknowledgements.
    """

    def __init__(self, transport: Transport, config: RosRobotConfig) -> None:
        from pycram.environments import load as load_environment

        self.robot = config.robot
        self.config = config
        #: the environment description of the robot's map (``config.environment``)
        self.environment = load_environment(config.environment)
        self.base_pose = Fluent(None, name="base_pose")
        self.joint_states = Fluent(None, name="joint_states")
        self.joint_velocities = Fluent(None, name="joint_velocities")
        self.gripper_openings = {g: Fluent(None, name=f"{g}_gripper_opening") for g in config.grippers}
        self._ready = threading.Event()
        self.pose_updates = MessageCounter()  #: base-pose messages received
        self.joint_updates = MessageCounter()  #: joint-state messages received
        self.stamp = -math.inf
        #: per topic: the latest stamp taken in [s] and as the message had it
        self._stamps: dict[str, tuple[float, Any]] = dict.fromkeys(("pose", "joints", "clock"), (-math.inf, None))
        self._acknowledged = -math.inf  # the newest complete instant acknowledged [s]
        self._stamp_lock = threading.Lock()
        self._transport = transport
        self._acknowledge: Publication | None = None
        try:
            self._acknowledge = transport.advertise(config.sensor_ack_topic, "rosgraph_msgs/Clock")
        except NotImplementedError:
            pass
        self._subscriptions = [
            transport.subscribe(config.pose_topic, "geometry_msgs/PoseWithCovarianceStamped", self._on_pose),
            transport.subscribe(config.joint_states_topic, "sensor_msgs/JointState", self._on_joints),
        ]
        if self._acknowledge is not None:
            self._subscriptions.append(
                transport.subscribe(config.clock_topic, "rosgraph_msgs/Clock", lambda m: self._taken("clock", m.clock))
            )

    def _on_pose(self, message: Any) -> None:
        pose = message.pose.pose
        self.base_pose.set_value(Pose2D(pose.position.x, pose.position.y, yaw_of(pose.orientation)))
        self.pose_updates.tick()
        self._check_ready()
        self._taken("pose", message.header.stamp)

    def _taken(self, topic: str, stamp: Any) -> None:
        """A message of ``topic`` stamped ``stamp`` is taken in: acknowledge the newest complete
        instant when it grew, or again when this message repeats it (see the class docstring)."""
        seconds = self._transport.time_to_seconds(stamp)
        with self._stamp_lock:
            if seconds < self._stamps[topic][0]:  # a restarted simulator: its instants only
                self._stamps = dict.fromkeys(self._stamps, (-math.inf, None))
                self._acknowledged = -math.inf
            self._stamps[topic] = (seconds, stamp)
            self.stamp = min(self._stamps["pose"][0], self._stamps["joints"][0])
            newest, newest_stamp = min(self._stamps.values(), key=lambda entry: entry[0])
            if newest == -math.inf or newest < self._acknowledged:
                return
            if newest == self._acknowledged and seconds != newest:
                return  # nothing new, and not a repetition of the instant acknowledged
            self._acknowledged = newest
        if self._acknowledge is not None:
            try:
                self._acknowledge.publish(self._transport.message("rosgraph_msgs/Clock", clock=newest_stamp))
            except Exception:  # e.g. the node shutting down
                logger.debug("could not acknowledge the sensor instant %.3f", newest, exc_info=True)

    def fresh_base_pose(self, timeout: float = 2.0) -> Pose2D | None:
        """The base pose from a message sampled after now (see :meth:`wait_fresh`)."""
        self.wait_fresh(self.pose_updates, timeout)
        return self.base_pose.get_value()

    @staticmethod
    def wait_fresh(updates: MessageCounter, timeout: float = 2.0) -> bool:
        """Wait (at most ``timeout`` [s, wall]) for the second message from now on the topic
        counted by ``updates`` (:attr:`pose_updates`, :attr:`joint_updates`): the first may have
        been sampled before now and still be on its way. Afterwards the sensor fluents show the
        robot as it was after now."""
        return updates.wait_for_count(updates.count + 2, timeout)

    def _on_joints(self, message: Any) -> None:
        positions = dict(zip(message.name, message.position))
        velocities = dict(zip(message.name, message.velocity)) if len(message.velocity) == len(message.name) else {}
        self.joint_velocities.set_value(velocities)  # first: a waiter on the positions sees both
        self.joint_states.set_value(positions)
        for name, gripper in self.config.grippers.items():
            if all(j in positions for j in gripper.opening_joints):
                self.gripper_openings[name].set_value(sum(positions[j] for j in gripper.opening_joints))
        self.joint_updates.tick()
        self._check_ready()
        self._taken("joints", message.header.stamp)

    def _check_ready(self) -> None:
        if (
            not self._ready.is_set()
            and self.base_pose.get_value() is not None
            and all(f.get_value() is not None for f in self.gripper_openings.values())
        ):
            self._ready.set()

    def wait_ready(self, timeout: float) -> bool:
        """Wait at most ``timeout`` [s, wall] for the first pose and gripper openings."""
        return self._ready.wait(timeout)

    def close(self) -> None:
        """End the subscriptions and the acknowledgements (idempotent)."""
        for subscription in self._subscriptions:
            subscription.close()
        if self._acknowledge is not None:
            self._acknowledge.close()

    def __repr__(self) -> str:
        return f"RosRobotState({self.robot!r})"


def _reason_of(outcome: GoalOutcome) -> tuple[str, str]:
    """(reason, message) from a goal's status text ``'reason: message'`` (the bridge's form),
    else (status, text)."""
    head, sep, rest = outcome.text.partition(": ")
    if sep and head and " " not in head:
        return head, rest
    return outcome.status, outcome.text or f"goal {outcome.status}"


class RosProcessModule(ProcessModule):
    """Base class: sends goals over a transport; the cancel hook cancels the running goal."""

    def __init__(self, name: str, transport: Transport, config: RosRobotConfig, state: RosRobotState) -> None:
        super().__init__(name)
        self.transport, self.config, self.state = transport, config, state
        self._handle: GoalHandle | None = None

    def _send(self, action: str, action_type: str, goal: Any) -> GoalHandle:
        handle = self.transport.action(action, action_type).send(goal)
        self._handle = handle
        return handle

    def _run_goal(self, action: str, action_type: str, goal: Any, command: str, timeout: float) -> Any:
        """Send ``goal``, wait for it (evaporably, at most ``timeout`` [s, active clock]) and
        return the server's result message. Raises :class:`RosMotionFailed` (or a subclass)."""
        handle = self._send(action, action_type, goal)
        if not handle.result.wait_for(timeout):
            self._handle = None
            handle.cancel()
            raise RosMotionFailed(command, "timeout", f"did not end within {timeout:.1f} s", action)
        outcome = handle.result.get_value()
        self._handle = None
        if outcome.succeeded:
            logger.debug("%s: %s succeeded", self.name, command)
            return outcome.result
        reason, message = _reason_of(outcome)
        error = ActionServerLost if outcome.status == "lost" else RosMotionFailed
        raise error(command, reason, message, action, outcome)

    def _cancel(self, designator: Any) -> None:
        cancel_running_handle(self, designator)

    def _point(self, x: float, y: float, z: float) -> Any:
        return self.transport.message("geometry_msgs/Point", x=float(x), y=float(y), z=float(z))

    def _header(self) -> Any:
        return self.transport.message("std_msgs/Header", frame_id=self.config.map_frame)


class RosNavigationModule(RosProcessModule):
    """``'cmd': 'navigate'`` → a ``move_base`` goal in the map frame; returns the base pose
    reached (from a pose message sampled after the goal succeeded)."""

    def __init__(
        self, transport: Transport, config: RosRobotConfig, state: RosRobotState, name: str = "navigation"
    ) -> None:
        super().__init__(name, transport, config, state)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "navigate")
        pose = solution["pose"]
        here = self.state.base_pose.get_value()
        distance = math.hypot(pose.x - here.x, pose.y - here.y) if here is not None else 10.0
        m = self.transport.message
        goal = m("move_base_msgs/MoveBaseGoal")
        goal.target_pose = m(
            "geometry_msgs/PoseStamped",
            header=self._header(),
            pose=m(
                "geometry_msgs/Pose",
                position=self._point(pose.x, pose.y, 0.0),
                orientation=m(
                    "geometry_msgs/Quaternion", x=0.0, y=0.0, z=math.sin(pose.yaw / 2), w=math.cos(pose.yaw / 2)
                ),
            ),
        )
        command = f"drive to {format_pose2d(pose)}"
        try:
            self._run_goal(
                self.config.move_base_action, "move_base_msgs/MoveBase", goal, command, timeout=30.0 + 4.0 * distance
            )
        except RosMotionFailed as e:
            e.args = (f"{e.args[0]} (stopped at {format_pose2d(self.state.base_pose.get_value())})",)
            raise
        return self.state.fresh_base_pose()


class RosBaseStopModule(RosProcessModule):
    """``'cmd': 'stop_base'``: cancels the running drive (waited or not) and every goal on
    ``move_base``; returns the base pose. Separate from navigation so it never queues behind
    the drive it stops."""

    def __init__(
        self,
        transport: Transport,
        config: RosRobotConfig,
        state: RosRobotState,
        navigation: RosNavigationModule,
        name: str = "base_stop",
    ) -> None:
        super().__init__(name, transport, config, state)
        self.navigation = navigation

    def _execute(self, designator: Any) -> Any:
        check_command(self, designator.reference(), "stop_base")
        execution = self.navigation.current
        if execution is not None:
            execution.cancel()  # its cancel hook cancels its goal
        self.transport.action(self.config.move_base_action, "move_base_msgs/MoveBase").cancel_all()
        if execution is not None:
            waiter = Fluent(lambda: True if execution.done else None)
            execution.status.add_child(waiter)
            waiter.wait_for(5.0)
        return self.state.fresh_base_pose()


class RosHeadModule(RosProcessModule):
    """``'cmd': 'point_head'`` → a PointHead goal (target in the map frame). With ``'track'``
    (a ``('wait', False)`` designator) the goal is sent and the module returns at once; the next
    head goal replaces it on the server. Returns ``None`` (PointHead's result is empty)."""

    def __init__(self, transport: Transport, config: RosRobotConfig, state: RosRobotState, name: str = "head") -> None:
        super().__init__(name, transport, config, state)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "point_head")
        point = tuple(float(v) for v in solution["point"])
        m, c = self.transport.message, self.config
        goal = m("control_msgs/PointHeadGoal", pointing_frame=c.head_pointing_frame, max_velocity=1.0)
        goal.target = m("geometry_msgs/PointStamped", header=self._header(), point=self._point(*point))
        goal.pointing_axis = m(
            "geometry_msgs/Vector3", x=c.head_pointing_axis[0], y=c.head_pointing_axis[1], z=c.head_pointing_axis[2]
        )
        if solution.get("track"):
            self._send(c.head_action, "control_msgs/PointHead", goal)
            return None
        self._run_goal(
            c.head_action, "control_msgs/PointHead", goal, f"point the head at {format_values(point)}", timeout=10.0
        )
        return None


class RosTorsoModule(RosProcessModule):
    """``'cmd': 'set_torso'`` (``'height'`` [m]) → SingleJointPosition (PR2) or a one-joint
    trajectory (TIAGo); returns the height reached [m] (the commanded one: the server succeeds
    only within its tolerance)."""

    def __init__(self, transport: Transport, config: RosRobotConfig, state: RosRobotState, name: str = "torso") -> None:
        super().__init__(name, transport, config, state)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "set_torso")
        height = float(solution["height"])
        c = self.config
        if c.torso_interface == "single_joint_position":
            goal = self.transport.message("control_msgs/SingleJointPositionGoal", position=height, max_velocity=1.0)
            action_type = "control_msgs/SingleJointPosition"
        else:
            goal = _trajectory_goal(self.transport, (c.torso_joint,), (height,))
            action_type = "control_msgs/FollowJointTrajectory"
        self._run_goal(c.torso_action, action_type, goal, f"set the torso to {height:.3f} m", timeout=20.0)
        return height


def _trajectory_goal(transport: Transport, joints: tuple[str, ...], positions: tuple[float, ...]) -> Any:
    """A one-point trajectory to ``positions`` (the controller interpolates from where it is)."""
    return path_goal(transport, joints, [(ARM_MOTION_DURATION, positions)])


def path_goal(transport: Transport, joints: Sequence[str], samples: Sequence[tuple[float, Sequence[float]]]) -> Any:
    """A ``control_msgs/FollowJointTrajectoryGoal`` through ``samples``: (time from start [s],
    positions [rad or m] in the order of ``joints``) pairs, times increasing, e.g. a planned
    path's :func:`pycram.reasoning.motion.time_parameterize` samples. Velocities are left for
    the controller to interpolate except at the last point (0: the path ends at rest).
    ``ValueError`` for no samples, positions of the wrong length, non-finite values or times
    that do not increase."""
    joints = list(joints)
    if not samples:
        raise ValueError("a joint trajectory needs at least one sample")
    m = transport.message
    points, last = [], -math.inf
    for k, (t, positions) in enumerate(samples):
        values = [float(v) for v in positions]
        if len(values) != len(joints):
            raise ValueError(f"sample {k}: {len(values)} positions for the {len(joints)} joints {joints}")
        if not (math.isfinite(float(t)) and all(math.isfinite(v) for v in values)):
            raise ValueError(f"sample {k}: time and positions must be finite, got t={t!r}, {values}")
        if float(t) <= last:
            raise ValueError(f"sample {k}: times must increase, got {t!r} after {last!r} [s]")
        last = float(t)
        fields: dict[str, Any] = {"positions": values, "time_from_start": transport.duration(float(t))}
        if k == len(samples) - 1:
            fields["velocities"] = [0.0] * len(values)
        points.append(m("trajectory_msgs/JointTrajectoryPoint", **fields))
    trajectory = m("trajectory_msgs/JointTrajectory", joint_names=joints, points=points)
    return m("control_msgs/FollowJointTrajectoryGoal", trajectory=trajectory)


class RosArmModule(RosProcessModule):
    """One arm: ``'move_arm'`` → FollowJointTrajectory on the arm's joints; ``'reach'`` → a
    Reach goal (tool pose in the map frame). Returns the commanded joint positions [rad]
    (``move_arm``) or the reached tool ``Pose`` (``reach``)."""

    def __init__(
        self, transport: Transport, config: RosRobotConfig, state: RosRobotState, arm: str, name: str | None = None
    ) -> None:
        super().__init__(name or f"arm_{arm}", transport, config, state)
        self.arm = arm
        self.interface = config.arms[arm]

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        cmd = solution.get("cmd")
        if cmd == "move_arm":
            positions = tuple(float(v) for v in solution["positions"])
            if len(positions) != len(self.interface.joint_names):
                raise ValueError(
                    f"the {self.arm} arm has {len(self.interface.joint_names)} joints "
                    f"{list(self.interface.joint_names)}, got {len(positions)} positions"
                )
            what = solution.get("configuration") or format_values(positions)
            goal = _trajectory_goal(self.transport, self.interface.joint_names, positions)
            self._run_goal(
                self.interface.trajectory_action,
                "control_msgs/FollowJointTrajectory",
                goal,
                f"move the {self.arm} arm to {what}",
                timeout=30.0,
            )
            return positions
        if cmd == "reach":
            return self._reach(solution)
        check_command(self, solution, "move_arm", "reach")

    def follow_path(
        self,
        joints: Sequence[str],
        samples: Sequence[tuple[float, Sequence[float]]],
        what: str,
        timeout: float,
    ) -> tuple[float, ...]:
        """Send the timed joint path ``samples`` ((t [s] from 0, positions in the order of
        ``joints``), see :func:`path_goal`) as one FollowJointTrajectory goal on this arm's
        trajectory action and wait for it (evaporably, at most ``timeout`` [s, active clock]).
        Returns the last sample's positions; raises :class:`RosMotionFailed` with the robot's
        reason (the simulator bridge: ``'collision'``, ``'blocked'``, ...). Called from within
        this module's execution (a planned motion)."""
        unknown = sorted(set(joints) - set(self.interface.joint_names))
        if unknown:
            raise ValueError(
                f"the {self.arm} arm has no joints {unknown}; its joints: {list(self.interface.joint_names)}"
            )
        goal = path_goal(self.transport, joints, samples)
        self._run_goal(
            self.interface.trajectory_action, "control_msgs/FollowJointTrajectory", goal, what, timeout=timeout
        )
        return tuple(float(v) for v in samples[-1][1])

    def _reach(self, solution: dict) -> Pose:
        m = self.transport.message
        position = tuple(float(v) for v in solution["position"])
        orientation = solution.get("orientation")
        w, x, y, z = orientation if orientation is not None else (1.0, 0.0, 0.0, 0.0)
        target = m(
            "geometry_msgs/PoseStamped",
            header=self._header(),
            pose=m(
                "geometry_msgs/Pose",
                position=self._point(*position),
                orientation=m("geometry_msgs/Quaternion", x=float(x), y=float(y), z=float(z), w=float(w)),
            ),
        )
        goal = m(
            "pycram_msgs/ReachGoal",
            arm=self.arm,
            target=target,
            use_orientation=orientation is not None,
            tolerance=float(solution.get("tolerance", 0.01)),
        )
        phase = solution.get("phase")
        what = f"reach with the {self.arm} arm to {format_values(position)}" + (
            f" ({phase} of {format_values(solution['target'])})" if phase else ""
        )
        result = self._run_goal(self.interface.reach_action, "pycram_msgs/Reach", goal, what, timeout=30.0)
        p, q = result.reached.position, result.reached.orientation
        return Pose((p.x, p.y, p.z), (q.w, q.x, q.y, q.z))


class RosGripperModule(RosProcessModule):
    """``'cmd': 'set_gripper'`` → a GripperCommand goal (position = opening [m], max_effort [N],
    0 for the gripper's default); returns the measured opening [m] once the joint states (and
    so the gripper-opening fluents) show the gripper after the command."""

    def __init__(
        self, transport: Transport, config: RosRobotConfig, state: RosRobotState, gripper: str, name: str | None = None
    ) -> None:
        super().__init__(name or f"gripper_{gripper}", transport, config, state)
        self.gripper = gripper

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "set_gripper")
        opening = float(solution["opening"])
        effort = solution.get("effort")
        m = self.transport.message
        goal = m(
            "control_msgs/GripperCommandGoal",
            command=m("control_msgs/GripperCommand", position=opening, max_effort=float(effort or 0.0)),
        )
        result = self._run_goal(
            self.config.grippers[self.gripper].action,
            "control_msgs/GripperCommand",
            goal,
            f"set the {self.gripper} gripper to {opening:.3f} m",
            timeout=10.0,
        )
        self.state.wait_fresh(self.state.joint_updates)  # the opening fluents show the result
        return float(result.position)


class RosPerceptionModule(RosProcessModule):
    """``'cmd': 'perceive'``: one look, from the detections topic, folded into the robot's belief
    exactly as the in-process :class:`pycram.robots.common.sim_modules.PerceptionModule` does.

    Takes the first ``pycram_msgs/DetectedItems`` message whose image was taken after the
    request (the second message from then on: the first may show the scene from before it),
    turns it into a :class:`~pycram.world.belief.PerceptionReport`
    (:func:`pycram.backends.ros.detections.report_of`, stamped with the message's ``header.stamp``) and
    calls ``belief.update`` (a :class:`~pycram.world.belief.BeliefState`): new objects are
    added, seen ones refreshed, believed ones that the view says should have been seen but were
    not are marked gone. Returns the believed objects seen (``PerceivedObject``, most visible
    first), restricted by ``'object'`` when given (a type, a belief name or an object
    designator, see :func:`~pycram.robots.common.sim_modules.seen_objects`); the look's
    :class:`~pycram.world.belief.BeliefUpdate` is kept in ``last_update``. Fails with reason
    ``'timeout'`` when no detections arrive within ``timeout`` [s, wall time].
    """

    def __init__(
        self,
        transport: Transport,
        config: RosRobotConfig,
        state: RosRobotState,
        belief: BeliefState,
        name: str = "perception",
        timeout: float = 10.0,
    ) -> None:
        super().__init__(name, transport, config, state)
        self.belief = belief
        self.timeout = timeout
        self.last_update: BeliefUpdate | None = None
        self.detections = MessageCounter()
        self._subscription: Any = None  # subscribed on first use: the bridge renders only for subscribers

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "perceive")
        if self._subscription is None:
            self._subscription = self.transport.subscribe(
                self.config.detections_topic, "pycram_msgs/DetectedItems", self.detections.tick
            )
        # the second message from now: the first may show the scene from before the request
        if not self.detections.wait_for_count(self.detections.count + 2, self.timeout):
            raise RosMotionFailed(
                "perceive", "timeout", f"no detections on {self.config.detections_topic} within {self.timeout:.1f} s"
            )
        message = self.detections.latest
        report = report_of(message, self.transport.time_to_seconds(message.header.stamp))
        update = self.last_update = self.belief.update(report)
        return seen_objects(update, solution.get("object"), report.stamp)

    def close(self) -> None:
        """End the detections subscription (idempotent)."""
        subscription, self._subscription = self._subscription, None
        if subscription is not None:
            subscription.close()
