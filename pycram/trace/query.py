"""Reading recorded runs back: runs, task trees, failures and durations across runs.

    from pycram.trace import query
    for run in query.runs(limit=5): print(run.id, run.plan, run.outcome)
    grasps = query.failed_tasks(name="grasp")            # all failed grasps, every run
    seconds = query.durations("perform navigating")       # how long each navigation took
    slips = query.executions(module="gripper", outcome="failed")   # failed gripper motions
    plans = query.designators(designator_type="fetching")  # what each fetch resolved to
    tree = query.task_tree()                              # the newest run's task tree

Every function takes `url=None` (`$PYCRAM_DB_URL` or the default SQLite file) and returns
plain frozen dataclasses, newest run first where runs are listed. Functions that need one run
raise `RunNotFound` (a `LookupError`) with the ids that exist. Engines are cached per URL.
Reading never creates a database: a SQLite file that does not exist reads as an empty trace.
"""

from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass, field
from typing import Any, Iterable, Iterator

import sqlalchemy as sa

from pycram.trace.db import (TraceDatabaseError, connect, designators_table, empty_engine, executions_table,
                             fluent_samples_table, runs_table, sqlite_file, tasks_table)

__all__ = [
    "RunInfo",
    "TaskRecord",
    "TaskNode",
    "DesignatorRecord",
    "ExecutionRecord",
    "FluentSample",
    "RunNotFound",
    "runs",
    "get_run",
    "tasks",
    "task_tree",
    "failed_tasks",
    "durations",
    "designators",
    "executions",
    "fluent_samples",
    "build_tree",
    "records_from_task",
    "TraceDatabaseError",
]


class RunNotFound(LookupError):
    """No run with the requested id (or no run at all)."""


def _utc(value: _dt.datetime | None) -> _dt.datetime | None:
    if value is not None and value.tzinfo is None:  # SQLite stores naive datetimes
        value = value.replace(tzinfo=_dt.timezone.utc)
    return value


@dataclass(frozen=True)
class RunInfo:
    """One recorded run. `outcome` is None while it runs or if its process was killed; see
    `state` for a display value."""

    id: int
    uuid: str
    plan: str | None
    robot: str | None
    host: str | None
    pid: int | None
    command: str | None
    started_at: _dt.datetime
    ended_at: _dt.datetime | None
    last_seen_at: _dt.datetime | None
    outcome: str | None
    duration: float | None
    clock_origin: float | None
    error: str | None
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def state(self) -> str:
        """The outcome, or "running" (seen within the last 10 s) / "unfinished" (killed)."""
        if self.outcome is not None:
            return self.outcome
        seen = self.last_seen_at or self.started_at
        age = (_dt.datetime.now(_dt.timezone.utc) - seen).total_seconds()
        return "running" if age < 10.0 else "unfinished"

    @property
    def elapsed(self) -> float | None:
        """The duration, or for an unfinished run the time until its last committed batch [s]."""
        if self.duration is not None:
            return self.duration
        if self.last_seen_at is not None:
            return (self.last_seen_at - self.started_at).total_seconds()
        return None


@dataclass(frozen=True)
class TaskRecord:
    """One task of a run. Times are on the run's active clock [s]."""

    run_id: int
    task_id: int
    parent_id: int | None
    name: str
    kind: str | None
    path: str | None
    thread: str | None
    status: str
    start: float | None
    end: float | None
    duration: float | None
    error_type: str | None
    error_message: str | None

    @property
    def failed(self) -> bool:
        return self.status == "failed"

    @property
    def error(self) -> str | None:
        """"Type: message" of the failure, if any."""
        if self.error_type is None:
            return None
        return f"{self.error_type}: {self.error_message}" if self.error_message else self.error_type


@dataclass
class TaskNode:
    """A task record with its children (for trees and pictures)."""

    record: TaskRecord
    children: list[TaskNode] = field(default_factory=list)

    def walk(self) -> Iterator[tuple[TaskNode, int]]:
        """(node, depth) for this node and its descendants, depth first, in creation order."""
        stack: list[tuple[TaskNode, int]] = [(self, 0)]
        while stack:
            node, depth = stack.pop()
            yield node, depth
            stack.extend((child, depth + 1) for child in reversed(node.children))


@dataclass(frozen=True)
class DesignatorRecord:
    run_id: int
    task_id: int | None
    time: float | None
    designator_class: str | None
    designator_type: str | None
    designator: str | None
    solution: str | None
    error_type: str | None
    error_message: str | None


@dataclass(frozen=True)
class ExecutionRecord:
    run_id: int
    task_id: int | None
    module: str | None
    designator_type: str | None
    designator: str | None
    outcome: str | None
    start: float | None
    end: float | None
    duration: float | None
    error_type: str | None
    error_message: str | None


@dataclass(frozen=True)
class FluentSample:
    run_id: int
    name: str
    time: float | None
    value: str | None
    number: float | None


def _engine(url: str | None) -> Any:
    path = sqlite_file(url)
    if path is not None and not path.exists():  # nothing recorded there: read an empty trace
        return empty_engine()
    return connect(url, cached=True)


def _run_info(row: Any) -> RunInfo:
    m = row._mapping
    try:
        info = json.loads(m["info"]) if m["info"] else {}
    except ValueError:
        info = {}
    return RunInfo(
        id=m["id"], uuid=m["uuid"], plan=m["plan"], robot=m["robot"], host=m["host"], pid=m["pid"],
        command=m["command"], started_at=_utc(m["started_at"]), ended_at=_utc(m["ended_at"]),
        last_seen_at=_utc(m["last_seen_at"]), outcome=m["outcome"], duration=m["duration"],
        clock_origin=m["clock_origin"], error=m["error"], info=info)


def _columns(table: sa.Table, record: type) -> list[Any]:
    """The columns of `table` in the field order of the dataclass `record`."""
    return [table.c[name] for name in record.__dataclass_fields__]


def _records(stmt: Any, record: type, url: str | None) -> list[Any]:
    """Run `stmt` (selecting `_columns(..., record)`) and build one `record` per row."""
    with _engine(url).connect() as conn:
        return [record(*row) for row in conn.execute(stmt).all()]


def runs(url: str | None = None, limit: int | None = None, plan: str | None = None) -> list[RunInfo]:
    """Recorded runs, newest first; `plan` filters by a case-insensitive substring."""
    stmt = sa.select(runs_table).order_by(runs_table.c.id.desc())
    if plan:
        stmt = stmt.where(runs_table.c.plan.ilike(f"%{plan}%"))
    if limit is not None:
        stmt = stmt.limit(limit)
    with _engine(url).connect() as conn:
        return [_run_info(row) for row in conn.execute(stmt)]


def get_run(run_id: int | None = None, url: str | None = None) -> RunInfo:
    """The run `run_id`, or the newest run when None. Raises `RunNotFound`."""
    stmt = sa.select(runs_table)
    stmt = stmt.where(runs_table.c.id == run_id) if run_id is not None else stmt.order_by(runs_table.c.id.desc()).limit(1)
    with _engine(url).connect() as conn:
        row = conn.execute(stmt).first()
        if row is None:
            if run_id is None:
                raise RunNotFound("no run has been recorded in this database yet")
            newest = conn.execute(sa.select(sa.func.min(runs_table.c.id), sa.func.max(runs_table.c.id))).first()
            known = f"runs {newest[0]}..{newest[1]} exist" if newest and newest[0] is not None else "no runs exist"
            raise RunNotFound(f"no run {run_id} in this database ({known})")
    return _run_info(row)


def tasks(run_id: int, url: str | None = None) -> list[TaskRecord]:
    """The tasks of run `run_id` in creation order (empty if it has none)."""
    stmt = (sa.select(*_columns(tasks_table, TaskRecord)).where(tasks_table.c.run_id == run_id)
            .order_by(tasks_table.c.task_id))
    return _records(stmt, TaskRecord, url)


def build_tree(records: Iterable[TaskRecord]) -> list[TaskNode]:
    """Task records linked into trees; returns the roots (tasks whose parent is not recorded)."""
    nodes = {r.task_id: TaskNode(r) for r in records}
    roots: list[TaskNode] = []
    for node in nodes.values():
        parent = nodes.get(node.record.parent_id) if node.record.parent_id is not None else None
        (parent.children if parent is not None else roots).append(node)
    return roots


def task_tree(run_id: int | None = None, url: str | None = None) -> list[TaskNode]:
    """The task tree(s) of a run (newest when None): one root per thread that started tasks."""
    run = get_run(run_id, url)
    return build_tree(tasks(run.id, url))


def records_from_task(task: Any, run_id: int = 0) -> list[TaskRecord]:
    """Task records of an in-memory `pycram.runtime.Task` and its descendants (no database)."""
    records = []
    for node in task.walk():
        status = node.status.get_value()
        error = node.exception if status.value != "succeeded" else None
        records.append(TaskRecord(
            run_id=run_id, task_id=node.id, parent_id=node.parent.id if node.parent is not None and node is not task else None,
            name=str(node.name), kind=node.kind, path=node.path, thread=None, status=status.value,
            start=node.start_time, end=node.end_time, duration=node.duration,
            error_type=type(error).__name__ if error is not None else None,
            error_message=str(error) if error is not None else None))
    return records


def failed_tasks(name: str | None = None, kind: str | None = None, error_type: str | None = None,
                 run_id: int | None = None, url: str | None = None) -> list[TaskRecord]:
    """Failed tasks across all runs (or one), newest run first.

    `name` and `error_type` match case-insensitive substrings (`failed_tasks(name="grasp")`:
    all failed grasps); `kind` matches exactly (e.g. "action", "step", "branch").
    """
    t = tasks_table.c
    stmt = sa.select(*_columns(tasks_table, TaskRecord)).where(t.status == "failed")
    if name:
        stmt = stmt.where(t.name.ilike(f"%{name}%"))
    if kind:
        stmt = stmt.where(t.kind == kind)
    if error_type:
        stmt = stmt.where(t.error_type.ilike(f"%{error_type}%"))
    if run_id is not None:
        stmt = stmt.where(t.run_id == run_id)
    stmt = stmt.order_by(t.run_id.desc(), t.task_id)
    return _records(stmt, TaskRecord, url)


def durations(name: str, kind: str | None = None, status: str | None = None, exact: bool = True,
              run_id: int | None = None, url: str | None = None) -> list[float]:
    """Durations [s] of the ended tasks called `name` (a substring if not `exact`), across
    runs (oldest first), optionally only of one `kind` / `status`."""
    t = tasks_table.c
    stmt = sa.select(t.duration).where(t.duration.is_not(None))
    stmt = stmt.where(t.name == name) if exact else stmt.where(t.name.ilike(f"%{name}%"))
    if kind:
        stmt = stmt.where(t.kind == kind)
    if status:
        stmt = stmt.where(t.status == status)
    if run_id is not None:
        stmt = stmt.where(t.run_id == run_id)
    stmt = stmt.order_by(t.run_id, t.task_id)
    with _engine(url).connect() as conn:
        return [row[0] for row in conn.execute(stmt)]


def designators(run_id: int | None = None, designator_type: str | None = None,
                url: str | None = None) -> list[DesignatorRecord]:
    """Designators performed (in one run or all), with the solutions they resolved to."""
    d = designators_table.c
    stmt = sa.select(*_columns(designators_table, DesignatorRecord)).order_by(d.run_id, d.id)
    if run_id is not None:
        stmt = stmt.where(d.run_id == run_id)
    if designator_type:
        stmt = stmt.where(d.designator_type == designator_type)
    return _records(stmt, DesignatorRecord, url)


def executions(run_id: int | None = None, module: str | None = None, outcome: str | None = None,
               designator_type: str | None = None, url: str | None = None) -> list[ExecutionRecord]:
    """Process-module executions (in one run or all), optionally filtered."""
    x = executions_table.c
    stmt = sa.select(*_columns(executions_table, ExecutionRecord)).order_by(x.run_id, x.id)
    if run_id is not None:
        stmt = stmt.where(x.run_id == run_id)
    if module:
        stmt = stmt.where(x.module == module)
    if outcome:
        stmt = stmt.where(x.outcome == outcome)
    if designator_type:
        stmt = stmt.where(x.designator_type == designator_type)
    return _records(stmt, ExecutionRecord, url)


def fluent_samples(run_id: int, name: str | None = None, url: str | None = None) -> list[FluentSample]:
    """Samples of the watched fluents of a run (one name or all), in time order."""
    f = fluent_samples_table.c
    stmt = sa.select(*_columns(fluent_samples_table, FluentSample)).where(f.run_id == run_id).order_by(f.id)
    if name:
        stmt = stmt.where(f.name == name)
    return _records(stmt, FluentSample, url)
