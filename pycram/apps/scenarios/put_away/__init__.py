"""The put-away scenario: groceries from the counter into the fridge and the cupboard, the doors
closed after (issue 33, the household task suite).

From a seed, the groceries of `OBJECTS` (a milk carton, a cereal box) start at spots drawn
uniformly over the kitchen's worktops (the counters, the cabinet top, the cookers), kept where
some standing pose of the robot grasps them (the scene generator's `ReachabilityFilter`). Where
each belongs is data (`pycram.world.objects.STORED_IN`): milk cold on a fridge shelf, cereal dry
in the cupboard. The plan (`plan.put_away`, the suite's) uses the action library only:
`Transport` to ``('in', 'fridge')`` / ``('in', 'cupboard')`` (opening the door first), then
`Close`. Judged with the simulator's truth: each grocery upright, resting inside its container,
every door below 4 deg and every drawer below 3 cm. Runs in the apartment and in every generated
apartment (``procedural:SEED``).

Modules: `data`, `scene` (`start_scene`), `plan`, `driver` (`TASK`, `run_put_away`), `display`
(`main`); the judge and the faults are the suite's (`pycram.apps.scenarios.common`).
"""

from pycram.apps.scenarios.put_away.data import FAULTS, OBJECTS
from pycram.apps.scenarios.put_away.driver import TASK, run_put_away
from pycram.apps.scenarios.put_away.scene import start_scene

__all__ = ["OBJECTS", "FAULTS", "TASK", "run_put_away", "start_scene"]
