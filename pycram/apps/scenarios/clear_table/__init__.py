"""The clear-table scenario: everything on the table into the drawers and the cupboard, the
containers closed after (issue 33, the household task suite).

From a seed, the objects of `OBJECTS` (a cup, a bowl, a plate) start at spots drawn uniformly over
the whole table, kept where some standing pose of the robot grasps them (the scene generator's
`ReachabilityFilter`; the robot is not told). Each goes where its type is put away
(`pycram.world.objects.STORED_IN`): the cup and the bowl into a drawer, the plate into the
cupboard -- the environment's containers of those kinds, found by their inside's kind, so the
scene runs in the apartment and in every generated apartment (``procedural:SEED``). The plan
(`plan.clear_table`) uses the action library only: `Transport` to ``('in', container)`` (it opens
a closed container first), the next container after a failure there, then `Close` for every
container believed open. Judged with the simulator's truth: each object upright, resting inside
one of its containers, every drawer below 3 cm and every door below 4 deg.

Modules: `data` (objects, faults, budgets), `scene` (`start_scene`), `plan` (`clear_table`),
`driver` (`TASK`, `run_clear_table` for `pycram experiment`), `display` (`main` for `pycram demo`);
the judge and the faults are the suite's (`pycram.apps.scenarios.common`).
"""

from pycram.apps.scenarios.clear_table.data import FAULTS, OBJECTS
from pycram.apps.scenarios.clear_table.driver import TASK, run_clear_table
from pycram.apps.scenarios.clear_table.scene import start_scene

__all__ = ["OBJECTS", "FAULTS", "TASK", "run_clear_table", "start_scene"]
