"""`pycram sim-ros-bridge`: the simulated robot's ROS face -- what a real robot's drivers serve.

A ROS 1 node that runs a :class:`pycram.sim.World` and serves, under the names of the robot's
:class:`~pycram.backends.ros.config.RosRobotConfig` (the PR2's real names by default):

* actions: ``move_base``, the head's PointHead, the torso's SingleJointPosition (PR2) or
  FollowJointTrajectory (TIAGo), each arm's FollowJointTrajectory and Reach, each gripper's
  GripperCommand. An arm's trajectory of one point is a joint goal (``World.move_arm``); of
  several, a timed path followed point by point by the monitored path controller
  (``World.follow_arm_path``: a contact stops it with ``collision``, a lagging joint with
  ``blocked``; see :meth:`SimRosBridge._follow_trajectory`). One goal at a time per action: a
  new goal preempts the running one (the simulator's command is replaced), a cancel request
  stops the part (base stopped, arm holding).
  A failed goal is aborted with the status text ``'<reason>: <message>'`` (the simulator's
  outcome reason: ``collision``, ``blocked``, ``unreachable``, ``timeout``, ``invalid`` ...);
  a malformed goal (wrong frame, unknown joints) is rejected with reason ``invalid``.
* topics, per interval of *simulated* time (as a real robot's drivers publish per interval of
  real time): at every sensor publication of the world (``World.sensor_rate`` [Hz of simulated
  time], 50 Hz by default, and right after a command ended) the base pose (``/amcl_pose``, and
  as the tf transform map -> base_footprint on ``/tf``), ``/joint_states`` (gripper openings as
  the configured opening joints; positions and velocities), ``<sim_namespace>/items``
  (simulator ground truth: where each item is and which gripper holds it -- for judging runs,
  never for plans), and *then*
  ``/clock`` (``rosgraph_msgs/Clock``) with the same simulated time: ROS time never runs ahead
  of the sensor messages already on their way. Every header stamp is simulated time.
  ``detections_topic``: what the head camera's object perception measures (type, centre, size,
  colour, support and container of each object seen, the camera view with its depth image --
  :meth:`pycram.sim.World.detect`, the world's perception faults included; no simulator names
  or true poses), at ``detection_rate`` [Hz of simulated time], only while somebody subscribes
  (rendering costs CPU), stamped with the simulated time of the image.
* service ``<sim_namespace>/command`` (pycram_msgs/SimCommand): the environment's hands
  (``take_item``, ``give_item``) and pictures (``snapshot``).

Security: the node binds to ``ROS_IP``/``ROS_HOSTNAME``; the CLI sets both to 127.0.0.1
unless ``--host`` says otherwise, and refuses a master that is not on loopback unless told.

Time (issue 31): the bridge sets ``/use_sim_time`` (the launcher of
:mod:`pycram.backends.ros.launch` sets it already when it starts roscore), so every ROS node
started afterwards -- the plan's process included -- reads its time from ``/clock``. The
simulation runs free (``stepping="free"``: the plan is in another process, its thinking cannot
be seen from here), as fast as it can or paced to wall time (``realtime``).

Keeping step with the client: the sensor messages of one instant go to rospy *in the simulation
thread*, sensor topics first and ``/clock`` last. While a client is connected to
``sensor_ack_topic`` (PyCRAM's :class:`~pycram.backends.ros.modules.RosRobotState` acknowledges
each instant once its fluents and its clock show it), the simulation publishes the next instant
only after the client acknowledged the previous one. It waits on a condition, with no time limit
for as long as the client stays connected: the simulation never runs ahead of the plan's process
by more than one sensor period, whatever the load. An instant not acknowledged within
:data:`RESEND_AFTER` [s, wall] is published again (a client that subscribed after it went out,
or whose acknowledgement went out before the bridge was connected to it, never saw it); a wait
longer than :data:`WARN_AFTER` [s, wall] is logged at WARNING, and so is a client that
disconnects while the simulation waits for it (then it goes on without waiting). When an
acknowledgement arrives while the bridge was not keeping step (the first one, or the first after
a client disconnected), the bridge publishes on ``<sim_namespace>/keeping_step``
(``rosgraph_msgs/Clock``, latched) the simulated time of the instant last published: every
instant after it goes out only once the client acknowledged the one before.

Without acknowledgements the simulation outruns a client and rospy subscribers keep only the
newest of what piled up: the joint states seen jumped by 0.76-0.86 s of simulated time. Nothing
else ever waits for a subscriber: rospy's publishers (``queue_size=1``) drop older messages for a
slow one. The cost: one round trip per instant; the PR2 kitchen ran at 9-16x real time with the
test client keeping step, idle (5-11x beside two CPU-burning processes on two cores).
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, cast

import actionlib
import rospy

from pycram.backends.ros.config import RosRobotConfig
from pycram.backends.ros.detections import detections_message
from pycram.backends.ros.ros1 import message_class
from pycram.backends.sim.items import ItemSpec
from pycram.backends.sim.perception import PerceptionFaults
from pycram.world.types import Outcome, Pose2D, Vec3

__all__ = ["SimRosBridge", "RESEND_AFTER", "WARN_AFTER"]

logger = logging.getLogger(__name__)

#: After how long without a client's acknowledgement [s of wall time] the bridge publishes the
#: sensor instant again (and keeps waiting).
RESEND_AFTER = 0.5
#: After how long without a client's acknowledgement [s of wall time] the wait is logged (WARNING).
WARN_AFTER = 5.0


@dataclass(frozen=True)
class _Instant:
    """The world's sensors at one instant of simulated ``time`` [s], as the bridge publishes them."""

    time: float
    base_pose: Pose2D
    joint_states: Any
    gripper_openings: dict[str, float]  # [m]
    holding: dict[str, str | None]  # gripper -> item held
    item_poses: dict[str, Any]


class _Rejected(Exception):
    """A goal the bridge cannot execute (wrong frame, unknown joints)."""


class _GoalServer:
    """One action: a goal starts a simulator command; its outcome ends the goal."""

    def __init__(
        self,
        name: str,
        action_type: str,
        start: Callable[..., Any],  # start(goal); `...`: the lambdas passed bind loop values as defaults
        make_result: Callable[[Outcome], Any],
    ) -> None:
        self.name = name
        self._start, self._make_result = start, make_result
        self._lock = threading.Lock()
        self._running: dict[str, tuple[Any, Any]] = {}  # goal id -> (server goal handle, sim handle)
        self._server = actionlib.ActionServer(
            name, message_class(action_type + "Action"), self._on_goal, self._on_cancel, auto_start=False
        )
        self._server.start()

    def _on_goal(self, goal_handle: Any) -> None:
        try:
            sim_handle = self._start(goal_handle.get_goal())
        except (_Rejected, ValueError, KeyError) as e:
            goal_handle.set_rejected(text=f"invalid: {e}")
            return
        goal_id = goal_handle.get_goal_id().id
        with self._lock:
            self._running[goal_id] = (goal_handle, sim_handle)
        goal_handle.set_accepted()
        threading.Thread(
            target=self._finish, args=(goal_id, goal_handle, sim_handle), name=f"bridge {self.name}", daemon=True
        ).start()

    def _finish(self, goal_id: str, goal_handle: Any, sim_handle: Any) -> None:
        outcome = sim_handle.wait()  # the simulator ends every command (closing ends it "closed")
        with self._lock:
            self._running.pop(goal_id, None)
        text = f"{outcome.reason}: {outcome.message}"
        try:
            result = self._make_result(outcome)
            if outcome.succeeded:
                goal_handle.set_succeeded(result, text)
            elif outcome.reason in ("cancelled", "preempted"):
                goal_handle.set_canceled(result, text)
            else:
                goal_handle.set_aborted(result, text)
        except Exception:  # e.g. the node shutting down
            logger.debug("could not report the outcome of %s", self.name, exc_info=True)

    def _on_cancel(self, goal_handle: Any) -> None:
        with self._lock:
            entry = self._running.get(goal_handle.get_goal_id().id)
        if entry is not None:
            entry[1].cancel()


class SimRosBridge:
    """Serve ``world`` (a running :class:`pycram.sim.World`) over ROS under ``config``'s names.

    The ROS node must be initialised (``rospy.init_node``) before. The sensor topics and
    ``/clock`` go out at every sensor publication of ``world`` (its ``sensor_rate`` [Hz of
    simulated time]), from the simulation thread (see the module docstring); the detections at
    ``detection_rate`` [Hz of simulated time] (0: never) while somebody subscribes. While a
    client is connected to ``config.sensor_ack_topic``, the simulation waits until it
    acknowledged the previous instant (``resend_after`` [s, wall]: see :data:`RESEND_AFTER`).
    :meth:`close` stops publishing; the world is the caller's to close.
    """

    def __init__(
        self, world: Any, config: RosRobotConfig, detection_rate: float = 2.0, resend_after: float = RESEND_AFTER
    ) -> None:
        if config.robot != world.robot:
            raise ValueError(f"ROS configuration of {config.robot!r} for a world with {world.robot!r}")
        self.world, self.config = world, config
        c, w = config, world
        self._servers = [
            _GoalServer(
                c.move_base_action,
                "move_base_msgs/MoveBase",
                self._drive,
                lambda o: message_class("move_base_msgs/MoveBaseResult")(),
            ),
            _GoalServer(
                c.head_action,
                "control_msgs/PointHead",
                self._point_head,
                lambda o: message_class("control_msgs/PointHeadResult")(),
            ),
        ]
        if c.torso_interface == "single_joint_position":
            self._servers.append(
                _GoalServer(
                    c.torso_action,
                    "control_msgs/SingleJointPosition",
                    lambda goal: w.set_torso(float(goal.position)),
                    lambda o: message_class("control_msgs/SingleJointPositionResult")(),
                )
            )
        else:
            self._servers.append(
                _GoalServer(
                    c.torso_action,
                    "control_msgs/FollowJointTrajectory",
                    lambda goal: w.set_torso(self._trajectory_end(goal, (c.torso_joint,))[0]),
                    self._trajectory_result,
                )
            )
        for arm, interface in c.arms.items():
            self._servers.append(
                _GoalServer(
                    interface.trajectory_action,
                    "control_msgs/FollowJointTrajectory",
                    lambda goal, a=arm, j=interface.joint_names: self._follow_trajectory(a, j, goal),
                    self._trajectory_result,
                )
            )
            self._servers.append(
                _GoalServer(
                    interface.reach_action,
                    "pycram_msgs/Reach",
                    lambda goal, a=arm: self._reach(a, goal),
                    self._reach_result,
                )
            )
        for gripper, gripper_interface in c.grippers.items():
            self._servers.append(
                _GoalServer(
                    gripper_interface.action,
                    "control_msgs/GripperCommand",
                    lambda goal, g=gripper: w.set_gripper(
                        g,
                        float(goal.command.position),
                        float(goal.command.max_effort) if goal.command.max_effort > 0 else None,
                    ),
                    self._gripper_result,
                )
            )
        msg = message_class
        self._clock_cls, self._pose_cls = msg("rosgraph_msgs/Clock"), msg("geometry_msgs/PoseWithCovarianceStamped")
        self._transform_cls, self._joints_cls = msg("geometry_msgs/TransformStamped"), msg("sensor_msgs/JointState")
        self._items_cls, self._item_cls = msg("pycram_msgs/ItemStates"), msg("pycram_msgs/ItemState")
        # rospy's queued publishers: `publish` hands a message to each subscriber's writer thread
        # and never waits for a subscriber (one that cannot keep up gets the newest message).
        self._clock_pub = rospy.Publisher(c.clock_topic, self._clock_cls, queue_size=1)
        self._pose_pub = rospy.Publisher(c.pose_topic, self._pose_cls, queue_size=1)
        self._joints_pub = rospy.Publisher(c.joint_states_topic, self._joints_cls, queue_size=1)
        self._items_pub = rospy.Publisher(f"{c.sim_namespace}/items", self._items_cls, queue_size=1)
        self._detections_pub = rospy.Publisher(c.detections_topic, msg("pycram_msgs/DetectedItems"), queue_size=1)
        import tf2_ros

        self._tf = tf2_ros.TransformBroadcaster()
        self._service = rospy.Service(
            f"{c.sim_namespace}/command", msg("pycram_msgs/SimCommand", "srv"), self._on_command
        )
        rospy.set_param("/use_sim_time", True)
        self._stop = threading.Event()
        self._publish_lock = threading.Lock()  # one instant at a time, in order
        # Keeping step with the ROS client: PyCRAM's ROS robot acknowledges each sensor instant it
        # has taken in (see `pycram.backends.ros.modules.RosRobotState`).
        self._resend_after = float(resend_after)
        self._ack_cv = threading.Condition()
        self._acked = -1  # the newest instant a client acknowledged [ns, simulated]
        self._keeping_step = False  # acknowledgements come (since the last disconnection)
        self._keeping_step_pub = rospy.Publisher(
            f"{c.sim_namespace}/keeping_step", self._clock_cls, queue_size=1, latch=True
        )
        self._ack_sub = rospy.Subscriber(c.sensor_ack_topic, self._clock_cls, self._on_ack, queue_size=1)
        self._last_clock = -math.inf  # the simulated time last published on /clock [s]
        self._last_clock_ns = -1  # the same, as published [ns]
        self._last_instant: _Instant | None = None  # the instant last published
        #: sensor instants published (each: the sensor topics, then /clock), resends not counted
        self.published = 0
        #: acknowledgements received; instants published while no client was connected; waits
        #: for an acknowledgement; instants published again (see :data:`RESEND_AFTER`)
        self.acks = self.unacknowledged = self.waits = self.resent = 0
        # detections: a thread woken (condition, no polling) when simulated time reaches the next look
        self._detection_period = 1.0 / detection_rate if detection_rate > 0 else math.inf
        self._next_detection = 0.0
        self._detection_cv = threading.Condition()
        self._publish(self._sample())
        # Every sensor publication of the world ends by setting `item_poses` (after `sim_time`,
        # `base_pose`, `joint_states`, `gripper_*` and `tool_poses`): its change callback runs in
        # the simulation thread with the whole instant in the fluents.
        self._hook = w.item_poses.on_change(self._on_sensor_instant)
        self._threads: list[threading.Thread] = []
        if detection_rate > 0:
            self._threads.append(threading.Thread(target=self._detection_loop, name="bridge-detections", daemon=True))
        for thread in self._threads:
            thread.start()
        logger.info(
            "sim-ros-bridge for %s: serving %d actions; sensor topics and %s every %.3f s of simulated time",
            c.robot,
            len(self._servers),
            c.clock_topic,
            getattr(w, "_sensor_period", float("nan")),
        )

    # -- goals → simulator commands ------------------------------------------------------------
    def _check_frame(self, header: Any, what: str) -> None:
        if header.frame_id not in ("", self.config.map_frame):
            raise _Rejected(f"{what} must be given in the {self.config.map_frame!r} frame, not {header.frame_id!r}")

    def _drive(self, goal: Any) -> Any:
        self._check_frame(goal.target_pose.header, "a move_base goal")
        p, q = goal.target_pose.pose.position, goal.target_pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        return self.world.move_base(Pose2D(p.x, p.y, yaw))

    def _point_head(self, goal: Any) -> Any:
        self._check_frame(goal.target.header, "a point_head target")
        p = goal.target.point
        return self.world.point_head((p.x, p.y, p.z))

    @staticmethod
    def _trajectory_end(goal: Any, joints: tuple[str, ...]) -> list[float]:
        """The last point's positions of ``goal``'s trajectory, in the order of ``joints``."""
        names = list(goal.trajectory.joint_names)
        if sorted(names) != sorted(joints) or not goal.trajectory.points:
            raise _Rejected(f"a trajectory for joints {list(joints)} with at least one point, got joints {names}")
        positions = dict(zip(names, goal.trajectory.points[-1].positions))
        return [float(positions[j]) for j in joints]

    def _follow_trajectory(self, arm: str, joints: tuple[str, ...], goal: Any) -> Any:
        """An arm's FollowJointTrajectory goal: one point -> the joint goal (``World.move_arm``:
        interpolated from where the arm is); more -> the timed path through every point
        (``World.follow_arm_path``: the simulated controller follows the points' positions at
        their ``time_from_start``, from the arm's current positions at t = 0 when the first
        point comes later; it stops the arm on a contact of the arm or of what its gripper holds
        -- ``'collision'`` -- or on a joint lagging its reference -- ``'blocked'``). The object
        being grasped cannot be named in a FollowJointTrajectory goal: only what the gripper
        touches when the path starts is exempt from the contact monitoring."""
        names = list(goal.trajectory.joint_names)
        points = goal.trajectory.points
        if sorted(names) != sorted(joints) or not points:
            raise _Rejected(f"a trajectory for joints {list(joints)} with at least one point, got joints {names}")
        if len(points) == 1:
            return self.world.move_arm(arm, self._trajectory_end(goal, joints))
        samples = [(p.time_from_start.to_sec(), [float(v) for v in p.positions]) for p in points]
        if samples[0][0] > 0.0:
            now = self.world.joint_states.get_value().position
            samples.insert(0, (0.0, [float(now[j]) for j in names]))
        return self.world.follow_arm_path(arm, names, samples)

    @staticmethod
    def _trajectory_result(outcome: Outcome) -> Any:
        cls = message_class("control_msgs/FollowJointTrajectoryResult")
        if outcome.succeeded:
            code = cls.SUCCESSFUL
        elif outcome.reason in ("collision", "blocked"):
            code = cls.PATH_TOLERANCE_VIOLATED
        elif outcome.reason == "invalid":
            code = cls.INVALID_GOAL
        else:
            code = cls.GOAL_TOLERANCE_VIOLATED
        return cls(error_code=code, error_string="" if outcome.succeeded else outcome.message)

    def _reach(self, arm: str, goal: Any) -> Any:
        self._check_frame(goal.target.header, "a reach target")
        p, q = goal.target.pose.position, goal.target.pose.orientation
        orientation = (q.w, q.x, q.y, q.z) if goal.use_orientation else None
        return self.world.reach(
            arm, (p.x, p.y, p.z), orientation, tolerance=float(goal.tolerance) if goal.tolerance > 0 else 0.01
        )

    def _reach_result(self, outcome: Outcome) -> Any:
        result = message_class("pycram_msgs/ReachResult")()
        if outcome.succeeded and outcome.value is not None:
            result.reached = _pose_msg(outcome.value)
        return result

    @staticmethod
    def _gripper_result(outcome: Outcome) -> Any:
        opening = float(outcome.value) if isinstance(outcome.value, (int, float)) else 0.0
        return message_class("control_msgs/GripperCommandResult")(position=opening, reached_goal=outcome.succeeded)

    # -- topics ---------------------------------------------------------------------------------
    def _sample(self) -> _Instant:
        """The world's sensor fluents as they are now (cheap: references to immutable values)."""
        w = self.world
        return _Instant(
            float(w.sim_time.get_value()),
            w.base_pose.get_value(),
            w.joint_states.get_value(),
            {g: float(f.get_value()) for g, f in w.gripper_openings.items()},
            {g: f.get_value().holding for g, f in w.gripper_states.items()},
            w.item_poses.get_value(),
        )

    def _on_ack(self, message: Any) -> None:
        t = message.clock.to_nsec()
        with self._ack_cv:
            self.acks += 1
            # an instant not (yet) published here is no acknowledgement (a client still on the
            # instants of an earlier simulator)
            if t > self._last_clock_ns:
                return
            if t > self._acked:
                self._acked = t
                self._ack_cv.notify_all()
            if self._keeping_step:
                return
            self._keeping_step = True
            since = self._last_clock_ns
        caller = getattr(message, "_connection_header", {}).get("callerid", "?")
        logger.info("sim-ros-bridge: keeping step with the client %s after t=%.3f s", caller, since / 1e9)
        self._keeping_step_pub.publish(self._clock_cls(clock=rospy.Time(nsecs=since)))

    def _client_connected(self) -> bool:
        return bool(self._ack_sub.get_num_connections())

    def _wait_for_client(self) -> None:
        """Simulation thread, before it publishes the next instant: while a client is connected
        to the acknowledgements, wait until it acknowledged the instant last published --
        publishing it again every ``resend_after`` [s, wall] without one; going on when the client
        disconnects (see the module docstring)."""
        if not self._client_connected():
            self.unacknowledged += 1
            with self._ack_cv:
                self._keeping_step = False
            return
        waited, warned = 0.0, False
        with self._ack_cv:
            if self._acked >= self._last_clock_ns:
                return
            self.waits += 1
        while True:
            with self._ack_cv:
                if self._ack_cv.wait_for(
                    lambda: self._stop.is_set() or self._acked >= self._last_clock_ns, self._resend_after
                ):
                    break
            waited += self._resend_after
            if not self._client_connected():
                with self._ack_cv:
                    self._keeping_step = False
                logger.warning(
                    "sim-ros-bridge: the client on %s disconnected without acknowledging t=%.3f s: "
                    "the simulation goes on without waiting",
                    self.config.sensor_ack_topic,
                    self._last_clock,
                )
                return
            if waited >= WARN_AFTER and not warned:
                warned = True
                logger.warning(
                    "sim-ros-bridge: the simulation waits since %.1f s of wall time for the client on %s "
                    "to acknowledge t=%.3f s (it stays connected); publishing that instant again every %.2f s",
                    waited,
                    self.config.sensor_ack_topic,
                    self._last_clock,
                    self._resend_after,
                )
            if self._last_instant is not None:
                self.resent += 1
                with self._publish_lock:
                    self._publish_locked(self._last_instant, resend=True)

    def _on_sensor_instant(self, _item_poses: Any) -> None:
        """The world published its sensors (simulation thread): wait until the client took in the
        previous instant (:meth:`_wait_for_client`), publish this one over ROS before the
        simulation takes its next step, and wake the detections when their simulated time has
        come. Never raises (a failure is logged; the simulation goes on)."""
        if self._stop.is_set():
            return
        self._wait_for_client()
        instant = self._sample()
        try:
            self._publish(instant)
        except Exception:  # e.g. the node shutting down
            if not (self._stop.is_set() or rospy.is_shutdown()):
                logger.exception("sim-ros-bridge: publishing failed")
            return
        if instant.time >= self._next_detection:
            with self._detection_cv:
                self._detection_cv.notify_all()

    def _publish(self, instant: _Instant) -> None:
        """Publish ``instant``: base pose (and its tf), joint states, item states, each stamped with
        its simulated time, then ``/clock`` with that time (never backwards: an instant older
        than the last published is skipped)."""
        with self._publish_lock:
            self._publish_locked(instant)

    def _publish_locked(self, instant: _Instant, resend: bool = False) -> None:
        c = self.config
        t = instant.time
        if t < self._last_clock:
            return
        stamp = rospy.Time.from_sec(t)
        base = instant.base_pose
        pose = self._pose_cls()
        pose.header.stamp, pose.header.frame_id = stamp, c.map_frame
        pose.pose.pose.position.x, pose.pose.pose.position.y = base.x, base.y
        pose.pose.pose.orientation.z = math.sin(base.yaw / 2)
        pose.pose.pose.orientation.w = math.cos(base.yaw / 2)
        self._pose_pub.publish(pose)
        transform = self._transform_cls()
        transform.header.stamp, transform.header.frame_id = stamp, c.map_frame
        transform.child_frame_id = c.base_frame
        transform.transform.translation.x, transform.transform.translation.y = base.x, base.y
        transform.transform.rotation = pose.pose.pose.orientation
        self._tf.sendTransform(transform)
        positions = dict(instant.joint_states.position)
        for gripper, interface in c.grippers.items():
            opening = instant.gripper_openings[gripper]
            for joint in interface.opening_joints:
                positions[joint] = opening / len(interface.opening_joints)
        speeds = instant.joint_states.velocity
        joints = self._joints_cls(
            name=list(positions),
            position=list(positions.values()),
            velocity=[float(speeds.get(name, 0.0)) for name in positions],
        )
        joints.header.stamp = stamp
        self._joints_pub.publish(joints)
        holders = {item: g for g, item in instant.holding.items()}
        items = self._items_cls()
        items.header.stamp, items.header.frame_id = stamp, c.map_frame
        items.items = [
            self._item_cls(name=name, pose=_pose_msg(p), held_by=holders.get(name, ""))
            for name, p in instant.item_poses.items()
        ]
        self._items_pub.publish(items)
        if t > self._last_clock or resend:  # last: ROS time never runs ahead of the sensor messages
            with self._ack_cv:  # before it goes out: its acknowledgement may come at once
                self._last_clock, self._last_clock_ns = t, stamp.to_nsec()
            self._clock_pub.publish(self._clock_cls(clock=stamp))
        self._last_instant = instant
        if not resend:
            self.published += 1

    def _detection_loop(self) -> None:
        """Every ``1 / detection_rate`` s of simulated time, while somebody subscribes to the
        detections topic, one look of the head camera (:meth:`_publish_detections`). Waits on a
        condition that the simulation thread notifies when the time has come (no polling)."""
        while not self._stop.is_set():
            with self._detection_cv:
                while not self._stop.is_set() and float(self.world.sim_time.get_value()) < self._next_detection:
                    self._detection_cv.wait()
            if self._stop.is_set():
                return
            self._next_detection = float(self.world.sim_time.get_value()) + self._detection_period
            try:
                self._publish_detections()
            except Exception:  # e.g. the node shutting down, the world closed
                if self._stop.is_set() or rospy.is_shutdown():
                    return
                logger.exception("sim-ros-bridge: publishing detections failed")

    def _publish_detections(self) -> None:
        """One look of the head camera (:meth:`pycram.sim.World.detect`: measured detections,
        the world's perception faults included, no simulator names or true poses) as a
        ``pycram_msgs/DetectedItems``, stamped with the simulated time of the image."""
        if self._detections_pub.get_num_connections() == 0:
            return
        outcome = self.world.detect().wait(10.0)
        if outcome is None or not outcome.succeeded:
            return
        report = outcome.value
        message = detections_message(report, lambda t, **f: message_class(t)(**f), self.config.map_frame)
        message.header.stamp = rospy.Time.from_sec(report.stamp)
        message.depth.header.stamp = message.header.stamp
        self._detections_pub.publish(message)

    # -- the environment's hands ----------------------------------------------------------------
    def _on_command(self, request: Any) -> Any:
        response = message_class("pycram_msgs/SimCommand", "srv")._response_class
        try:
            if request.command == "take_item":
                handle = self.world.take_item(gripper=request.gripper or None, item=request.item or None)
            elif request.command == "give_item":
                handle = self.world.give_item(
                    request.item,
                    request.gripper,
                    close=request.close,
                    timeout=request.timeout if request.timeout > 0 else 5.0,
                )
            elif request.command == "snapshot":
                self.world.snapshot(request.item)
                return response(success=True, reason="succeeded", message=request.item, value=request.item)
            else:
                return response(
                    success=False,
                    reason="invalid",
                    message=f"unknown command {request.command!r}; available: take_item, give_item, snapshot",
                )
        except Exception as e:  # an unknown item or gripper: say so to the caller
            return response(success=False, reason="invalid", message=str(e))
        outcome = handle.wait(request.wait if request.wait > 0 else None)
        if outcome is None:
            return response(success=True, reason="running", message=f"{request.command} still running")
        return response(
            success=outcome.succeeded,
            reason=outcome.reason,
            message=outcome.message,
            value="" if outcome.value is None else str(outcome.value),
        )

    def close(self) -> None:
        """Stop publishing (the simulation thread's hook is removed; the detections thread is
        joined) and the service (idempotent)."""
        self._stop.set()
        self._hook.remove()
        with self._ack_cv:
            self._ack_cv.notify_all()
        self._ack_sub.unregister()
        logger.info(
            "sim-ros-bridge: %d sensor instants published (%d without a client acknowledging), "
            "%d acknowledgements received, %d waits for one, %d instants published again",
            self.published,
            self.unacknowledged,
            self.acks,
            self.waits,
            self.resent,
        )
        with self._detection_cv:
            self._detection_cv.notify_all()
        for thread in self._threads:
            thread.join(5.0)
        self._service.shutdown()


def _pose_msg(pose: Any) -> Any:
    msg = message_class("geometry_msgs/Pose")()
    msg.position.x, msg.position.y, msg.position.z = pose.position
    msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z = pose.orientation
    return msg


def _keep_wall_time() -> None:
    """Make this process's rospy keep wall time although ``/use_sim_time`` is set: the bridge is
    the source of ``/clock``, and its own timers -- the action servers' status heartbeats, which
    the ROS process modules judge in wall time to tell a dead server (2 s) -- must not speed up
    or stall with the simulation. rospy offers no option for it: undo what ``init_node`` did
    (its ``/clock`` subscriber, the simulated time source)."""
    from rospy.impl import simtime

    subscriber = getattr(simtime, "_clock_sub", None)
    if subscriber is not None:
        subscriber.unregister()
        simtime._clock_sub = None
    rospy.rostime.switch_to_wallclock()


def run_bridge(
    robot: str,
    items: Sequence[ItemSpec],
    base_pose: tuple[float, float, float] | None,
    realtime: bool = False,
    publish_rate: float = 50.0,
    detection_rate: float = 2.0,
    ready: Callable[[], None] | None = None,
    perception_faults: PerceptionFaults | None = None,
    environment: str = "thesis-kitchen",
) -> None:
    """Run the bridge until the node is shut down (SIGINT/SIGTERM): builds ``environment`` (an
    environment's name, :mod:`pycram.environments`; the thesis kitchen by default) with ``robot``
    at ``base_pose`` (x [m], y [m], yaw [rad]; None: the environment's start pose) and ``items``
    (the demo's mug: see ``pycram sim-ros-bridge``), the head camera's object perception with
    ``perception_faults`` (none by default), and serves it under the robot's default ROS
    configuration with its ``environment`` set to ``environment``. Initialises the ROS node
    ``sim_ros_bridge`` (on wall time: see :func:`_keep_wall_time`) and sets ``/use_sim_time``
    for every other node.

    ``publish_rate``: sensor topics and ``/clock`` per second of *simulated* time [Hz] (the
    world's ``sensor_rate``); ``detection_rate``: looks of the head camera per second of
    simulated time [Hz] while somebody subscribes. ``realtime``: pace the simulation to wall
    time (else as fast as it can). ``ready()`` is called once everything is served."""
    from pycram.backends.ros.config import robot_config
    from pycram.backends.sim.world import World

    if publish_rate <= 0:
        raise ValueError(f"publish_rate must be > 0 [Hz of simulated time], not {publish_rate!r}")
    config = robot_config(robot).replace(environment=environment)
    rospy.init_node("sim_ros_bridge", disable_signals=False)
    _keep_wall_time()
    world = World(
        robot,
        list(items),
        environment=environment,
        base_pose=None if base_pose is None else cast(Vec3, tuple(base_pose)),
        realtime=realtime,
        sensor_rate=publish_rate,
        perception_faults=perception_faults,
        stepping="free",  # the plan runs in another process: the bridge cannot see when it thinks
    )
    bridge = None
    try:
        bridge = SimRosBridge(world, config, detection_rate)
        if ready is not None:
            ready()
        rospy.spin()
    finally:
        if bridge is not None:
            bridge.close()
        world.close()
