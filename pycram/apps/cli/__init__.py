"""The `pycram` command line (typer + rich).

    pycram run FILE.py [ARGS...]        run a plan script (block syntax on), recorded by default
    pycram demo [--robot NAME]...       the thesis demo in the simulated kitchen, recorded by default
    pycram scene --env apartment --seed 3 -o scene.png   a labelled picture of a random scene
    pycram runs                         recorded runs, newest first, one line each (with why they failed)
    pycram show [RUN]                   a run's task tree with statuses, durations, failures
    pycram graph [RUN] -o tree.svg      the task tree as an SVG picture
    pycram timeline [RUN] -o tl.png     which branches ran when (Gantt chart)
    pycram replay RUN                   run a recorded run again: "identical" or where it diverged
    pycram view [RUN]                   the run in Rerun's web viewer (tree, statuses, failures; world with --rrd)
    pycram experiment --scenario thesis --robot pr2,tiago --seeds 1-200   many runs in parallel
    pycram robot list                   the registered robots: arms, grippers, base kind, URDF
    pycram robot check NAME [--short]   a conformance run for a robot: a table of what passed, exit 1 on a failure

The database is `--db URL`, else `$PYCRAM_DB_URL`, else the default SQLite file (see
`pycram.trace.db`); a database named with `--db` must exist for the inspecting commands, and
one that cannot be read gives a one-line error and exit code 1. Recording for `run`/`demo` is
on unless `--no-record` or `PYCRAM_RECORD=0`; records the database could not take are counted
and reported at the end of the run (the plan's outcome does not depend on them).
Heavy modules (SQLAlchemy, matplotlib, the simulator) are imported only by the commands that
need them.

One module per group of commands: :mod:`~pycram.apps.cli.app` (the application and what
the commands share), ``traces``, ``run``, ``demo``, ``replay``, ``scenes``, ``ros``, ``experiments``, ``view``,
``robot``.
"""

from __future__ import annotations

import sys

# The command groups register their commands on import, in the order `pycram --help` lists them.
# isort: off
from pycram.apps.cli import traces, run, demo, replay, scenes, ros, experiments, view, robot  # noqa: F401

# isort: on
from pycram.apps.cli.app import app, console, err

__all__ = ["app", "main", "console", "err"]


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `pycram` script. Returns the exit code (also when typer exits)."""
    try:
        app(args=argv, prog_name="pycram", standalone_mode=True)
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
