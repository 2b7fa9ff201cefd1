"""Running the serve scenario (`pycram.apps.scenarios.common.driver.run_task` with `TASK`)."""

from __future__ import annotations

from typing import Any

from pycram.apps.scenarios.common.driver import TaskScenario, run_task_for_experiment
from pycram.apps.scenarios.common.judge import judge_serve
from pycram.apps.scenarios.serve.data import COUNT, FAULTS, SIM_TIME_LIMIT, WALL_TIME_LIMIT
from pycram.apps.scenarios.serve.plan import serve
from pycram.apps.scenarios.serve.scene import requested, start_scene
from pycram.core.runtime.lockstep import DEFAULT_STEPPING

__all__ = ["TASK", "run_serve"]

#: The serve scenario for the suite's driver.
TASK = TaskScenario(
    name="serve",
    title="serve at the table",
    faults=FAULTS,
    sim_time_limit=SIM_TIME_LIMIT,
    wall_time_limit=WALL_TIME_LIMIT,
    scene=start_scene,
    plan=serve,
    judge=judge_serve,
    done_text="every object served at the seat, next to each other",
    count=COUNT,
)


def run_serve(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = DEFAULT_STEPPING,
    environment: str = "apartment",
    objects: tuple[str, ...] | None = None,
    count: int = COUNT,
) -> dict[str, Any]:
    """The ``serve`` scenario of `pycram experiment`: one run in `environment`
    (``apartment``, ``procedural:SEED``, ...) bringing `objects` (None: `count` types drawn from
    the seed, see `requested`), judged with the simulator's truth; see `run_task_for_experiment`
    for the other arguments and the result. Raises `ValueError` for bad inputs (an unknown or
    repeated type, a count out of range) before anything runs."""
    asked = requested(seed, objects, count)
    return run_task_for_experiment(TASK, robot, seed, faults, db_url, pictures, stepping, environment, asked)


run_serve.FAULTS = FAULTS  # type: ignore[attr-defined]
