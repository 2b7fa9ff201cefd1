"""`pycram demo --scenario clear-table` in the terminal (`pycram.apps.scenarios.common.display`)."""

from __future__ import annotations

from pycram.apps.scenarios.clear_table.driver import TASK
from pycram.apps.scenarios.common.display import task_demo

__all__ = ["main"]

#: The terminal front end: ``main(robot, seed, faults, output, db, record, quiet, animation,
#: stepping, until, environment, objects) -> exit code``.
main = task_demo(TASK)
