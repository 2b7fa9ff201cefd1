"""Check f: the set-table scenario on a few development seeds, through its own driver.

Each seed of `SEEDS` is one run of the ``set-table`` scenario exactly as ``pycram experiment
--scenario set-table`` runs it (:func:`pycram.apps.scenarios.set_table.driver.run_set_table`:
the apartment, the breakfast objects at random spots -- some in closed containers --, no faults,
lock-step simulation, not recorded), judged by the scenario's judge: every object at its place
setting and every container closed. The seeds are development seeds
(:data:`pycram.apps.experiments.splits.DEV_SEEDS`): a conformance check is for developing a
robot, not for reporting figures.

Only the full form runs them: one seed took 9-24 s (PR2) and 13-54 s (TIAGo) of wall time on
this project's 2-core machines (seeds 0-2, with and without other work beside it), too long for
the short form that the test suite runs for every registered robot.
"""

from __future__ import annotations

from typing import Any

from pycram.apps.robot_check.results import CheckFailed

__all__ = ["SEEDS", "set_table_seed"]

#: The development seeds the full form runs.
SEEDS = (0, 1, 2)


def set_table_seed(robot: str, seed: int) -> tuple[str, dict[str, Any], float]:
    """Run set-table with `robot` on `seed`; returns (detail, data, simulated time [s]). Raises
    `CheckFailed` with the judge's summary when the table is not set."""
    from pycram.apps.scenarios.set_table.driver import run_set_table

    result = run_set_table(robot, seed)
    objects = result.get("objects", {})
    placed = sum(1 for o in objects.values() if o.get("placed"))
    data = {
        "success": result["success"],
        "placed": placed,
        "objects": len(objects),
        "failure_causes": result.get("failure_causes", []),
        "sim_time": result.get("sim_time"),
        "wall_time": result.get("wall_time"),
    }
    if not result["success"]:
        raise CheckFailed(f"{placed}/{len(objects)} placed: {result.get('summary', '')}", data)
    return (
        f"{placed}/{len(objects)} objects at their place settings, containers closed",
        data,
        float(result["sim_time"]),
    )
