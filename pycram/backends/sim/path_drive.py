"""Driving the base along a planned, collision-free path, re-planning when the way gets blocked.

`PlannedDrive` is the controller behind `World.drive_to`: it plans a path on the occupancy grid
of the current state (`pycram.world.navigation.PathPlanner`; the straight line when it is free)
and drives it waypoint by waypoint with `BaseDrive` segments. Every control tick it watches the
movable parts of the environment (obstacles, doors, drawers); when one moved and the rest of
the path is no longer free, it stops the base, waits until it stands still, and plans again
from where it stopped. It fails with reason "no_path" (message: the planner's reason) only when
no path exists; contact and lag failures of the segments stay what they are ("collision",
"blocked"), as the last line of defence.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence

import mujoco
import numpy as np

from pycram.world.base_kinematics import BaseKinematics
from pycram.world.navigation import Footprint, NoPathError, PathPlanner
from pycram.world.prospection import BasePose
from pycram.world.types import Outcome, Pose2D

from .controllers import BaseDrive, Controller, fail, invalid_input
from .drive_check import DRIVE_TOLERANCE, band_outlines, layered_planner
from .engine import Engine
from .occupancy import FloorMap, base_footprint, build_floor_map, local_vertices, robot_parts
from .occupancy import _add as rasterize
from .prospection import SimProspection
from .recording import StateSnapshot
from .robot_model import BASE_JOINTS

_log = logging.getLogger(__name__)

#: Tolerances [m], [rad] at intermediate waypoints (the goal keeps BaseDrive's own).
WAYPOINT_TOLERANCE = (0.03, 0.05)
#: A movable part of the environment counts as moved when a coordinate of its pose or joint
#: changed by more than this [m, rad or quaternion component] (less than a grid cell).
MOVED = 0.01
#: The base counts as stopped below this planar speed [m/s] (and a tenth of it in [rad/s]).
STOPPED_SPEED = 0.02


class Navigation:
    """A scene's floor map, the robot's footprint and the planner of the current state; used by
    the simulation thread only. The planner is rebuilt when a movable geom moved."""

    def __init__(self, eng: Engine) -> None:
        self.floor: FloorMap = build_floor_map(eng.scene, eng.data)
        self.footprint: Footprint = base_footprint(eng.scene, eng.data)
        self.kinematics = BaseKinematics.of(eng.desc.BASE)
        self._state: np.ndarray | None = None
        # `FloorMap.movable_state`'s indices as arrays: the state is compared every control tick
        self._mocap = np.asarray(self.floor.mocap_ids, dtype=np.int64)
        self._qpos = np.asarray(self.floor.qpos_addresses, dtype=np.int64)
        self._outline = np.zeros(0)
        # the occupied cells by band (`FloorMap.bands`) of the movable state `_bands_of`
        self._bands: dict[float, np.ndarray] = {}
        self._bands_of: np.ndarray | None = None
        self._robot_parts = robot_parts(eng.scene)
        self._item_points: dict[int, np.ndarray] = {}
        # each item's position's qpos addresses (x, y, z), in `eng.item_qpos`'s order
        self._items = list(eng.item_qpos)
        self._item_qpos = np.array([[a, a + 1, a + 2] for a in eng.item_qpos.values()], dtype=np.int64).reshape(-1, 3)
        self._planner: PathPlanner | None = None
        self._robot_state = StateSnapshot.of(eng.data)
        # a drive fails on any contact (`DRIVE_TOLERANCE`)
        self._prospection = SimProspection(eng.scene, lambda: self._robot_state, tolerance=DRIVE_TOLERANCE)

    def exact_check(self, eng: Engine) -> Callable[[float, float, float], bool]:
        """Whether the whole robot, in its configuration now and with the items its grippers
        hold, touches nothing of the environment and no other item at a base pose (x, y, yaw):
        the 3D check behind the planner's outlines. Answers are memoized per pose (to 1 mm /
        1 mrad) for this state."""
        self._robot_state = StateSnapshot.of(eng.data)
        return memoized_free(self._prospection, carried_items(eng))

    def _parts(self, eng: Engine) -> list[dict[int, np.ndarray]]:
        """The robot's parts (`robot_parts`), each arm's with the geoms of the item its gripper
        holds now: a carried object is kept off the furniture as the arm holding it is."""
        held = {g: item for g, item in ((name, gr.holding) for name, gr in eng.grippers.items()) if item}
        if not held:
            return self._robot_parts
        parts = [dict(part) for part in self._robot_parts]
        for k, spec in enumerate(eng.scene.description.ARMS.values(), start=1):
            item = held.get(spec["gripper"])
            for g in eng.item_part_geoms.get(item, ()) if item else ():
                local = self._item_points.get(g)
                if local is None:
                    local = self._item_points[g] = local_vertices(eng.model, g, 100)
                parts[k][g] = local
        return parts

    def movable_state(self, data: mujoco.MjData) -> np.ndarray:
        """`FloorMap.movable_state` of `data` (the same numbers, a few microseconds)."""
        return np.concatenate(
            (data.mocap_pos[self._mocap].ravel(), data.mocap_quat[self._mocap].ravel(), data.qpos[self._qpos])
        )

    def _items_state(self, eng: Engine) -> np.ndarray:
        """The positions of the items no gripper holds (x, y, z each [m]; zeros for held ones):
        what moves the items' cells on the floor map."""
        positions = eng.data.qpos[self._item_qpos]  # a copy (fancy indexing)
        for item in carried_items(eng):
            positions[self._items.index(item)] = 0.0
        return positions.ravel()

    def _with_items(self, eng: Engine, bands: dict[float, np.ndarray]) -> dict[float, np.ndarray]:
        """`bands` with the cells of every item no gripper holds, each in the band of its top:
        the robot keeps what stands on a counter or a table off the arms' and the held
        objects' outlines as it would a box of that height (a base's 3D obstacle layer sees
        them). Read-only from here."""
        held = set(carried_items(eng))
        for item in self._items:
            if item not in held:
                for g in eng.item_part_geoms[item]:
                    rasterize(bands, self.floor, eng.model, eng.data, g)
        return dict(sorted(bands.items()))

    def planner(self, eng: Engine, refresh_outline: bool = True) -> tuple[PathPlanner, bool]:
        """The planner of the current state, and whether it is new (something moved by more
        than `MOVED` since the planner was built; smaller motions, e.g. a door settling, do not
        rebuild it). The robot's outline is taken anew only with `refresh_outline` (or when
        something moved): drives take it when they plan.

        Each height band of obstacles is kept off by the outline of the robot as it stands
        (arms included) below that band's top: the base alone keeps off a counter whose top
        the arms reach over, the whole robot keeps off walls and tall boxes."""
        state = np.concatenate((self.movable_state(eng.data), self._items_state(eng)))
        moved = self._state is None or float(np.abs(state - self._state).max(initial=0.0)) > MOVED
        if self._planner is not None and not moved and not refresh_outline:
            return self._planner, False
        if self._bands_of is None or not np.array_equal(state, self._bands_of):
            self._bands, self._bands_of = self._with_items(eng, self.floor.bands(eng.model, eng.data)), state
        bands = self._bands
        outlines = band_outlines(eng.scene, eng.data, bands, self._parts(eng))
        # the robot's pose, to the cm
        key = np.round(np.concatenate([np.asarray(p.vertices).ravel() for o in outlines.values() for p in o]), 2)
        if (
            self._planner is not None
            and not moved
            and key.shape == self._outline.shape
            and float(np.abs(key - self._outline).max(initial=0.0)) <= MOVED
        ):
            return self._planner, False
        self._state, self._outline = state, key
        self._planner = layered_planner(self.floor, self.footprint, self.kinematics, bands, outlines)
        return self._planner, True


def memoized_free(prospection: SimProspection, carried: Sequence[str] = ()) -> Callable[[float, float, float], bool]:
    """(x, y, yaw) -> the robot, with the items `carried` moving with it, touches nothing there,
    neither the environment nor another item (`prospection.in_collision`), memoized per pose to
    1 mm / 1 mrad (for one plan: the state must not change meanwhile)."""
    memo: dict[tuple[int, int, int], bool] = {}

    def free(x: float, y: float, yaw: float) -> bool:
        key = (round(x * 1e3), round(y * 1e3), round(yaw * 1e3))
        answer = memo.get(key)
        if answer is None:
            answer = memo[key] = not prospection.in_collision((x, y, yaw), carried=carried, objects=True)
        return answer

    return free


def carried_items(eng: Engine) -> list[str]:
    """The items the robot's grippers hold now (simulator names), in the grippers' order."""
    return [g.holding for g in eng.grippers.values() if g.holding]


def navigation_of(eng: Engine) -> Navigation:
    """The engine's `Navigation`, built on first use (a few ms)."""
    nav = getattr(eng, "_navigation", None)
    if nav is None:
        nav = eng._navigation = Navigation(eng)  # type: ignore[attr-defined]
    return nav


def _pose(p: Pose2D) -> BasePose:
    return BasePose(p.x, p.y, p.yaw)


class PlannedDrive(Controller):
    """Drive the base to `goal` (map frame) around obstacles; see the module docstring.

    The outcome's value is the final `Pose2D` (also on failure: where the base stopped).
    `replans` counts the plans made after the first (for tests and traces).
    """

    channel = "base"

    def __init__(self, goal: Pose2D) -> None:
        self.goal = goal
        self.waypoints: list[BasePose] = []
        self.segment: BaseDrive | None = None
        self.stopping = False
        self.replans = 0

    def _plan(self, eng: Engine) -> Outcome | None:
        nav = navigation_of(eng)
        planner, _ = nav.planner(eng)
        here = eng.base_pose()
        try:
            self.waypoints = planner.plan(_pose(here), _pose(self.goal), nav.exact_check(eng))
        except NoPathError as exc:
            return fail("no_path", str(exc), here)
        if len(self.waypoints) > 1:
            _log.info(
                "drive to (%.2f, %.2f): path around obstacles with %d waypoints",
                self.goal.x,
                self.goal.y,
                len(self.waypoints),
            )
        return self._next_segment(eng)

    def _next_segment(self, eng: Engine) -> Outcome | None:
        w = self.waypoints.pop(0)
        if self.waypoints:
            self.segment = BaseDrive(Pose2D(w.x, w.y, w.yaw), *WAYPOINT_TOLERANCE)
        else:
            self.segment = BaseDrive(self.goal)
        return self.segment.start(eng)

    def start(self, eng: Engine) -> Outcome | None:
        refused = invalid_input(goal=(self.goal.x, self.goal.y, self.goal.yaw))
        if refused is not None:  # "invalid" before anything is planned or moves, as BaseDrive
            return refused
        return self._plan(eng)

    def _remaining_free(self, eng: Engine, planner: PathPlanner) -> bool:
        rest = (
            [BasePose(self.segment.goal.x, self.segment.goal.y, self.segment.goal.yaw)]
            if self.segment is not None
            else []
        ) + self.waypoints
        return planner.path_free(_pose(eng.base_pose()), rest, navigation_of(eng).exact_check(eng))

    def update(self, eng: Engine, t: float) -> Outcome | None:
        if self.stopping:
            v = math.hypot(*(float(eng.data.qvel[i]) for i in eng.base_dof[:2]))
            if v > STOPPED_SPEED or abs(float(eng.data.qvel[eng.base_dof[2]])) > STOPPED_SPEED * 10:
                return None
            self.stopping = False
            self.replans += 1
            return self._plan(eng)
        planner, changed = navigation_of(eng).planner(eng, refresh_outline=False)
        if changed and not self._remaining_free(eng, planner):
            _log.info("drive to (%.2f, %.2f): the path is blocked; stopping to re-plan", self.goal.x, self.goal.y)
            eng.hold(list(BASE_JOINTS))
            self.segment = None
            self.stopping = True
            return None
        assert self.segment is not None
        out = self.segment.update(eng, t)
        if out is None or not out.succeeded:
            return out
        if self.waypoints:
            return self._next_segment(eng)
        return out

    def stop(self, eng: Engine) -> None:
        eng.hold(list(BASE_JOINTS))


__all__ = ["PlannedDrive", "Navigation", "navigation_of"]
