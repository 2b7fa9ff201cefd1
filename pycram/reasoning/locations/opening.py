"""The ``to_open`` vocabulary: base poses from which an arm opens or closes a drawer or a door.

``('to_open', c)`` [``('arm', a)``, ``('opening', q)``] is answered with `BaseLocation`s from which
the arm grasps the handle of the drawer or door ``c`` and follows its trajectory from the believed
opening to ``q`` [m for drawers, rad for doors; default `DRAWER_OPENING` / `DOOR_OPENING`];
closing a drawer, the push `DRAWER_PUSH_BEYOND` [m] beyond closed must be reachable too.
``('to_open', door), ('pushing', s)`` [``('opening', q)``, ``('arm', a)``] is answered with
`BaseLocation`s from which the hand pushes the door's face ``s`` (``'inside'``/``'outside'``)
along its arc to ``q`` (`pycram.reasoning.locations.doors`; ``push`` names the side).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from pycram.world.environment import Container, Vec3

from . import doors
from .costmap import Costmap, FloorGrid, occupancy_layer, ring_layer
from .grasps import _quat_yaw, _quat_yaw_rolled
from .search import NO_WAY_IN, _ranked
from .solutions import BaseLocation
from .standing import REACH_SIGMA, StandingSearch, _wrap
from .targets import Target

__all__ = [
    "OpenVocabulary",
    "DRAWER_PUSH_BEYOND",
    "PUSH_YAW_OFFSETS",
    "PUSH_BEARING_SCALE",
    "DRAWER_OPENING",
    "DOOR_OPENING",
]

#: Closing a drawer, the hand pushes its handle this far [m] beyond closed (against the slide's
#: stop: the bar sits loose between the fingers, and a drawer pushed to exactly 0 stays ajar).
#: Standing poses for closing a drawer are checked for it too.
DRAWER_PUSH_BEYOND = 0.03
#: Pushing a door: base headings tried per cell, relative to the one that puts the push's first
#: tool pose at the arm's comfortable reach point [rad] (the hand then sweeps across the front).
PUSH_YAW_OFFSETS = (0.0, -0.4, 0.4, -0.8, 0.8)
#: ... and the cells are ranked by how far [rad, as a scale] their bearing from the hinge is from
#: the door's direction half way through the push (the robot stands in front of the swing).
PUSH_BEARING_SCALE = 0.5
#: Default opening [m] of a drawer followed by ``to_open``.
DRAWER_OPENING = 0.3
#: Default opening [rad] of a door followed by ``to_open``.
DOOR_OPENING = 1.2


class OpenVocabulary(StandingSearch):
    """Answers ``to_open``, pulling a handle or pushing a door (see the module docstring)."""

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
            arrival = self.arrival_configuration(prosp)
            if prosp.in_collision((x, y, yaw), {**arrival, **pulled_out}, self.carried(), objects=True):
                return None, ("in collision", None)
            if self.cannot_drive_in(prosp, (x, y, yaw), arrival):  # the drawer is closed as it comes
                return None, (NO_WAY_IN, None)
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

            answer = reachable(arrival)
            if answer:
                return (
                    BaseLocation(x, y, yaw, arm, handle_grasp, cost, joints=answer.solutions, tool_poses=tuple(poses)),
                    None,
                )
            # a handle too low or too high for the torso as it is: another named torso height
            for torso, height in self._other_torso_heights():
                joint = self.geometry.torso_joint
                assert joint is not None  # there are other torso heights only with a torso joint
                configuration = {**arrival, joint: height}
                if prosp.in_collision((x, y, yaw), {**configuration, **pulled_out}, self.carried(), objects=True):
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
            arrival = self.arrival_configuration(prosp)
            failure: tuple[str, str | None] = ("in collision", None)
            for offset in PUSH_YAW_OFFSETS:
                yaw = _wrap(natural + offset)
                if prosp.in_collision((x, y, yaw), arrival, self.carried(), objects=True):
                    continue
                if self.cannot_drive_in(prosp, (x, y, yaw), arrival):
                    failure = (NO_WAY_IN, None)
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

    @staticmethod
    def _pull_heading(container: Container, q: float) -> float:
        """Tool heading [rad] at the handle when the joint is at `q`: against the opening motion."""
        dx, dy = container.opening_direction
        if container.kind == "door":
            a = container.hinge_sign * q
            dx, dy = math.cos(a) * dx - math.sin(a) * dy, math.sin(a) * dx + math.cos(a) * dy
        return math.atan2(-dy, -dx)


def _corners(rect: Sequence[float]) -> list[tuple[float, float]]:
    x0, y0, x1, y1 = rect
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
