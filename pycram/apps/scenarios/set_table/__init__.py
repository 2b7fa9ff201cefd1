"""The set-table scenario: a breakfast for one, from a seed, in the apartment (issue 17).

From a seed, the objects of `OBJECTS` start at random spots on the kitchen counter and the
drawer cabinet's top (`START_REGIONS`), the cup in about a third of the seeds inside the closed
drawer 2 or the closed cupboard instead (`START_CONTAINERS`; not in the ``set-table-open``
scenario; nothing starts in the fridge yet, see `docs/set-table.md`). The ``set-table-anywhere``
scenario (start mode ``anywhere``, `STARTS`) draws all six breakfast types (`ANYWHERE_OBJECTS`)
over the whole worktops and inside the drawers, the fridge and the cupboard, wherever some
standing pose of the robot reaches them (`anywhere_scene`). The robot starts at the
apartment's start pose, knowing nothing about the objects, and runs `plan.set_table` for the
place settings of `SETTINGS` (stated relative to the table's edge at the seat). The simulator's
ground truth is used for judging only (`judge`): every object upright at its place setting
within `TOLERANCE` and `MAX_TILT`, no gripper holding it, every drawer and door closed.

Faults (`FAULTS`, off by default), drawn from the seed -- a simulated person and a flaky camera,
acting on the simulator (the `faults` module is the plan's environment, not the plan):

* ``moved``: a person moves the object the robot is about to fetch, once it comes near;
* ``taken``: a person takes the object out of the gripper while the robot carries it and puts it
  back on the counter;
* ``stuck``: a drawer (one holding an object, if any does) is stuck at first and frees itself a
  while after the robot first pulls on it (it matters when a search opens the drawers);
* ``obstacle``: a box appears on the floor in the robot's way once it drives to the table;
* ``missed``: perception misses a visible object with a probability (`MISS_PROBABILITY`).

`run_set_table(robot, seed, faults)` runs one scenario headless and returns a JSON-serialisable
dict (for `pycram experiment`); `run_scenario` does the same for `pycram demo --scenario
set-table` with pictures and the trace; `main` is that demo in the terminal.

The modules, one concept each:

- `data`: the scenario as data (objects, start regions, place settings, fault kinds, thresholds);
- `scene`: where the objects start (`start_scene`) and where they belong (`place_settings`);
- `faults`: the simulated person and the flaky camera (`Faults`, `check_faults`);
- `judge`: success and failure causes from the simulator's truth (`judge`, `SetTableResult`);
- `driver`: the world, the plan in its thread under time limits, the faults, the judge
  (`run_scenario`, `run_set_table`);
- `display`: `pycram demo --scenario set-table` in the terminal (`main`);
- `plan`: the robot-agnostic plan itself (`set_table`), which knows nothing of the simulator.
"""

from pycram.apps.scenarios.set_table.data import (
    ANYWHERE_OBJECTS,
    FAULTS,
    MAX_TILT,
    OBJECTS,
    SCENARIOS,
    SEAT,
    SETTINGS,
    START_CONTAINERS,
    START_REGIONS,
    START_SPACING,
    STARTS,
    TOLERANCE,
)
from pycram.apps.scenarios.set_table.display import main
from pycram.apps.scenarios.set_table.driver import (
    run_scenario,
    run_set_table,
    run_set_table_anywhere,
    run_set_table_on_open_surfaces,
)
from pycram.apps.scenarios.set_table.faults import Faults, check_faults
from pycram.apps.scenarios.set_table.judge import ObjectResult, SetTableResult, judge
from pycram.apps.scenarios.set_table.scene import anywhere_scene, anywhere_sources, place_settings, start_scene

__all__ = [
    "OBJECTS",
    "ANYWHERE_OBJECTS",
    "STARTS",
    "anywhere_scene",
    "anywhere_sources",
    "run_set_table_anywhere",
    "START_REGIONS",
    "START_CONTAINERS",
    "START_SPACING",
    "start_scene",
    "SEAT",
    "SETTINGS",
    "FAULTS",
    "SCENARIOS",
    "TOLERANCE",
    "MAX_TILT",
    "ObjectResult",
    "SetTableResult",
    "place_settings",
    "check_faults",
    "judge",
    "run_set_table",
    "run_set_table_on_open_surfaces",
    "run_scenario",
    "Faults",
    "main",
]
