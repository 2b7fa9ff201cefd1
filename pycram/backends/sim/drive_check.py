"""The drive's own model of the floor, for whoever asks where the robot may stand.

`layered_planner` builds the path planner the drive plans with (`path_drive.Navigation`): the
floor map's height bands of occupied cells -- furniture, doors and drawers as they stand, the
objects in the band of their tops -- each kept off by the robot's outline below that band's top
(`pycram.world.navigation.PathPlanner`'s layers). `DriveCheck` builds it for any state of a
scene, e.g. the believed world of location reasoning (`SimProspection.drivable`): reasoning then
offers only base poses the drive takes as goals -- one model of the robot's footprint, its
clearance and the grid's cells for both -- instead of an estimate of it (measured: the TIAGo
Pro's 0.72 x 0.50 m base, offered poses 0.40 m from a drawer cabinet's corner cells that the
drive refused, "goal_in_collision", twice in one set-table run).
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco
import numpy as np

from pycram.world.base_kinematics import BaseKinematics
from pycram.world.navigation import Footprint, OccupancyGrid, PathPlanner

from .occupancy import FloorMap, base_footprint, body_outlines, build_floor_map, robot_parts
from .occupancy import _add as rasterize
from .scene import Scene

__all__ = ["layered_planner", "band_outlines", "DriveCheck", "OUTLINE_ABOVE", "DRIVE_TOLERANCE"]

#: A band's obstacles are kept off by the robot's outline below its top plus this [m].
OUTLINE_ABOVE = 0.02
#: The drive's exact check (the whole robot and what it holds, where only an arm's outline is in
#: the way) counts every contact penetrating more than this [m] -- none: a drive fails on any
#: contact. Location reasoning's `SimProspection.drivable` checks with the same tolerance, not
#: prospection's `COLLISION_TOLERANCE` (measured: a carried cereal box 0.1 mm into the counter's
#: edge at a standing pose reasoning offered, refused by the drive as "goal_in_collision" at every
#: candidate; set-table-anywhere, PR2, `procedural:46`, seed 1).
DRIVE_TOLERANCE = 0.0


def layered_planner(
    floor: FloorMap,
    footprint: Footprint,
    kinematics: BaseKinematics,
    bands: dict[float, np.ndarray],
    outlines: dict[float, list[Footprint]],
) -> PathPlanner:
    """The drive's planner: each band of `bands` (top [m] -> occupied cells of `floor`) kept off
    by `outlines[top]`, the outline of the robot below that band's top (`band_outlines`)."""
    layers = [(mask, outlines[top]) for top, mask in bands.items()]
    nothing = OccupancyGrid(floor.origin, floor.resolution, np.zeros(floor.shape, bool))
    return PathPlanner(nothing, footprint, layers=layers, kinematics=kinematics)


def band_outlines(
    scene: Scene, data: mujoco.MjData, tops: Iterable[float], parts: list[dict[int, np.ndarray]]
) -> dict[float, list[Footprint]]:
    """Band top [m] -> the outline of the robot as it stands in `data` (kinematics computed;
    `parts`: `robot_parts`, with what the hands hold) below that top plus `OUTLINE_ABOVE`."""
    tops = list(tops)
    below = body_outlines(scene, data, [top + OUTLINE_ABOVE for top in tops], parts)
    return {top: below[top + OUTLINE_ABOVE] for top in tops}


class DriveCheck:
    """The drive's floor map, footprint and robot parts for `scene` (built once from `data`,
    kinematics computed: the static environment does not move), and its planner for any state
    (`planner`)."""

    def __init__(self, scene: Scene, data: mujoco.MjData) -> None:
        self.scene = scene
        self.floor: FloorMap = build_floor_map(scene, data)
        self.footprint: Footprint = base_footprint(scene, data)
        self.kinematics = BaseKinematics.of(scene.description.BASE)
        self.parts = robot_parts(scene)

    def planner(self, data: mujoco.MjData, object_geoms: Iterable[int]) -> PathPlanner:
        """The drive's planner in the state of `data` (kinematics computed): the environment's
        bands with the geoms `object_geoms` (the objects no hand holds) in the band of their
        tops, the robot's outline as it stands in `data`."""
        model = self.scene.model
        bands = self.floor.bands(model, data)
        for g in object_geoms:
            rasterize(bands, self.floor, model, data, int(g))
        bands = dict(sorted(bands.items()))
        outlines = band_outlines(self.scene, data, bands, self.parts)
        return layered_planner(self.floor, self.footprint, self.kinematics, bands, outlines)
