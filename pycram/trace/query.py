"""Reading recorded runs back: runs, task trees, failures and durations across runs.

    from pycram.trace import query
    for run in query.runs(limit=5): print(run.id, run.plan, run.outcome, run.error)
    failed_grasps = len(query.failed_tasks(error_type="GraspFailed"))   # in all runs, each once
    grasps = query.failed_tasks(name="grab_item")        # the grab_item tasks that raised an error
    seconds = query.durations("perform navigating")       # how long each navigation took
    slips = query.executions(module="gripper", outcome="failed")   # failed gripper motions
    plans = query.designators(designator_type="fetching")  # what each fetch resolved to
    tree = query.task_tree()                              # the newest run's task tree

Every function takes `url=None` (`$PYCRAM_DB_URL` or the default SQLite file) and returns
plain frozen dataclasses, newest run first where runs are listed. Functions that need one run
raise `RunNotFound` (a `LookupError`) with the ids that exist; a database that cannot be read
(unreachable, corrupt, not a trace database) raises `TraceDatabaseError` with a one-line
reason. Engines are cached per URL. Reading never creates a database: a SQLite file that
does not exist reads as an empty trace. Databases written by older versions are read as they
are (new columns read as None) when they cannot be migrated.

Failures are counted once: a failure re-raised by the enclosing tasks (a `seq` step, the `seq`,
a `try_in_order`, ...) fails each of them, but `failed_tasks()` returns only the task where it
was raised (`TaskRecord.error_origin`); `failed_tasks(propagated=True)` returns every task it
failed.
"""

from __future__ import annotations

import datetime as _dt
import json
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import sqlalchemy as sa
from sqlalchemy import exc as sa_exc

from pycram.trace.db import (
    TraceDatabaseError,
    connect,
    database_error,
    designators_table,
    empty_engine,
    executions_table,
    fluent_samples_table,
    present_columns,
    runs_table,
    sqlite_file,
    tasks_table,
)

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

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
    "find_run",
    "tasks",
    "task_tree",
    "failed_tasks",
    "durations",
    "designators",
    "executions",
    "fluent_samples",
    "build_tree",
    "records_from_task",
    "execution_nodes",
    "tree_records",
    "TraceDatabaseError",
]


class RunNotFound(LookupError):
    """No run with the requested id (or no run at all)."""


@overload
def _utc(value: _dt.datetime) -> _dt.datetime: ...
@overload
def _utc(value: None) -> None: ...
@overload
def _utc(value: _dt.datetime | None) -> _dt.datetime | None: ...
def _utc(value: _dt.datetime | None) -> _dt.datetime | None:
    if value is not None and value.tzinfo is None:  # SQLite stores naive datetimes
        value = value.replace(tzinfo=_dt.UTC)
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
    #: Kind of clock the task and execution times were read from: "simulated", "wall-clock"
    #: (or both joined by "+"); None for runs recorded before PyCRAM noted it. `duration`,
    #: `started_at` and `ended_at` are always wall-clock.
    clock: str | None = None
    #: Trace rows that could not be written while the run was recorded (None: not known).
    lost_records: int | None = None

    @property
    def state(self) -> str:
        """The outcome, or "running" (seen within the last 10 s) / "unfinished" (killed)."""
        if self.outcome is not None:
            return self.outcome
        seen = self.last_seen_at or self.started_at
        age = (_dt.datetime.now(_dt.UTC) - seen).total_seconds()
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
    #: task_id of the task the error was raised in (this task's own id if it was raised here);
    #: None without error, and for tasks recorded before PyCRAM noted it.
    error_origin: int | None = None
    #: Where the task's code is (`file.py:line`), when the runtime knows it; None for tasks
    #: recorded before PyCRAM stored it.
    location: str | None = None

    @property
    def failed(self) -> bool:
        return self.status == "failed"

    @property
    def propagated(self) -> bool:
        """True when the error was raised in a descendant (`error_origin`) and only passed
        through this task."""
        return self.error_origin is not None and self.error_origin != self.task_id

    @property
    def error(self) -> str | None:
        """ "Type: message" of the failure, if any."""
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


class _Reading:
    """An engine for reading `url` (an empty one for a SQLite file that does not exist) whose
    SQLAlchemy and driver errors become `TraceDatabaseError` ("cannot read database ...")."""

    def __init__(self, url: str | None) -> None:
        path = sqlite_file(url)
        if path is not None and not path.exists():  # nothing recorded there: read an empty trace
            self.engine = empty_engine()
        else:
            self.engine = connect(url, cached=True)

    def columns(self, table: sa.Table, record: type[DataclassInstance]) -> list[Any]:
        """The columns of `table` in the field order of the dataclass `record`; a column an
        old, unmigrated database lacks reads as NULL."""
        try:
            present = present_columns(self.engine, table)
        except sa_exc.SQLAlchemyError as e:
            raise database_error(self.engine.url, e, "read") from None
        return [
            table.c[name] if name in present else sa.null().label(name)
            for name in record.__dataclass_fields__
            if name in table.c
        ]

    def has(self, column: sa.Column) -> bool:
        """Whether the database has `column` (an old, unmigrated one may lack it)."""
        try:
            return column.name in present_columns(self.engine, column.table)
        except sa_exc.SQLAlchemyError as e:
            raise database_error(self.engine.url, e, "read") from None

    def rows(self, stmt: Any) -> Sequence[Any]:
        try:
            with self.engine.connect() as conn:
                return conn.execute(stmt).all()
        except sa_exc.SQLAlchemyError as e:
            raise database_error(self.engine.url, e, "read") from None

    def records(self, stmt: Any, record: type) -> list[Any]:
        """Run `stmt` (selecting `columns(..., record)`) and build one `record` per row."""
        return [record(*row) for row in self.rows(stmt)]


def _run_info(row: Any) -> RunInfo:
    m = row._mapping
    try:
        info = json.loads(m["info"]) if m["info"] else {}
    except ValueError:
        info = {}
    return RunInfo(
        id=m["id"],
        uuid=m["uuid"],
        plan=m["plan"],
        robot=m["robot"],
        host=m["host"],
        pid=m["pid"],
        command=m["command"],
        started_at=_utc(m["started_at"]),
        ended_at=_utc(m["ended_at"]),
        last_seen_at=_utc(m["last_seen_at"]),
        outcome=m["outcome"],
        duration=m["duration"],
        clock_origin=m["clock_origin"],
        error=m["error"],
        info=info,
        clock=m["clock"],
        lost_records=m["lost_records"],
    )


def runs(url: str | None = None, limit: int | None = None, plan: str | None = None) -> list[RunInfo]:
    """Recorded runs, newest first; `plan` filters by a case-insensitive substring."""
    db = _Reading(url)
    stmt = sa.select(*db.columns(runs_table, RunInfo)).order_by(runs_table.c.id.desc())
    if plan:
        stmt = stmt.where(runs_table.c.plan.ilike(f"%{plan}%"))
    if limit is not None:
        stmt = stmt.limit(limit)
    return [_run_info(row) for row in db.rows(stmt)]


def get_run(run_id: int | None = None, url: str | None = None) -> RunInfo:
    """The run `run_id`, or the newest run when None. Raises `RunNotFound`."""
    db = _Reading(url)
    stmt = sa.select(*db.columns(runs_table, RunInfo))
    stmt = (
        stmt.where(runs_table.c.id == run_id) if run_id is not None else stmt.order_by(runs_table.c.id.desc()).limit(1)
    )
    found = db.rows(stmt)
    if not found:
        if run_id is None:
            raise RunNotFound("no run has been recorded in this database yet")
        newest = db.rows(sa.select(sa.func.min(runs_table.c.id), sa.func.max(runs_table.c.id)))
        known = f"runs {newest[0][0]}..{newest[0][1]} exist" if newest and newest[0][0] is not None else "no runs exist"
        raise RunNotFound(f"no run {run_id} in this database ({known})")
    return _run_info(found[0])


def find_run(run: str | int | None, url: str | None = None) -> RunInfo:
    """The run named by `run`: its id (an int or a string of digits), its uuid or a unique
    prefix of at least 4 characters of it, or the newest run when None. Raises `RunNotFound`
    (also for a prefix that several runs share)."""
    if run is None or isinstance(run, int):
        return get_run(run, url)
    text = str(run).strip()
    if text.isdigit():
        return get_run(int(text), url)
    if len(text) < 4:
        raise RunNotFound(f"no run {text!r}: give a run id or (a prefix of at least 4 characters of) a uuid")
    db = _Reading(url)
    stmt = sa.select(*db.columns(runs_table, RunInfo)).where(runs_table.c.uuid.like(f"{text}%")).limit(2)
    found = db.rows(stmt)
    if not found:
        raise RunNotFound(f"no run with uuid {text!r} in this database")
    if len(found) > 1:
        raise RunNotFound(f"several runs have a uuid starting with {text!r}: give more of it")
    return _run_info(found[0])


def tasks(run_id: int, url: str | None = None) -> list[TaskRecord]:
    """The tasks of run `run_id` in creation order (empty if it has none)."""
    db = _Reading(url)
    stmt = (
        sa.select(*db.columns(tasks_table, TaskRecord))
        .where(tasks_table.c.run_id == run_id)
        .order_by(tasks_table.c.task_id)
    )
    return db.records(stmt, TaskRecord)


def build_tree(records: Iterable[TaskRecord]) -> list[TaskNode]:
    """Task records linked into trees; returns the roots (tasks whose parent is not recorded).

    Children are in creation order; execution records (`execution_nodes`, negative ids) are
    placed among their siblings by start time.
    """
    nodes = {r.task_id: TaskNode(r) for r in records}
    roots: list[TaskNode] = []
    mixed: dict[int, TaskNode] = {}  # parents of execution records
    for node in nodes.values():
        parent = nodes.get(node.record.parent_id) if node.record.parent_id is not None else None
        (parent.children if parent is not None else roots).append(node)
        if node.record.task_id < 0 and parent is not None:
            mixed[parent.record.task_id] = parent
    for parent in mixed.values():
        parent.children = _by_start(parent.children)
    return roots


def _by_start(children: list[TaskNode]) -> list[TaskNode]:
    """Tasks in creation order, each execution record before the first task that started
    after it (executions without start time last)."""
    tasks_ = [c for c in children if c.record.task_id >= 0]
    executions_ = sorted(
        (c for c in children if c.record.task_id < 0),
        key=lambda c: (c.record.start is None, c.record.start or 0.0, -c.record.task_id),
    )
    out: list[TaskNode] = []
    i = 0
    for task in tasks_:
        start = task.record.start
        while (
            i < len(executions_)
            and start is not None
            and (execution_start := executions_[i].record.start) is not None
            and execution_start < start
        ):
            out.append(executions_[i])
            i += 1
        out.append(task)
    out.extend(executions_[i:])
    return out


#: What an execution's outcome reads as in a task tree.
_EXECUTION_STATUS = {"succeeded": "succeeded", "failed": "failed", "cancelled": "evaporated"}


def execution_nodes(records: Sequence[TaskRecord], executions_: Iterable[ExecutionRecord]) -> list[TaskRecord]:
    """Task-tree records (kind "process-module", negative `task_id`) for the process-module
    executions that are not a task of their own: the blocking ones, which run in the thread
    of the task that performed them and so appear only in the executions table. Each becomes
    a child of that task, named "module: designator type" like a non-blocking execution's task."""
    kinds = {r.task_id: (r.kind, r.name) for r in records}
    out: list[TaskRecord] = []
    for x in executions_:
        name = f"{x.module}: {x.designator_type}" if x.designator_type else str(x.module)
        if x.task_id is not None and kinds.get(x.task_id) == ("process-module", name):
            continue  # a non-blocking execution: its own task already stands for it
        status = _EXECUTION_STATUS.get(x.outcome or "", x.outcome or "unknown")
        out.append(
            TaskRecord(
                run_id=x.run_id,
                task_id=-(len(out) + 1),
                parent_id=x.task_id,
                name=name,
                kind="process-module",
                path=None,
                thread=None,
                status=status,
                start=x.start,
                end=x.end,
                duration=x.duration,
                error_type=x.error_type if status != "succeeded" else None,
                error_message=x.error_message if status != "succeeded" else None,
                error_origin=-(len(out) + 1) if x.error_type and status != "succeeded" else None,
            )
        )
    return out


def tree_records(run_id: int, url: str | None = None) -> tuple[list[TaskRecord], list[TaskRecord]]:
    """The task records of run `run_id` and the records of its process-module executions that
    are not tasks (`execution_nodes`); `build_tree(tasks + executions)` is the whole tree."""
    task_records = tasks(run_id, url)
    return task_records, execution_nodes(task_records, executions(run_id, url=url))


def task_tree(run_id: int | None = None, url: str | None = None) -> list[TaskNode]:
    """The task tree(s) of a run (newest when None): one root per thread that started tasks."""
    run = get_run(run_id, url)
    return build_tree(tasks(run.id, url))


def records_from_task(task: Any, run_id: int = 0) -> list[TaskRecord]:
    """Task records of an in-memory `pycram.runtime.Task` and its descendants (no database)."""
    from pycram.trace.recorder import error_origin

    records = []
    for node in task.walk():
        status = node.status.get_value()
        error = node.exception if status.value != "succeeded" else None
        records.append(
            TaskRecord(
                run_id=run_id,
                task_id=node.id,
                parent_id=node.parent.id if node.parent is not None and node is not task else None,
                name=str(node.name),
                kind=node.kind,
                path=node.path,
                thread=None,
                status=status.value,
                start=node.start_time,
                end=node.end_time,
                duration=node.duration,
                error_type=type(error).__name__ if error is not None else None,
                error_message=str(error) if error is not None else None,
                error_origin=error_origin(node) if error is not None else None,
                location=node.location,
            )
        )
    return records


def failed_tasks(
    name: str | None = None,
    kind: str | None = None,
    error_type: str | None = None,
    run_id: int | None = None,
    url: str | None = None,
    propagated: bool = False,
) -> list[TaskRecord]:
    """Failed tasks across all runs (or one), newest run first -- each failure once.

    A failure re-raised by enclosing tasks fails each of them; by default only the task where
    it was raised is returned (`TaskRecord.error_origin`), so
    `len(failed_tasks(error_type="GraspFailed"))` is how many grasps failed in all runs.
    `propagated=True` also returns the tasks it only passed through. For runs recorded
    before the origin was noted, a failed task counts as the origin unless one of its
    children failed with the same error type and message.

    `name` and `error_type` match case-insensitive substrings (`failed_tasks(name="grab")`);
    `kind` matches exactly (e.g. "action", "step", "branch", "plan").
    """
    db = _Reading(url)
    t = tasks_table.c
    stmt = sa.select(*db.columns(tasks_table, TaskRecord)).where(t.status == "failed")
    if name:
        stmt = stmt.where(t.name.ilike(f"%{name}%"))
    if kind:
        stmt = stmt.where(t.kind == kind)
    if error_type:
        stmt = stmt.where(t.error_type.ilike(f"%{error_type}%"))
    if run_id is not None:
        stmt = stmt.where(t.run_id == run_id)
    if not propagated:
        child = tasks_table.alias("child")
        passed_on = sa.exists().where(
            child.c.run_id == t.run_id,
            child.c.parent_id == t.task_id,
            child.c.status == "failed",
            child.c.error_type == t.error_type,
            sa.or_(
                child.c.error_message == t.error_message,
                sa.and_(child.c.error_message.is_(None), t.error_message.is_(None)),
            ),
        )
        if db.has(t.error_origin):
            stmt = stmt.where(sa.or_(t.error_origin == t.task_id, sa.and_(t.error_origin.is_(None), ~passed_on)))
        else:
            stmt = stmt.where(~passed_on)
    stmt = stmt.order_by(t.run_id.desc(), t.task_id)
    return db.records(stmt, TaskRecord)


def durations(
    name: str,
    kind: str | None = None,
    status: str | None = None,
    exact: bool = True,
    run_id: int | None = None,
    url: str | None = None,
) -> list[float]:
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
    return [row[0] for row in _Reading(url).rows(stmt)]


def designators(
    run_id: int | None = None, designator_type: str | None = None, url: str | None = None
) -> list[DesignatorRecord]:
    """Designators performed (in one run or all), with the solutions they resolved to."""
    db = _Reading(url)
    d = designators_table.c
    stmt = sa.select(*db.columns(designators_table, DesignatorRecord)).order_by(d.run_id, d.id)
    if run_id is not None:
        stmt = stmt.where(d.run_id == run_id)
    if designator_type:
        stmt = stmt.where(d.designator_type == designator_type)
    return db.records(stmt, DesignatorRecord)


def executions(
    run_id: int | None = None,
    module: str | None = None,
    outcome: str | None = None,
    designator_type: str | None = None,
    url: str | None = None,
) -> list[ExecutionRecord]:
    """Process-module executions (in one run or all), optionally filtered."""
    db = _Reading(url)
    x = executions_table.c
    stmt = sa.select(*db.columns(executions_table, ExecutionRecord)).order_by(x.run_id, x.id)
    if run_id is not None:
        stmt = stmt.where(x.run_id == run_id)
    if module:
        stmt = stmt.where(x.module == module)
    if outcome:
        stmt = stmt.where(x.outcome == outcome)
    if designator_type:
        stmt = stmt.where(x.designator_type == designator_type)
    return db.records(stmt, ExecutionRecord)


def fluent_samples(run_id: int, name: str | None = None, url: str | None = None) -> list[FluentSample]:
    """Samples of the watched fluents of a run (one name or all), in time order."""
    db = _Reading(url)
    f = fluent_samples_table.c
    stmt = sa.select(*db.columns(fluent_samples_table, FluentSample)).where(f.run_id == run_id).order_by(f.id)
    if name:
        stmt = stmt.where(f.name == name)
    return db.records(stmt, FluentSample)
