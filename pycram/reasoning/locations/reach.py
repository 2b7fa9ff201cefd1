"""The ``to_reach`` vocabulary: base poses from which an arm grasps or places an object.

``('to_reach', t)`` [``('arm', a)``, ``('grasp', g)``, ``('action', 'place')``] is answered
with `BaseLocation`s from which the arm executes the whole grasp sequence (pre_grasp, grasp,
lift; with ``('action', 'place')``: pre_place, place, retreat; `grasp_sequence`) without
collision; each names the arm and grasp found. Layers: occupancy (with open drawers and doors),
a reach ring around the target, facing the furniture squarely, and the grasps that fit the
heading. A target in a drawer is grasped over its walls (`RIM_CLEARANCE`); when nothing works
with the torso as it is, higher named torso heights are tried.

The grasps are the object type's (`pycram.world.objects.Grasp`), extended by grasps planned
from the object's measured shape and pose (`pycram.reasoning.grasps`) where the type's do not
cover it: an object lying on its side (planned grasps only), an upright box turned far from
square to its furniture. A planned grasp is validated with the base facing the object and the
tool turned to the grasp; its solution carries it (`BaseLocation.grasp_candidate`).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Iterator
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from pycram.designators.core import NoSolutionError
from pycram.reasoning.grasps import (
    MAX_TURN,
    TURN_SCALE,
    GraspOption,
    GripperGeometry,
    ObjectPose,
    grasp_candidates,
    grasp_options,
)
from pycram.reasoning.grasps import TOP_PENALTY as GRASP_TOP_PENALTY
from pycram.world.environment import FURNITURE_TOPS, Container, Environment
from pycram.world.objects import SIDE, Grasp, approach_matches

from .costmap import Costmap, FloorGrid, angle_difference, ring_layer
from .grasps import PHASES, grasp_sequence
from .search import NO_WAY_IN, _ranked, _Tally
from .solutions import BaseLocation
from .standing import FACING_SCALE, REACH_INSIDE, REACH_OUTSIDE, REACH_SIGMA, StandingSearch, _wrap
from .targets import Target

__all__ = ["ReachVocabulary", "APPROACH_TOLERANCE", "RIM_CLEARANCE", "TOP_PENALTY", "RANK_SLACK", "COVERED_TURN"]

#: A grasp's approach may deviate this much [rad] from the base heading.
APPROACH_TOLERANCE = 0.45
#: In a drawer, a tool without the object passes this far [m] above the top of its walls, and a
#: held object's bottom as far (the approach and the lift of top grasps).
RIM_CLEARANCE = 0.04
#: Rank of a top grasp among horizontal ones (as if it deviated this much [rad]).
TOP_PENALTY = 0.3
#: An upright object's directional grasps of its type cover its pose while they fit a base
#: heading turned at most this much [rad] from facing its furniture squarely (the facing layer's
#: cost scale, `FACING_SCALE`: the types' grasps pick up the cereal box turned 30 deg,
#: `tests/sim/test_actions.py`); beyond, planned grasps (`pycram.reasoning.grasps`) compete.
COVERED_TURN = FACING_SCALE
#: A cell is validated with the planned grasps (`pycram.reasoning.grasps`) ranked at most this
#: much worse than the best grasp its cost counts (one `TURN_SCALE` of the tool's turn).
RANK_SLACK = 1.0
#: Approach side in the object's frame -> angle [rad] of that side.
_SIDE_ANGLE = {"+x": 0.0, "-x": math.pi, "+y": math.pi / 2, "-y": -math.pi / 2}
_POINT_GRASP = Grasp("side", 0.07, 0.0)


class ReachVocabulary(StandingSearch):
    """Answers ``to_reach`` (see the module docstring)."""

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
        pose = _object_pose(target)
        # the tables' grasps are for objects standing upright: one lying on its side is grasped
        # with planned grasps only
        requested = desig.prop_value("grasp")
        lying = pose is not None and not pose.is_upright and requested in (None, SIDE)
        if lying:
            grasps = []
        elif drawer is not None:
            grasps = self._over_the_rim(desig, target, grasps, drawer)
        elif requested is None:  # out in the open, a cup is taken by its side
            grasps = [g for g in grasps if not _body_from_the_top(g)] or grasps
        grid = FloorGrid.of(env)
        # the base may come closer to an open drawer than to the furniture
        occupancy = self._occupancy_with_drawers(env, grid, self._open_drawers(env), self._open_doors(env))
        facing = self._facing_yaws(env, target)
        planned = self._planned_options(desig, target, pose, grasps, facing, drawer, action, arms)
        if lying and not any(planned.values()):
            raise self._fail(
                desig,
                f"{target.describe()} lies on its side and no planned grasp fits it (the grasps of its "
                f"type are for it standing upright; see pycram.reasoning.grasps)",
            )
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
            layer = self._grasp_layer(yaw, grasps, target)
            if planned[arm]:
                layer = np.minimum(layer, _planned_layer(grid, yaw, planned[arm], self.geometry.reach_points[arm][1]))
            costmap.add("grasp", layer)
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
            tucked = self.arrival_configuration(prosp)
            raised = {**tucked, **(self.geometry.ready or {}).get(arm, {})}

            # (rank, grasp, base yaw, tool point, tool heading, planned candidate or None)
            options: list[tuple[float, Grasp, float, tuple[float, float, float], float, Any]] = []
            for grasp, heading in self._grasp_options(grasps, target, natural):
                yaw = natural if grasp.approach in ("side", "top") else _wrap(heading)
                rank = _table_rank(grasp, heading, natural)
                if grasp.approach != "top":
                    options.append((rank, grasp, yaw, self._grasp_point(target, grasp, yaw), yaw, None))
                    continue
                point, tool_heading = self._top_grasp(target, grasp, x, y)
                options.append((rank, grasp, yaw, point, tool_heading, None))
                if grasp.radius == 0.0 and grasp.across != "radial":
                    # across an axis: the gripper turned half round grasps alike
                    options.append((rank, grasp, yaw, point, _wrap(tool_heading + math.pi), None))
            if planned[arm] and pose is not None:
                # planned grasps: the base faces the object, the tool turns to the grasp
                left = self.geometry.reach_points[arm][1]
                root = (x - left * math.sin(natural), y + left * math.cos(natural))  # the shoulder
                gripper = self._gripper(arm)
                for planned_grasp in grasp_candidates(pose, gripper, (x, y, natural), planned[arm], arm_root=root):
                    g = planned_grasp
                    options.append((g.score, g.grasp, natural, g.point, g.heading, g))
                options.sort(key=lambda o: o[0])  # stable: the tables' grasps first on a tie
                # the cell was ranked for its best grasp: one much worse is tried from the cells
                # ranked for it (a left arm reaching across in front of a box to grasp its right
                # side knocked it over, where the right arm coming from that side was ranked)
                best = float(maps[arm].layers["grasp"][r, c])
                options = [o for o in options if o[5] is None or o[0] <= best + RANK_SLACK]

            def sequences(
                configuration: dict[str, float], arrival: dict[str, float]
            ) -> tuple[BaseLocation | None, tuple[str, str | None]]:
                """The first option whose grasp sequence the arm reaches in `configuration`;
                `arrival`: the robot as it comes (the base pose was checked with it facing
                `natural`: an option that turns the base otherwise is checked anew)."""
                failure: tuple[str, str | None] = ("no fitting grasp", None)
                for _, grasp, yaw, point, heading, candidate in options:
                    if abs(_wrap(yaw - natural)) > 1e-6:
                        turned = self._base_refused(prosp, (x, y, yaw), arrival, configuration)
                        if turned is not None:
                            failure = (turned, None)
                            continue
                    poses = grasp_sequence(self.geometry, point, heading, grasp.approach, action)
                    if drawer is not None:
                        poses = self._clear_of_the_rim(poses, grasp, drawer.rim_height, action)
                    margin = self.geometry.contact_margin if action == "grasp" else 0.0
                    if margin:  # room to spare below the grasp
                        (gx, gy, gz), q = poses[1]
                        poses.insert(2, ((gx, gy, gz - margin), q))
                    answer = None
                    coming = (self.geometry.carry_top or {}).get(arm)
                    if coming and grasp.held_from_above:
                        # IK from where the arm comes (it carries the object in `carry_top` too):
                        # from `ready`, the TIAGo Pro's grasps came out with the wrist turned the
                        # other way round, and the way to `carry_top` swung a plate held from
                        # above 0.55 m sideways into a milk carton it had not seen (dev seed 28)
                        answer = prosp.reachable(arm, poses, (x, y, yaw), {**configuration, **coming})
                    if not answer:
                        answer = prosp.reachable(arm, poses, (x, y, yaw), configuration)
                    if answer:
                        joints = tuple(j for i, j in enumerate(answer.solutions) if not (margin and i == 2))
                        tool = tuple(p for i, p in enumerate(poses) if not (margin and i == 2))
                        location = BaseLocation(
                            x,
                            y,
                            yaw,
                            arm,
                            grasp.approach,
                            cost,
                            joints=joints,
                            tool_poses=tool,
                            grasp_candidate=candidate,
                        )
                        return location, failure
                    failure = (f"unreachable for arm {arm!r}", answer.reason)
                return None, failure

            failure: tuple[str, str | None] = ("in collision at every other torso height", None)
            if torsos != "other":
                lifted: tuple[float, ...] = ()
                if prosp.in_collision((x, y, natural), tucked, self.carried(), objects=True):
                    # an object held in `arm` may come lifted clear of the furniture
                    lifted = self._lifted_arrival(prosp, arm, (x, y, natural), tucked) if action == "place" else ()
                    if not lifted:
                        return None, ("in collision", None)
                coming = {**tucked, **dict(zip(self.geometry.arm_joints[arm], lifted))} if lifted else tucked
                if self.cannot_drive_in(prosp, (x, y, natural), coming):
                    return None, (NO_WAY_IN, None)
                if prosp.in_collision((x, y, natural), raised):
                    failure = (f"arm {arm!r} hits the furniture when raised to approach", None)
                    if torsos == "current":
                        return None, failure
                else:
                    found, failure = sequences(raised, coming)
                    if found is not None and lifted:
                        found = replace(found, arrival=lifted)
                    if found is not None or torsos == "current":
                        return found, (None if found is not None else failure)
            # the target lies low or high for the torso as it is: another torso height
            joint = self.geometry.torso_joint
            for torso, height in self._other_torso_heights() if heights is None else heights:
                assert joint is not None  # there are other torso heights only with a torso joint
                arrival, ready = {**tucked, joint: height}, {**raised, joint: height}
                if self._base_refused(prosp, (x, y, natural), arrival, ready) is not None:
                    continue
                other, why = sequences(ready, arrival)
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

    def _base_refused(
        self,
        prosp: Any,
        base: tuple[float, float, float],
        arrival: dict[str, float],
        raised: dict[str, float],
    ) -> str | None:
        """Why the robot may not stand at `base` (x [m], y [m], yaw [rad]) -- coming in
        `arrival`, the arm raised to `raised` there -- or None: what `to_reach` checks of a base
        pose facing the object, for a grasp that turns the base to another heading (measured: the
        TIAGo Pro's rectangular base checked facing the milk carton, 1.79 rad, offered at 1.57
        rad, which navigation refused)."""
        if prosp.in_collision(base, arrival, self.carried(), objects=True):
            return "in collision"
        if self.cannot_drive_in(prosp, base, arrival):
            return NO_WAY_IN
        if prosp.in_collision(base, raised):
            return f"arm hits the furniture when raised to approach (base turned to {base[2]:.2f} rad)"
        return None

    def _gripper(self, arm: str) -> GripperGeometry:
        """The gripper of `arm` as grasp planning needs it (the robot's description)."""
        return GripperGeometry(
            self.geometry.max_openings[arm],
            self.geometry.fingertip_reach,
            self.geometry.top_grasp_clearance,
            self.geometry.approach_offsets.get("pre_grasp", (0.1, 0.0))[0],
        )

    def _planned_options(
        self,
        desig: Any,
        target: Target,
        pose: ObjectPose | None,
        grasps: list[Grasp],
        facing: list[float],
        drawer: Container | None,
        action: str,
        arms: list[str],
    ) -> dict[str, list[GraspOption]]:
        """Per arm, the planned grasps (`pycram.reasoning.grasps`) that extend the object type's
        grasps `grasps` for `target` where it is -- for grasping only, when no grasp was asked
        for: every one for an object lying on its side (in a drawer: from the top only); for one
        standing upright, only when its type's grasps do not cover its pose (`_table_covers`:
        a box turned far from square to the furniture it stands on), and then no top grasp when
        its type has one of its own. Empty lists otherwise."""
        none: dict[str, list[GraspOption]] = {arm: [] for arm in arms}
        requested = desig.prop_value("grasp")
        if action != "grasp" or requested not in (None, SIDE) or pose is None:
            return none
        if not self.geometry.max_openings:
            return none
        upright = pose.is_upright
        if upright and (drawer is not None or self._table_covers(target, grasps, facing)):
            return none
        has_top = any(g.approach == "top" for g in grasps)
        out = {}
        for arm in arms:
            options = grasp_options(pose, self.geometry.max_openings[arm])
            if drawer is not None:  # over the drawer's walls
                options = [o for o in options if o.approach == "top"]
            elif upright and has_top:  # the type's own top grasp is tuned
                options = [o for o in options if o.approach != "top"]
            if requested == SIDE:  # from the side only: any horizontal approach
                options = [o for o in options if o.approach != "top"]
            out[arm] = options
        return out

    def _table_covers(self, target: Target, grasps: list[Grasp], facing: list[float]) -> bool:
        """Whether the grasps of an upright object's type (`grasps`) cover its pose: it stands on
        no furniture top with edges to face, one of them takes it from any side, or one of its
        directional grasps fits a base heading turned at most `COVERED_TURN` from facing the
        furniture squarely."""
        directional = [g for g in grasps if g.approach in _SIDE_ANGLE]
        if not facing or not directional or any(g.approach == "side" for g in grasps):
            return True
        headings = [self._grasp_heading(g, target) for g in directional]
        return any(angle_difference(h, f) <= COVERED_TURN for h in headings if h is not None for f in facing)

    def _grasps(self, target: Target, requested: Any) -> list[Grasp]:
        """The grasps to consider: the object type's, those with the approach `requested`
        (``'side'``: every horizontal approach -- a box's ``+x``/``-y``... as much as a cup's
        ``side``), or the `Grasp` `requested` itself (a planned grasp an object is held with, to
        put it down as it is held)."""
        if isinstance(requested, Grasp):
            return [requested]
        grasps = list(target.type.grasps) if target.type is not None else [_POINT_GRASP]
        if requested is not None:
            chosen = [g for g in grasps if approach_matches(g.approach, requested)]
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

    @staticmethod
    def _facing_yaws(env: Environment, target: Target) -> list[float]:
        """Headings [rad] that face squarely the edges of the counter or table under `target`."""
        x, y, _ = target.position
        for surface in env.surfaces_of_kind(*FURNITURE_TOPS):
            if surface.contains(x, y, -1e-6):
                return [math.atan2(-n[1], -n[0]) for _, _, n in surface.edges()]
        return []

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


def _object_pose(target: Target) -> ObjectPose | None:
    """`target` as grasp planning sees it (None when it is no object of a known type)."""
    if target.kind != "object" or target.type is None:
        return None
    if target.orientation is None:
        return ObjectPose.upright(target.type, target.position, target.yaw)
    return ObjectPose(target.type, target.position, target.orientation)


def _table_rank(grasp: Grasp, heading: float, natural: float) -> float:
    """Rank of a type's grasp at a base heading `natural` [rad] among planned ones (their
    `pycram.reasoning.grasps.GraspCandidate.score`): as in the grasp layer."""
    if grasp.approach == "top":
        return TOP_PENALTY
    if grasp.approach == "side":
        return 0.0
    return (angle_difference(heading, natural) / APPROACH_TOLERANCE) ** 2


def _planned_layer(grid: FloorGrid, yaw: np.ndarray, options: list[GraspOption], left: float) -> np.ndarray:
    """Per cell (base heading `yaw` [rad]): the cost of the best planned grasp (`options`), as
    `pycram.reasoning.grasps.grasp_candidates` ranks them -- a horizontal one by how far its tool
    turns from the line from the arm's root (`left` [m] beside the base's centre) to the grasp
    point (``(turn / TURN_SCALE) ** 2``; ``inf`` where it turns more than `MAX_TURN` from the
    base's heading), one from any side 0, one from the top `GRASP_TOP_PENALTY`."""
    best = np.full(yaw.shape, np.inf)
    root_x, root_y = grid.x - left * np.sin(yaw), grid.y + left * np.cos(yaw)
    for option in options:
        if option.approach == "top":
            best = np.minimum(best, GRASP_TOP_PENALTY)
        elif option.heading is None:
            best = np.minimum(best, 0.0)
        else:
            wrist = np.abs((yaw - option.heading + np.pi) % (2 * np.pi) - np.pi)
            line = np.arctan2(option.point[1] - root_y, option.point[0] - root_x)
            turn = np.abs((line - option.heading + np.pi) % (2 * np.pi) - np.pi)
            best = np.minimum(best, np.where(wrist <= MAX_TURN, (turn / TURN_SCALE) ** 2, np.inf))
    return best


def _body_from_the_top(grasp: Grasp) -> bool:
    """A grasp of a round body from the top (cups, mugs): for where its sides are walled in (in a
    drawer), or when asked for; elsewhere its horizontal grasps are used."""
    return grasp.approach == "top" and grasp.across == "radial" and grasp.radius == 0.0
