"""The view of a recorded run rebuilt from the trace database (no simulator, no ``.rrd``).

`recording_from_database(run_id, path, url=None)` writes an ``.rrd`` recording of run `run_id`
holding what the database has: the task tree with each task's status over time
(``tree/status``: one row per status change, at the simulated time it happened; ``tree/graph``;
``plan/current``), the failures where they were raised with their typed reason
(``tree/failures``), the process-module executions and performed designators as a text log
(``log``), the watched fluents as time series (``fluents/NAME``, those with numbers) and a
summary of the run (``run``). `pycram view RUN` serves it, with the run's own ``.rrd`` (the
world, the belief, the camera) when there is one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import paths

__all__ = ["recording_from_database", "DatabaseView"]


@dataclass(frozen=True)
class DatabaseView:
    """What `recording_from_database` wrote: the file, the run, how many task-status changes,
    failures, executions and designators it logged."""

    path: Path
    run_id: int
    status_changes: int
    failures: int
    executions: int
    designators: int


def recording_from_database(
    run_id: int,
    path: str | Path,
    url: str | None = None,
    *,
    recording_id: str | None = None,
    tree: bool = True,
) -> DatabaseView:
    """Write the view of run `run_id` of the trace database `url` (None: the default) to the
    ``.rrd`` file `path` (see the module docstring). `recording_id`: the recording's id (the
    viewer merges recordings with one id: give the run's ``.rrd``'s to show both as one);
    `tree`: with False, the task tree is left out (the run's ``.rrd`` has it already). Raises
    `RunNotFound` for an unknown run, `TraceDatabaseError` for an unusable database."""
    import rerun as rr

    from pycram.trace import query

    from .blueprint import default_blueprint
    from .tree import TreeLog

    run = query.get_run(run_id, url)
    records = query.tasks(run.id, url)
    executions = query.executions(run.id, url=url)
    designators = query.designators(run.id, url=url)
    samples = query.fluent_samples(run.id, url=url)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    rec = rr.RecordingStream(paths.APPLICATION_ID, recording_id=recording_id or f"pycram-run-{run.uuid}")
    rec.set_sinks(rr.FileSink(str(path)))
    rec.send_recording_name(f"run {run.id}: {run.plan or 'plan'} (from the trace database)")
    rec.send_blueprint(default_blueprint())
    started = run.started_at.timestamp()
    origin = run.clock_origin or 0.0

    def at(t: float) -> None:
        rec.set_time(paths.SIM_TIMELINE, duration=float(t))
        rec.set_time(paths.WALL_TIMELINE, timestamp=started + max(0.0, float(t) - origin))

    summary = [
        f"**run {run.id}** ({run.uuid})  ",
        f"plan: {run.plan or '-'}  ",
        f"robot: {run.robot or '-'}  ",
        f"outcome: {run.state}  ",
        f"started: {run.started_at.isoformat(timespec='seconds')}  ",
        f"clock: {run.clock or '-'}  ",
    ]
    if run.error:
        summary.append(f"error: {run.error}")
    rec.log(paths.RUN, rr.TextDocument("\n".join(summary), media_type="text/markdown"), static=True)
    # every event at its time, in time order (ties: the order the database has them)
    events: list[tuple[float, int, str, Any]] = []
    for i, r in enumerate(records):
        if r.start is not None:
            events.append((r.start, 2 * i, "running", r))
        if r.end is not None:
            events.append((r.end, 2 * i + 1, "ended", r))
    offset = 2 * len(records)
    for i, x in enumerate(executions):
        when = x.end if x.end is not None else x.start
        if when is not None:
            events.append((when, offset + i, "execution", x))
    offset += len(executions)
    for i, d in enumerate(designators):
        if d.time is not None:
            events.append((d.time, offset + i, "designator", d))
    offset += len(designators)
    for i, s in enumerate(samples):
        if s.time is not None and s.number is not None:
            events.append((s.time, offset + i, "fluent", s))
    events.sort(key=lambda e: (e[0], e[1]))
    log = TreeLog(rec)
    failures = changes = 0
    for t, _, kind, item in events:
        at(t)
        if kind in ("running", "ended"):
            if not tree:
                continue
            status = "running" if kind == "running" else item.status
            error = item.error if kind == "ended" else None
            origin_here = item.error_origin == item.task_id if item.error_origin is not None else True
            wall = started + max(0.0, float(t) - origin)
            log.change(
                t, wall, item.task_id, item.parent_id, item.name, item.kind, item.path, status, error, origin_here
            )
            changes += 1
            if error and origin_here and status == "failed":
                failures += 1
            log.log_current()
            log.log_graph(t)
        elif kind == "execution":
            level = "INFO" if item.outcome == "succeeded" else "WARN"
            reason = f" -- {item.error_type}: {item.error_message}" if item.error_type else ""
            rec.log(paths.LOG, rr.TextLog(f"{item.module}: {item.designator_type} {item.outcome}{reason}", level=level))
        elif kind == "designator":
            reason = f" -- {item.error_type}: {item.error_message}" if item.error_type else ""
            text = f"performed {item.designator_class} {item.designator_type or ''}{reason}"
            rec.log(paths.LOG, rr.TextLog(text, level="ERROR" if item.error_type else "DEBUG"))
        else:
            from rerun import escape_entity_path_part as esc

            rec.log(f"fluents/{esc(item.name)}", rr.Scalars(item.number))
    log.flush()
    if tree and events:
        log.log_graph(events[-1][0], force=True)
    rec.flush()
    rec.disconnect()
    return DatabaseView(path, run.id, changes, failures, len(executions), len(designators))
