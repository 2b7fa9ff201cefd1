"""The serve scenario as data: what may be asked for, how many, the seat, the faults, the budgets.

Times in seconds; lengths in metres.
"""

from __future__ import annotations

__all__ = ["SERVABLE", "COUNT", "SEAT", "INWARD", "SOURCE_KINDS", "FAULTS", "SIM_TIME_LIMIT", "WALL_TIME_LIMIT"]

#: The object types that may be asked for (each at most once: the plan finds objects by type).
SERVABLE = ("cup", "bowl", "plate", "cereal", "milk")
#: How many objects are asked for when the caller does not say which (drawn from the seed).
COUNT = 2
#: The seat the objects are brought to: a named place of the environment (a person sitting there,
#: facing the table).
SEAT = "table south"
#: The objects are served around the point this far [m] in from the table's edge in front of the
#: seat (a place setting's depth; spots at the very edge let a cup and a cereal box fall off).
INWARD = 0.2
#: Where the objects start: the kitchen's worktops (counters, the cabinet top, the cookers).
SOURCE_KINDS = ("counter", "cooker")
#: The fault kinds (set-table's, those that apply: see `pycram.apps.scenarios.common.faults`).
FAULTS = ("moved", "taken", "obstacle", "missed")
#: The budget of simulated time [s] (all objects) ...
SIM_TIME_LIMIT = 2000.0
#: ... and of wall time [s].
WALL_TIME_LIMIT = 1500.0
