"""`pycram demo --scenario put-away` in the terminal (`pycram.apps.scenarios.common.display`)."""

from __future__ import annotations

from pycram.apps.scenarios.common.display import task_demo
from pycram.apps.scenarios.put_away.driver import TASK

__all__ = ["main"]

#: The terminal front end: ``main(robot, seed, faults, output, db, record, quiet, animation,
#: stepping, until, environment, objects) -> exit code``.
main = task_demo(TASK)
