"""The robot numbers location reasoning needs, read from a robot's description.

Location reasoning is robot-agnostic: it asks a `RobotGeometry` how big the base is, where each
arm reaches comfortably, how the grasp phases are offset and how the arms are tucked away. Every
number comes from the robot's validated description (:class:`pycram.world.robot_description.RobotDescription`,
from ``pycram.robots.<name>.description``): ``BASE``
(``radius``: circumscribed, ``inscribed_radius``), ``ARMS``, ``ARM_ALIASES``, ``DEFAULT_ARM``,
``REACH_POINT_IN_BASE``, ``APPROACH_OFFSETS``, ``ARM_CONFIGURATIONS`` (``park``), optionally
``DOOR_PUSH``; ``BASE["kind"]`` (its kinematics). Lengths in [m].
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, cast

from pycram.world.base_kinematics import BaseKinematics
from pycram.world.robot_description import RobotDescription

__all__ = ["RobotGeometry"]

_XY = tuple[float, float]  # the pairs of the description module


@dataclass(frozen=True)
class RobotGeometry:
    """A robot as location reasoning sees it.

    `inscribed_radius` [m]: a circle around the base centre the robot always covers (cells
    closer than this to an obstacle are surely in collision); `circumscribed_radius` [m]: a
    circle the base never leaves. `reach_points` per physical arm: (ahead, left) [m] in the base
    frame where a point to reach lies comfortably. `approach_offsets`: phase -> (back along the
    approach [m], up [m]). `tucked`: joint name -> position of every arm's park configuration.
    `ready` per arm: the configuration the arm is raised to before it approaches (``carry``: over
    the furniture), joint name -> position; `carry_top` per arm: the one it comes in instead for a
    grasp `Grasp.held_from_above` (``carry_top``: the tool pointing down), joint name -> position.
    `contact_margin` [m]: how far below a grasp pose the arm must reach as well without touching
    anything (``GRASP_CONTACT_MARGIN``; executed motions pass through configurations IK did not
    check). `torso_joint` and `torso_positions` (name -> height [m]): the torso lift, for
    solutions that need another torso height. `door_push`: how the hand meets a door's face when
    it pushes one (``DOOR_PUSH``, see `pycram.reasoning.locations.doors`; None: the robot does not
    push doors).
    `fingertip_reach` [m]: how far the finger tips reach beyond the tool frame along the approach
    (``FINGERTIP_REACH``); a top grasp keeps them `top_grasp_clearance` [m]
    (``TOP_GRASP_CLEARANCE``) above the surface the object rests on (`top_grasp_height`).
    `max_openings` per arm: the largest opening [m] of its gripper (``GRIPPERS[...]['max_opening']``;
    grasp planning, `pycram.reasoning.grasps`). `base_kinematics`: how the base moves
    (``BASE["kind"]``; a differential drive must be able to drive into a base pose,
    `CandidateSearch.no_way_in`).
    """

    name: str
    arms: tuple[str, ...]
    default_arm: str
    arm_aliases: Mapping[Any, str]
    reach_points: Mapping[str, tuple[float, float]]
    inscribed_radius: float
    circumscribed_radius: float
    approach_offsets: Mapping[str, tuple[float, float]]
    tucked: Mapping[str, float]
    arm_joints: Mapping[str, tuple[str, ...]]
    ready: Mapping[str, Mapping[str, float]] = None  # type: ignore[assignment]
    carry_top: Mapping[str, Mapping[str, float]] = None  # type: ignore[assignment]
    contact_margin: float = 0.0
    torso_joint: str | None = None
    torso_positions: Mapping[str, float] = None  # type: ignore[assignment]
    door_push: Mapping[str, Any] | None = None
    fingertip_reach: float = 0.0
    top_grasp_clearance: float = 0.0
    max_openings: Mapping[str, float] = None  # type: ignore[assignment]
    base_kinematics: BaseKinematics = BaseKinematics()

    @classmethod
    def from_description(cls, d: RobotDescription) -> RobotGeometry:
        """The geometry of the robot described by `d` (see the module docstring)."""
        tucked: dict[str, float] = {}
        for arm, spec in d.ARMS.items():
            park = d.ARM_CONFIGURATIONS[arm].get("park")
            if park is not None:
                tucked.update(zip(spec["joints"], park))
        radius = float(d.BASE["radius"])
        return cls(
            name=d.NAME,
            arms=tuple(d.ARMS),
            default_arm=d.DEFAULT_ARM,
            arm_aliases=dict(d.ARM_ALIASES),
            reach_points={a: cast(_XY, tuple(map(float, p))) for a, p in d.REACH_POINT_IN_BASE.items()},
            inscribed_radius=float(d.BASE.get("inscribed_radius", radius / math.sqrt(2.0))),
            circumscribed_radius=radius,
            approach_offsets={k: cast(_XY, tuple(map(float, v))) for k, v in d.APPROACH_OFFSETS.items()},
            tucked=tucked,
            arm_joints={a: tuple(s["joints"]) for a, s in d.ARMS.items()},
            ready={
                a: dict(zip(s["joints"], d.ARM_CONFIGURATIONS[a]["carry"]))
                for a, s in d.ARMS.items()
                if "carry" in d.ARM_CONFIGURATIONS[a]
            },
            carry_top={
                a: dict(zip(s["joints"], d.ARM_CONFIGURATIONS[a]["carry_top"]))
                for a, s in d.ARMS.items()
                if "carry_top" in d.ARM_CONFIGURATIONS[a]
            },
            contact_margin=float(d.GRASP_CONTACT_MARGIN),
            torso_joint=d.TORSO.get("joint"),
            torso_positions={k: float(v) for k, v in d.TORSO_POSITIONS.items()},
            door_push=d.DOOR_PUSH,
            fingertip_reach=float(d.FINGERTIP_REACH),
            top_grasp_clearance=float(d.TOP_GRASP_CLEARANCE),
            max_openings={a: float(d.GRIPPERS[s["gripper"]]["max_opening"]) for a, s in d.ARMS.items()},
            base_kinematics=d.base_kinematics,
        )

    def top_grasp_height(self, bottom: float, wanted: float) -> float:
        """Height [m] of the tool in a top grasp of an object whose bottom is at `bottom` [m]:
        `wanted` [m] (the grasp's height), raised so that the finger tips stay
        `top_grasp_clearance` above the surface (thin objects: spoons, plates)."""
        return max(wanted, bottom + self.fingertip_reach + self.top_grasp_clearance)

    def arm(self, name: Any) -> str:
        """The physical arm serving a request for arm `name` (ValueError listing the valid names)."""
        try:
            return self.arm_aliases[name]
        except (KeyError, TypeError):
            raise ValueError(
                f"{self.name} has no arm {name!r}; available: {sorted({str(k) for k in self.arm_aliases})}"
            ) from None

    def reach_distance(self, arm: str) -> float:
        """Distance [m] from the base centre to the comfortable reach point of `arm`."""
        return math.hypot(*self.reach_points[arm])

    def reach_bearing(self, arm: str) -> float:
        """Angle [rad] of the reach point of `arm` from the base's heading (left positive)."""
        ahead, left = self.reach_points[arm]
        return math.atan2(left, ahead)

    def raised(self, arm: str) -> dict[str, float]:
        """Every arm tucked but `arm`, which is raised to its `ready` configuration."""
        return {**self.tucked, **(self.ready or {}).get(arm, {})}

    def tucked_except(self, arm: str | None) -> dict[str, float]:
        """The park configuration of every arm but `arm` (joint name -> position)."""
        if arm is None:
            return dict(self.tucked)
        own = set(self.arm_joints.get(arm, ()))
        return {j: v for j, v in self.tucked.items() if j not in own}
