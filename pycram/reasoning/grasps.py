"""Grasp planning: ranked grasp candidates from an object's measured shape and pose.

The per-type grasp tables (`pycram.world.objects.Grasp`, ``ObjectType.grasps``) are tuned for
objects standing upright, turned so that the robot can face them squarely. This module plans
grasps for whatever pose perception measured: a box turned to any yaw, an object lying on its
side, a bowl's or a plate's rim. Pure geometry (no robot, no simulator): location reasoning
(``to_reach``, `pycram.reasoning.locations.reach`) ranks the candidates for each base pose it
considers and validates them with prospection's inverse kinematics.

Inputs:

- `ObjectPose`: the object's type (its shape and size), its centre [m, map] and orientation
  (w, x, y, z) as measured (`pycram.world.belief.PerceivedObject.orientation`: up to the
  symmetries of its shape, turned by its measured yaw, lying with a measured axis up);
- `GripperGeometry`: the robot's gripper as its description gives it: the largest opening
  [m], how far the finger tips reach past the tool frame [m], the clearance they keep above
  the surface in a top grasp [m], and how far the tool starts back from a grasp [m].

`grasp_options` lists the ways to grasp the object where it is, independent of the robot:

- **faces** of a box (upright at any yaw, or lying): across each pair of opposite faces the
  gripper can open around (width + `MIN_MARGIN` <= largest opening) whose normal is horizontal,
  from the top (tool pointing down, fingers along that normal) and horizontally from either
  side along the box's other horizontal axis (the tool `GRASP_DEPTH` in past the near face of a
  deep box, at the middle of a thin one);
- **body** of a round object: upright, horizontally from any side and from the top; lying, from
  the top across its body and horizontally along its axis (from either end);
- **rim** of a bowl or plate (upright): from the top at the rim point nearest the robot, the
  fingers closing across the wall.

Handles are not planned: no object type describes one (the thesis demo's mug is a cylinder).

`grasp_candidates` turns the options into tool poses for a robot base at (x, y, yaw): for each
option the tool point [m, map], the tool heading [rad] (horizontal grasps: where the tool
points; top grasps: the heading `pycram.reasoning.locations.grasps.grasp_sequence` takes, the
fingers opening along it + 90 deg), its orientation (w, x, y, z; tool x along the approach, y
along the finger opening), the approach direction, the finger opening (the gripper's largest)
and the pre-grasp tool position -- ranked best first by how well the approach faces the robot
(the tool turned from the base's heading, `TURN_SCALE`; top grasps `TOP_PENALTY`) and by the
margin the opening leaves (`MARGIN_WEIGHT`). Horizontal grasps whose tool would turn more than
`MAX_TURN` from the base's heading, or come from the far side of the object, are left out.

Each candidate carries a `pycram.world.objects.Grasp` record for the actions (the approach
``'top'`` or ``'side'``, the width the fingers close on as ``opening``, the grasp point's height
above the object's bottom as it lies, the offset towards the robot as ``radius``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from pycram.world.objects import Grasp, ObjectType

__all__ = [
    "ObjectPose",
    "GripperGeometry",
    "GraspOption",
    "GraspCandidate",
    "grasp_options",
    "grasp_candidates",
    "tool_orientation",
    "GRASP_DEPTH",
    "TOP_DEPTH",
    "RIM_DEPTH",
    "MIN_MARGIN",
    "SURFACE_CLEARANCE",
    "UPRIGHT_TILT",
    "MAX_TURN",
    "TURN_SCALE",
    "TOP_PENALTY",
    "MARGIN_WEIGHT",
]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

#: A horizontal grasp of a box deeper than twice this [m] along the approach puts the tool frame
#: this far in past the face it comes through (the palm clear of the box); a thinner box is
#: grasped at its middle. The per-type tables' tuned grasps reach 2.5 cm into the cereal box.
GRASP_DEPTH = 0.025
#: A top grasp's tool frame lies this far [m] below the object's top (the tables' tuned top
#: grasps of boxes, cups and mugs: 2 to 3 cm), not below the object's middle.
TOP_DEPTH = 0.025
#: A rim grasp's tool frame lies this far [m] below the rim's top, at most half the wall's height
#: (the tables' bowl: 1 cm; plate: 4 mm).
RIM_DEPTH = 0.01
#: The gripper's largest opening must exceed the width it closes on by at least this [m].
MIN_MARGIN = 0.01
#: A horizontal grasp's tool point lies at least this far [m] above the object's bottom (the
#: fingers' own half thickness off the surface it rests on).
SURFACE_CLEARANCE = 0.02
#: An axis tilted less than this [rad] from the vertical (or horizontal) counts as vertical
#: (horizontal); an object whose own z axis is that near the vertical stands upright.
UPRIGHT_TILT = 0.35
#: A horizontal grasp's tool turns at most this much [rad] from the base's heading.
MAX_TURN = 1.25
#: Cost scale [rad] of the tool turned from the base's heading: ``(turn / TURN_SCALE) ** 2``.
TURN_SCALE = 0.6
#: Cost of a grasp from the top, as if the tool turned `TURN_SCALE` * sqrt(0.3) (ranked after
#: horizontal grasps that face the robot, as location reasoning ranks the tables' top grasps).
TOP_PENALTY = 0.3
#: Cost weight of the width closed on as a fraction of the largest opening (less margin, worse).
MARGIN_WEIGHT = 0.1


def _wrap(angle: float) -> float:
    """`angle` [rad] wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _rotation(q: Sequence[float]) -> np.ndarray:
    """The rotation matrix of a quaternion (w, x, y, z) (normalised first)."""
    w, x, y, z = (float(v) for v in q)
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def tool_orientation(heading: float, approach: str) -> Quat:
    """The tool's orientation (w, x, y, z) for `heading` [rad]: horizontal (``approach`` other
    than ``'top'``), tool x along the heading, fingers opening horizontally; ``'top'``: tool x
    pointing down, fingers opening along heading + 90 deg (as
    `pycram.reasoning.locations.grasps.grasp_sequence` orients the tool)."""
    if approach == "top":
        cz, sz, c = math.cos(heading / 2), math.sin(heading / 2), math.cos(math.pi / 4)
        return (cz * c, -sz * c, cz * c, sz * c)
    return (math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2))


@dataclass(frozen=True)
class ObjectPose:
    """An object as grasp planning sees it: its `type` (shape and size), its `centre` [m, map]
    and its `orientation` (w, x, y, z, map frame; up to the symmetries of its shape)."""

    type: ObjectType
    centre: Vec3
    orientation: Quat = (1.0, 0.0, 0.0, 0.0)

    @classmethod
    def upright(cls, type: ObjectType, centre: Sequence[float], yaw: float = 0.0) -> ObjectPose:
        """The object standing upright at `centre` [m], turned by `yaw` [rad] about z."""
        x, y, z = (float(v) for v in centre)
        return cls(type, (x, y, z), (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)))

    @property
    def rotation(self) -> np.ndarray:
        """Its own axes in the map frame, as the columns of a 3x3 matrix."""
        return _rotation(self.orientation)

    @property
    def is_upright(self) -> bool:
        """Whether its own z axis is within `UPRIGHT_TILT` of the vertical (either way up for
        boxes and round bodies; bowls and plates only the right way up)."""
        up = float(self.rotation[2, 2])
        if self.type.shape in ("bowl", "plate"):
            return up > math.cos(UPRIGHT_TILT)
        return abs(up) > math.cos(UPRIGHT_TILT)

    @property
    def half_height(self) -> float:
        """Half its vertical extent [m] as it stands or lies."""
        r = self.rotation
        if self.type.shape == "box":
            return float(sum(abs(r[2, i]) * self.type.size[i] for i in range(3)))
        radius, half = self.type.size[0], self.type.size[1]
        tilt = min(1.0, abs(float(r[2, 2])))
        return tilt * half + math.sqrt(max(0.0, 1.0 - tilt * tilt)) * radius

    @property
    def bottom(self) -> float:
        """Height [m, map] of its lowest point."""
        return self.centre[2] - self.half_height

    @property
    def top(self) -> float:
        """Height [m, map] of its highest point."""
        return self.centre[2] + self.half_height


@dataclass(frozen=True)
class GripperGeometry:
    """A robot's gripper as grasp planning needs it (from the robot's description):
    `max_opening` [m] between the finger pads fully open; `fingertip_reach` [m] how far the
    finger tips reach past the tool frame along the approach; `top_clearance` [m] they keep
    above the surface in a top grasp; `pre_grasp` [m] how far back along the approach (up, for
    top grasps) the tool starts."""

    max_opening: float
    fingertip_reach: float = 0.0
    top_clearance: float = 0.0
    pre_grasp: float = 0.1

    def __post_init__(self) -> None:
        if self.max_opening <= 0.0:
            raise ValueError(f"a gripper's max_opening must be > 0 [m], got {self.max_opening}")


@dataclass(frozen=True)
class GraspOption:
    """One way to grasp an object where it is, whatever the robot's pose.

    `approach`: ``'side'`` (horizontal) or ``'top'``; `kind`: ``'faces'`` (a box's face pair),
    ``'body'`` (a round body) or ``'rim'``; `width` [m]: what the fingers close on; `point` [m,
    map]: the tool point, for rims and round bodies on the object's axis (moved `radius` [m]
    towards the robot); `heading` [rad]: the direction a horizontal tool points (None: any,
    facing the robot); `closing` [rad]: the direction the fingers of a top grasp close along
    (None: along the line from the robot); `grasp`: the equivalent `Grasp` record.
    """

    approach: str
    kind: str
    width: float
    point: Vec3
    heading: float | None = None
    closing: float | None = None
    radius: float = 0.0
    grasp: Grasp = field(default=Grasp("side", 0.0, 0.0), compare=False)


@dataclass(frozen=True)
class GraspCandidate:
    """A grasp candidate for a robot base pose: the `option` it comes from, the tool `point`
    [m, map] at the grasp, the tool `heading` [rad] (horizontal: where the tool points; top:
    the fingers open along heading + 90 deg), the tool `orientation` (w, x, y, z), the unit
    `direction` the tool moves along into the grasp, the finger `opening` [m] to open to before
    closing, the tool's `pre_grasp` position [m, map], the `score` (lower is better) and the
    object's `centre` [m, map] it was planned for (an action that sees the object again moves
    the tool poses along with it)."""

    option: GraspOption
    point: Vec3
    heading: float
    orientation: Quat
    direction: Vec3
    opening: float
    pre_grasp: Vec3
    score: float
    centre: Vec3 = (0.0, 0.0, 0.0)

    @property
    def approach(self) -> str:
        """``'side'`` or ``'top'``."""
        return self.option.approach

    @property
    def grasp(self) -> Grasp:
        """The `Grasp` record of this candidate (see the module docstring)."""
        return self.option.grasp

    @property
    def margin(self) -> float:
        """The opening [m] left beyond the width closed on."""
        return self.opening - self.option.width


def grasp_options(obj: ObjectPose, max_opening: float) -> list[GraspOption]:
    """The ways to grasp `obj` where it is with a gripper opening at most `max_opening` [m]
    (see the module docstring); empty when none fits (too wide everywhere, or tilted neither
    upright nor on a side)."""
    if obj.type.shape == "box":
        return _box_options(obj, max_opening)
    if obj.type.shape == "cylinder":
        return _body_options(obj, max_opening)
    return _rim_options(obj, max_opening)


def _top_height(obj: ObjectPose) -> float:
    """Height [m, map] of a top grasp's tool point: `TOP_DEPTH` below the top, not below the
    middle."""
    return max(obj.centre[2], obj.top - TOP_DEPTH)


def _side_height(obj: ObjectPose) -> float:
    """Height [m, map] of a horizontal grasp's tool point: the middle, `SURFACE_CLEARANCE` above
    the bottom at least."""
    return max(obj.centre[2], obj.bottom + SURFACE_CLEARANCE)


def _box_options(obj: ObjectPose, max_opening: float) -> list[GraspOption]:
    r = obj.rotation
    half = obj.type.size
    vertical = [abs(float(r[2, i])) for i in range(3)]
    up = int(np.argmax(vertical))
    if vertical[up] < math.cos(UPRIGHT_TILT):  # on an edge or a corner: no face lies flat
        return []
    cx, cy, _ = obj.centre
    bottom = obj.bottom
    options = []
    for i in range(3):  # the axis the fingers close along
        width = 2.0 * half[i]
        if i == up or width + MIN_MARGIN > max_opening:
            continue
        closing = math.atan2(float(r[1, i]), float(r[0, i]))
        across = "xyz"[i]
        z = _top_height(obj)
        options.append(
            GraspOption(
                "top",
                "faces",
                width,
                (cx, cy, z),
                closing=closing,
                grasp=Grasp("top", width, z - bottom, across=across),
            )
        )
        j = 3 - i - up  # the other horizontal axis: the approach runs along it
        depth = max(0.0, half[j] - GRASP_DEPTH)  # the tool point's offset from the centre
        z = _side_height(obj)
        for sign in (1.0, -1.0):
            heading = math.atan2(sign * float(r[1, j]), sign * float(r[0, j]))  # the tool points so
            point = (cx - depth * math.cos(heading), cy - depth * math.sin(heading), z)
            options.append(
                GraspOption(
                    "side",
                    "faces",
                    width,
                    point,
                    heading=heading,
                    grasp=Grasp("side", width, z - bottom, radius=depth, across=across),
                )
            )
    return options


def _body_options(obj: ObjectPose, max_opening: float) -> list[GraspOption]:
    radius, half = obj.type.size[0], obj.type.size[1]
    width = 2.0 * radius
    cx, cy, _ = obj.centre
    bottom = obj.bottom
    options: list[GraspOption] = []
    if obj.is_upright:
        if width + MIN_MARGIN > max_opening:
            return []
        z = _side_height(obj)
        options.append(GraspOption("side", "body", width, (cx, cy, z), grasp=Grasp("side", width, z - bottom)))
        z = _top_height(obj)
        options.append(
            GraspOption("top", "body", width, (cx, cy, z), grasp=Grasp("top", width, z - bottom, across="radial"))
        )
        return options
    r = obj.rotation
    if abs(float(r[2, 2])) > math.sin(UPRIGHT_TILT):  # neither standing nor lying
        return []
    axis = math.atan2(float(r[1, 2]), float(r[0, 2]))  # the body's axis, horizontal
    if width + MIN_MARGIN <= max_opening:
        z = _top_height(obj)
        options.append(
            GraspOption(
                "top",
                "body",
                width,
                (cx, cy, z),
                closing=_wrap(axis + math.pi / 2),
                grasp=Grasp("top", width, z - bottom, across="x"),
            )
        )
        depth = max(0.0, half - GRASP_DEPTH)
        z = _side_height(obj)
        for heading in (axis, _wrap(axis + math.pi)):
            point = (cx - depth * math.cos(heading), cy - depth * math.sin(heading), z)
            options.append(
                GraspOption(
                    "side",
                    "body",
                    width,
                    point,
                    heading=heading,
                    grasp=Grasp("side", width, z - bottom, radius=depth, across="x"),
                )
            )
    return options


def _rim_options(obj: ObjectPose, max_opening: float) -> list[GraspOption]:
    if not obj.is_upright:
        return []
    radius, half, wall = obj.type.size
    if wall + MIN_MARGIN > max_opening:
        return []
    # the wall rises above the base: a bowl's base is half a wall thick, a plate's most of its
    # height (`pycram.world.objects.shape_parts`)
    base = wall / 2 if obj.type.shape == "bowl" else 0.6 * half
    wall_height = 2.0 * half - base
    z = obj.top - min(RIM_DEPTH, wall_height / 2)
    rim = radius - wall / 2
    cx, cy, _ = obj.centre
    grasp = Grasp("top", wall, z - obj.bottom, radius=rim, across="radial")
    return [GraspOption("top", "rim", wall, (cx, cy, z), radius=rim, grasp=grasp)]


def grasp_candidates(
    obj: ObjectPose,
    gripper: GripperGeometry,
    base: Sequence[float],
    options: Sequence[GraspOption] | None = None,
    max_turn: float = MAX_TURN,
    arm_root: Sequence[float] | None = None,
) -> list[GraspCandidate]:
    """The grasp candidates of `obj` for a robot whose base stands at `base` = (x [m], y [m],
    yaw [rad]), best first (see the module docstring). `options` defaults to
    ``grasp_options(obj, gripper.max_opening)``; horizontal grasps turning the tool more than
    `max_turn` [rad] from the base's heading are left out. `arm_root` (x, y) [m, map]: where the
    arm reaches out from (its shoulder); a horizontal grasp is then ranked by how far its tool
    turns from the line from there to the grasp point -- an arm reaching across in front of
    the object (a left arm grasping its right side) ranks after one coming from that side --
    else by how far it turns from the base's heading."""
    bx, by, byaw = (float(v) for v in base)
    cx, cy, _ = obj.centre
    toward = math.atan2(by - cy, bx - cx)  # from the object to the robot
    if options is None:
        options = grasp_options(obj, gripper.max_opening)
    out = []
    for option in options:
        margin_cost = MARGIN_WEIGHT * option.width / gripper.max_opening
        if option.approach == "top":
            if option.kind == "rim" or option.closing is None:  # along the line from the robot
                closing = toward
                px, py, pz = option.point
                point = (px + option.radius * math.cos(toward), py + option.radius * math.sin(toward), pz)
                headings = [_wrap(closing - math.pi / 2)]
            else:  # across a fixed direction: the gripper turned half round grasps alike
                point = option.point
                headings = [_wrap(option.closing - math.pi / 2), _wrap(option.closing + math.pi / 2)]
            # the finger tips stay clear of the surface the object rests on
            lowest = obj.bottom + gripper.fingertip_reach + gripper.top_clearance
            point = (point[0], point[1], max(point[2], lowest))
            # the fingers closing along the base's heading first (as for a rim ahead of the robot)
            headings.sort(key=lambda h: abs(_wrap(h - math.pi / 2 - byaw)))
            for rank, heading in enumerate(headings):
                out.append(
                    GraspCandidate(
                        option,
                        point,
                        heading,
                        tool_orientation(heading, "top"),
                        (0.0, 0.0, -1.0),
                        gripper.max_opening,
                        (point[0], point[1], point[2] + gripper.pre_grasp),
                        TOP_PENALTY + margin_cost + 1e-3 * rank,
                        obj.centre,
                    )
                )
            continue
        heading = byaw if option.heading is None else option.heading
        if option.heading is None:  # a round body: from the robot's side, at its axis
            px, py, pz = option.point
            point = (px + option.radius * math.cos(toward), py + option.radius * math.sin(toward), pz)
        else:
            point = option.point
            if math.cos(heading - (toward + math.pi)) < 0.0:  # from the far side of the object
                continue
        if abs(_wrap(heading - byaw)) > max_turn:
            continue
        line = byaw if arm_root is None else math.atan2(point[1] - arm_root[1], point[0] - arm_root[0])
        turn = abs(_wrap(heading - line))
        c, s = math.cos(heading), math.sin(heading)
        out.append(
            GraspCandidate(
                option,
                point,
                heading,
                tool_orientation(heading, "side"),
                (c, s, 0.0),
                gripper.max_opening,
                (point[0] - gripper.pre_grasp * c, point[1] - gripper.pre_grasp * s, point[2]),
                (turn / TURN_SCALE) ** 2 + margin_cost,
                obj.centre,
            )
        )
    return sorted(out, key=lambda candidate: candidate.score)
