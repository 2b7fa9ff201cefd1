"""Object types: what a cup, a bowl, a spoon, a cereal box, a milk carton and a plate are.

Each `ObjectType` states its shape and size (as primitive parts a simulator or a picture can
build), mass, colour, where such objects are usually found (surface kinds), and how it is
grasped (`Grasp`: approach direction, finger opening, grasp height) — data that grasp planning
reads. Conventions: the object's frame sits at its centre, z up; lengths in [m], mass in [kg].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from .errors import UnknownNameError

#: A colour: red, green, blue, alpha in [0, 1].
RGBA = tuple[float, float, float, float]
#: Horizontal approach directions in the object's frame; "side" means any horizontal direction
#: (round objects), "top" straight down.
APPROACHES = ("top", "side", "+x", "-x", "+y", "-y")
#: The approach "side": asked for (`PickUp(grasp='side')`, ``('grasp', 'side')``), any horizontal
#: approach of the object's type (a box's ``+x``, ``-y``, ...), not from the top.
SIDE = "side"


def approach_matches(approach: str, requested: str) -> bool:
    """Whether a grasp approached along `approach` is one `requested` asks for: the same
    approach, or, for `SIDE`, any but ``"top"``."""
    return approach == requested or (requested == SIDE and approach != "top")


#: An object measured wider on its surface than its standing footprint (`ObjectType.footprint_radius`)
#: by more than this [m] lies on its side (seen from above, a toppled object's shadow is longer
#: than any standing one's: a milk carton lying shows at least 19 cm, standing at most 10 cm).
FOOTPRINT_SLACK = 0.02


@dataclass(frozen=True)
class Part:
    """A primitive of an object's shape, in the object's frame: a "box" (half sizes) or a
    "cylinder" (radius, half height) at `pos` [m], turned by `yaw` [rad] about z."""

    kind: Literal["box", "cylinder"]
    pos: tuple[float, float, float]
    size: tuple[float, ...]
    yaw: float = 0.0


@dataclass(frozen=True)
class Grasp:
    """One way to grasp an object type.

    `approach` is where the gripper comes from (`APPROACHES`); `opening` [m] is the distance
    between the finger pads when they close on the object; `height` [m] is the grasp point above
    the object's bottom; `radius` [m] moves the grasp point off the object's axis towards the
    gripper (rim grasps of bowls and plates: the fingers pinch the wall; side grasps of deep
    boxes: the fingers close near the face the gripper comes from, the palm clear of the box);
    `across` says which object axis the fingers close across for a top grasp ("x", "y", or
    "radial": along the line from the robot -- a rim at `radius`, or, without one, a round body
    at its axis).
    """

    approach: str
    opening: float
    height: float
    radius: float = 0.0
    across: str = ""

    def __post_init__(self) -> None:
        if self.approach not in APPROACHES:
            raise ValueError(f"grasp approach {self.approach!r} is not one of {', '.join(APPROACHES)}")

    @property
    def held_from_above(self) -> bool:
        """Whether an object held with this grasp is carried with the tool pointing down (the
        arm's ``carry_top`` configuration, where it has one): top grasps of rims and across an
        axis (bowls, plates, spoons, boxes from above) -- not the top grasp of a cup's or mug's
        body (out of a drawer): carried so and put down on the table, the PR2's cup ended tilted
        75 deg (measured), in ``carry`` (the tool level) upright."""
        return self.approach == "top" and not (self.across == "radial" and self.radius == 0.0)

    def side_point(
        self, centre: tuple[float, float, float] | list[float], half_height: float, heading: float
    ) -> tuple[float, float, float]:
        """The tool point [m, map] of this grasp from a horizontal approach along `heading` [rad]
        (the direction the tool points) of an object whose centre is at `centre` [m] and whose
        half height is `half_height` [m]: `height` above its bottom, `radius` back towards the
        gripper."""
        x, y, z = centre
        return (
            x - self.radius * math.cos(heading),
            y - self.radius * math.sin(heading),
            z - half_height + self.height,
        )


@dataclass(frozen=True)
class ObjectType:
    """A kind of household object.

    `shape` is "box" (size: half sizes x, y, z), "cylinder" (radius, half height), "bowl" or
    "plate" (radius, half height, wall thickness: a base with a wall around it). `found_on` are
    the surface kinds such objects are put on or in ("counter", "table", "cupboard", "drawer",
    "shelf" -- a fridge's), most likely first: a search opens the containers whose insides are
    of an earlier kind first (cups are kept in drawers, then in a cupboard, before the fridge).
    `stored_in` are the kinds of container insides such objects are *put away* in, best first
    (`STORED_IN`: milk cold on a fridge's "shelf", cereal dry in the "cupboard", cups in a
    "drawer"); empty for a type that is not put away.
    """

    name: str
    shape: Literal["box", "cylinder", "bowl", "plate"]
    size: tuple[float, ...]
    mass: float
    rgba: RGBA
    grasps: tuple[Grasp, ...]
    found_on: tuple[str, ...] = ("counter", "table", "drawer", "cupboard", "shelf")
    description: str = ""
    stored_in: tuple[str, ...] = ()

    @property
    def half_height(self) -> float:
        """Half the object's height [m]."""
        return self.size[2] if self.shape == "box" else self.size[1]

    @property
    def height(self) -> float:
        return 2.0 * self.half_height

    @property
    def lying_height(self) -> float:
        """The tallest [m] the object stands when toppled over (on a side, not its base): a box's
        larger horizontal size, a cylinder's or dish's diameter."""
        return 2.0 * max(self.size[0], self.size[1]) if self.shape == "box" else 2.0 * self.size[0]

    @property
    def topples_visibly(self) -> bool:
        """Whether standing and toppled over are told apart by the measured height alone (lying,
        it is at most 3/4 as tall as standing): milk cartons and cereal boxes, not cups."""
        return self.lying_height <= 0.75 * self.height

    @property
    def footprint_radius(self) -> float:
        """Radius [m] of the smallest circle around the object's shadow on a surface (any yaw)."""
        return math.hypot(self.size[0], self.size[1]) if self.shape == "box" else self.size[0]

    @property
    def extents(self) -> tuple[float, float, float]:
        """The object's full lengths [m] along its own x, y and z axes (a box's sizes; a round
        object's diameter twice, then its height)."""
        if self.shape == "box":
            return (2.0 * self.size[0], 2.0 * self.size[1], 2.0 * self.size[2])
        return (2.0 * self.size[0], 2.0 * self.size[0], 2.0 * self.size[1])

    def lying_axis(self, measured: tuple[float, ...] | list[float]) -> str | None:
        """Which of the object's own axes (``"x"`` or ``"y"``) stands vertical when an object of
        this type, measured `measured` = (width, depth, height) [m] on a surface by perception,
        lies on its side; None when it stands upright (or the measurement does not tell).

        It lies when its measured shadow is wider than its standing footprint by more than
        `FOOTPRINT_SLACK` (the height alone is no proof: the robot's own arm hiding the top makes
        a standing object look short). Of a box the axis whose length is nearest the measured
        height stands up (a cereal box lies on its broad or its narrow face); a round object's
        radial axis is called ``"x"``."""
        if len(measured) < 3 or max(float(measured[0]), float(measured[1])) <= (
            2.0 * self.footprint_radius + FOOTPRINT_SLACK
        ):
            return None
        if self.shape != "box":
            return "x"
        height = float(measured[2])
        return min(("x", "y"), key=lambda a: abs(self.extents["xy".index(a)] - height))

    def parts(self) -> list[Part]:
        """The object's shape as primitives (see `shape_parts`)."""
        return shape_parts(self.shape, self.size)


def shape_parts(shape: str, size: tuple[float, ...]) -> list[Part]:
    """Primitive parts of a shape: one part for "box" and "cylinder"; a base disc and 12 wall
    boxes around it for "bowl" and "plate" (size: radius, half height, wall thickness)."""
    if shape == "box":
        return [Part("box", (0.0, 0.0, 0.0), tuple(size))]
    if shape == "cylinder":
        return [Part("cylinder", (0.0, 0.0, 0.0), (size[0], size[1]))]
    if shape in ("bowl", "plate"):
        radius, half, wall = size
        base = wall / 2 if shape == "bowl" else 0.6 * half  # a plate's base is most of its height
        n = 12
        parts = [Part("cylinder", (0.0, 0.0, -half + base), (radius, base))]
        wall_half = half - base
        r = radius - wall / 2
        for i in range(n):
            a = 2 * math.pi * i / n
            parts.append(
                Part(
                    "box",
                    (r * math.cos(a), r * math.sin(a), half - wall_half),
                    (wall / 2, r * math.tan(math.pi / n) + 0.001, wall_half),
                    a,
                )
            )
        return parts
    raise ValueError(f"shape {shape!r} is not one of: box, cylinder, bowl, plate")


_ANY_SURFACE = ("counter", "table", "drawer", "cupboard", "shelf")

#: Where each object type is put away, as data: type -> the kinds of container insides
#: (`pycram.world.environment.Surface.kind`: "drawer", "cupboard", "shelf" -- a fridge's) it
#: belongs in, best first; each kind is one the type is found on (`ObjectType.found_on`). Cold
#: food (milk) goes into the fridge, dry food (cereal) into the cupboard, cups, bowls and cutlery
#: into the drawers, plates (too wide for a drawer) into the cupboard. Read by
#: `ObjectType.stored_in`.
STORED_IN: dict[str, tuple[str, ...]] = {
    "cup": ("drawer", "cupboard"),
    "mug": ("cupboard",),
    "bowl": ("drawer", "cupboard"),
    "plate": ("cupboard",),
    "spoon": ("drawer",),
    "cereal": ("cupboard",),
    "milk": ("shelf",),
}

#: Every object type by name.
OBJECT_TYPES: dict[str, ObjectType] = {
    t.name: t
    for t in (
        ObjectType(
            "cup",
            "cylinder",
            (0.035, 0.045),
            0.2,
            (0.80, 0.18, 0.15, 1.0),
            (Grasp("side", 0.07, 0.05), Grasp("top", 0.07, 0.06, across="radial")),
            _ANY_SURFACE,
            "a drinking cup, 7 cm wide, 9 cm tall; from the top (in drawers) by its body",
            stored_in=STORED_IN["cup"],
        ),
        ObjectType(
            "mug",
            "cylinder",
            (0.03, 0.05),
            0.25,
            (1.0, 0.82, 0.05, 1.0),
            (Grasp("side", 0.06, 0.05), Grasp("top", 0.06, 0.07, across="radial")),
            ("counter", "table", "cupboard", "shelf"),
            "the thesis demo's mug, 6 cm wide, 10 cm tall (yellow, to stand out in pictures)",
            stored_in=STORED_IN["mug"],
        ),
        ObjectType(
            "bowl",
            "bowl",
            (0.07, 0.035, 0.008),
            0.25,
            (0.95, 0.82, 0.25, 1.0),
            (Grasp("top", 0.008, 0.06, radius=0.066, across="radial"),),
            _ANY_SURFACE,
            "a cereal bowl, 14 cm wide, 7 cm tall; grasped at its rim",
            stored_in=STORED_IN["bowl"],
        ),
        ObjectType(
            "plate",
            "plate",
            (0.11, 0.012, 0.008),
            0.35,
            (0.96, 0.96, 0.93, 1.0),
            (Grasp("top", 0.008, 0.02, radius=0.106, across="radial"),),
            ("counter", "table", "cupboard", "shelf"),
            "a dinner plate, 22 cm wide, with a 1 cm rim; grasped at its rim",
            stored_in=STORED_IN["plate"],
        ),
        ObjectType(
            "spoon",
            "box",
            (0.075, 0.011, 0.005),
            0.04,
            (0.70, 0.72, 0.75, 1.0),
            (Grasp("top", 0.022, 0.005, across="y"),),
            ("counter", "table", "drawer"),
            "a spoon (a flat bar, 15 cm long); grasped from above across its handle",
            stored_in=STORED_IN["spoon"],
        ),
        ObjectType(
            "cereal",
            "box",
            (0.035, 0.095, 0.14),
            0.4,
            (0.92, 0.55, 0.12, 1.0),
            (
                Grasp("+y", 0.07, 0.16, radius=0.07),
                Grasp("-y", 0.07, 0.16, radius=0.07),
                Grasp("top", 0.07, 0.26, across="x"),
            ),
            ("counter", "table", "cupboard", "shelf"),
            "a cereal box, 7 x 19 x 28 cm; grasped across its narrow side, 2.5 cm in from its end",
            stored_in=STORED_IN["cereal"],
        ),
        ObjectType(
            "milk",
            "box",
            (0.035, 0.035, 0.1),
            0.5,
            (0.92, 0.94, 1.0, 1.0),
            tuple(Grasp(a, 0.07, 0.1) for a in ("+x", "-x", "+y", "-y")),
            ("counter", "table", "shelf"),
            "a milk carton, 7 x 7 x 20 cm",
            stored_in=STORED_IN["milk"],
        ),
    )
}


def object_type(name: str) -> ObjectType:
    """The object type called `name` (`UnknownNameError` listing the valid names otherwise)."""
    if name not in OBJECT_TYPES:
        raise UnknownNameError("object type", name, OBJECT_TYPES)
    return OBJECT_TYPES[name]


__all__ = [
    "SIDE",
    "approach_matches",
    "ObjectType",
    "Grasp",
    "Part",
    "OBJECT_TYPES",
    "STORED_IN",
    "APPROACHES",
    "FOOTPRINT_SLACK",
    "object_type",
    "shape_parts",
]
