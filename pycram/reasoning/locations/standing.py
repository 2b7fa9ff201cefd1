"""Where the base may stand and which way it faces: the layers and options shared by the
base-pose vocabularies that use an arm (``to_reach``, ``to_open``).

`StandingSearch` adds to `CandidateSearch`: the floor's occupancy with the drawers and doors
believed open (the base keeps `DRAWER_CLEARANCE` / `DOOR_CLEARANCE` [m] from them), the base
heading that puts a point at an arm's comfortable reach point, the cost of not facing the
furniture squarely, the order in which arms are tried and the robot's other named torso heights.
Angles are in radians, distances in metres, in the map frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pycram.world.environment import Container, Environment

from .costmap import FloorGrid, occupancy_layer, rect_distance, segment_distance
from .search import CandidateSearch

__all__ = [
    "StandingSearch",
    "REACH_SIGMA",
    "REACH_INSIDE",
    "REACH_OUTSIDE",
    "FACING_SCALE",
    "DRAWER_CLEARANCE",
    "DOOR_CLEARANCE",
    "DOOR_OPEN_FROM",
    "HANDLE_DEPTH",
]

#: Reach ring spread [m] around the arm's comfortable distance [m].
REACH_SIGMA = 0.12
#: The reach ring's limit [m] inside the arm's comfortable distance ...
REACH_INSIDE = 0.35
#: ... and outside it [m].
REACH_OUTSIDE = 0.30
#: Facing the furniture: angle [rad] scale of its cost.
FACING_SCALE = 0.6
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


class StandingSearch(CandidateSearch):
    """The search for base poses from which an arm works (see the module docstring)."""

    def _arms(self, requested: Any) -> list[str]:
        if requested is not None:
            return [self.geometry.arm(requested)]
        others = [a for a in self.geometry.arms if a != self.geometry.default_arm]
        return [self.geometry.default_arm] + others

    def _other_torso_heights(self) -> list[tuple[str, float]]:
        """The robot's named torso heights other than the one it has now, nearest first."""
        joint, named = self.geometry.torso_joint, self.geometry.torso_positions or {}
        if joint is None or not named:
            return []
        now = self.prospection().joint_position(joint) if hasattr(self.prospection(), "joint_position") else None
        options = [(name, h) for name, h in named.items() if now is None or abs(h - now) > 0.01]
        return sorted(options, key=lambda o: 0.0 if now is None else abs(o[1] - now))

    def _natural_yaw(self, grid: FloorGrid, point: Sequence[float], arm: str) -> np.ndarray:
        """Per cell: the base heading that puts `point` at `arm`'s comfortable reach point."""
        return np.arctan2(point[1] - grid.y, point[0] - grid.x) - self.geometry.reach_bearing(arm)

    @staticmethod
    def _facing_layer(yaw: np.ndarray, facing: list[float]) -> np.ndarray:
        diff = np.min([np.abs((yaw - f + np.pi) % (2 * np.pi) - np.pi) for f in facing], axis=0)
        return (diff / FACING_SCALE) ** 2

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


def _wrap(angle: float) -> float:
    """`angle` [rad] wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi
