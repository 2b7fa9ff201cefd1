"""The motion vocabulary of the simulated robots, as data: every type, key, unit and valid value.

:func:`motion_types` builds the :class:`~pycram.designators.motion_types.MotionType` table of one
robot from its description module (arm and gripper names, named arm configurations, torso
positions and range, reaching phases) and its world (the free floor a base goal must lie on).
The robot packages register it as ``robot.motion_types``; designators are checked against it
before anything moves, and :func:`pycram.designators.motion_types.vocabulary_table` prints it
for the docs. What each type resolves to is in :mod:`pycram.robots.common.sim_resolvers`.
"""

from __future__ import annotations

import math
from typing import Any

from pycram.designators.motion_types import GoalOutsideEnvironment, MotionKey, MotionType
from pycram.robots.common.sim_resolvers import REACH_GRASPS, base_goal_in_map, describe_free_floor, on_free_floor

__all__ = ["motion_types"]


def _goal_on_free_floor(world: Any):
    """A check of ``moving``: the goal (in the map frame) lies on the environment's free floor."""

    def goal_on_free_floor(designator: Any, motion_type: MotionType) -> None:
        goal = base_goal_in_map(world, designator.prop_value("pose"), designator.prop_value("frame"))
        if not on_free_floor(world, goal.x, goal.y):
            raise GoalOutsideEnvironment(
                f"motion designator of type {motion_type.name!r}: the goal "
                f"(x={goal.x:.3f}, y={goal.y:.3f}) [m, map] is outside the environment: the base "
                f"can only stand on {describe_free_floor(world)} (in {designator!r})",
                designator=designator,
                motion_type=motion_type.name,
                key="pose",
                valid_keys=[k.name for k in motion_type.all_keys()],
            )

    return goal_on_free_floor


def motion_types(world: Any, description: Any) -> dict[str, MotionType]:
    """The motion types the robot of ``description`` understands in ``world``, by name."""
    d = description
    arm = MotionKey("arm", "which arm", form="name", choices=tuple(d.ARM_ALIASES))
    gripper = MotionKey("gripper", "which gripper", form="name", choices=tuple(d.GRIPPER_ALIASES))
    fluent = MotionKey("fl", "the user's fluent that follows the sensor", form="fluent")
    configurations = sorted({name for per_arm in d.ARM_CONFIGURATIONS.values() for name in per_arm})
    low, high = d.TORSO["range"]
    types = (
        MotionType(
            "moving",
            "drive the base to a pose; returns the reached Pose2D",
            (
                MotionKey("pose", "base goal: Pose2D or (x [m], y [m], yaw [rad]); on the free floor", form="pose2d"),
                MotionKey(
                    "frame",
                    "frame of the pose (default 'map')",
                    form="name",
                    required=False,
                    choices=("map", "base_footprint"),
                ),
            ),
            checks=(_goal_on_free_floor(world),),
        ),
        MotionType("cancelling_movement", "stop the base (and the drive running on it)"),
        MotionType(
            "pointing_head",
            "point the head camera at a point; with ('wait', False) keep tracking it",
            (
                MotionKey("coordinates", "point to look at [x, y, z] [m]", form="point"),
                MotionKey("frame", "frame of the point (default 'map')", form="name", required=False, choices=("map",)),
            ),
        ),
        MotionType(
            "setting_torso",
            "move the torso lift joint",
            (
                MotionKey(
                    "position",
                    "a named position or a height [m]",
                    form="number",
                    choices=tuple(d.TORSO_POSITIONS),
                    range=(float(low), float(high)),
                ),
            ),
        ),
        MotionType(
            "setting_gripper",
            "open or close a gripper; returns the measured opening [m]",
            (
                gripper,
                MotionKey("position", "fraction open: 0 closed, 1 fully open", form="number", range=(0.0, 1.0)),
                MotionKey(
                    "max_effort",
                    "largest force at the finger tips [N] (default: the gripper's)",
                    form="number",
                    required=False,
                    range=(1e-3, math.inf),
                ),
            ),
        ),
        MotionType(
            "setting_arm_configuration",
            "move an arm to a named joint configuration",
            (
                arm,
                MotionKey("configuration", "named configuration", form="name", choices=tuple(configurations)),
            ),
        ),
        MotionType(
            "setting_arm_joints",
            "move an arm's joints",
            (
                arm,
                MotionKey("positions", "joint positions [rad], one per joint of the arm", form="numbers"),
            ),
        ),
        MotionType(
            "reaching",
            "move the tool of an arm to a target, facing along the base's heading; returns the reached tool Pose",
            (
                arm,
                MotionKey("target", "point to reach [x, y, z] [m, map]", form="point"),
                MotionKey(
                    "phase",
                    "approach phase: offset of the tool from the target (default: none)",
                    form="name",
                    required=False,
                    choices=tuple(d.APPROACH_OFFSETS),
                ),
                MotionKey(
                    "grasp",
                    "how the tool meets the target: 'front' along the base's "
                    "heading, fingers opening horizontally (default); "
                    "'front_vertical' fingers opening vertically; 'top' from above",
                    form="name",
                    required=False,
                    choices=REACH_GRASPS,
                ),
                MotionKey(
                    "orientation",
                    "the tool's orientation (w, x, y, z) [map]: then `target` is the tool's position "
                    "itself (no phase offset; the phase sets only the tolerance)",
                    form="numbers",
                    required=False,
                ),
                MotionKey(
                    "object",
                    "the object being grasped (a believed object or its name): it may touch the "
                    "fingers on the way (default: none)",
                    form="any",
                    required=False,
                ),
                MotionKey(
                    "contact",
                    "True: the tool is meant to touch what it reaches (a door it pushes): moved "
                    "directly, not planned (default: False)",
                    form="any",
                    required=False,
                ),
                MotionKey(
                    "joints",
                    "the arm's joint positions [rad] found for this tool pose before (e.g. validated "
                    "by location reasoning): the first guess of the arm's IK (default: none)",
                    form="numbers",
                    required=False,
                ),
            ),
        ),
        MotionType("subscribing_pose", "make a fluent follow the base pose (Pose2D, map)", (fluent,)),
        MotionType("subscribing_gripper", "make a fluent follow a gripper's opening [m]", (gripper, fluent)),
        MotionType(
            "detecting",
            "perceive the objects the head camera sees and update the robot's "
            "belief; returns the believed objects seen (PerceivedObject)",
            (
                MotionKey(
                    "object",
                    "object type, belief name or object designator to look for (default: every object seen)",
                    form="any",
                    required=False,
                ),
            ),
        ),
    )
    return {t.name: t for t in types}
