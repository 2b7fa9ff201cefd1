"""Planned arm motions over ROS: planned in the believed world, sent as joint trajectories.

:class:`RosPlannedArmModule` is the ROS robot's arm process module with motion planning: for
``move_arm`` (a joint goal) and ``reach`` (a tool pose) it runs the simulated robots' planner,
:class:`pycram.robots.common.arm_motion.ArmMotionPlanner` (IK and a collision-free path from
:class:`~pycram.reasoning.motion.OMPLPlanner` in the robot's prospection -- the world it believes
in, :mod:`pycram.robots.common.ros_prospection` --, timed by
:func:`~pycram.reasoning.motion.time_parameterize`, re-planned after a stop), against the robot as
its ROS topics show it (:class:`RosArmWorld`), and sends each timed path as **one**
``control_msgs/FollowJointTrajectory`` goal with every sample as a trajectory point
(:meth:`~pycram.backends.ros.modules.RosArmModule.follow_path`). What the planner executes "the
direct way" (contact motions, the ``place`` phase, no path found, the base or torso moving) is
the plain ROS goal of :class:`~pycram.backends.ros.modules.RosArmModule`: a one-point trajectory
(joint goal) or a ``pycram_msgs/Reach`` goal (tool pose).

What is monitored, and by whom
------------------------------
- **Planning** checks every configuration of the path in prospection (the environment's
  description, the objects the robot perceived, the containers as last measured, the held object
  moving with the hand). What nobody perceived is not in it.
- **Execution** is watched by the robot's trajectory controller, not by PyCRAM: a goal it
  aborts fails with the reason it gives. ``pycram sim-ros-bridge`` follows a multi-point
  trajectory with the simulator's monitored path controller (``World.follow_arm_path``): it
  stops the arm on a contact of the arm or of the object its gripper holds (``'collision'``) or a
  joint lagging its reference (``'blocked'``). A FollowJointTrajectory goal cannot name the
  object being grasped, so -- unlike in-process -- that object is not exempt from the bridge's
  contact monitoring: a hand that touches it on the way stops, and the planner goes on directly
  (its rule for a stop that a re-plan cannot avoid). A real robot's controller typically
  watches only its path and goal tolerances.
- **After a stop** (reason ``'collision'`` or ``'blocked'``) the arm's measured joints (from a
  joint-states message sampled after the goal ended) say where it stopped; the planner backs off
  along the executed samples, looks at where the hand is (one detection into the belief) and
  plans again, as in-process.
- **The reached tool pose** is forward kinematics of the measured joints in the believed world
  (:func:`~pycram.robots.common.ros_prospection.tool_poses`), as a real robot's tf would give it.
- **Standing still** (the planner plans only while the base and torso rest) is judged from the
  joint-states topic's velocities (``RosRobotState.joint_velocities``; the bridge publishes
  them, base joints included). A robot that publishes no base velocities counts as standing.

Switch: :func:`plan_ros_arm_motions` (on by default in
:func:`pycram.robots.common.ros_robot.make_ros_robot` when the robot has a prospection, as the
simulated robots plan theirs).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from pycram.backends.ros.config import RosRobotConfig
from pycram.backends.ros.modules import RosArmModule, RosRobotState
from pycram.backends.ros.transport import RosMotionFailed, Transport
from pycram.execution.module_support import format_values
from pycram.execution.robot import Robot
from pycram.world.types import JointStates, Outcome, Pose

from .ros_prospection import tool_poses

__all__ = ["ArmPathFailed", "RosArmWorld", "RosPlannedArmModule", "plan_ros_arm_motions"]

logger = logging.getLogger(__name__)


class ArmPathFailed(RosMotionFailed):
    """A planned arm motion over ROS ended without success: the trajectory controller stopped
    the arm (``reason`` ``'collision'`` or ``'blocked'``, after the re-plans), or the tool ended
    farther than the tolerance from its goal (``'blocked'``). ``outcome`` is an
    :class:`~pycram.world.types.Outcome` whose ``value`` is a
    :class:`~pycram.backends.sim.arm_path.PathStop` (where the arm stopped, measured from the
    joint states), or None."""

    def __init__(self, command: str, reason: str, message: str, outcome: Any = None, action: str = "") -> None:
        super().__init__(command, reason, message, action)
        self.outcome = outcome


@dataclass(frozen=True)
class _PathRequest:
    """A timed arm path the planner asks the robot to follow (sent by the module's runner)."""

    arm: str
    joints: tuple[str, ...]
    samples: tuple[tuple[float, tuple[float, ...]], ...]


class _Value:
    """A read-only fluent-like view: ``get_value()`` computes the value now."""

    def __init__(self, compute: Callable[[], Any]) -> None:
        self._compute = compute

    def get_value(self) -> Any:
        return self._compute()


class RosArmWorld:
    """The robot over ROS, as :class:`~pycram.robots.common.arm_motion.ArmMotionPlanner` reads
    a world: ``description``, ``base_pose`` (the pose topic's fluent), ``joint_states`` (a view
    whose value is a :class:`~pycram.world.types.JointStates` of the joint-states topic: positions
    and velocities by name), ``tool_poses`` (a view: ``{arm: Pose}`` by forward kinematics in the
    robot's prospection) and :meth:`follow_arm_path` (the path to send, as a request the arm
    module's runner sends)."""

    def __init__(self, state: RosRobotState, description: Any, robot: Callable[[], Any]) -> None:
        self.state, self.description, self._robot = state, description, robot
        self.base_pose = state.base_pose
        self.joint_states = _Value(self._joint_states)
        self.tool_poses = _Value(self._tool_poses)

    def _joint_states(self) -> JointStates:
        positions = self.state.joint_states.get_value() or {}
        velocities = self.state.joint_velocities.get_value() or {}
        return JointStates(self.state.stamp, dict(positions), dict(velocities))

    def _tool_poses(self) -> dict[str, Pose]:
        prospection = getattr(self._robot(), "prospection", None)
        if prospection is None:
            raise LookupError(f"the {self.state.robot} has no prospection to compute its tool poses")
        return tool_poses(prospection)

    def follow_arm_path(
        self,
        arm: str,
        joints: Sequence[str],
        samples: Sequence[tuple[float, Sequence[float]]],
        exempt_item: str | None = None,
        tolerance: float | None = None,
        exempt_near: Sequence[float] | None = None,
    ) -> _PathRequest:
        """The request to follow ``samples`` ((t [s], positions) in the order of ``joints``) with
        ``arm``. ``exempt_item``, ``exempt_near`` and ``tolerance`` have no FollowJointTrajectory
        field: the robot's controller decides (see the module docstring)."""
        del exempt_item, tolerance, exempt_near
        return _PathRequest(arm, tuple(joints), tuple((float(t), tuple(float(v) for v in q)) for t, q in samples))


def _look_at(point: tuple[float, float, float]) -> None:
    """Point the active robot's head at ``point`` [m, map] and detect once (into its belief)."""
    from pycram.designators.motion import MotionDesignator
    from pycram.execution.perform import perform

    perform(MotionDesignator(type="pointing_head", coordinates=list(point)))
    perform(MotionDesignator(type="detecting"))


class RosPlannedArmModule(RosArmModule):
    """One arm of a robot over ROS whose motions are planned (see the module docstring) while
    ``robot`` is set (its ``prospection`` and ``belief`` are read at each motion); without it,
    or without the planning libraries, exactly :class:`RosArmModule`. The object being grasped
    is the motion designator's ``object`` (a believed object or its name). Returns what
    :class:`RosArmModule` returns: the joint goal [rad] (``move_arm``) or the reached tool
    ``Pose`` (``reach``)."""

    def __init__(
        self,
        transport: Transport,
        config: RosRobotConfig,
        state: RosRobotState,
        arm: str,
        description: Any,
        robot: Robot | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(transport, config, state, arm, name)
        self.description = description
        self.robot = robot
        self._motions: Any = None  # the ArmMotionPlanner, made at the first motion

    def _planner(self) -> Any:
        if self.robot is None:
            return None
        if self._motions is None:
            from .arm_motion import ArmMotionPlanner  # OMPL and Ruckig: imported when first used

            world = RosArmWorld(self.state, self.description, lambda: self.robot)
            try:
                self._motions = ArmMotionPlanner(
                    world, self.arm, lambda: self.robot, self._run_path, ArmPathFailed, look=_look_at
                )
            except ImportError as missing:  # without the planning libraries: plain goals
                logger.warning("%s: arm motions are not planned: %s", self.name, missing)
                self.robot = None
                return None
        return self._motions

    def _run_path(self, start: Callable[[], Any], what: str, timeout: float) -> Any:
        """The planner's runner: send the path ``start()`` asks for and wait for it (at most
        ``timeout`` [s, active clock]). A stop (``'collision'``, ``'blocked'``) raises
        :class:`ArmPathFailed` with where the arm stopped; other failures propagate as they are."""
        request = start()
        if not isinstance(request, _PathRequest):
            raise TypeError(f"{self.name}: expected a path to follow, got {request!r}")
        try:
            reached = self.follow_path(request.joints, request.samples, what, timeout)
            self.state.wait_fresh(self.state.joint_updates)  # the joint states show the arm after it
            return reached
        except RosMotionFailed as failure:
            if failure.reason not in ("collision", "blocked"):
                raise
            stop = self._stop_of(request)
            raise ArmPathFailed(
                what,
                failure.reason,
                failure.message,
                Outcome(False, failure.reason, failure.message, stop),
                failure.action,
            ) from None

    def _stop_of(self, request: _PathRequest) -> Any:
        """Where the arm stopped on ``request``'s path: its joints as the first joint-states
        message sampled after now shows them, and the sample nearest to them (the last one it
        passed, as far as the measurement tells)."""
        from pycram.backends.sim.arm_path import PathStop

        self.state.wait_fresh(self.state.joint_updates)
        measured = self.state.joint_states.get_value() or {}
        if not all(j in measured for j in request.joints):
            return None
        here = tuple(float(measured[j]) for j in request.joints)
        nearest = min(range(len(request.samples)), key=lambda k: math.dist(request.samples[k][1], here))
        return PathStop(here, nearest, request.samples[nearest][0])

    def _execute(self, designator: Any) -> Any:
        planner = self._planner()
        if planner is None:
            return super()._execute(designator)
        from .sim_modules import _object_of

        solution = designator.reference()
        cmd = solution.get("cmd")
        grasped = _object_of(designator)
        self.state.wait_fresh(self.state.joint_updates)  # plan from the arm as it is after the last goal

        def directly() -> Any:
            return super(RosPlannedArmModule, self)._execute(designator)

        if cmd == "move_arm":
            positions = tuple(float(v) for v in solution["positions"])
            what = f"move the {self.arm} arm to {solution.get('configuration') or format_values(positions)}"
            planner.move(positions, what, directly, grasped)
            return positions  # the joint goal, as RosArmModule returns it (a planned path ends within limits)
        if cmd == "reach":
            position = tuple(float(v) for v in solution["position"])
            phase = solution.get("phase")
            what = f"reach with the {self.arm} arm to {format_values(position)}" + (
                f" ({phase} of {format_values(solution['target'])})" if phase else ""
            )
            if grasped[1] is None:  # what lies at the target is what the hand goes for
                tx, ty, tz = (float(v) for v in solution.get("target") or position)
                grasped = (grasped[0], (tx, ty, tz))
            return planner.reach(
                position,
                solution.get("orientation"),
                float(solution.get("tolerance", 0.01)),
                what,
                directly,
                grasped,
                phase,
                bool(solution.get("contact")),
            )
        return super()._execute(designator)


def plan_ros_arm_motions(robot: Robot, on: bool = True) -> None:
    """Switch planned arm motions on (or off) for every :class:`RosPlannedArmModule` of ``robot``
    (a robot over ROS with a ``prospection``)."""
    for module in robot.process_modules.values():
        if isinstance(module, RosPlannedArmModule):
            module.robot = robot if on else None
            module._motions = None
