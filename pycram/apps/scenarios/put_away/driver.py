"""Running the put-away scenario (`pycram.apps.scenarios.common.driver.run_task` with `TASK`)."""

from __future__ import annotations

from pycram.apps.scenarios.common.driver import TaskScenario, task_experiment
from pycram.apps.scenarios.common.judge import judge_put_away
from pycram.apps.scenarios.put_away.data import FAULTS, OBJECTS, SIM_TIME_LIMIT, WALL_TIME_LIMIT
from pycram.apps.scenarios.put_away.plan import put_away
from pycram.apps.scenarios.put_away.scene import start_scene

__all__ = ["TASK", "run_put_away"]

#: The put-away scenario for the suite's driver.
TASK = TaskScenario(
    name="put-away",
    title="put the groceries away",
    faults=FAULTS,
    sim_time_limit=SIM_TIME_LIMIT,
    wall_time_limit=WALL_TIME_LIMIT,
    scene=start_scene,
    plan=put_away,
    judge=judge_put_away,
    done_text="the groceries are put away, every door closed",
    count=len(OBJECTS),
)


#: The ``put-away`` scenario of `pycram experiment`: ``run_put_away(robot, seed, faults, db_url,
#: pictures, stepping, environment, objects) -> dict`` (`task_experiment`).
run_put_away = task_experiment(TASK)
