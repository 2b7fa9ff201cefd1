"""The put-away scenario as data: the groceries on the counter, the fault kinds, the budgets.

Where each grocery belongs is the object types' data (`pycram.world.objects.STORED_IN`: milk
cold on a fridge shelf, cereal dry in the cupboard). Times in seconds.
"""

from __future__ import annotations

__all__ = ["OBJECTS", "ALLOWED", "SOURCE_KINDS", "FAULTS", "SIM_TIME_LIMIT", "WALL_TIME_LIMIT"]

#: The groceries on the counter, in the order they are put away.
OBJECTS = ("milk", "cereal")
#: The object types a put-away scene may hold (`objects=`): those put away somewhere.
ALLOWED = ("milk", "cereal", "cup", "mug", "bowl", "plate", "spoon")
#: Where the groceries start: the kitchen's worktops (counters, the cabinet top, the cookers).
SOURCE_KINDS = ("counter", "cooker")
#: The fault kinds (set-table's, those that apply: see `pycram.apps.scenarios.common.faults`).
FAULTS = ("moved", "taken", "missed")
#: The budget of simulated time [s] (all objects) ...
SIM_TIME_LIMIT = 2000.0
#: ... and of wall time [s].
WALL_TIME_LIMIT = 1500.0
