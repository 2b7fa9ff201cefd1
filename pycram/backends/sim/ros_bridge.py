"""`pycram sim-ros-bridge`: the simulated robot's ROS face -- what a real robot's drivers serve.

A ROS 1 node that runs a :class:`pycram.sim.World` and serves, under the names of the robot's
:class:`~pycram.backends.ros.config.RosRobotConfig` (the PR2's real names by default):

* actions: ``move_base``, the head's PointHead, the torso's SingleJointPosition (PR2) or
  FollowJointTrajectory (TIAGo), each arm's FollowJointTrajectory and Reach, each gripper's
  GripperCommand. One goal at a time per action: a new goal preempts the running one (the
  simulator's command is replaced), a cancel request stops the part (base stopped, arm holding).
  A failed goal is aborted with the status text ``'<reason>: <message>'`` (the simulator's
  outcome reason: ``collision``, ``blocked``, ``unreachable``, ``timeout``, ``invalid`` ...);
  a malformed goal (wrong frame, unknown joints) is rejected with reason ``invalid``.
* topics, at ``publish_rate`` [Hz of wall time]: ``/clock`` (simulation time; the bridge sets
  ``/use_sim_time``), the base pose (``/amcl_pose``, and as the tf transform map ->
  base_footprint on ``/tf``), ``/joint_states`` (gripper openings as
  the configured opening joints), and ``<sim_namespace>/items`` (simulator ground truth:
  where each item is and which gripper holds it -- for judging runs, never for plans).
  ``detections_topic``: what the head camera's object perception measures (type, centre, size,
  colour, support and container of each object seen, the camera view with its depth image --
  :meth:`pycram.sim.World.detect`, the world's perception faults included; no simulator names
  or true poses), at ``detection_rate`` [Hz], only while somebody subscribes (rendering costs
  CPU).
* service ``<sim_namespace>/command`` (pycram_msgs/SimCommand): the environment's hands
  (``take_item``, ``give_item``) and pictures (``snapshot``).

Security: the node binds to ``ROS_IP``/``ROS_HOSTNAME``; the CLI sets both to 127.0.0.1
unless ``--host`` says otherwise, and refuses a master that is not on loopback unless told.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Sequence
from typing import Any, cast

import actionlib
import rospy

from pycram.backends.ros.config import RosRobotConfig
from pycram.backends.ros.detections import detections_message
from pycram.backends.ros.ros1 import message_class
from pycram.backends.sim.items import ItemSpec
from pycram.backends.sim.perception import PerceptionFaults
from pycram.world.types import Outcome, Pose2D, Vec3

__all__ = ["SimRosBridge"]

logger = logging.getLogger(__name__)


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

    The ROS node must be initialised (``rospy.init_node``) before. :meth:`close` stops the
    rate loops; the world is the caller's to close.
    """

    def __init__(
        self, world: Any, config: RosRobotConfig, publish_rate: float = 50.0, detection_rate: float = 2.0
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
                    lambda goal, a=arm, j=interface.joint_names: w.move_arm(a, self._trajectory_end(goal, j)),
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
        self._clock_pub = rospy.Publisher(c.clock_topic, message_class("rosgraph_msgs/Clock"), queue_size=1)
        self._pose_pub = rospy.Publisher(
            c.pose_topic, message_class("geometry_msgs/PoseWithCovarianceStamped"), queue_size=1
        )
        self._joints_pub = rospy.Publisher(c.joint_states_topic, message_class("sensor_msgs/JointState"), queue_size=1)
        self._items_pub = rospy.Publisher(
            f"{c.sim_namespace}/items", message_class("pycram_msgs/ItemStates"), queue_size=1
        )
        self._detections_pub = rospy.Publisher(
            c.detections_topic, message_class("pycram_msgs/DetectedItems"), queue_size=1
        )
        import tf2_ros

        self._tf = tf2_ros.TransformBroadcaster()
        self._service = rospy.Service(
            f"{c.sim_namespace}/command", message_class("pycram_msgs/SimCommand", "srv"), self._on_command
        )
        rospy.set_param("/use_sim_time", True)
        self._publish()
        # Rate loops in wall time (not rospy.Timer: with /use_sim_time set by an earlier bridge,
        # rospy's timers would wait for a /clock that only this bridge publishes).
        self._stop = threading.Event()
        self._threads = [
            threading.Thread(
                target=self._every, args=(1.0 / publish_rate, self._publish), name="bridge-publish", daemon=True
            )
        ]
        if detection_rate > 0:
            self._threads.append(
                threading.Thread(
                    target=self._every,
                    args=(1.0 / detection_rate, self._publish_detections),
                    name="bridge-detections",
                    daemon=True,
                )
            )
        for thread in self._threads:
            thread.start()
        logger.info("sim-ros-bridge for %s: serving %d actions", c.robot, len(self._servers))

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

    @staticmethod
    def _trajectory_result(outcome: Outcome) -> Any:
        cls = message_class("control_msgs/FollowJointTrajectoryResult")
        code = cls.SUCCESSFUL if outcome.succeeded else cls.GOAL_TOLERANCE_VIOLATED
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
    def _publish(self) -> None:
        w, c = self.world, self.config
        stamp = rospy.Time.from_sec(w.sim_time.get_value())
        self._clock_pub.publish(message_class("rosgraph_msgs/Clock")(clock=stamp))
        base = w.base_pose.get_value()
        pose = message_class("geometry_msgs/PoseWithCovarianceStamped")()
        pose.header.stamp, pose.header.frame_id = stamp, c.map_frame
        pose.pose.pose.position.x, pose.pose.pose.position.y = base.x, base.y
        pose.pose.pose.orientation.z, pose.pose.pose.orientation.w = math.sin(base.yaw / 2), math.cos(base.yaw / 2)
        self._pose_pub.publish(pose)
        transform = message_class("geometry_msgs/TransformStamped")()
        transform.header.stamp, transform.header.frame_id = stamp, c.map_frame
        transform.child_frame_id = c.base_frame
        transform.transform.translation.x, transform.transform.translation.y = base.x, base.y
        transform.transform.rotation = pose.pose.pose.orientation
        self._tf.sendTransform(transform)
        positions = dict(w.joint_states.get_value().position)
        for gripper, interface in c.grippers.items():
            opening = float(w.gripper_openings[gripper].get_value())
            for joint in interface.opening_joints:
                positions[joint] = opening / len(interface.opening_joints)
        joints = message_class("sensor_msgs/JointState")(name=list(positions), position=list(positions.values()))
        joints.header.stamp = stamp
        self._joints_pub.publish(joints)
        holders = {state.get_value().holding: g for g, state in w.gripper_states.items()}
        items = message_class("pycram_msgs/ItemStates")()
        items.header.stamp, items.header.frame_id = stamp, c.map_frame
        items.items = [
            message_class("pycram_msgs/ItemState")(name=name, pose=_pose_msg(p), held_by=holders.get(name, ""))
            for name, p in w.item_poses.get_value().items()
        ]
        self._items_pub.publish(items)

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

    def _every(self, period: float, publish: Callable[[], None]) -> None:
        """Call ``publish`` every ``period`` [s, wall] until :meth:`close`."""
        while not self._stop.wait(period):
            try:
                publish()
            except Exception:  # e.g. the node shutting down, the world closed
                if self._stop.is_set() or rospy.is_shutdown():
                    return
                logger.exception("sim-ros-bridge: publishing failed")

    def close(self) -> None:
        """Stop publishing (joins the rate loops) and the service (idempotent)."""
        self._stop.set()
        for thread in self._threads:
            thread.join(5.0)
        self._service.shutdown()


def _pose_msg(pose: Any) -> Any:
    msg = message_class("geometry_msgs/Pose")()
    msg.position.x, msg.position.y, msg.position.z = pose.position
    msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z = pose.orientation
    return msg


def run_bridge(
    robot: str,
    items: Sequence[ItemSpec],
    base_pose: tuple[float, float, float],
    realtime: bool = False,
    publish_rate: float = 50.0,
    detection_rate: float = 2.0,
    ready: Callable[[], None] | None = None,
    perception_faults: PerceptionFaults | None = None,
) -> None:
    """Run the bridge until the node is shut down (SIGINT/SIGTERM): builds the thesis kitchen with
    ``robot`` at ``base_pose`` (x [m], y [m], yaw [rad]) and ``items`` (the demo's mug: see
    ``pycram sim-ros-bridge``), the head camera's object perception with ``perception_faults``
    (none by default). Initialises the ROS node ``sim_ros_bridge``. ``ready()`` is called once
    everything is served."""
    from pycram.backends.ros.config import robot_config
    from pycram.backends.sim.world import World

    config = robot_config(robot)
    rospy.init_node("sim_ros_bridge", disable_signals=False)
    world = World(
        robot,
        list(items),
        base_pose=cast(Vec3, tuple(base_pose)),
        realtime=realtime,
        perception_faults=perception_faults,
    )
    bridge = None
    try:
        bridge = SimRosBridge(world, config, publish_rate, detection_rate)
        if ready is not None:
            ready()
        rospy.spin()
    finally:
        if bridge is not None:
            bridge.close()
        world.close()
