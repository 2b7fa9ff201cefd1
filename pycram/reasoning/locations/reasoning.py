"""Location reasoning: costmaps ranked best-first, candidates validated by prospection.

`LocationReasoner` resolves the robot- and environment-agnostic location vocabulary:

===================================  ===========================================================
designator                           solutions
===================================  ===========================================================
``('to_reach', t)`` [``('arm', a)``,  `BaseLocation` from which the arm executes the whole grasp
``('grasp', g)``, ``('action',        sequence (pre_grasp, grasp, lift; with ``('action',
'place')``]                           'place')``: pre_place, place, retreat) without collision; it
                                     names the arm and grasp found
``('to_see', t)``                    `BaseLocation` from which the head camera sees ``t``
                                     (at least half of it, unoccluded)
``('to_open', c)`` [``('arm', a)``,   `BaseLocation` from which the arm grasps the handle of the
``('opening', q)``]                   drawer or door ``c`` and follows its opening trajectory
``('to_open', door), ('pushing', s)``  `BaseLocation` from which the hand pushes the door's face
[``('opening', q)``, ``('arm', a)``]  ``s`` (``'inside'``/``'outside'``) along its arc to ``q``
                                     (`pycram.reasoning.locations.doors`; ``push`` names the side)
``('on', s)`` [``('near', o)``,       `Spot`: a free spot on surface ``s`` where an object of that
``('for', type/object)``]             type fits without touching the known objects
``('in', c)`` [same options]         `Spot` inside container ``c`` (its interior surfaces)
===================================  ===========================================================

A target ``t`` is an object designator, a believed object, a named place/surface/container or a
point (see `pycram.reasoning.locations.targets`). Designators with other properties are not ours
(``None``: other generators answer them, e.g. a world's named places).

How: layers over the floor (`pycram.reasoning.locations.costmap`) -- occupancy from the environment's
description inflated by the robot's inscribed radius, a Gaussian reachability ring around the
target from the arm's comfortable reach (robot description), a preference for facing the
furniture squarely, and for ``to_see`` a viewing ring -- are summed, and cells are taken
cheapest first, lazily. Each candidate is checked with prospection (`Prospection.in_collision`,
`reachable` for the IK sequence, `visible`) in the world as it is now; solutions keep
`SPACING` apart, so the next solution is a different place, never a repeat.

Bounded: at most `MAX_CANDIDATES` candidates are checked per designator. When none passes,
`NoSolutionError` says how many were tried and what ruled them out, e.g. ``312 candidates: 280
in collision, 32 unreachable for arm 'left' (out_of_reach 20, collision 12)``.
"""

from __future__ import annotations

import heapq
import logging
import math
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from pycram.designators.core import NoSolutionError
from pycram.world.environment import FURNITURE_TOPS, Container, Environment, Surface, Vec3
from pycram.world.objects import Grasp, ObjectType, object_type

from . import doors
from .costmap import Costmap, FloorGrid, angle_difference, occupancy_layer, rect_distance, ring_layer, segment_distance
from .robot_geometry import RobotGeometry
from .solutions import BaseLocation, Spot
from .targets import KnownObject, Target, as_target

__all__ = ["LocationReasoner", "VOCABULARY", "MAX_CANDIDATES", "SPACING", "grasp_sequence"]

log = logging.getLogger(__name__)

#: The keys location reasoning understands; a designator with any other key is left to others.
VOCABULARY = frozenset(
    {"to_reach", "to_see", "to_open", "on", "in", "arm", "grasp", "near", "for", "action", "opening", "pushing"}
)
#: Free space [m] kept between the base's inscribed circle and the furniture: the base must be
#: able to drive there (navigation keeps its own clearance of a few cm, on a 5 cm grid).
BASE_CLEARANCE = 0.1
#: Candidates checked with prospection per designator before giving up.
MAX_CANDIDATES = 100
#: Distance [m] between two solutions of one designator (base poses or spots).
SPACING = 0.1
#: Cells closer than this [m] to a candidate that failed for the same arm are not checked (the
#: cells around it: their answer is almost always the same).
FAILED_SPACING = 0.075
#: Spots on surfaces: grid cell [m], free space [m] to other objects and to the surface's edge.
SPOT_RESOLUTION = 0.02
SPOT_GAP = 0.02
SPOT_EDGE_MARGIN = 0.03
#: Footprint radius [m] and half height [m] assumed for ``('on', s)`` without ``('for', ...)``.
DEFAULT_OBJECT = (0.05, 0.0)
#: Viewing ring for ``to_see`` [m]: preferred distance, spread, nearest, farthest.
VIEW_RING = (1.3, 0.5, 0.6, 3.0)
#: Reach ring spread [m] and its limits around the arm's comfortable distance [m].
REACH_SIGMA, REACH_INSIDE, REACH_OUTSIDE = 0.12, 0.35, 0.30
#: Facing the furniture: angle [rad] scale of its cost; a grasp's approach may deviate this much
#: [rad] from the base heading.
FACING_SCALE = 0.6
APPROACH_TOLERANCE = 0.45
#: In a drawer, a tool without the object passes this far [m] above the top of its walls, and a
#: held object's bottom as far (the approach and the lift of top grasps).
RIM_CLEARANCE = 0.04
#: Free space [m] kept between the base's inscribed circle and an open drawer (the base stands
#: close to reach over it; its footprint is checked with prospection).
DRAWER_CLEARANCE = 0.08
#: Free space [m] kept between the base's inscribed circle and an open door's panel (more than
#: for a drawer: a corner of the base turned towards the panel comes closer than the circle).
DOOR_CLEARANCE = 0.12
#: A door counts as standing out into the room from this opening [rad] on.
DOOR_OPEN_FROM = 0.05
#: How far [m] a drawer's handle bar reaches beyond its grasp point (the bar's half thickness).
HANDLE_DEPTH = 0.015
#: Closing a drawer, the hand pushes its handle this far [m] beyond closed (against the slide's
#: stop: the bar sits loose between the fingers, and a drawer pushed to exactly 0 stays ajar).
#: Standing poses for closing a drawer are checked for it too.
DRAWER_PUSH_BEYOND = 0.03
#: Rank of a top grasp among horizontal ones (as if it deviated this much [rad]).
TOP_PENALTY = 0.3
#: Pushing a door: base headings tried per cell, relative to the one that puts the push's first
#: tool pose at the arm's comfortable reach point [rad] (the hand then sweeps across the front).
PUSH_YAW_OFFSETS = (0.0, -0.4, 0.4, -0.8, 0.8)
#: ... and the cells are ranked by how far [rad, as a scale] their bearing from the hinge is from
#: the door's direction half way through the push (the robot stands in front of the swing).
PUSH_BEARING_SCALE = 0.5
#: Default opening [m for drawers, rad for doors] followed by ``to_open``.
DRAWER_OPENING, DOOR_OPENING = 0.3, 1.2
#: Grasp phases of ``to_reach`` by action.
PHASES = {"grasp": ("pre_grasp", "grasp", "lift"), "place": ("pre_place", "place", "retreat")}
#: Approach side in the object's frame -> angle [rad] of that side.
_SIDE_ANGLE = {"+x": 0.0, "-x": math.pi, "+y": math.pi / 2, "-y": -math.pi / 2}
_POINT_GRASP = Grasp("side", 0.07, 0.0)


def _quat_yaw(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def _quat_yaw_rolled(yaw: float) -> tuple[float, float, float, float]:
    """Tool x along `yaw`, turned 90 deg about itself: the fingers open vertically."""
    c, s, r = math.cos(yaw / 2), math.sin(yaw / 2), math.sqrt(0.5)
    return (c * r, c * r, s * r, s * r)


def _quat_down(yaw: float) -> tuple[float, float, float, float]:
    """Tool x pointing down, tool y across `yaw` (rotation about z by yaw, then about y by 90 deg)."""
    cz, sz, c, s = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(math.pi / 4), math.sin(math.pi / 4)
    return (cz * c, -sz * s, cz * s, sz * c)


def grasp_sequence(
    geometry: RobotGeometry, point: Sequence[float], heading: float, approach: str, action: str = "grasp"
) -> list[tuple[tuple[float, float, float], tuple]]:
    """Tool poses (position [m], orientation (w, x, y, z)) of the grasp or place sequence at
    `point`: the tool points along `heading` [rad] (horizontal approaches) or down (``'top'``),
    each phase offset by the robot's ``APPROACH_OFFSETS`` (back along the approach, up)."""
    x, y, z = point
    out = []
    for phase in PHASES[action]:
        back, up = geometry.approach_offsets.get(phase, (0.0, 0.0))
        if approach == "top":
            out.append(((x, y, z + back + up), _quat_down(heading)))
        else:
            c, s = math.cos(heading), math.sin(heading)
            out.append(((x - c * back, y - s * back, z + up), _quat_yaw(heading)))
    return out


class _Tally:
    """Why candidates failed, for the error message."""

    def __init__(self) -> None:
        self.tried = 0
        self.reasons: Counter[str] = Counter()
        self.details: dict[str, Counter[str]] = {}

    def fail(self, reason: str, detail: str | None = None) -> None:
        self.reasons[reason] += 1
        if detail:
            self.details.setdefault(reason, Counter())[detail] += 1

    def summary(self) -> str:
        parts = []
        for reason, n in self.reasons.most_common():
            if not n:
                continue
            detail = self.details.get(reason)
            more = (
                f" ({', '.join(f'{k} {v}' for k, v in detail.most_common() if v)})"
                if detail and any(detail.values())
                else ""
            )
            parts.append(f"{n} {reason}{more}")
        return f"{self.tried} candidates: " + ", ".join(parts) if parts else f"{self.tried} candidates"


class LocationReasoner:
    """Resolves the location vocabulary for one robot (see the module docstring).

    `environment()` returns the environment's description, `prospection()` the robot's
    `Prospection` in the current world, `known_objects()` the objects believed to be around
    (`KnownObject`s; used for free spots and to look up targets by name), `container_states()`
    how far each container is believed open (``to_open`` moves the handle on from there). All are
    called at
    resolution time, so answers reflect the world as it is then. `last_costmaps` holds the
    costmaps of the latest base-pose resolution by name (for pictures; not for reasoning).
    """

    def __init__(
        self,
        geometry: RobotGeometry,
        environment: Callable[[], Environment],
        prospection: Callable[[], Any],
        known_objects: Callable[[], Sequence[KnownObject]] = lambda: (),
        max_candidates: int = MAX_CANDIDATES,
        container_states: Callable[[], Mapping[str, float]] = dict,
    ) -> None:
        self.geometry = geometry
        self.environment = environment
        self.prospection = prospection
        self.known_objects = known_objects
        #: How far each container is believed open [m or rad] (perceived; missing: closed).
        self.container_states = container_states
        self.max_candidates = max_candidates

    @property
    def _base_radius(self) -> float:
        """The base's inscribed radius plus the clearance it keeps [m] (the occupancy inflation)."""
        return self.geometry.inscribed_radius + BASE_CLEARANCE

    # ------------------------------------------------------------------ entry point
    def generator(self, desig: Any) -> Iterator[Any] | None:
        """The location generator: an iterator of solutions, or None when `desig` is not ours."""
        keys = [k for k, _ in desig.properties]
        if not keys or any(k not in VOCABULARY for k in keys):
            return None
        for key, method in (
            ("to_reach", self.to_reach),
            ("to_see", self.to_see),
            ("to_open", self.to_open),
            ("on", self.on),
            ("in", self.inside),
        ):
            if desig.prop_value(key) is not None:
                return method(desig)
        return None

    def _fail(self, desig: Any, what: str) -> NoSolutionError:
        return NoSolutionError(f"Cannot resolve {desig!r}: {what}", designator=desig)

    def _target(self, value: Any) -> Target:
        return as_target(value, self.environment(), self.known_objects())

    # ------------------------------------------------------------------ to_reach
    def to_reach(self, desig: Any) -> Iterator[BaseLocation]:
        target = self._target(desig.prop_value("to_reach"))
        action = desig.prop_value("action") or "grasp"
        if action not in PHASES:
            raise ValueError(f"('action', {action!r}) is not one of {sorted(PHASES)}")
        arms = self._arms(desig.prop_value("arm"))
        grasps = self._grasps(target, desig.prop_value("grasp"))
        env = self.environment()
        drawer = self._drawer_around(target)
        if drawer is not None:
            grasps = self._over_the_rim(desig, target, grasps, drawer)
        elif desig.prop_value("grasp") is None:  # out in the open, a cup is taken by its side
            grasps = [g for g in grasps if not _body_from_the_top(g)] or grasps
        grid = FloorGrid.of(env)
        # the base may come closer to an open drawer than to the furniture
        occupancy = self._occupancy_with_drawers(env, grid, self._open_drawers(env), self._open_doors(env))
        facing = self._facing_yaws(env, target)
        streams = []
        maps = {}
        for arm in arms:
            yaw = self._natural_yaw(grid, target.position, arm)
            costmap = Costmap(grid, {"occupancy": occupancy})
            d0 = self.geometry.reach_distance(arm)
            costmap.add(
                "reach",
                ring_layer(grid, target.position, d0, REACH_SIGMA, max(0.2, d0 - REACH_INSIDE), d0 + REACH_OUTSIDE),
            )
            if facing:
                costmap.add("facing", self._facing_layer(yaw, facing))
            costmap.add("grasp", self._grasp_layer(yaw, grasps, target))
            maps[arm] = costmap
            streams.append(_ranked(costmap, arms.index(arm), arm))
        self.last_costmaps = maps

        def validate(
            cell: tuple, torsos: str = "current", heights: list[tuple[str, float]] | None = None
        ) -> tuple[BaseLocation | None, tuple[str, str | None] | None]:
            """`torsos`: which torso heights to validate at -- the ``current`` one, the ``other``
            named ones (`heights`, default: every other one), or ``both`` (the current one first)."""
            cost, _, arm, r, c = cell
            x, y = maps[arm].xy(r, c)
            natural = _wrap(
                math.atan2(target.position[1] - y, target.position[0] - x) - self.geometry.reach_bearing(arm)
            )
            prosp = self.prospection()
            tucked = dict(self.geometry.tucked)
            raised = self.geometry.raised(arm)

            options = []  # (grasp, base yaw, tool point, tool heading)
            for grasp, heading in self._grasp_options(grasps, target, natural):
                yaw = natural if grasp.approach in ("side", "top") else _wrap(heading)
                if grasp.approach != "top":
                    options.append((grasp, yaw, self._grasp_point(target, grasp, yaw), yaw))
                    continue
                point, tool_heading = self._top_grasp(target, grasp, x, y)
                options.append((grasp, yaw, point, tool_heading))
                if grasp.radius == 0.0 and grasp.across != "radial":
                    # across an axis: the gripper turned half round grasps alike
                    options.append((grasp, yaw, point, _wrap(tool_heading + math.pi)))

            def sequences(configuration: dict[str, float]) -> tuple[BaseLocation | None, tuple[str, str | None]]:
                failure: tuple[str, str | None] = ("no fitting grasp", None)
                for grasp, yaw, point, heading in options:
                    poses = grasp_sequence(self.geometry, point, heading, grasp.approach, action)
                    if drawer is not None:
                        poses = self._clear_of_the_rim(poses, grasp, drawer.rim_height, action)
                    margin = self.geometry.contact_margin if action == "grasp" else 0.0
                    if margin:  # room to spare below the grasp
                        (gx, gy, gz), q = poses[1]
                        poses.insert(2, ((gx, gy, gz - margin), q))
                    answer = prosp.reachable(arm, poses, (x, y, yaw), configuration)
                    if answer:
                        joints = tuple(j for i, j in enumerate(answer.solutions) if not (margin and i == 2))
                        tool = tuple(p for i, p in enumerate(poses) if not (margin and i == 2))
                        location = BaseLocation(x, y, yaw, arm, grasp.approach, cost, joints=joints, tool_poses=tool)
                        return location, failure
                    failure = (f"unreachable for arm {arm!r}", answer.reason)
                return None, failure

            failure: tuple[str, str | None] = ("in collision at every other torso height", None)
            if torsos != "other":
                if prosp.in_collision((x, y, natural), tucked):
                    return None, ("in collision", None)
                if prosp.in_collision((x, y, natural), raised):
                    failure = (f"arm {arm!r} hits the furniture when raised to approach", None)
                    if torsos == "current":
                        return None, failure
                else:
                    found, failure = sequences(raised)
                    if found is not None or torsos == "current":
                        return found, (None if found is not None else failure)
            # the target lies low or high for the torso as it is: another torso height
            joint = self.geometry.torso_joint
            for torso, height in self._other_torso_heights() if heights is None else heights:
                assert joint is not None  # there are other torso heights only with a torso joint
                if prosp.in_collision((x, y, natural), {**tucked, joint: height}) or prosp.in_collision(
                    (x, y, natural), {**raised, joint: height}
                ):
                    continue
                other, why = sequences({**raised, joint: height})
                if other is not None:
                    return replace(other, torso=torso), None
                failure = why
            return None, failure

        if drawer is not None:  # in a drawer the torso height is part of every candidate's question
            return self._search(
                desig, heapq.merge(*streams), partial(validate, torsos="both"), "to_reach", target, maps
            )
        tally = _Tally()
        first = self._search(desig, heapq.merge(*streams), validate, "to_reach", target, maps, tally)
        higher = self._higher_torso_heights()
        if not higher:
            return first

        def again() -> Iterator[BaseLocation]:
            cells = heapq.merge(*(_ranked(maps[arm], arms.index(arm), arm) for arm in arms))
            check = partial(validate, torsos="other", heights=higher)
            return self._search(desig, cells, check, "to_reach", target, maps)

        return self._or_else(desig, first, tally, again)

    def _or_else(
        self,
        desig: Any,
        first: Iterator[BaseLocation],
        tally: _Tally,
        second: Callable[[], Iterator[BaseLocation]],
    ) -> Iterator[BaseLocation]:
        """The solutions of `first` (the torso as it is); only when it has none at all and not
        every candidate was in collision (`tally`: the base itself; another torso height would
        not help), those of `second()` (a higher torso) -- `NoSolutionError` saying why neither
        had any."""
        try:
            yield from first
            return
        except NoSolutionError as error:
            if set(tally.reasons) <= {"in collision"}:
                raise
            why = str(error)
        try:
            yield from second()
        except NoSolutionError as error:
            raise NoSolutionError(
                f"{why}; with the torso higher: {str(error).split(': ', 1)[-1]}", designator=desig
            ) from error

    def _arms(self, requested: Any) -> list[str]:
        if requested is not None:
            return [self.geometry.arm(requested)]
        others = [a for a in self.geometry.arms if a != self.geometry.default_arm]
        return [self.geometry.default_arm] + others

    def _grasps(self, target: Target, requested: Any) -> list[Grasp]:
        grasps = list(target.type.grasps) if target.type is not None else [_POINT_GRASP]
        if requested is not None:
            chosen = [g for g in grasps if g.approach == requested]
            if not chosen:
                raise ValueError(
                    f"no grasp {requested!r} for {target.describe()}; available: {[g.approach for g in grasps]}"
                )
            return chosen
        return grasps

    def _drawer_around(self, target: Target) -> Container | None:
        """The drawer `target` (an object) lies in, as far as the environment's description and
        the believed openings (`container_states`) say; None when it lies in none."""
        if target.kind != "object":
            return None
        above = (target.type.half_height if target.type is not None else 0.0) + 0.05
        states = self.container_states()
        for container in self.environment().containers:
            q = float(states.get(container.name, 0.0))
            if container.surface_holding(target.position, q, above) is not None:
                return container
        return None

    def _over_the_rim(self, desig: Any, target: Target, grasps: list[Grasp], drawer: Container) -> list[Grasp]:
        """The grasps of `target` lying in `drawer` that do not pass through its walls: from the
        top, or horizontal ones whose grasp point lies `RIM_CLEARANCE` above the walls' top.
        `NoSolutionError` when none is left."""
        rim = drawer.rim_height
        bottom = target.position[2] - (target.type.half_height if target.type is not None else 0.0)
        fitting = [g for g in grasps if g.approach == "top" or bottom + g.height > rim + RIM_CLEARANCE]
        if not fitting:
            raise self._fail(
                desig,
                f"{target.describe()} lies in {drawer.name!r}, whose walls rise to {rim:.2f} m, above the "
                f"grasp points of its grasps {[g.approach for g in grasps]} (from the side the fingers "
                f"would pass through the walls; a grasp from the top would not)",
            )
        return fitting

    @staticmethod
    def _clear_of_the_rim(
        poses: list[tuple[tuple[float, float, float], tuple]], grasp: Grasp, rim: float, action: str
    ) -> list[tuple[tuple[float, float, float], tuple]]:
        """A top grasp's or placing's sequence in a drawer with walls up to `rim` [m]: the tool
        comes in and leaves above them -- empty (pre_grasp, retreat) `RIM_CLEARANCE` above, holding
        the object (lift, pre_place) with the object's bottom that much above."""
        if grasp.approach != "top":
            return poses
        holding = {"grasp": (False, True), "place": (True, False)}[action]  # (first pose, last pose)
        out = list(poses)
        for index, carries in ((0, holding[0]), (len(out) - 1, holding[1])):
            (x, y, z), q = out[index]
            lowest = rim + RIM_CLEARANCE + (grasp.height if carries else 0.0)
            out[index] = ((x, y, max(z, lowest)), q)
        return out

    @staticmethod
    def _grasp_point(target: Target, grasp: Grasp, heading: float) -> tuple[float, float, float]:
        """Tool point [m] of a horizontal `grasp` of `target`, the tool pointing along `heading`."""
        if target.type is None:
            return target.position
        return grasp.side_point(target.position, target.type.half_height, heading)

    def _top_grasp(self, target: Target, grasp: Grasp, x: float, y: float) -> tuple[tuple[float, float, float], float]:
        """Tool point [m] and heading [rad] (for `grasp_sequence`) of a top grasp from a base at
        (x, y): a rim (``radius``) is taken at its point nearest the base, the fingers closing
        across the wall; a body (``across='radial'`` without a radius: cups and mugs) at its
        axis, the fingers closing along the line from the base; otherwise at the centre, the
        fingers closing across the object's ``across`` axis (`to_reach` also tries the gripper
        turned half round, which closes across that axis alike). The tool points down; its fingers
        open along heading + 90 deg; the tool is raised as far as needed to keep the finger tips
        above the surface the object rests on (`RobotGeometry.top_grasp_height`)."""
        cx, cy, cz = target.position
        half = target.type.half_height if target.type is not None else 0.0
        z = self.geometry.top_grasp_height(cz - half, cz - half + grasp.height)
        if grasp.radius > 0.0 or grasp.across == "radial":
            toward = math.atan2(y - cy, x - cx)
            point = (cx + grasp.radius * math.cos(toward), cy + grasp.radius * math.sin(toward), z)
            fingers = toward
        else:
            point = (cx, cy, z)
            fingers = target.yaw + (math.pi / 2 if grasp.across == "y" else 0.0)
        return point, _wrap(fingers - math.pi / 2)

    @staticmethod
    def _grasp_heading(grasp: Grasp, target: Target) -> float | None:
        """Tool heading [rad] a directional grasp requires (None: any horizontal heading)."""
        side = _SIDE_ANGLE.get(grasp.approach)
        return None if side is None else target.yaw + side + math.pi

    def _grasp_options(self, grasps: list[Grasp], target: Target, natural: float) -> list[tuple[Grasp, float]]:
        """Grasps that fit a base heading `natural`, the best-aligned first, with their heading."""
        options = []
        for g in grasps:
            heading = self._grasp_heading(g, target)
            if heading is None:  # any heading; top grasps after the horizontal ones
                options.append((TOP_PENALTY if g.approach == "top" else 0.0, g, natural))
            elif angle_difference(heading, natural) <= APPROACH_TOLERANCE:
                options.append((angle_difference(heading, natural), g, heading))
        return [(g, h) for _, g, h in sorted(options, key=lambda o: o[0])]

    def _natural_yaw(self, grid: FloorGrid, point: Sequence[float], arm: str) -> np.ndarray:
        """Per cell: the base heading that puts `point` at `arm`'s comfortable reach point."""
        return np.arctan2(point[1] - grid.y, point[0] - grid.x) - self.geometry.reach_bearing(arm)

    @staticmethod
    def _facing_yaws(env: Environment, target: Target) -> list[float]:
        """Headings [rad] that face squarely the edges of the counter or table under `target`."""
        x, y, _ = target.position
        for surface in env.surfaces_of_kind(*FURNITURE_TOPS):
            if surface.contains(x, y, -1e-6):
                return [math.atan2(-n[1], -n[0]) for _, _, n in surface.edges()]
        return []

    @staticmethod
    def _facing_layer(yaw: np.ndarray, facing: list[float]) -> np.ndarray:
        diff = np.min([np.abs((yaw - f + np.pi) % (2 * np.pi) - np.pi) for f in facing], axis=0)
        return (diff / FACING_SCALE) ** 2

    def _grasp_layer(self, yaw: np.ndarray, grasps: list[Grasp], target: Target) -> np.ndarray:
        """0 where some grasp fits the cell's heading (``inf`` where none does)."""
        best = np.full(yaw.shape, np.inf)
        for g in grasps:
            heading = self._grasp_heading(g, target)
            if heading is None:
                best = np.minimum(best, TOP_PENALTY if g.approach == "top" else 0.0)
                continue
            diff = np.abs((yaw - heading + np.pi) % (2 * np.pi) - np.pi)
            best = np.minimum(best, np.where(diff <= APPROACH_TOLERANCE, (diff / APPROACH_TOLERANCE) ** 2, np.inf))
        return best

    # ------------------------------------------------------------------ to_see
    def to_see(self, desig: Any) -> Iterator[BaseLocation]:
        target = self._target(desig.prop_value("to_see"))
        env = self.environment()
        grid = FloorGrid.of(env)
        preferred, sigma, low, high = VIEW_RING
        costmap = Costmap(
            grid,
            {
                "occupancy": occupancy_layer(env, grid, self._base_radius),
                "view": ring_layer(grid, target.position, preferred, sigma, low, high),
            },
        )
        self.last_costmaps = {"view": costmap}
        what = target.name if target.kind == "object" and target.name else target.position

        def validate(cell: tuple) -> tuple[BaseLocation | None, tuple[str, str | None] | None]:
            cost, _, _, r, c = cell
            x, y = costmap.xy(r, c)
            yaw = math.atan2(target.position[1] - y, target.position[0] - x)
            prosp = self.prospection()
            if prosp.in_collision((x, y, yaw), self.geometry.tucked):
                return None, ("in collision", None)
            seen = prosp.visible(what, (x, y, yaw), 0.5, self.geometry.tucked)
            if seen:
                return BaseLocation(x, y, yaw, cost=cost, visible=seen.fraction), None
            if seen.in_view < 0.5:
                return None, ("out of the camera's view", None)
            return None, ("occluded", seen.occluders[0] if seen.occluders else None)

        cells = _ranked(costmap, 0, None)
        return self._search(desig, cells, validate, "to_see", target, {"view": costmap})

    # ------------------------------------------------------------------ to_open
    def to_open(self, desig: Any) -> Iterator[BaseLocation]:
        env = self.environment()
        value = desig.prop_value("to_open")
        name = value.name if isinstance(value, Container) else value
        container = env.container(name)
        lo, hi = container.limits
        wanted = desig.prop_value("opening")
        opening = (
            min(hi, DRAWER_OPENING if container.kind == "drawer" else DOOR_OPENING) if wanted is None else float(wanted)
        )
        if not lo <= opening <= hi:
            raise ValueError(f"opening {opening} of {container.name!r} is outside its limits {container.limits}")
        side = desig.prop_value("pushing")
        if side is not None:
            return self._to_push(desig, container, opening, side)
        # from where the handle is believed to be now (a drawer already partly open moves on
        # from there, or back to `opening`)
        start = float(self.container_states().get(container.name, 0.0))
        steps = [start + (opening - start) * k / 3 for k in range(4)]
        trajectory = [container.handle_position(q) for q in steps]
        headings = [self._pull_heading(container, q) for q in steps]
        # closing a drawer: the push home beyond closed must be reachable too (not checked for
        # opening: the poses that reach it stand so close that the pull stalls)
        beyond = (
            container.handle_position(-DRAWER_PUSH_BEYOND)
            if container.kind == "drawer" and opening <= 0.0 < start
            else None
        )
        arms = self._arms(desig.prop_value("arm"))
        grid = FloorGrid.of(env)
        # the drawer out as far as it is or will be: the base may come as close to it as to an
        # open drawer in ``to_reach`` (each candidate is checked against the drawer pulled out)
        furthest = max(opening, start)
        swept = self._swept_rects(container, furthest)
        occupancy = self._occupancy_with_drawers(env, grid, swept, self._open_doors(env, skip=container.name))
        pulled_out = {container.joint_name: furthest} if swept else {}
        if container.kind == "door":
            occupancy = occupancy.copy()
            assert container.hinge is not None  # a door has its hinge (checked by Container)
            hx, hy = container.hinge
            reach = max(math.hypot(x - hx, y - hy) for x, y in _corners(container.body.footprint))
            occupancy[np.hypot(grid.x - hx, grid.y - hy) < reach + self.geometry.inscribed_radius] = np.inf
        middle = tuple(np.mean(trajectory, axis=0))
        maps, streams = {}, []
        for i, arm in enumerate(arms):
            d0 = self.geometry.reach_distance(arm)
            costmap = Costmap(
                grid,
                {
                    "occupancy": occupancy,
                    "reach": ring_layer(grid, middle, d0, 2 * REACH_SIGMA, max(0.2, d0 - 0.4), d0 + 0.4),
                },
            )
            costmap.add("facing", self._facing_layer(self._natural_yaw(grid, middle, arm), [headings[0]]))
            maps[arm] = costmap
            streams.append(_ranked(costmap, i, arm))
        self.last_costmaps = maps

        def validate(cell: tuple) -> tuple[BaseLocation | None, tuple[str, str | None] | None]:
            cost, _, arm, r, c = cell
            x, y = maps[arm].xy(r, c)
            yaw = _wrap(math.atan2(middle[1] - y, middle[0] - x) - self.geometry.reach_bearing(arm))
            prosp = self.prospection()
            if prosp.in_collision((x, y, yaw), {**self.geometry.tucked, **pulled_out}):
                return None, ("in collision", None)
            back = self.geometry.approach_offsets.get("pre_grasp", (0.1, 0.0))[0]
            hx, hy, hz = trajectory[0]
            c0, s0 = math.cos(headings[0]), math.sin(headings[0])
            # A drawer's handle is a horizontal bar: the fingers close on it vertically and keep
            # that orientation along the straight pull. A door's handle is vertical: the fingers
            # close horizontally, and the wrist turns with the door as it likes (position only).
            if container.kind == "drawer":
                grip, hold = _quat_yaw_rolled(headings[0]), _quat_yaw_rolled(headings[0])
            else:
                grip, hold = _quat_yaw(headings[0]), None
            poses: list[tuple[Vec3, tuple[float, float, float, float] | None]] = [
                ((hx - c0 * back, hy - s0 * back, hz), grip),
                (trajectory[0], grip),
            ]
            poses += [(p, hold) for p in trajectory[1:]]
            handle_grasp = "front_vertical" if container.kind == "drawer" else "front"

            def reachable(configuration: Mapping[str, float]) -> Any:
                answer = prosp.reachable(arm, poses, (x, y, yaw), configuration)
                if not answer or beyond is None:
                    return answer
                # the push home against the stop: the hand touches the drawer's front there (a
                # collision is expected), but the arm must reach it -- else the drawer stays ajar
                home = prosp.reachable(arm, [(beyond, hold)], (x, y, yaw), configuration)
                return answer if home or home.reason == "collision" else home

            answer = reachable(self.geometry.tucked)
            if answer:
                return (
                    BaseLocation(x, y, yaw, arm, handle_grasp, cost, joints=answer.solutions, tool_poses=tuple(poses)),
                    None,
                )
            # a handle too low or too high for the torso as it is: another named torso height
            for torso, height in self._other_torso_heights():
                joint = self.geometry.torso_joint
                assert joint is not None  # there are other torso heights only with a torso joint
                configuration = {**self.geometry.tucked, joint: height}
                if prosp.in_collision((x, y, yaw), {**configuration, **pulled_out}):
                    continue
                other = reachable(configuration)
                if other:
                    location = BaseLocation(
                        x, y, yaw, arm, handle_grasp, cost, joints=other.solutions, tool_poses=tuple(poses), torso=torso
                    )
                    return location, None
            return None, (f"unreachable for arm {arm!r}", answer.reason)

        target = Target(container.handle, "container", container.name, thing=container)
        return self._search(desig, heapq.merge(*streams), validate, "to_open", target, maps)

    def _to_push(self, desig: Any, container: Container, goal: float, side: str) -> Iterator[BaseLocation]:
        """Solutions of ``('to_open', door), ('pushing', side)``: base poses from which the hand
        pushes the door's `side` face from its believed angle to `goal` [rad]. Each tool pose is
        checked with the door where it will be then (the door moves ahead of the hand)."""
        if container.kind != "door":
            raise self._fail(desig, f"only doors are pushed open or shut, {container.name!r} is a {container.kind}")
        if side not in doors.PUSH_SIDES:
            raise ValueError(f"('pushing', {side!r}): a door is pushed from {' or '.join(doors.PUSH_SIDES)}")
        contact = self.geometry.door_push
        if contact is None:
            raise self._fail(desig, f"the {self.geometry.name} does not push doors (its description has no DOOR_PUSH)")
        env = self.environment()
        start = float(self.container_states().get(container.name, 0.0))
        poses = doors.push_sequence(container, contact, start, goal, side)
        # the hardest pose to reach is the first (from inside: past the door's free edge)
        first = poses[0].position
        arms = self._arms(desig.prop_value("arm"))
        grid = FloorGrid.of(env)
        occupancy = occupancy_layer(env, grid, self._base_radius).copy()
        assert container.hinge is not None  # a door (checked above)
        hx, hy = container.hinge
        # the base keeps clear of the panel wherever it will be during the push (the door swings
        # only between where it is and `goal`, not all round the hinge)
        low, high = sorted((start, goal))
        for q in np.linspace(low, high, max(2, int(math.degrees(high - low) / 3) + 1)):
            for distance in np.linspace(0.0, container.door_width, 8):
                (px, py), _, _ = container.door_face(float(q), float(distance), "outside")
                occupancy[np.hypot(grid.x - px, grid.y - py) < self._base_radius] = np.inf
        # in front of the middle of the swing: around the hinge, where the door points half way
        (mx, my), _, _ = container.door_face((start + goal) / 2, 1.0, "outside")
        bearing = np.arctan2(grid.y - hy, grid.x - hx) - math.atan2(my - hy, mx - hx)
        swing_layer = (np.abs((bearing + np.pi) % (2 * np.pi) - np.pi) / PUSH_BEARING_SCALE) ** 2
        maps, streams = {}, []
        for i, arm in enumerate(arms):
            d0 = self.geometry.reach_distance(arm)
            maps[arm] = Costmap(
                grid,
                {
                    "occupancy": occupancy,
                    "reach": ring_layer(grid, first, d0, 2 * REACH_SIGMA, max(0.2, d0 - 0.4), d0 + 0.4),
                    "swing": swing_layer,
                },
            )
            streams.append(_ranked(maps[arm], i, arm))
        self.last_costmaps = maps
        joint = container.joint_name

        def validate(cell: tuple) -> tuple[BaseLocation | None, tuple[str, str | None] | None]:
            cost, _, arm, r, c = cell
            x, y = maps[arm].xy(r, c)
            natural = math.atan2(first[1] - y, first[0] - x) - self.geometry.reach_bearing(arm)
            prosp = self.prospection()
            failure: tuple[str, str | None] = ("in collision", None)
            for offset in PUSH_YAW_OFFSETS:
                yaw = _wrap(natural + offset)
                if prosp.in_collision((x, y, yaw), self.geometry.tucked):
                    continue
                solved, reason = self._reachable_along(prosp, arm, (x, y, yaw), poses, joint)
                if reason is None:
                    location = BaseLocation(
                        x, y, yaw, arm, "push", cost, joints=tuple(solved), tool_poses=tuple(poses), push=side
                    )
                    return location, None
                failure = (f"unreachable for arm {arm!r}", reason)
            return None, failure

        target = Target(container.handle, "container", container.name, thing=container)
        return self._search(desig, heapq.merge(*streams), validate, f"pushing the {side} of", target, maps)

    def _reachable_along(
        self, prosp: Any, arm: str, base: tuple[float, float, float], poses: Sequence[Any], joint: str
    ) -> tuple[list[tuple[float, ...]], str | None]:
        """IK for each tool pose of `poses` in turn (each with its `angle`: the position of the
        container's `joint` then), seeded with the previous solution; (solutions, None) or
        (the solutions so far, why the next pose failed)."""
        joints = self.geometry.arm_joints[arm]
        solutions: list[tuple[float, ...]] = []
        for pose in poses:
            configuration = dict(self.geometry.tucked)
            if solutions:
                configuration.update(zip(joints, solutions[-1]))
            configuration[joint] = pose.angle
            answer = prosp.reachable(arm, [pose], base, configuration)
            if not answer:
                return solutions, f"{pose.phase}: {answer.reason}"
            solutions.append(tuple(answer.solutions[0]))
        return solutions, None

    def _higher_torso_heights(self) -> list[tuple[str, float]]:
        """The robot's named torso heights above its torso now, nearest first (none when the
        height now is unknown): out in the open a torso left low (e.g. by opening a low drawer)
        is raised when nothing works as it is -- never lowered, which would rarely help and
        would double the time of every query that fails."""
        joint, named = self.geometry.torso_joint, self.geometry.torso_positions or {}
        prosp = self.prospection()
        if joint is None or not named or not hasattr(prosp, "joint_position"):
            return []
        now = prosp.joint_position(joint)
        return sorted(((n, h) for n, h in named.items() if h > now + 0.01), key=lambda o: o[1] - now)

    def _other_torso_heights(self) -> list[tuple[str, float]]:
        """The robot's named torso heights other than the one it has now, nearest first."""
        joint, named = self.geometry.torso_joint, self.geometry.torso_positions or {}
        if joint is None or not named:
            return []
        now = self.prospection().joint_position(joint) if hasattr(self.prospection(), "joint_position") else None
        options = [(name, h) for name, h in named.items() if now is None or abs(h - now) > 0.01]
        return sorted(options, key=lambda o: 0.0 if now is None else abs(o[1] - now))

    @staticmethod
    def _pull_heading(container: Container, q: float) -> float:
        """Tool heading [rad] at the handle when the joint is at `q`: against the opening motion."""
        dx, dy = container.opening_direction
        if container.kind == "door":
            a = container.hinge_sign * q
            dx, dy = math.cos(a) * dx - math.sin(a) * dy, math.sin(a) * dx + math.cos(a) * dy
        return math.atan2(-dy, -dx)

    def _occupancy_with_drawers(
        self,
        env: Environment,
        grid: FloorGrid,
        drawers: Sequence[tuple[float, float, float, float]],
        doors: Sequence[tuple[tuple[float, float], tuple[float, float]]] = (),
    ) -> np.ndarray:
        """The base's occupancy layer of `env` on `grid`, with the base kept `DRAWER_CLEARANCE`
        [m] clear of each pulled-out drawer's rectangle in `drawers` (nearer than to furniture)
        and `DOOR_CLEARANCE` [m] clear of each open door's panel in `doors` (floor segments from
        the hinge to the free edge). The layer is copied before it is marked (`occupancy_layer`
        may share it)."""
        occupancy = occupancy_layer(env, grid, self._base_radius)
        if drawers or doors:
            occupancy = occupancy.copy()
            near = self.geometry.inscribed_radius + DRAWER_CLEARANCE
            for rect in drawers:
                occupancy[rect_distance(grid, rect) < near] = np.inf
            near = self.geometry.inscribed_radius + DOOR_CLEARANCE
            for a, b in doors:
                occupancy[segment_distance(grid, a, b) < near] = np.inf
        return occupancy

    def _open_doors(
        self, env: Environment, skip: str | None = None
    ) -> list[tuple[tuple[float, float], tuple[float, float]]]:
        """Floor segments [m] of the door panels believed open (but `skip`'s), where they stand
        now: their outside faces from the hinge to the free edge."""
        segments = []
        for name, q in self.container_states().items():
            if name == skip or abs(q) < DOOR_OPEN_FROM:
                continue
            try:
                container = env.container(name)
            except KeyError:
                continue
            if container.kind == "door" and container.hinge is not None:
                width = container.door_width
                ends = [container.door_face(float(q), d, "outside")[0] for d in (0.0, width)]
                segments.append((ends[0], ends[1]))
        return segments

    def _open_drawers(self, env: Environment) -> list[tuple[float, float, float, float]]:
        """Floor rectangles of the drawers believed open (where they stick out now, handle
        included)."""
        rects: list[tuple[float, float, float, float]] = []
        for name, q in self.container_states().items():
            if abs(q) > 0.01:
                try:
                    container = env.container(name)
                except KeyError:
                    continue
                handle = max(0.0, container.along_slide(*container.handle[:2]) - container.front) + HANDLE_DEPTH
                rects += self._swept_rects(container, float(q) + handle)
        return rects

    @staticmethod
    def _swept_rects(container: Container, opening: float) -> list[tuple[float, float, float, float]]:
        if container.kind != "drawer":
            return []
        x0, y0, x1, y1 = container.body.footprint
        dx, dy = container.opening_direction
        return [
            (
                min(x0, x0 + dx * opening),
                min(y0, y0 + dy * opening),
                max(x1, x1 + dx * opening),
                max(y1, y1 + dy * opening),
            )
        ]

    # ------------------------------------------------------------------ on / in
    def on(self, desig: Any) -> Iterator[Spot]:
        env = self.environment()
        value = desig.prop_value("on")
        surface = value if isinstance(value, Surface) else env.surface(value)
        return self._spots(desig, [surface], None)

    def inside(self, desig: Any) -> Iterator[Spot]:
        env = self.environment()
        value = desig.prop_value("in")
        container = value if isinstance(value, Container) else env.container(value)
        if not container.interior:
            raise self._fail(desig, f"{container.name!r} has no surfaces inside")
        return self._spots(desig, list(container.interior), container.name)

    def _object_size(self, value: Any, known: Sequence[KnownObject]) -> tuple[float, float, str, str | None]:
        """(footprint radius [m], half height [m], description, name) of the object to put down."""
        if value is None:
            return DEFAULT_OBJECT[0], DEFAULT_OBJECT[1], "an object", None
        if isinstance(value, ObjectType):
            return value.footprint_radius, value.half_height, f"a {value.name}", None
        if isinstance(value, str):
            for k in known:
                if k.name == value:
                    assert k.radius is not None and k.half_height is not None  # set by KnownObject.__post_init__
                    return float(k.radius), float(k.half_height), f"the {k.name}", k.name
            t = object_type(value)
            return t.footprint_radius, t.half_height, f"a {t.name}", None
        target = as_target(value, None, known)
        if target.type is None:
            raise ValueError(f"('for', {value!r}): need an object type, a known object or an object with a type")
        return target.type.footprint_radius, target.type.half_height, target.describe(), target.name

    def _spots(self, desig: Any, surfaces: list[Surface], container: str | None) -> Iterator[Spot]:
        known = list(self.known_objects())
        radius, half, what, own = self._object_size(desig.prop_value("for"), known)
        near = desig.prop_value("near")
        near_xy = None if near is None else self._target(near).position[:2]
        fitting = [s for s in surfaces if s.clearance >= 2 * half + 0.01]
        if not fitting:
            raise self._fail(
                desig,
                f"{what} ({2 * half:.2f} m tall) fits on none of "
                f"{[s.name for s in surfaces]} (clearance "
                f"{', '.join(f'{s.clearance:.2f} m' for s in surfaces)})",
            )
        candidates = []
        tally = _Tally()
        for surface in fitting:
            x0, y0, x1, y1 = surface.bounds
            xs = np.arange(x0 + SPOT_RESOLUTION / 2, x1, SPOT_RESOLUTION)
            ys = np.arange(y0 + SPOT_RESOLUTION / 2, y1, SPOT_RESOLUTION)
            gx, gy = np.meshgrid(xs, ys)
            inside = np.ones(gx.shape, bool)
            for (ax, ay), _, n in surface.edges():
                inside &= (gx - ax) * -n[0] + (gy - ay) * -n[1] >= radius + SPOT_EDGE_MARGIN
            tally.tried += int(gx.size)
            tally.reasons["too close to the edge"] += int((~inside).sum())
            free = inside.copy()
            z = surface.height + half
            for k in known:
                if k.name == own:
                    continue
                assert k.radius is not None and k.half_height is not None  # set by KnownObject.__post_init__
                kz0, kz1 = k.position[2] - k.half_height, k.position[2] + k.half_height
                if kz1 <= surface.height - 0.01 or kz0 >= surface.height + 2 * half + 0.01:
                    continue
                blocked = np.hypot(gx - k.position[0], gy - k.position[1]) < radius + k.radius + SPOT_GAP
                tally.details.setdefault("occupied", Counter())[k.name] += int((blocked & free).sum())
                tally.reasons["occupied"] += int((blocked & free).sum())
                free &= ~blocked
            if near_xy is not None:
                cost = np.hypot(gx - near_xy[0], gy - near_xy[1])
            else:
                cx, cy, _ = surface.centroid
                cost = np.hypot(gx - cx, gy - cy)
            for i in np.flatnonzero(free.ravel()):
                candidates.append((float(cost.ravel()[i]), float(gx.ravel()[i]), float(gy.ravel()[i]), z, surface.name))
        candidates.sort()
        if not candidates:
            raise self._fail(
                desig,
                f"no free spot for {what} (footprint radius {radius:.2f} m) on "
                f"{', '.join(s.name for s in fitting)}: {tally.summary()}",
            )

        def spots() -> Iterator[Spot]:
            given: list[tuple[float, float]] = []
            for cost, x, y, z, name in candidates:
                if any(math.hypot(x - gx_, y - gy_) < SPACING for gx_, gy_ in given):
                    continue
                given.append((x, y))
                yield Spot(x, y, z, name, container, None if own else _type_name(desig.prop_value("for")), cost)

        return spots()

    def _empty_costmap(self, maps: dict[str, Costmap], target: Target) -> str:
        """Why no cell of the costmaps is left: the layer that alone rules out every cell, or
        the layers that do together."""
        env = self.environment()
        where = "(" + ", ".join(f"{v:.1f}" for v in target.position) + ") [m, map]"
        alone = sorted(
            {
                name
                for m in maps.values()
                for name, layer in m.layers.items()
                if name != "occupancy" and bool(np.isinf(layer).all())
            }
        )
        if alone:
            return (
                f"{target.describe()} at {where} is outside the environment: no cell of the floor of "
                f"{env.name} lies within the layer {alone[0]!r} around it"
            )
        return (
            f"every cell of the floor of {env.name} within reach of {target.describe()} at {where} is "
            f"occupied (layer 'occupancy': furniture and walls inflated by the {self.geometry.name}'s "
            f"{self._base_radius:.2f} m footprint radius with clearance; {_layer_summary(maps)})"
        )

    # ------------------------------------------------------------------ the search
    def _search(
        self,
        desig: Any,
        cells: Iterator[tuple],
        validate: Callable,
        kind: str,
        target: Target,
        maps: dict[str, Costmap],
        tally: _Tally | None = None,
    ) -> Iterator[BaseLocation]:
        """Walk `cells` (cost, tie, arm, row, col) cheapest first; validate each; yield the valid
        ones at least `SPACING` apart; after `max_candidates` checks or when the costmap is used
        up, stop -- with `NoSolutionError` naming what ruled the candidates out if nothing passed
        (counted in `tally` when given)."""
        tally = _Tally() if tally is None else tally
        given: list[BaseLocation] = []
        failed: list[tuple[str | None, float, float]] = []
        for cell in cells:
            if tally.tried >= self.max_candidates:
                break
            cost, _, arm, r, c = cell
            x, y = next(iter(maps.values())).xy(r, c)
            if any(math.hypot(x - g.x, y - g.y) < SPACING for g in given):
                continue
            if any(a == arm and math.hypot(x - fx, y - fy) < FAILED_SPACING for a, fx, fy in failed):
                continue
            tally.tried += 1
            solution, failure = validate(cell)
            if solution is not None:
                given.append(solution)
                yield solution
            else:
                failed.append((arm, x, y))
                tally.fail(*failure)
        if not given:
            if tally.tried == 0:
                raise self._fail(desig, self._empty_costmap(maps, target))
            raise self._fail(
                desig, f"no base pose for {kind} {target.describe()} with the {self.geometry.name}: {tally.summary()}"
            )


def _body_from_the_top(grasp: Grasp) -> bool:
    """A grasp of a round body from the top (cups, mugs): for where its sides are walled in (in a
    drawer), or when asked for; elsewhere its horizontal grasps are used."""
    return grasp.approach == "top" and grasp.across == "radial" and grasp.radius == 0.0


def _layer_summary(maps: dict[str, Costmap]) -> str:
    out = []
    for name, costmap in maps.items():
        out.append(f"{name}: " + ", ".join(f"{k} forbids {v} cells" for k, v in costmap.ruled_out_by().items()))
    return "; ".join(out)


def _ranked(costmap: Costmap, tie: int, arm: str | None) -> Iterator[tuple]:
    """The cells of `costmap` cheapest first as (cost, tie, arm, row, column)."""
    for r, c, cost in costmap.cells():
        yield cost, tie, arm, r, c


def _wrap(angle: float) -> float:
    """`angle` [rad] wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _corners(rect: Sequence[float]) -> list[tuple[float, float]]:
    x0, y0, x1, y1 = rect
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def _type_name(value: Any) -> str | None:
    if isinstance(value, ObjectType):
        return value.name
    return value if isinstance(value, str) else None
