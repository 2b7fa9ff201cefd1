"""A run's view in Rerun: the world, the belief, the camera, the location reasoning, the task
tree and the log, live while a run goes and afterwards (the ``view`` extra: ``rerun-sdk``).

- `ViewSession` (`pycram.trace.view.session`): logs a run into a recording -- streamed to a
  viewer and/or saved as an ``.rrd`` file.
- `ViewerServer` (`pycram.trace.view.server`): Rerun's web viewer, served from this machine
  (127.0.0.1 unless asked otherwise).
- `recording_from_database` (`pycram.trace.view.from_db`): the view of a recorded run rebuilt
  from the trace database (task tree, statuses, failures, performed designators, log of
  process-module executions).
- `pycram.trace.view.paths`: what a recording holds, and where; `default_blueprint`: its layout.

`import pycram.trace.view` is cheap: Rerun, MuJoCo and SQLAlchemy are imported when used.
The command line: ``pycram demo --view``, ``pycram run FILE --view``, ``--rrd``, ``pycram view
RUN`` (see docs/view.md).
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "ViewSession",
    "ViewerServer",
    "ViewError",
    "recording_from_database",
    "default_blueprint",
    "find_run_folder",
]

_LAZY = {
    "ViewSession": "pycram.trace.view.session",
    "find_run_folder": "pycram.trace.view.session",
    "ViewerServer": "pycram.trace.view.server",
    "ViewError": "pycram.trace.view.server",
    "recording_from_database": "pycram.trace.view.from_db",
    "default_blueprint": "pycram.trace.view.blueprint",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'pycram.trace.view' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_LAZY))
