"""The set-table scenario as data: its objects, where they may start, the place settings, the
fault kinds, the judging thresholds and the time budgets.

Plain constants, no logic: lengths in metres in the map frame, regions as (x0, y0, x1, y1) [m],
angles in radians, times in seconds. The scene (`scene`), the faults (`faults`), the judge
(`judge`) and the driver (`driver`) read them.
"""

from __future__ import annotations

import math

__all__ = [
    "SCENARIOS",
    "OBJECTS",
    "STARTS",
    "ANYWHERE_OBJECTS",
    "ANYWHERE_SOURCE_KINDS",
    "START_REGIONS",
    "START_CONTAINERS",
    "START_SPACING",
    "SCENE_DRAWS",
    "SEAT",
    "SETTINGS",
    "FAULTS",
    "TOLERANCE",
    "MAX_TILT",
    "CLOSED",
    "MISS_PROBABILITY",
    "SIM_TIME_LIMIT",
    "WALL_TIME_LIMIT",
]

#: The scenarios of `pycram demo --scenario`.
SCENARIOS = ("thesis", "set-table", "set-table-open", "set-table-anywhere")
#: The start modes of the scene (`start_scene(..., starts=)`): ``narrow`` -- the measured strips
#: of `START_REGIONS` and the containers of `START_CONTAINERS` (the ``set-table`` and
#: ``set-table-open`` scenarios); ``anywhere`` -- the ``set-table-anywhere`` scenario: every
#: object of `ANYWHERE_OBJECTS` anywhere on the worktops and inside every container it is found
#: in, wherever some standing pose of the robot reaches it
#: (`pycram.apps.scenarios.reachability.ReachabilityFilter`).
STARTS = ("narrow", "anywhere")
#: The objects of the breakfast setting, in the order they are brought (types both robots grasp
#: reliably: spoons are too thin for the fingers, cereal boxes push away; see the docs).
OBJECTS = ("plate", "bowl", "cup", "milk")
#: The objects of the breakfast setting in the ``anywhere`` starts, in the order they are
#: brought: all six breakfast types.
ANYWHERE_OBJECTS = ("plate", "bowl", "cup", "spoon", "cereal", "milk")
#: Where objects start in the ``anywhere`` starts: the whole of the environment's open surfaces
#: of these kinds (`pycram.world.environment.Surface.kind`: the counters, the cabinet top, the
#: cookers; front to back) and the insides of every container (drawers, fridge shelves, the
#: cupboard) of a kind the object type is found on (`pycram.world.objects.ObjectType.found_on`).
ANYWHERE_SOURCE_KINDS = ("counter", "cooker")
#: Where objects start, as data: object type -> the supports (surface names) it may start on,
#: each with the region (x0, y0, x1, y1) [m, map] where it may stand: the front strips of the
#: kitchen counter and of the drawer cabinet's top. Measured: the counter's back half is out of
#: both robots' reach; side grasps of tall objects need the pre-grasp off the counter. The milk
#: carton starts on the counter only: on the cabinet top the PR2's arm knocked it over in 2 of
#: 12 seeds. (Inside containers: `START_CONTAINERS`.)
START_REGIONS: dict[str, dict[str, tuple[float, float, float, float]]] = {
    "plate": {"counter": (0.5, 4.54, 2.4, 4.56), "cabinet top": (0.42, 2.6, 0.45, 3.15)},
    "bowl": {"counter": (0.5, 4.5, 2.4, 4.55), "cabinet top": (0.42, 2.6, 0.5, 3.15)},
    "cup": {"counter": (0.5, 4.46, 2.4, 4.52), "cabinet top": (0.45, 2.6, 0.54, 3.15)},
    "milk": {"counter": (0.5, 4.47, 2.4, 4.5)},  # on the cabinet top the arm knocks it over
}
#: Objects that may start inside a closed container, as data: object type -> (probability,
#: {inside surface: region (x0, y0, x1, y1) [m, map, the container closed]}). Drawn from the
#: seed after the object's spot in `START_REGIONS` (so every other object starts where it did
#: without containers; the container is drawn with equal chances). Measured (docs/set-table.md):
#: cups are picked from the top out of drawer 2 by both robots, 15-22 cm behind its front,
#: mid-width (0.24 m off the middle the TIAGo's look into the opened drawer did not see the
#: cup), and by their side from the cupboard's east half, 6-13 cm behind its door (its west
#: half is behind the door opened 69 deg; 4 cm from the east wall the fingers hit it). Not
#: drawer 3 (the TIAGo opened it but did not see the object, 0 of 2), not drawer 1 (too low to
#: pick from), not the bowl (the PR2's rim grasp out of drawer 2 failed or dropped it in 3 of 4
#: runs), not the plate (it does not fit a drawer: `found_on`), not the milk in the fridge
#: (neither robot finds a standing pose to grasp it on a shelf: the opened door stands in front
#: of the west half, the raised arm and the side grasps hit the fridge's side wall and shelf
#: boards).
START_CONTAINERS: dict[str, tuple[float, dict[str, tuple[float, float, float, float]]]] = {
    "cup": (0.35, {"drawer 2 inside": (0.38, 2.82, 0.45, 2.98), "cupboard shelf": (4.14, 4.59, 4.24, 4.66)}),
}
#: Objects start at least this far [m] apart (between their footprints): an arm reaching for one
#: object knocks over a neighbour closer than this (measured: tall milk cartons and cups).
START_SPACING = 0.25
#: Draws of a start scene per seed before giving up (a draw fails when the objects drawn first
#: leave no room for the next one on its surfaces: the milk in 1 of ~250 seeds).
SCENE_DRAWS = 20
#: The seat the table is set for: a named place of the environment (the base pose of a person
#: sitting there, facing the table).
SEAT = "table south"
#: The place settings, as data: object type -> (sideways [m], to the right of the seat's
#: heading; inwards [m], from the table's edge at the seat). The plate in front of the seat, the
#: bowl left of it, the cup right, the milk beyond the cup; the spoon left of the bowl, the
#: cereal beyond the bowl (brought in the ``anywhere`` starts only).
SETTINGS: dict[str, tuple[float, float]] = {
    "plate": (0.0, 0.2),
    "bowl": (-0.3, 0.2),
    "cup": (0.28, 0.18),
    "milk": (0.5, 0.2),
    "spoon": (-0.47, 0.18),  # left of the bowl (a top grasp reaches about 0.25 m in from the edge)
    "cereal": (-0.3, 0.45),  # beyond the bowl (a side grasp reaches that far in)
}
#: The fault kinds `run_set_table` / `pycram demo --faults` accept.
FAULTS = ("moved", "taken", "stuck", "obstacle", "missed")
#: Judging: an object counts as placed within this distance [m] of its setting ...
TOLERANCE = 0.05
#: ... and tilted at most this much [rad] from upright.
MAX_TILT = math.radians(20.0)
#: A drawer counts as closed below this opening [m].
CLOSED = 0.03
#: Probability of a missed detection with the ``missed`` fault.
MISS_PROBABILITY = 0.3
#: The scenario's budget of simulated time [s] (all objects) ...
SIM_TIME_LIMIT = 2400.0
#: ... and of wall time [s].
WALL_TIME_LIMIT = 1800.0
