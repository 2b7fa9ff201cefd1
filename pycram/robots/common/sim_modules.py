"""Simulated process modules, shared by every robot of :mod:`pycram.sim` (PR2, TIAGo).

A process module is the only place that talks to the simulator. Each module here serves one
component of the robot and is parametrised by the robot's world (and arm / gripper name); the
robot packages (:mod:`pycram.robots.pr2`, :mod:`pycram.robots.tiago`) build one set per robot.

Every module executes the *solution* of its motion designator (``designator.reference()``, a
``dict`` with a ``'cmd'`` key produced by the robot's motion resolver, thesis ch. 4.2.1) by
sending one thread-safe command to the :class:`pycram.sim.World` and waiting -- evaporably, on
the command handle's ``result`` fluent -- for its outcome.

Guarantees
----------
- ``_execute`` returns the outcome's value on success (e.g. the reached ``Pose2D``, the measured
  gripper opening [m]) and raises :class:`SimMotionFailed` otherwise; its message names the
  command, the outcome reason and the simulator's message ("drive to (x, y, yaw) failed:
  collision: base touches obstacle_0 (stopped at ...)").
- A command that does not end within its time-out [s of simulated time] is cancelled and
  reported as ``SimMotionFailed`` with reason ``'timeout'``.
- ``_cancel`` (run by :class:`ProcessModule` when the executing task is evaporated) cancels the
  running simulator command, which leaves the part at rest (base stopped, arm holding).
- :class:`BaseStopModule` is separate from :class:`NavigationModule`, so ``cancelling_movement``
  never queues behind the drive it is meant to stop.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any

from pycram.core.fluent import Fluent
from pycram.execution.failures import MotionFailure, NavigationFailure, SimulationFault
from pycram.execution.module_support import (
    cancel_running_handle,
    check_command,
    format_pose2d,
    format_values,
    seen_objects,
)
from pycram.execution.process_module import ProcessModule, ProcessModuleStatus
from pycram.execution.robot import Robot

__all__ = [
    "SimMotionFailed",
    "NavigationFailed",
    "SimProcessModule",
    "NavigationModule",
    "BaseStopModule",
    "HeadModule",
    "TorsoModule",
    "ArmModule",
    "GripperModule",
    "SensorModule",
    "PerceptionModule",
    "SimRobot",
    "cancel_running_handle",
    "seen_objects",
    "shutdown_modules",
    "plan_arm_motions",
]

logger = logging.getLogger(__name__)

#: Default time-out of one simulator command [s of simulated time].
COMMAND_TIMEOUT = 60.0


class SimMotionFailed(MotionFailure):
    """A simulator command ended without success.

    Attributes: ``command`` (what was asked, readable), ``reason`` (the
    :class:`pycram.sim.Outcome` reason: ``'blocked'``, ``'collision'``, ``'unreachable'``,
    ``'timeout'``, ``'cancelled'``, ``'preempted'``, ``'invalid'``, ``'closed'``, ...),
    ``outcome`` (the simulator's outcome, or ``None`` after a time-out).
    """

    def __init__(self, command: str, reason: str, message: str, outcome: Any = None) -> None:
        super().__init__(f"{command} failed: {reason}: {message}")
        self.command = command
        self.reason = reason
        self.message = message
        self.outcome = outcome


class NavigationFailed(SimMotionFailed, NavigationFailure):
    """The base found no collision-free path to its goal (``reason`` ``'no_path'``); a
    :class:`pycram.world.navigation.NavigationFailure`, so plans can catch it without knowing
    the backend. The message says why (goal in collision, no connection, off the map)."""


class SimProcessModule(ProcessModule):
    """Base class: a process module running commands on a :class:`pycram.sim.World`.

    Subclasses call :meth:`_run_command` from ``_execute``. The running command's handle is
    kept so that the cancel hook can stop it.
    """

    def __init__(self, name: str, world: Any) -> None:
        super().__init__(name)
        self.world = world
        self._handle: Any = None

    def _run_command(
        self,
        start: Callable[[], Any],
        command: str,
        timeout: float = COMMAND_TIMEOUT,
        describe_failure: Callable[[Any], str] | None = None,
    ) -> Any:
        """Send a command (``start()`` returns its handle), wait for it and return its value.

        Blocks until the command ends or ``timeout`` [s, simulated] passes (then the command is
        cancelled). Evaporable: the caller's evaporation interrupts the wait (the module's cancel
        hook stops the command). Raises :class:`SimMotionFailed` on any unsuccessful outcome,
        ``ValueError`` (before sending anything) for a time-out that is not a positive finite
        number -- a NaN time-out would never expire.
        """
        if not (isinstance(timeout, (int, float)) and math.isfinite(timeout) and timeout > 0):
            raise ValueError(f"{command}: the time-out must be a positive number of seconds, got {timeout!r}")
        _raise_physics_fault(self.world)
        handle = start()
        self._handle = handle
        if not handle.result.wait_for(timeout):
            self._handle = None
            handle.cancel()
            _raise_physics_fault(self.world)
            raise SimMotionFailed(command, "timeout", f"did not end within {timeout:.1f} s of simulated time")
        outcome = handle.result.get_value()
        self._handle = None
        _raise_physics_fault(self.world)  # the world's physics broke: no command means anything now
        if not outcome.succeeded:
            message = outcome.message
            if describe_failure is not None:
                message = f"{message} {describe_failure(outcome)}".strip()
            raise SimMotionFailed(command, outcome.reason, message, outcome)
        logger.debug("%s: %s succeeded", self.name, command)
        return outcome.value

    def _cancel(self, designator: Any) -> None:
        cancel_running_handle(self, designator)


def _raise_physics_fault(world: Any) -> None:
    """Raise the world's `SimulationFault` once more, if its physics broke (see
    :mod:`pycram.backends.sim.physics_faults`); a plan's recoveries let it pass."""
    fault = getattr(getattr(world, "physics_fault", None), "get_value", lambda: None)()
    if isinstance(fault, SimulationFault):
        raise fault.again()


class NavigationModule(SimProcessModule):
    """Drives the base (``'cmd': 'navigate'`` with ``'pose'``: a ``Pose2D`` in the map frame)
    along a collision-free path around the environment and obstacles, re-planning when the
    path gets blocked (see :mod:`pycram.backends.sim.path_drive`).

    Returns the reached ``Pose2D``. Fails with :class:`NavigationFailed` (reason ``no_path``)
    when no path exists, otherwise with the outcome reason (``collision``: the base touched
    something; ``blocked``: it could not follow its path; ``timeout``; ``cancelled`` by
    ``cancelling_movement``) and the pose where the base stopped.
    """

    def __init__(self, world: Any, name: str = "navigation") -> None:
        super().__init__(name, world)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "navigate")
        pose = solution["pose"]
        distance = math.hypot(pose.x - self.world.base_pose.get_value().x, pose.y - self.world.base_pose.get_value().y)
        try:
            return self._run_command(
                lambda: self.world.move_base(pose),
                f"drive to {format_pose2d(pose)}",
                timeout=30.0 + 4.0 * distance,
                describe_failure=lambda out: f"(stopped at {format_pose2d(out.value)})",
            )
        except SimMotionFailed as exc:
            if exc.reason != "no_path":
                raise
            raise NavigationFailed(exc.command, exc.reason, exc.message, exc.outcome) from None


class BaseStopModule(SimProcessModule):
    """Stops the base (``'cmd': 'stop_base'``): cancels whatever drives it, waited or not.

    Separate from :class:`NavigationModule` so that it does not queue behind the drive it stops.
    The stopped drive's execution ends ``CANCELLED`` (a non-waited one) or ``FAILED`` with
    reason ``cancelled`` (a waited one). Returns the base pose after stopping.
    """

    def __init__(self, world: Any, navigation: NavigationModule, name: str = "base_stop") -> None:
        super().__init__(name, world)
        self.navigation = navigation

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "stop_base")
        execution = self.navigation.current
        if execution is not None:
            execution.cancel()  # a non-waited drive: evaporates its task (cancel hook stops it)
        self._run_command(lambda: self.world.cancel("base"), "stop the base", timeout=5.0)
        if execution is not None:  # its cancel hook has run once its status is an outcome
            waiter = Fluent(lambda: True if execution.done else None)
            execution.status.add_child(waiter)
            waiter.wait_for(5.0)
        return self.world.base_pose.get_value()


class HeadModule(SimProcessModule):
    """Points the head camera (``'cmd': 'point_head'``, ``'point'`` [m, map]).

    ``'track': False`` waits until the camera looks at the point (within ~1 deg) and returns the
    remaining angle [rad]. ``'track': True`` (a ``('wait', False)`` designator) starts tracking
    the point -- the camera stays on it while the base moves -- and returns at once; the next
    head command replaces it.
    """

    def __init__(self, world: Any, name: str = "head") -> None:
        super().__init__(name, world)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "point_head")
        point = tuple(float(v) for v in solution["point"])
        if solution.get("track"):
            self.world.track_point(point)
            return None
        return self._run_command(
            lambda: self.world.point_head(point), f"point the head at {format_values(point)}", timeout=10.0
        )


class TorsoModule(SimProcessModule):
    """Moves the torso lift joint (``'cmd': 'set_torso'``, ``'height'`` [m])."""

    def __init__(self, world: Any, name: str = "torso") -> None:
        super().__init__(name, world)

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "set_torso")
        height = float(solution["height"])
        return self._run_command(lambda: self.world.set_torso(height), f"set the torso to {height:.3f} m", timeout=20.0)


class ArmModule(SimProcessModule):
    """One physical arm: ``'cmd': 'move_arm'`` (``'positions'`` [rad], joint order of the
    description) and ``'cmd': 'reach'`` (``'position'`` [m, map], ``'orientation'`` (w, x, y, z)
    or ``None``, ``'tolerance'`` [m]).

    With ``robot`` (its ``prospection`` and ``belief`` read at each motion) the motions are
    planned: a collision-free path in prospection's world, timed within the joints' limits,
    executed and watched, re-planned after an unexpected contact (see
    :mod:`pycram.robots.common.arm_motion`); the object being grasped is the motion
    designator's ``object`` (a believed object or its name), exempt at the fingers. Motions that
    start or end in contact (handles, doors), and every motion without ``robot`` or without a
    prospection that plans, move directly (joint interpolation, as the simulator's ``move_arm`` /
    ``reach``).

    Planning is off unless the module has a ``robot`` (the PR2's and the TIAGo's have theirs);
    :func:`plan_arm_motions` switches it on or off for every arm module of a robot. After a stop
    the head looks at the tool and one detection goes into the belief before the motion is
    planned again.

    ``reach`` returns the reached tool ``Pose``; an unreachable target fails with reason
    ``'unreachable'``, a motion stopped by a contact with ``'collision'`` and one stopped by a
    lagging joint with ``'blocked'`` (after its re-plans).
    """

    def __init__(self, world: Any, arm: str, name: str | None = None, robot: Robot | None = None) -> None:
        super().__init__(name or f"arm_{arm}", world)
        self.arm = arm
        self.robot = robot
        self._motions: Any = None  # the ArmMotionPlanner, made at the first motion

    def _planner(self) -> Any:
        if self.robot is None:
            return None
        if self._motions is None:
            from .arm_motion import ArmMotionPlanner  # OMPL and Ruckig: imported when first used

            try:
                self._motions = ArmMotionPlanner(
                    self.world, self.arm, lambda: self.robot, self._run_command, SimMotionFailed, look=_look_at
                )
            except ImportError as missing:  # without the planning libraries: direct motions
                logger.warning("%s: arm motions are not planned: %s", self.name, missing)
                self.robot = None
                return None
        return self._motions

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        cmd = solution.get("cmd")
        planner = self._planner()
        grasped = _object_of(designator)
        if cmd == "move_arm":
            positions = tuple(float(v) for v in solution["positions"])
            what = f"move the {self.arm} arm to {solution.get('configuration') or format_values(positions)}"

            def move_directly() -> Any:
                return self._run_command(lambda: self.world.move_arm(self.arm, positions), what, timeout=30.0)

            if planner is None:
                return move_directly()
            return planner.move(positions, what, move_directly, grasped)
        if cmd == "reach":
            position = tuple(float(v) for v in solution["position"])
            orientation = solution.get("orientation")
            tolerance = float(solution.get("tolerance", 0.01))
            phase = solution.get("phase")
            what = f"reach with the {self.arm} arm to {format_values(position)}" + (
                f" ({phase} of {format_values(solution['target'])})" if phase else ""
            )

            def reach_directly() -> Any:
                return self._run_command(
                    lambda: self.world.reach(self.arm, position, orientation, tolerance=tolerance), what, timeout=30.0
                )

            if planner is None:
                return reach_directly()
            if grasped[1] is None:  # what lies at the target is what the hand goes for
                tx, ty, tz = (float(v) for v in solution.get("target") or position)
                grasped = (grasped[0], (tx, ty, tz))
            return planner.reach(
                position,
                orientation,
                tolerance,
                what,
                reach_directly,
                grasped,
                phase,
                bool(solution.get("contact")),
                solution.get("joints"),
            )
        check_command(self, solution, "move_arm", "reach")


def plan_arm_motions(robot: Robot, on: bool = True) -> None:
    """Switch planned arm motions (:mod:`pycram.robots.common.arm_motion`) on (or off) for every
    :class:`ArmModule` of ``robot``: their motions are then planned in ``robot.prospection``
    with ``robot.belief``'s held objects, executed by the monitored path controller and re-planned
    after an unexpected contact."""
    for module in robot.process_modules.values():
        if isinstance(module, ArmModule):
            module.robot = robot if on else None
            module._motions = None


def _look_at(point: tuple[float, float, float]) -> None:
    """Point the active robot's head at ``point`` [m, map] and detect once (into its belief)."""
    from pycram.designators.motion import MotionDesignator
    from pycram.execution.perform import perform

    perform(MotionDesignator(type="pointing_head", coordinates=point))
    perform(MotionDesignator(type="detecting"))


def _object_of(designator: Any) -> tuple[str | None, tuple[float, float, float] | None]:
    """The name and believed position [m, map] of the object a motion designator's ``object``
    property names (a believed object, or only a name), else (None, None)."""
    value = designator.prop_value("object")
    if value is None or isinstance(value, str):
        return value, None
    name = getattr(value, "name", None)
    pose = getattr(value, "pose", None)
    try:
        position = None if pose is None else (float(pose[0]), float(pose[1]), float(pose[2]))
    except (TypeError, ValueError, IndexError):
        position = None
    return (name if isinstance(name, str) else None), position


class GripperModule(SimProcessModule):
    """One gripper: ``'cmd': 'set_gripper'`` with ``'opening'`` [m] and ``'effort'`` [N] or
    ``None``. Returns the measured opening [m] (closing on an item stalls at its width)."""

    def __init__(self, world: Any, gripper: str, name: str | None = None) -> None:
        super().__init__(name or f"gripper_{gripper}", world)
        self.gripper = gripper

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "set_gripper")
        opening = float(solution["opening"])
        effort = solution.get("effort")
        return self._run_command(
            lambda: self.world.set_gripper(self.gripper, opening, effort),
            f"set the {self.gripper} gripper to {opening:.3f} m",
            timeout=10.0,
        )


class _Relay(Fluent):
    """A child of a sensor fluent that copies the sensor's value into a user's fluent on every
    pulse (in the thread that updates the sensor), so the user's fluent pulses with it."""

    __slots__ = ("_source", "_target", "_convert", "active")

    def __init__(self, source: Fluent, target: Fluent, convert: Callable[[Any], Any]) -> None:
        super().__init__(None, name=f"relay({source.name} -> {target.name})")
        self._source, self._target, self._convert = source, target, convert
        self.active = True

    def pulse(self) -> None:
        if self.active:
            self._target.set_value(self._convert(self._source.get_value()))
        super().pulse()


class SensorModule(SimProcessModule):
    """Subscriptions (``'cmd': 'subscribe'``): make a user's fluent follow a sensor fluent.

    ``'source': 'base_pose'`` (a ``Pose2D``, map frame) or ``'gripper_opening'`` (with
    ``'gripper'``, [m]). The user's fluent ``'fl'`` gets the current value at once and is set
    (so pulsed) on every sensor update of the simulation until :meth:`unsubscribe_all`.
    Returns the fluent.
    """

    def __init__(self, world: Any, name: str = "sensors") -> None:
        super().__init__(name, world)
        self._relays: list[_Relay] = []  # strong references: sensor fluents hold children weakly

    def _source(self, solution: dict) -> Fluent:
        source = solution["source"]
        if source == "base_pose":
            return self.world.base_pose
        if source == "gripper_opening":
            return self.world.gripper_openings[solution["gripper"]]
        raise ValueError(f"unknown sensor {source!r}; available: base_pose, gripper_opening")

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "subscribe")
        target = solution["fl"]
        if not isinstance(target, Fluent):
            raise TypeError(f"'fl' must be a Fluent, got {target!r}")
        source = self._source(solution)
        convert = float if solution["source"] == "gripper_opening" else (lambda v: v)
        relay = _Relay(source, target, convert)
        self._relays.append(relay)
        target.set_value(convert(source.get_value()))
        source.add_child(relay)
        logger.debug("%s: %s follows %s", self.name, target.name, source.name)
        return target

    def unsubscribe_all(self) -> None:
        """Stop updating every subscribed user fluent (they keep their last value)."""
        for relay in self._relays:
            relay.active = False
        self._relays.clear()


class PerceptionModule(SimProcessModule):
    """Object perception with the head camera (``'cmd': 'perceive'``), filling the robot's belief.

    Each execution takes one look (:meth:`pycram.sim.World.detect`: segmentation, depth and
    colour images measured into detections) and folds it into ``belief`` (a
    :class:`pycram.world.belief.BeliefState`). Returns the believed objects seen in this look
    (:class:`pycram.world.belief.PerceivedObject`, most visible first), restricted by
    ``'object'`` when given: a type or belief name, or an object designator; for a designator
    the best match is recorded with ``designator.perceived(obj)`` (equated to it, thesis 3.3).
    The look's :class:`pycram.world.belief.BeliefUpdate` is kept in ``last_update``.
    """

    def __init__(self, world: Any, belief: Any, name: str = "perception") -> None:
        super().__init__(name, world)
        self.belief = belief
        self.last_update: Any = None

    def _execute(self, designator: Any) -> Any:
        solution = designator.reference()
        check_command(self, solution, "perceive")
        report = self._run_command(self.world.detect, "detect objects", timeout=10.0)
        update = self.last_update = self.belief.update(report)
        return seen_objects(update, solution.get("object"), report.stamp)


def shutdown_modules(robot: Robot) -> None:
    """End every subscription of ``robot``'s sensor modules and take all its process modules
    offline (running motions finish); idempotent."""
    for module in robot.process_modules.values():
        if isinstance(module, SensorModule):
            module.unsubscribe_all()
        if module.status.get_value() is not ProcessModuleStatus.OFFLINE:
            module.shutdown()


class SimRobot(Robot):
    """A :class:`pycram.robot.Robot` bound to a simulated :class:`pycram.sim.World`.

    ``world`` is the world, ``description`` the robot's description module, ``belief`` the
    robot's :class:`pycram.world.belief.BeliefState` (its resolver is the robot's object
    resolver, so object designators resolve against what it perceived). :meth:`shutdown`
    ends every subscription and takes every process module offline (idempotent).
    """

    def __init__(self, name: str, world: Any, description: Any) -> None:
        from pycram.world.belief import BeliefState

        super().__init__(name)
        self.world = world
        self.description = description
        #: What this robot believes is in the world: filled by its perception module, read by
        #: its object resolver.
        self.belief = BeliefState(getattr(world, "environment", None))
        self.object_resolvers.append(self.belief.resolver)
        make_prospection = getattr(world, "prospection", None)
        #: Prospection of the world this robot believes in (its belief, the environment's
        #: description, its own joints): what its reasoning asks.
        self.prospection = make_prospection(self.belief) if callable(make_prospection) else None

    def shutdown(self) -> None:
        """Stop subscriptions and take all process modules offline (running motions finish)."""
        shutdown_modules(self)

    def __repr__(self) -> str:
        return f"SimRobot({self.name!r}, {self.world!r})"
