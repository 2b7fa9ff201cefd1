"""Pushing a door along its arc: the tool poses, shared by location reasoning (which validates
them from a standing pose) and the opening and closing plans (which execute them).

A hand pushes a door's face without grasping anything: from ``'inside'`` (behind a door already
partly open, to open it further -- the way people open a door with the back of a hand or an
elbow) or from ``'outside'`` (its handle's face, to push it shut). How a robot's hand meets each
face is that robot's data, its description's ``DOOR_PUSH[side]``:

- ``'heading'`` [rad]: the direction the tool's x axis points, in the frame of the face at the
  contact point: 0 along the panel towards the free edge, pi towards the hinge, -pi/2 into
  the face;
- ``'offset'`` (along [m], off [m]): the tool frame from the contact point, along the panel
  (towards the free edge positive) and off the face;
- ``'gripper'`` (optional): how far open [fraction] the gripper is while pushing (default 0);

the tool's fingers open horizontally. The door's geometry (hinge, width, faces, handle height)
is the environment's description (`pycram.world.environment.Container.door_face`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

__all__ = [
    "PUSH_SIDES",
    "PushPose",
    "push_pose",
    "push_sequence",
    "push_distance",
    "INSIDE_FROM_EDGE",
    "OUTSIDE_FROM_HANDLE",
    "APPROACH_CLEARANCE",
    "EDGE_CLEARANCE",
    "PUSH_DEPTH",
    "PUSH_STEPS",
    "PUSH_BEYOND",
    "retreat_sequence",
]

Side = Literal["inside", "outside"]
#: The faces a door is pushed by: ``'inside'`` (to open it further), ``'outside'`` (to shut it).
PUSH_SIDES: tuple[Side, Side] = ("inside", "outside")

#: Pushing from inside, the hand meets the face this far [m] from the free edge (leverage, and
#: the hand stays clear of the edge).
INSIDE_FROM_EDGE = 0.08
#: Pushing from outside, the hand meets the face this much [m] nearer to the hinge than the
#: handle (clear of the handle's bar and standoffs).
OUTSIDE_FROM_HANDLE = 0.15
#: Approaching, the hand keeps this far [m] off the face: (inside, outside). Behind a door open
#: only 20 deg there is little room between the panel and the cabinet.
APPROACH_CLEARANCE = {"inside": 0.03, "outside": 0.10}
#: Reaching behind a door (and back), the tool frame goes this far [m] past its free edge.
EDGE_CLEARANCE = 0.17
#: While pushing, each tool pose is this far [m] into the face (the door moves ahead of it).
PUSH_DEPTH = 0.01
#: Tool poses along the arc of a push.
PUSH_STEPS = 6
#: Pushing a door shut, the last pose is this far [rad] beyond closed (the door's stop holds it).
PUSH_BEYOND = 0.03


class PushPose(tuple):
    """A tool pose of a push: (position [m], orientation (w, x, y, z)); `angle` [rad] is how far the
    door is open when the tool is there, `phase` one of ``'approach'``, ``'contact'``, ``'push'``,
    ``'retreat'``."""

    angle: float
    phase: str

    def __new__(cls, position: tuple[float, float, float], orientation: tuple[float, ...], angle: float, phase: str):
        pose = super().__new__(cls, (position, orientation))
        pose.angle, pose.phase = float(angle), phase
        return pose

    @property
    def position(self) -> tuple[float, float, float]:
        return self[0]

    @property
    def orientation(self) -> tuple[float, ...]:
        return self[1]


def push_distance(container: Any, side: Side) -> float:
    """Where [m from the hinge axis] the hand meets the `side` face of the door `container`."""
    if side == "inside":
        return float(container.door_width) - INSIDE_FROM_EDGE
    hx, hy = container.hinge
    handle = math.hypot(container.handle[0] - hx, container.handle[1] - hy)
    return handle - OUTSIDE_FROM_HANDLE


def push_pose(
    container: Any,
    contact: Mapping[str, Any],
    q: float,
    side: Side,
    distance: float,
    clearance: float = 0.0,
    phase: str = "push",
) -> PushPose:
    """The tool pose of the robot whose hand meets each face as `contact` says (its ``DOOR_PUSH``)
    touching the `side` face of the door `container` open by `q` [rad], `distance` [m] from the
    hinge axis, the hand `clearance` [m] off the face (negative: into it). Height: the handle's."""
    contact = contact[side]
    (px, py), along, normal = container.door_face(q, distance, side)
    heading = float(contact["heading"])
    off_along, off_face = (float(v) for v in contact["offset"])
    off_face += clearance
    x = px + off_along * along[0] + off_face * normal[0]
    y = py + off_along * along[1] + off_face * normal[1]
    dx = math.cos(heading) * along[0] + math.sin(heading) * normal[0]
    dy = math.cos(heading) * along[1] + math.sin(heading) * normal[1]
    yaw = math.atan2(dy, dx)
    return PushPose((x, y, float(container.handle[2])), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)), q, phase)


def _past_edge(container: Any, contact: Mapping[str, Any]) -> float:
    """The contact distance [m from the hinge axis] that puts the tool `EDGE_CLEARANCE` past the
    door's free edge."""
    return float(container.door_width) + EDGE_CLEARANCE - float(contact["inside"]["offset"][0])


def push_sequence(
    container: Any, contact: Mapping[str, Any], start: float, goal: float, side: Side, steps: int = PUSH_STEPS
) -> list[PushPose]:
    """The tool poses of pushing the door `container` from `start` to `goal` [rad] by its `side`
    face: the approach (from inside: past the free edge first, then along the face), the
    contact, `steps` poses along the arc (closing: one more, `PUSH_BEYOND` past closed), each
    with the door angle it expects."""
    distance = push_distance(container, side)
    clear = APPROACH_CLEARANCE[side]
    poses: list[PushPose] = []
    if side == "inside":  # round the free edge, then in along the face
        poses.append(push_pose(container, contact, start, side, _past_edge(container, contact), clear, "approach"))
    poses.append(push_pose(container, contact, start, side, distance, clear, "approach"))
    poses.append(push_pose(container, contact, start, side, distance, 0.0, "contact"))
    for k in range(1, steps + 1):
        q = start + (goal - start) * k / steps
        poses.append(push_pose(container, contact, q, side, distance, -PUSH_DEPTH))
    if goal <= 0.0:
        poses.append(push_pose(container, contact, -PUSH_BEYOND, side, distance, -PUSH_DEPTH))
    return poses


def retreat_sequence(container: Any, contact: Mapping[str, Any], q: float, side: Side) -> list[PushPose]:
    """Tool poses of letting go of a door open by `q` [rad] after pushing its `side` face: off the
    face, and from inside out past the free edge (an arm drawn back through the door would push it)."""
    distance = push_distance(container, side)
    clear = APPROACH_CLEARANCE[side] + 0.05
    poses = [push_pose(container, contact, q, side, distance, clear, "retreat")]
    if side == "inside":
        poses.append(push_pose(container, contact, q, side, _past_edge(container, contact), clear, "retreat"))
    return poses
