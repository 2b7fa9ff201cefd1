"""Per-robot ROS configuration, as data: action and topic names, joint names, frames.

:data:`ROBOT_CONFIGS` holds the defaults, one per registered robot, built from the ``ROS`` key of
its description (:mod:`pycram.world.robot_registry`): the PR2's real interface names (thesis
ch. 4.1, ``control.py``) and TIAGo's. Point PyCRAM at another robot, or at a PR2 whose controllers are
named differently, with :meth:`RosRobotConfig.replace` or :func:`config_from_dict` (e.g. from a
YAML/JSON file) -- nothing else changes. The simulator bridge serves exactly the names of the
configuration it is started with.

Interfaces (types)
------------------
===================  ==========================================  ===============================
part                 default action / topic                      type
===================  ==========================================  ===============================
base                 ``move_base``                               move_base_msgs/MoveBase
head                 ``head_action``                             control_msgs/PointHead
torso                ``torso_action``                            control_msgs/SingleJointPosition
                                                                 or .../FollowJointTrajectory
arm (joints)         ``arms[a].trajectory_action``               control_msgs/FollowJointTrajectory
arm (tool pose)      ``arms[a].reach_action``                    pycram_msgs/Reach (PyCRAM's own)
gripper              ``grippers[g].action``                      control_msgs/GripperCommand
base pose            ``pose_topic`` (``/amcl_pose``)             geometry_msgs/PoseWithCovarianceStamped
joints, grippers     ``joint_states_topic``                      sensor_msgs/JointState
detections           ``detections_topic``                        pycram_msgs/DetectedItems
simulation time      ``/clock``                                  rosgraph_msgs/Clock
sensor instant taken ``sensor_ack_topic`` (simulator only)       rosgraph_msgs/Clock
===================  ==========================================  ===============================

A gripper's opening [m] is the sum of the positions of its ``opening_joints`` in the joint
states (the PR2 publishes its gap as ``r_gripper_joint``; TIAGo's two fingers each move half).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from pycram.world.robot_registry import robot_description, robot_names

__all__ = ["ArmInterface", "GripperInterface", "RosRobotConfig", "ROBOT_CONFIGS", "robot_config", "config_from_dict"]


@dataclass(frozen=True)
class ArmInterface:
    """One arm: its joint-trajectory action, joint names (in the description's order) and the
    action that moves its tool to a pose."""

    trajectory_action: str
    joint_names: tuple[str, ...]
    reach_action: str


@dataclass(frozen=True)
class GripperInterface:
    """One gripper: its GripperCommand action and the joints whose positions add up to its
    opening [m] in the joint states."""

    action: str
    opening_joints: tuple[str, ...]


@dataclass(frozen=True)
class RosRobotConfig:
    """How one robot's parts are reached over ROS (names only: no numbers a plan needs)."""

    robot: str
    arms: dict[str, ArmInterface]
    grippers: dict[str, GripperInterface]
    head_action: str
    head_pointing_frame: str
    head_pointing_axis: tuple[float, float, float]
    torso_action: str
    torso_joint: str
    #: 'single_joint_position' (control_msgs/SingleJointPosition, the PR2) or 'joint_trajectory'
    #: (control_msgs/FollowJointTrajectory on ``torso_joint``, TIAGo)
    torso_interface: str = "single_joint_position"
    move_base_action: str = "move_base"
    pose_topic: str = "/amcl_pose"
    joint_states_topic: str = "/joint_states"
    detections_topic: str = "/pycram/detections"
    clock_topic: str = "/clock"
    map_frame: str = "map"
    base_frame: str = "base_footprint"
    #: the environment description (``pycram.environments``) of the robot's map: where the base
    #: may stand (goals off its free floor are refused before anything moves) and its surfaces
    environment: str = "thesis-kitchen"
    #: simulator-only services and topics of the bridge (item states, the environment's hands)
    sim_namespace: str = "/pycram_sim"
    #: simulator only: where PyCRAM's ROS robot acknowledges each sensor instant it took in
    #: (``rosgraph_msgs/Clock``: the stamp), so that the bridge's simulation keeps step with it
    sensor_ack_topic: str = "/pycram_sim/sensor_ack"
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.torso_interface not in ("single_joint_position", "joint_trajectory"):
            raise ValueError(
                f"ROS config of {self.robot!r}: torso_interface must be "
                f"'single_joint_position' or 'joint_trajectory', not {self.torso_interface!r}"
            )

    def replace(self, **changes: Any) -> RosRobotConfig:
        """A copy with ``changes`` (field names; ``TypeError`` names an unknown one)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    def actions(self) -> dict[str, str]:
        """``{action name: action type}`` of every action this robot offers."""
        torso_type = (
            "control_msgs/SingleJointPosition"
            if self.torso_interface == "single_joint_position"
            else "control_msgs/FollowJointTrajectory"
        )
        result = {
            self.move_base_action: "move_base_msgs/MoveBase",
            self.head_action: "control_msgs/PointHead",
            self.torso_action: torso_type,
        }
        for arm in self.arms.values():
            result[arm.trajectory_action] = "control_msgs/FollowJointTrajectory"
            result[arm.reach_action] = "pycram_msgs/Reach"
        for gripper in self.grippers.values():
            result[gripper.action] = "control_msgs/GripperCommand"
        return result


def _from_plain(data: dict[str, Any]) -> RosRobotConfig:
    """A configuration from complete plain data (arms and grippers as mappings of their fields)."""
    merged = dict(data)
    merged["arms"] = {
        k: ArmInterface(v["trajectory_action"], tuple(v["joint_names"]), v["reach_action"])
        for k, v in merged["arms"].items()
    }
    merged["grippers"] = {
        k: GripperInterface(v["action"], tuple(v["opening_joints"])) for k, v in merged["grippers"].items()
    }
    merged["head_pointing_axis"] = tuple(merged["head_pointing_axis"])
    return RosRobotConfig(**merged)


def _configs() -> dict[str, RosRobotConfig]:
    """The default configuration of every registered robot whose description has a ``ROS`` key."""
    configs = {}
    for name in robot_names():
        ros = robot_description(name).ROS
        if ros is not None:
            configs[name] = _from_plain({"robot": name, **ros})
    return configs


#: Default configurations by robot name (from the ``ROS`` key of each robot's description).
ROBOT_CONFIGS: dict[str, RosRobotConfig] = _configs()


def robot_config(robot: str) -> RosRobotConfig:
    """The default configuration of ``robot``; ``ValueError`` lists the known robots."""
    try:
        return ROBOT_CONFIGS[robot]
    except KeyError:
        raise ValueError(
            f"no ROS configuration for robot {robot!r}; available: {', '.join(sorted(ROBOT_CONFIGS))}"
        ) from None


def config_from_dict(data: dict[str, Any]) -> RosRobotConfig:
    """A configuration from plain data (as :meth:`RosRobotConfig.to_dict` writes it); keys not
    given keep the default of ``data['robot']``. ``ValueError`` names an unknown key."""
    base = robot_config(data["robot"]).to_dict()
    unknown = sorted(set(data) - set(base))
    if unknown:
        raise ValueError(f"unknown ROS configuration keys {unknown}; valid: {sorted(base)}")
    return _from_plain({**base, **data})
