"""Execution traces: every run recorded in a database, and pictures of plans.

`import pycram.trace` is cheap: SQLAlchemy and matplotlib are imported only when a recorder
starts, a query runs or a picture is drawn (the `db` extra).

- `Recorder` / `start_recording(url=None, plan=None, robot=None)` (`pycram.trace.recorder`):
  record the task tree, performed designators, process-module executions and watched fluents
  of a run; `recording_enabled(default)` reads `$PYCRAM_RECORD`; `watch(fluent, name)` records a
  fluent in every active recorder (no-op when nothing records).
- `pycram.trace.query`: runs, tasks, failures (each counted once, where it was raised) and
  durations across runs; the process-module executions of a task tree.
- `pycram.trace.pictures`: task-tree SVG, timeline (Gantt) PNG, `write_run_pictures`.
- `pycram.trace.db`: URLs (`$PYCRAM_DB_URL`, default SQLite file), schema, `TraceDatabaseError`.

May import: every layer above (core to robots); in practice the core's runtime and events only.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "Recorder",
    "start_recording",
    "recording_enabled",
    "watch",
    "active_recorders",
    "TraceDatabaseError",
    "default_url",
    "write_run_pictures",
]

_LAZY = {
    "Recorder": "pycram.trace.recorder",
    "start_recording": "pycram.trace.recorder",
    "recording_enabled": "pycram.trace.recorder",
    "watch": "pycram.trace.recorder",
    "active_recorders": "pycram.trace.recorder",
    "TraceDatabaseError": "pycram.trace.db",
    "default_url": "pycram.trace.db",
    "write_run_pictures": "pycram.trace.pictures",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'pycram.trace' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_LAZY))
