"""Running the clear-table scenario (`pycram.apps.scenarios.common.driver.run_task` with `TASK`)."""

from __future__ import annotations

from pycram.apps.scenarios.clear_table.data import FAULTS, OBJECTS, SIM_TIME_LIMIT, WALL_TIME_LIMIT
from pycram.apps.scenarios.clear_table.plan import clear_table
from pycram.apps.scenarios.clear_table.scene import start_scene
from pycram.apps.scenarios.common.driver import TaskScenario, task_experiment
from pycram.apps.scenarios.common.judge import judge_put_away

__all__ = ["TASK", "run_clear_table"]

#: The clear-table scenario for the suite's driver.
TASK = TaskScenario(
    name="clear-table",
    title="clear the table",
    faults=FAULTS,
    sim_time_limit=SIM_TIME_LIMIT,
    wall_time_limit=WALL_TIME_LIMIT,
    scene=start_scene,
    plan=clear_table,
    judge=judge_put_away,
    done_text="the table is cleared: everything put away, every container closed",
    count=len(OBJECTS),
)


#: The ``clear-table`` scenario of `pycram experiment`: ``run_clear_table(robot, seed, faults, db_url,
#: pictures, stepping, environment, objects) -> dict`` (`task_experiment`).
run_clear_table = task_experiment(TASK)
