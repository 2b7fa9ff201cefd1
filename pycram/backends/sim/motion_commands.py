"""The robot's motion commands of a `World`: drive the base, move the torso, the arms (joint
goals, named configurations, tool poses), the head camera and the grippers.

Each command returns a `CommandHandle` at once; the motion runs as a controller in the
simulation thread (see `controllers`, `path_drive`). Units: metres, radians, newtons; durations
in seconds of simulated time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

from pycram.world.types import Pose, Pose2D, Quat, Vec3

from .arm_path import LOADED_TOLERANCE, PATH_TOLERANCE, JointPath
from .commands import CommandQueue
from .controllers import BaseDrive, GripperCommand, HeadPointing, JointTrajectory, Reach
from .errors import UnknownNameError
from .handle import CommandHandle
from .path_drive import PlannedDrive


class MotionCommands(CommandQueue):
    """The motion commands of a `World` (a part of it: `World` inherits them)."""

    def drive_to(self, x: float, y: float, yaw: float, plan_path: bool = True) -> CommandHandle:
        """Drive the base to the map pose (x [m], y [m], yaw [rad]) with the base's limits.

        With `plan_path` the base follows a collision-free path around the environment and the
        obstacles (the straight line where that is free; see `pycram.backends.sim.path_drive`), stops and
        re-plans when the path gets blocked, and ends with "no_path" when there is none; without,
        it drives the straight line whatever is in the way. Ends with "collision"/"blocked"
        (stopped where it is) or "timeout"; value: final `Pose2D`.
        """
        goal = Pose2D(x, y, yaw)
        return self.submit(PlannedDrive(goal) if plan_path else BaseDrive(goal), "drive_to")

    def move_base(self, pose: Pose2D, plan_path: bool = True) -> CommandHandle:
        """`drive_to` with a `Pose2D`."""
        return self.drive_to(pose.x, pose.y, pose.yaw, plan_path)

    def set_torso(self, height: float, duration: float | None = None) -> CommandHandle:
        """Move the torso lift joint to `height` [m]."""
        joint = self.description.TORSO["joint"]
        return self.submit(
            JointTrajectory("torso", [joint], [height], duration, max_velocity=0.1, tolerance=0.005), "set_torso"
        )

    def move_arm(self, arm: str, positions: Sequence[float], duration: float | None = None) -> CommandHandle:
        """Move the joints of `arm` (order: `description.ARMS[arm]["joints"]`) to `positions` [rad]."""
        joints = self.description.ARMS[self._check_arm(arm)]["joints"]
        if len(positions) != len(joints):
            raise ValueError(f"{arm} arm has {len(joints)} joints, got {len(positions)} positions")
        trajectory = JointTrajectory(f"arm:{arm}", joints, positions, duration, loaded_tolerance=LOADED_TOLERANCE)
        return self.submit(trajectory, f"move_arm:{arm}")

    def move_arm_to(self, arm: str, configuration: str, duration: float | None = None) -> CommandHandle:
        """Move `arm` to a named configuration of `description.ARM_CONFIGURATIONS[arm]`."""
        configs = self.description.ARM_CONFIGURATIONS[self._check_arm(arm)]
        if configuration not in configs:
            raise UnknownNameError("arm configuration", configuration, configs)
        return self.move_arm(arm, configs[configuration], duration)

    def reach(
        self,
        arm: str,
        position: Sequence[float],
        orientation: Sequence[float] | None = None,
        duration: float | None = None,
        tolerance: float = 0.01,
    ) -> CommandHandle:
        """Move the tool frame of `arm` to `position` [m] (and `orientation` (w, x, y, z) if given).

        Ends with "unreachable" when inverse kinematics finds no solution within the joint limits;
        value: the reached tool `Pose`.
        """
        self._check_arm(arm)
        goal = Pose(
            cast(Vec3, tuple(map(float, position))),
            cast(Quat, tuple(map(float, orientation))) if orientation is not None else (1.0, 0.0, 0.0, 0.0),
        )
        return self.submit(Reach(arm, goal, orientation is not None, duration, tolerance), f"reach:{arm}")

    def follow_arm_path(
        self,
        arm: str,
        joints: Sequence[str],
        samples: Sequence[tuple[float, Sequence[float]]],
        exempt_item: str | None = None,
        tolerance: float | None = None,
        exempt_near: Sequence[float] | None = None,
    ) -> CommandHandle:
        """Move `arm` along a timed joint path: `samples` are (t [s] from 0, positions [rad or m]
        in the order of `joints`, joints of that arm), e.g. a planned path's
        `pycram.reasoning.motion.time_parameterize(...).samples()`.

        Monitored while it runs (see `pycram.backends.sim.arm_path`): an unexpected contact of the
        arm or of the object its gripper holds (not the item being grasped, at the fingers:
        `exempt_item` by name, or the item nearest to `exempt_near` [m, map], within
        `arm_path.EXEMPT_RADIUS`) ends with "collision", a joint that lags its reference with "blocked"; either
        stops the arm where it is, the outcome's value a `PathStop` (where, the last sample
        passed, the pair). Succeeds (value: the largest remaining joint error) when the joints
        are at the path's end (within `tolerance` [rad or m]; None: `arm_path.PATH_TOLERANCE`);
        "invalid" for malformed samples.
        """
        self._check_arm(arm)
        path = JointPath(
            arm,
            joints,
            samples,
            exempt_item=exempt_item,
            exempt_near=exempt_near,
            tolerance=tolerance or PATH_TOLERANCE,
        )
        return self.submit(path, f"arm_path:{arm}")

    def point_head(self, point: Sequence[float]) -> CommandHandle:
        """Turn the head camera to `point` [m, map frame]; succeeds when it looks at it (< ~1 deg)."""
        return self.submit(HeadPointing(point), "point_head")

    def track_point(self, point: Sequence[float]) -> CommandHandle:
        """Keep the head camera on `point` [m, map frame], also while driving, until cancelled."""
        return self.submit(HeadPointing(point, track=True), "track_point")

    def set_gripper(self, gripper: str, opening: float, effort: float | None = None) -> CommandHandle:
        """Open/close `gripper` to `opening` [m] with at most `effort` [N] at the finger tips
        (default: the description's `default_effort`); value: measured opening [m].

        The fingers never push harder than `effort` (the applied effort is published in
        `gripper_states[gripper].effort`). Closing on an item that is between the fingers (both
        touching it) grasps it with a weld; closing on nothing grasps nothing; any command that
        does not close releases a held item (also one to the width the fingers stand at). A
        non-positive effort ends with reason "invalid".
        """
        return self.submit(GripperCommand(self._check_gripper(gripper), opening, effort), f"gripper:{gripper}")


__all__ = ["MotionCommands"]
