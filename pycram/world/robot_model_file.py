"""A robot's model file (URDF) read without a simulator: its kinematic tree, so that a robot
description need not state what the file already says.

What a description may leave to the model file (`infer_from_model`):

- an arm's ``joints``: give ``root_link`` instead, and the arm's joints are the movable joints
  (revolute, continuous, prismatic; not mimic) on the way from that link to the arm's
  ``tool_link`` (or, for a robot with a gripper of our own, to ``GRIPPER_MODEL["mount_link"]``),
  in order from the root;
- a gripper's ``joint``, ``coupled_joints`` and ``joint_range``: the one movable, non-mimic joint
  below the last joint of the arm that carries the gripper, the mimic joints that follow it, and
  its URDF limits (lower: closed, upper: open);
- the head's ``camera_link`` (`camera_link`): below the head's tilt joint, the camera whose body
  frame (x: viewing direction, z: up) carries an ``*optical_frame`` (the ROS convention, REP 103),
  a colour camera (``rgb``/``color`` in its name) where there are several; without optical
  frames, the one link named ``*camera_link`` or ``*camera_frame``. A head with several cameras
  and none of them the colour one (the PR2's: a high-definition camera and two stereo pairs) is
  an error naming them: the description states which.

Joint position and velocity limits are read from the model by the simulator itself
(`pycram.backends.sim.arm_limits`). What a file cannot say stays in the description: which chain
is which arm, the tool frames, which of several cameras to use, grasp geometry and named
configurations.

The files are found in the installed `example-robot-data` package (`model_dir`; the environment
variable ``PYCRAM_ROBOT_DATA`` overrides the search). Pure Python: no simulator, no ROS.
"""

from __future__ import annotations

import functools
import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "ModelFileError",
    "UrdfJoint",
    "KinematicTree",
    "model_dir",
    "read_urdf",
    "infer_from_model",
    "camera_link",
]

#: Joint types that move (the others are fixed or floating).
MOVABLE = ("revolute", "continuous", "prismatic")


class ModelFileError(ValueError):
    """A model file that is missing, unreadable, or lacks a link or joint a description names."""


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint: its `type`, `parent` and `child` links, the joint it mimics (or None) and
    its limits (`lower`, `upper` [rad or m], `velocity` [rad/s or m/s]; None when not given)."""

    name: str
    type: str
    parent: str
    child: str
    mimic: str | None = None
    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None

    @property
    def movable(self) -> bool:
        """A joint that moves on its own: revolute, continuous or prismatic, and no mimic."""
        return self.type in MOVABLE and self.mimic is None


@dataclass(frozen=True)
class KinematicTree:
    """The links and joints of a URDF; `joints` by name, `parent_joint` by child link."""

    source: str
    links: frozenset[str]
    joints: Mapping[str, UrdfJoint]
    parent_joint: Mapping[str, UrdfJoint]

    def path(self, root_link: str, tip_link: str) -> list[UrdfJoint]:
        """The joints from `root_link` down to `tip_link`, root first. Raises `ModelFileError`
        naming the link that is missing, or the links above `tip_link` when `root_link` is not
        one of them."""
        for link in (root_link, tip_link):
            if link not in self.links:
                raise ModelFileError(f"{self.source} has no link {link!r}")
        chain: list[UrdfJoint] = []
        link = tip_link
        while link != root_link:
            joint = self.parent_joint.get(link)
            if joint is None:
                above = ", ".join(self.ancestors(tip_link)) or "none"
                raise ModelFileError(
                    f"link {root_link!r} is not above {tip_link!r} in {self.source}; links above it: {above}"
                )
            chain.append(joint)
            link = joint.parent
        return chain[::-1]

    def ancestors(self, link: str) -> list[str]:
        """The links above `link`, nearest first."""
        out = []
        while link in self.parent_joint:
            link = self.parent_joint[link].parent
            out.append(link)
        return out

    def below(self, link: str) -> list[UrdfJoint]:
        """Every joint in the subtree under `link` (breadth first, in file order)."""
        out: list[UrdfJoint] = []
        frontier = [link]
        while frontier:
            parent = frontier.pop(0)
            for joint in self.joints.values():
                if joint.parent == parent:
                    out.append(joint)
                    frontier.append(joint.child)
        return out


@functools.cache
def model_dir() -> Path:
    """The `share/example-robot-data` directory of the installed `example-robot-data` package
    (``PYCRAM_ROBOT_DATA`` overrides). Raises `ModelFileError` when it is not installed."""
    override = os.environ.get("PYCRAM_ROBOT_DATA")
    candidates = [Path(override)] if override else []
    candidates += [Path(p) / "cmeel.prefix" / "share" / "example-robot-data" for p in sys.path if p]
    candidates.append(Path(sys.prefix) / "share" / "example-robot-data")
    for c in candidates:
        if (c / "robots").is_dir():
            return c
    raise ModelFileError("example-robot-data is not installed (pip install 'pycram[sim]')")


def _limit(element: ET.Element | None, key: str) -> float | None:
    value = element.get(key) if element is not None else None
    return float(value) if value not in (None, "") else None


@functools.cache
def read_urdf(relative_path: str) -> KinematicTree:
    """The kinematic tree of the URDF at `relative_path` below `model_dir()` (read once, cached).
    Raises `ModelFileError` for a missing or malformed file."""
    path = model_dir() / relative_path
    if not path.is_file():
        raise ModelFileError(f"URDF {relative_path!r} not found under {model_dir()}")
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ModelFileError(f"URDF {relative_path!r} is not valid XML: {exc}") from None
    links = frozenset(link.get("name", "") for link in root.findall("link"))
    joints: dict[str, UrdfJoint] = {}
    for element in root.findall("joint"):
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise ModelFileError(f"URDF {relative_path!r}: joint {element.get('name')!r} lacks a parent or child")
        mimic, limit = element.find("mimic"), element.find("limit")
        joint = UrdfJoint(
            name=element.get("name", ""),
            type=element.get("type", ""),
            parent=parent.get("link", ""),
            child=child.get("link", ""),
            mimic=mimic.get("joint") if mimic is not None else None,
            lower=_limit(limit, "lower"),
            upper=_limit(limit, "upper"),
            velocity=_limit(limit, "velocity"),
        )
        joints[joint.name] = joint
    return KinematicTree(relative_path, links, joints, {j.child: j for j in joints.values()})


def _chain_tip(data: Mapping[str, Any], spec: Mapping[str, Any], tree: KinematicTree) -> str:
    """The URDF link an arm's chain ends at: its tool link, or the mount of our own gripper."""
    tool = spec.get("tool_link", "")
    model = data.get("GRIPPER_MODEL")
    if tool not in tree.links and isinstance(model, Mapping) and model.get("mount_link"):
        return str(model["mount_link"])
    return str(tool)


def camera_link(tree: KinematicTree, tilt_joint: str) -> str:
    """The camera link below the joint `tilt_joint` of `tree` (see the module docstring for the
    rule). Raises `ModelFileError` for an unknown joint, or naming the candidates when the rule
    finds none or several."""
    joint = tree.joints.get(tilt_joint)
    if joint is None:
        raise ModelFileError(f"{tree.source} has no joint {tilt_joint!r}")
    links = [j.child for j in tree.below(joint.child)]
    bodies = list(dict.fromkeys(tree.parent_joint[link].parent for link in links if link.endswith("optical_frame")))
    colour = [b for b in bodies if any(word in b for word in ("rgb", "color", "colour"))]
    named = [link for link in links if link.endswith(("camera_link", "camera_frame"))]
    for candidates in (colour, bodies if len(bodies) == 1 else [], [] if bodies else named):
        if len(candidates) == 1:
            return candidates[0]
    found = ", ".join(bodies or named) or "none"
    raise ModelFileError(
        f"cannot tell the camera below {tilt_joint!r} in {tree.source} (cameras: {found}); state 'camera_link' in HEAD"
    )


def infer_from_model(data: Mapping[str, Any], robot: str = "?") -> dict[str, Any]:
    """`data` (a description's keys) with what its ``URDF`` says filled in (see the module
    docstring): arms' ``joints`` from their ``root_link``, grippers' ``joint``,
    ``coupled_joints`` and ``joint_range``, the head's ``camera_link``. Keys the description
    states are kept as they are; a description that needs nothing from the file is returned
    unchanged (the file is not read).
    Raises `ModelFileError` naming the robot, the arm or gripper and what is missing."""
    data = _with_camera(data, robot)
    arms = data.get("ARMS")
    grippers = data.get("GRIPPERS")
    if not isinstance(arms, Mapping) or not isinstance(grippers, Mapping):
        return dict(data)
    arms_needing = [a for a, s in arms.items() if isinstance(s, Mapping) and "joints" not in s and "root_link" in s]
    gripper_keys = ("joint", "coupled_joints", "joint_range")
    grippers_needing = [
        g for g, s in grippers.items() if isinstance(s, Mapping) and not all(k in s for k in gripper_keys)
    ]
    if not arms_needing and not grippers_needing:
        return dict(data)
    if not isinstance(data.get("URDF"), str):
        return dict(data)  # the schema reports the missing URDF
    tree = read_urdf(data["URDF"])
    out = dict(data)
    new_arms = {a: dict(s) if isinstance(s, Mapping) else s for a, s in arms.items()}
    for arm in arms_needing:
        spec = new_arms[arm]
        try:
            path = tree.path(spec["root_link"], _chain_tip(data, spec, tree))
        except ModelFileError as exc:
            raise ModelFileError(f"robot description of {robot!r}: ARMS: arm {arm!r}: {exc}") from None
        spec["joints"] = tuple(j.name for j in path if j.movable)
    new_grippers = {g: dict(s) if isinstance(s, Mapping) else s for g, s in grippers.items()}
    for gripper in grippers_needing:
        spec = new_grippers[gripper]
        arm = next((a for a, s in new_arms.items() if isinstance(s, Mapping) and s.get("gripper") == gripper), None)
        joints = new_arms[arm].get("joints") if arm is not None else None
        if not joints or joints[-1] not in tree.joints:
            raise ModelFileError(
                f"robot description of {robot!r}: GRIPPERS: gripper {gripper!r} states no "
                f"{', '.join(k for k in gripper_keys if k not in spec)} and no arm of it is in {tree.source}"
            )
        hand = tree.below(tree.joints[joints[-1]].child)
        driving = [j for j in hand if j.movable]
        if len(driving) != 1:
            found = ", ".join(j.name for j in driving) or "none"
            raise ModelFileError(
                f"robot description of {robot!r}: GRIPPERS: gripper {gripper!r}: expected one movable "
                f"joint below arm {arm!r} in {tree.source}, found: {found}; state 'joint' and "
                "'coupled_joints' in the description"
            )
        joint = driving[0]
        spec.setdefault("joint", joint.name)
        spec.setdefault("coupled_joints", tuple(j.name for j in hand if j.mimic == joint.name))
        if "joint_range" not in spec:
            if joint.lower is None or joint.upper is None:
                raise ModelFileError(
                    f"robot description of {robot!r}: GRIPPERS: gripper {gripper!r}: joint {joint.name!r} "
                    "has no limits in the URDF; state 'joint_range' (closed, open)"
                )
            spec["joint_range"] = (joint.lower, joint.upper)
    out["ARMS"], out["GRIPPERS"] = new_arms, new_grippers
    return out


def _with_camera(data: Mapping[str, Any], robot: str) -> Mapping[str, Any]:
    """`data` with ``HEAD["camera_link"]`` read from the URDF when the head states none (a
    composed robot's head is no part of its URDF: left to the composition's checks)."""
    head = data.get("HEAD")
    if not isinstance(head, Mapping) or "camera_link" in head or data.get("COMPOSITION") is not None:
        return data
    if not isinstance(data.get("URDF"), str) or not isinstance(head.get("tilt_joint"), str):
        return data  # the schema reports what is missing
    try:
        link = camera_link(read_urdf(data["URDF"]), head["tilt_joint"])
    except ModelFileError as exc:
        raise ModelFileError(f"robot description of {robot!r}: HEAD: {exc}") from None
    return {**data, "HEAD": {**head, "camera_link": link}}
