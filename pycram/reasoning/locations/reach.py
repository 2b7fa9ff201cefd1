"""The ``to_reach`` vocabulary: base poses from which an arm grasps or places an object.

``('to_reach', t)`` [``('arm', a)``, ``('grasp', g)``, ``('action', 'place')``] is answered
with `BaseLocation`s from which the arm executes the whole grasp sequence (pre_grasp, grasp,
lift; with ``('action', 'place')``: pre_place, place, retreat; `grasp_sequence`) without
collision; each names the arm and grasp found. Layers: occupancy (with open drawers and doors),
a reach ring around the target, facing the furniture squarely, and the grasps that fit the
heading. A target in a drawer is grasped over its walls (`RIM_CLEARANCE`); when nothing works
with the torso as it is, higher named torso heights are tried.
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
from pycram.world.environment import FURNITURE_TOPS, Container, Environment
from pycram.world.objects import Grasp

from .costmap import Costmap, FloorGrid, angle_difference, ring_layer
from .grasps import PHASES, grasp_sequence
from .search import _ranked, _Tally
from .solutions import BaseLocation
from .standing import REACH_INSIDE, REACH_OUTSIDE, REACH_SIGMA, StandingSearch, _wrap
from .targets import Target

__all__ = ["ReachVocabulary", "APPROACH_TOLERANCE", "RIM_CLEARANCE", "TOP_PENALTY"]

#: A grasp's approach may deviate this much [rad] from the base heading.
APPROACH_TOLERANCE = 0.45
#: In a drawer, a tool without the object passes this far [m] above the top of its walls, and a
#: held object's bottom as far (the approach and the lift of top grasps).
RIM_CLEARANCE = 0.04
#: Rank of a top grasp among horizontal ones (as if it deviated this much [rad]).
TOP_PENALTY = 0.3
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


def _body_from_the_top(grasp: Grasp) -> bool:
    """A grasp of a round body from the top (cups, mugs): for where its sides are walled in (in a
    drawer), or when asked for; elsewhere its horizontal grasps are used."""
    return grasp.approach == "top" and grasp.across == "radial" and grasp.radius == 0.0
