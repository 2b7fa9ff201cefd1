"""`pycram robot check NAME`: a conformance run for a registered robot.

Does a robot described as data (`pycram.world.robot_registry`) work with PyCRAM's plans? The check
runs, in a fixed scene of the simulated apartment (:mod:`~pycram.apps.robot_check.scene`):

a. its description validates and its world builds;
b. every motion designator type of its vocabulary, performed once
   (:mod:`~pycram.apps.robot_check.motions`);
c. the reach envelope of each arm, from its own IK (:mod:`~pycram.apps.robot_check.reach`);
d. its camera sees a test object into its belief (:mod:`~pycram.apps.robot_check.camera`);
e. each action of the action library (:mod:`~pycram.apps.robot_check.actions`);
f. the set-table scenario on a few development seeds (:mod:`~pycram.apps.robot_check.set_table`),

one row per check (PASS / FAIL / SKIP, why, simulated and wall time: :mod:`~.results`), printed as
a table or written as JSON (:mod:`~.report`). :mod:`~.runner` runs them (`run_robot_check`; the
short form: a-d and one action); :mod:`~.listing` lists the registered robots
(`pycram robot list`). The command line is :mod:`pycram.apps.cli.robot`.
"""

from .listing import RobotRow, robot_rows, robots_table
from .report import report_table, write_json
from .results import FAIL, PASS, SKIP, CheckReport, CheckResult
from .runner import FORMS, run_robot_check

__all__ = [
    "run_robot_check",
    "FORMS",
    "CheckReport",
    "CheckResult",
    "PASS",
    "FAIL",
    "SKIP",
    "report_table",
    "write_json",
    "RobotRow",
    "robot_rows",
    "robots_table",
]
