"""The clear-table scenario as data: what stands on the table, the fault kinds, the time budgets.

Where each object goes is the object types' data (`pycram.world.objects.STORED_IN`: cups and
bowls into a drawer, plates into the cupboard); which containers those are in an environment is
read from its description (`pycram.apps.scenarios.common.scene.storage_containers`). Times in
seconds.
"""

from __future__ import annotations

__all__ = ["OBJECTS", "ALLOWED", "SOURCE_KINDS", "FAULTS", "SIM_TIME_LIMIT", "WALL_TIME_LIMIT"]

#: What stands on the table to be cleared away, in the order it is put away.
OBJECTS = ("cup", "bowl", "plate")
#: The object types a clear-table scene may hold (`objects=`): those put away somewhere.
ALLOWED = ("cup", "mug", "bowl", "plate", "spoon", "cereal", "milk")
#: Where the objects start: the open surfaces of these kinds (the table).
SOURCE_KINDS = ("table",)
#: The fault kinds (set-table's, those that apply: see `pycram.apps.scenarios.common.faults`).
FAULTS = ("moved", "taken", "stuck", "missed")
#: The budget of simulated time [s] (all objects) ...
SIM_TIME_LIMIT = 2400.0
#: ... and of wall time [s].
WALL_TIME_LIMIT = 1800.0
