"""The run recorder: stores a run's task tree, performed designators, process-module
executions and sampled fluents in a database, without ever making a plan wait for it.

    recorder = Recorder(plan="fetch and place").start()   # or start_recording(...)
    recorder.watch(robot_pose, "robot pose", max_rate_hz=5)
    ...run the plan...
    run_id = recorder.finish("succeeded")

Guarantees
----------
- Every callback that runs in a plan thread (`task_started`, `task_ended`, the event
  subscribers, the fluent samplers) is O(1) and never blocks on the database: it appends a
  tuple to an unbounded queue. A background writer thread turns the queue into rows and commits
  a batch every `flush_interval` seconds (0.5 s by default) — so a process killed with SIGKILL
  loses at most the last batch window (SQLite: WAL mode).
- `start()` connects synchronously and raises `TraceDatabaseError` for unusable databases, so
  a bad URL is reported before the plan runs.
- `finish()` stops listening, writes everything queued, records the outcome and returns the
  run id. It is idempotent and also runs at interpreter exit for recorders never finished.
- Fluents are observed through a child fluent that the watched fluent pulses (no polling);
  samples are rate limited per fluent to `max_rate_hz`; the last value of a burst is written
  once its window passed (so the final value is never lost).
- Database errors in the writer are logged, never raised into the plan. A batch that cannot
  be written is kept and retried with the next one (a restarted server loses nothing); rows
  are dropped only beyond `BACKLOG_LIMIT`, or when the last attempt in `finish()` fails.
  `lost_records` counts the dropped rows, `write_errors` the failed attempts, `last_error`
  says why; `finish()` logs a warning naming the count, and the run row keeps it (when the
  final write succeeded) in `lost_records`.
- Each task row says where its error originated (`error_origin`: the task id of the deepest
  task that ended with the very same exception object; its own id where it was raised), so
  a failure re-raised by enclosing tasks is counted once (`query.failed_tasks`).
- The run row's `clock` names the kind of the clock ("simulated", "wall-clock") that task and
  execution times were read from (the recorder follows `set_clock`).
- While the run lasts, `last_seen_at` is refreshed at least every `heartbeat_interval` (2 s),
  also when the plan is idle: a run not seen for 10 s reads as "unfinished" (killed).
- `pycram.trace.watch(fluent, name)` adds a fluent to every active recorder (for plan scripts
  run by `pycram run`, which never see the recorder object).
"""

from __future__ import annotations

import atexit
import datetime as _dt
import json
import logging
import os
import queue
import socket
import sys
import threading
import time
import uuid
import weakref
from collections.abc import Iterable
from enum import Enum
from typing import Any, Literal

from pycram.core import events
from pycram.core.fluent import Fluent
from pycram.core.runtime import Task, add_task_listener, current_clock, current_task, remove_task_listener
from pycram.core.runtime.clock import Clock, add_clock_listener, remove_clock_listener

log = logging.getLogger(__name__)

__all__ = [
    "Recorder",
    "start_recording",
    "recording_enabled",
    "watch",
    "active_recorders",
    "error_origin",
    "BACKLOG_LIMIT",
]

_TEXT_LIMIT = 4000
#: Rows kept for a retry while the database fails; older ones are dropped (and counted) beyond.
BACKLOG_LIMIT = 100_000
_current_thread = threading.current_thread


def recording_enabled(default: bool) -> bool:
    """Whether to record: `$PYCRAM_RECORD` ("1"/"0", "true"/"false", "on"/"off") if set, else
    `default` (True for `pycram run` / `pycram demo`, False for library use)."""
    value = os.environ.get("PYCRAM_RECORD")
    if value is None or value.strip() == "":
        return default
    return value.strip().lower() not in ("0", "false", "no", "off")


def _now_utc() -> _dt.datetime:
    return _dt.datetime.now(_dt.UTC)


def _short(text: str, limit: int = _TEXT_LIMIT) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _text(value: Any) -> str | None:
    if value is None:
        return None
    if isinstance(value, Enum):
        value = value.value
    if isinstance(value, str):
        return _short(value)
    try:
        return _short(repr(value))
    except Exception as e:  # a broken __repr__ must not stop the writer
        return f"<unrepresentable {type(value).__name__}: {type(e).__name__}>"


def _number(value: Any) -> float | None:
    if isinstance(value, Enum):
        value = value.value
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, (int, float)):
        return float(value)
    return None


def _error_fields(error: BaseException | None) -> tuple[str | None, str | None]:
    if error is None:
        return None, None
    try:
        message = str(error)
    except Exception:
        message = ""
    return type(error).__name__, _short(message)


def error_origin(task: Task) -> int | None:
    """The id of the task in which the exception that ended `task` was raised: follow the
    children that ended with the very same exception object (a failure re-raised by a `seq`,
    a `par`, a `try_in_order` or a plain `raise errors[0]`) down to the deepest one. None for a
    task without exception."""
    exception = task.exception
    if exception is None:
        return None
    node = task
    while True:
        for child in reversed(list(node.children)):
            if child.exception is exception:
                node = child
                break
        else:
            return node.id


def _designator_type(designator: Any) -> str | None:
    try:
        value = designator.prop_value("type")
    except Exception:
        return None
    return None if value is None else _short(str(value), 255)


class _Sampler(Fluent):
    """A child fluent of a watched fluent: its pulse hands the parent's value to the recorder."""

    __slots__ = ("_watch",)
    _watch: _Watch | None  # set by the _Watch that owns it

    def pulse(self) -> None:  # called by the parent's pulse, in the thread that set the value
        watch = self._watch
        if watch is not None:
            watch.sample()

    def get_value(self) -> Any:
        return None


class _Watch:
    """Rate-limited sampling of one fluent (see the module guarantees)."""

    def __init__(self, recorder: Recorder, fluent: Fluent, name: str, max_rate_hz: float | None) -> None:
        self.recorder = recorder
        self.fluent = fluent
        self.name = name
        self.min_interval = 0.0 if not max_rate_hz or max_rate_hz <= 0 else 1.0 / max_rate_hz
        self.last_emit = -1e18  # time.monotonic() of the last enqueued sample
        self.pending: tuple[Any, float] | None = None  # (value, clock time) held back by the limit
        self.lock = threading.Lock()
        self.sampler = _Sampler(name=f"recorder sampler of {name}")
        self.sampler._watch = self
        self.active = True

    def sample(self) -> None:
        if not self.active:
            return
        value = self.fluent.get_value()
        t = current_clock().now()
        now = time.monotonic()
        with self.lock:
            if now - self.last_emit >= self.min_interval:
                self.last_emit = now
                self.pending = None
                self.recorder._put(("f", self.name, value, t))
            else:
                self.pending = (value, t)
                self.recorder._pending_watches = True

    def due(self, now: float, force: bool = False) -> tuple[Any, float] | None:
        """The held-back sample if its window passed (or `force`); clears it."""
        with self.lock:
            if self.pending is None or (not force and now - self.last_emit < self.min_interval):
                return None
            pending, self.pending = self.pending, None
            self.last_emit = now
            return pending


class Recorder:
    """Records one run into the trace database (see the module docstring).

    `url`: any SQLAlchemy URL (None: `$PYCRAM_DB_URL` or the default SQLite file).
    `plan`, `robot`: run metadata (also settable later with `set_run_info`).
    `scope`: record only tasks below this task (default: every task of the process).
    `flush_interval`: seconds between batched commits (bounds what a SIGKILL loses).
    `fluent_rate_hz`: default sampling limit of `watch` (None or 0: every change).
    `heartbeat_interval`: an idle run still updates `last_seen_at` this often [s], so readers
    can tell a quiet running plan (state "running") from a killed one ("unfinished").
    """

    def __init__(
        self,
        url: str | None = None,
        *,
        plan: str | None = None,
        robot: str | None = None,
        scope: Task | None = None,
        flush_interval: float = 0.5,
        command: str | None = None,
        info: dict[str, Any] | None = None,
        fluent_rate_hz: float | None = 10.0,
        heartbeat_interval: float = 2.0,
    ) -> None:
        from pycram.trace.db import resolve_url

        self.url = resolve_url(url)
        self.plan = plan
        self.robot = robot
        self.scope = scope
        self.flush_interval = float(flush_interval)
        self.fluent_rate_hz = fluent_rate_hz
        self.heartbeat_interval = float(heartbeat_interval)
        self.command = command if command is not None else " ".join(sys.argv)
        self.info: dict[str, Any] = dict(info or {})
        self.run_id: int | None = None
        self.run_uuid = str(uuid.uuid4())
        self.outcome: str | None = None
        self._queue: queue.SimpleQueue[tuple[Any, ...] | Task] = queue.SimpleQueue()  # a task: started/ended
        self._put = self._queue.put
        # TaskListener methods: O(1), never block, no Python-level frame (see the writer)
        self.task_started = self._queue.put
        self.task_ended = self._queue.put
        self._wake = threading.Event()
        self._watches: dict[str, _Watch] = {}
        self._pending_watches = False
        self._writer: threading.Thread | None = None
        self._engine: Any = None
        self._unsubscribe: list[Any] = []
        self._started_wall = 0.0
        self._finished = False
        self._lock = threading.Lock()
        #: Failed attempts to write a batch (each is retried with the next one).
        self.write_errors = 0
        #: Trace rows given up (see the module guarantees); final once `finish()` returned.
        self.lost_records = 0
        #: Why the last write failed (the driver's first line), None if none failed.
        self.last_error: str | None = None

    # -- life cycle -------------------------------------------------------------------------------

    def start(self) -> Recorder:
        """Connect, create the schema if needed, insert the run row, start listening.

        Raises `TraceDatabaseError` if the database cannot be used. Returns self.
        """
        from sqlalchemy import exc as sa_exc

        from pycram.trace.db import connect, database_error, runs_table

        if self._engine is not None:
            return self
        engine = connect(self.url)
        self._started_wall = time.monotonic()
        clock = current_clock()
        self.clock_origin = clock.now()
        now = _now_utc()
        try:
            with engine.begin() as conn:
                result = conn.execute(
                    runs_table.insert().values(
                        uuid=self.run_uuid,
                        plan=_short(self.plan or "", 255) or None,
                        robot=self.robot,
                        host=_short(socket.gethostname(), 255),
                        pid=os.getpid(),
                        command=_short(self.command),
                        started_at=now,
                        last_seen_at=now,
                        clock_origin=self.clock_origin,
                        info=json.dumps(self.info, default=str) if self.info else None,
                    )
                )
                key = result.inserted_primary_key
                assert key is not None  # set by a single-row INSERT
                self.run_id = int(key[0])
        except sa_exc.SQLAlchemyError as e:  # e.g. a read-only file: say so before the plan runs
            engine.dispose()
            raise database_error(engine.url, e, "write to") from None
        self._engine = engine
        self._put(("clock", clock.kind))
        add_clock_listener(self._on_clock)
        self._writer = threading.Thread(target=self._writer_main, name=f"pycram-recorder-{self.run_id}", daemon=True)
        self._writer.start()
        add_task_listener(self)
        self._unsubscribe = [
            events.subscribe(events.DESIGNATOR_PERFORMED, self._on_designator),
            events.subscribe(events.PROCESS_MODULE_EXECUTED, self._on_execution),
        ]
        _live_recorders.add(self)
        log.info("recording run %s into %s", self.run_id, _display(self.url))
        return self

    def set_run_info(self, plan: str | None = None, robot: str | None = None, **info: Any) -> None:
        """Update the run's metadata (written with the next batch); None leaves a field as is."""
        if plan is not None:
            self.plan = plan
        if robot is not None:
            self.robot = robot
        self.info.update(info)
        self._put(("r", self.plan, self.robot, dict(self.info)))

    def watch(
        self, fluent: Fluent, name: str | None = None, max_rate_hz: float | None | Literal["default"] = "default"
    ) -> None:
        """Sample `fluent` under `name` (default: the fluent's name) whenever it is set, at most
        `max_rate_hz` times per second ("default": the recorder's `fluent_rate_hz`; None or 0:
        every change). The current value is recorded at once. O(1) per change, no thread.

        Raises ValueError if a different fluent is already watched under `name`.
        """
        if max_rate_hz == "default":
            max_rate_hz = self.fluent_rate_hz
        name = name or fluent.name
        existing = self._watches.get(name)
        if existing is not None:
            if existing.fluent is fluent:
                return
            raise ValueError(f"a fluent is already watched as {name!r}; choose another name")
        watch = _Watch(self, fluent, name, max_rate_hz)
        self._watches[name] = watch
        fluent.add_child(watch.sampler)  # held weakly by the fluent, strongly by the watch
        watch.sample()

    def unwatch(self, name: str) -> None:
        """Stop sampling the fluent watched as `name` (its held-back sample is written)."""
        watch = self._watches.pop(name, None)
        if watch is not None:
            self._flush_watch(watch, force=True)
            watch.active = False

    def flush(self, timeout: float | None = 10.0) -> bool:
        """Block until everything recorded so far is committed; False on timeout."""
        if self._writer is None or not self._writer.is_alive():
            return False
        for watch in list(self._watches.values()):
            self._flush_watch(watch, force=True)
        done = threading.Event()
        self._put(("flush", done))
        self._wake.set()
        return done.wait(timeout)

    def finish(self, outcome: str | None = None, error: BaseException | str | None = None) -> int | None:
        """Stop recording, write everything, record `outcome` ("succeeded", "failed", ...; None:
        "finished") and the wall-clock duration; return the run id. Idempotent."""
        with self._lock:
            if self._finished or self._engine is None:
                return self.run_id
            self._finished = True
        remove_task_listener(self)
        remove_clock_listener(self._on_clock)
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        for watch in list(self._watches.values()):
            self._flush_watch(watch, force=True)
            watch.active = False
        self.outcome = outcome or "finished"
        duration = time.monotonic() - self._started_wall
        if isinstance(error, BaseException):
            error = f"{type(error).__name__}: {error}"
        self._put(("end", self.outcome, duration, _short(error) if error else None))
        self._put(("stop",))
        self._wake.set()
        if self._writer is not None:
            self._writer.join(60.0)
            if self._writer.is_alive():
                log.warning("trace writer of run %s did not finish within 60 s", self.run_id)
        _live_recorders.discard(self)
        try:
            self._engine.dispose()
        except Exception as e:  # a broken connection must not turn the run into a failure
            log.debug("disposing the engine of run %s: %s", self.run_id, e)
        if self.lost_records:
            log.warning("run %s: %s (database %s)", self.run_id, self.loss_report(), _display(self.url))
        log.info("run %s recorded (%s, %.2f s)", self.run_id, self.outcome, duration)
        return self.run_id

    def loss_report(self) -> str | None:
        """ "N trace records could not be written: why" once records were lost, else None."""
        if not self.lost_records:
            return None
        records = "1 trace record" if self.lost_records == 1 else f"{self.lost_records} trace records"
        return f"{records} could not be written: {self.last_error or 'unknown error'}"

    def __enter__(self) -> Recorder:
        return self.start()

    def __exit__(self, exc_type: type | None, exc: BaseException | None, tb: Any) -> Literal[False]:
        self.finish("succeeded" if exc is None else "failed", exc)
        return False

    # -- callbacks in plan threads (O(1), never block) ------------------------------------------

    # `task_started` / `task_ended` are the queue's own `put` (set in __init__): no Python frame
    # per call. A task is enqueued itself (not in a tuple); the writer upserts its current state.

    def _on_designator(self, designator: Any, solution: Any = None, error: BaseException | None = None) -> None:
        self._put(("d", current_task(), current_clock().now(), designator, solution, error))

    def _on_execution(
        self,
        module: Any,
        designator: Any,
        outcome: Any,
        start: float | None,
        end: float | None,
        error: BaseException | None = None,
    ) -> None:
        self._put(("x", current_task(), module, designator, outcome, start, end, error))

    def _on_clock(self, clock: Clock) -> None:
        # queued in order with the task events: the writer knows which clock each one read
        self._put(("clock", clock.kind))

    # -- writer thread ----------------------------------------------------------------------------

    def _flush_watch(self, watch: _Watch, force: bool) -> None:
        pending = watch.due(time.monotonic(), force)
        if pending is not None:
            self._put(("f", watch.name, pending[0], pending[1]))

    def _writer_main(self) -> None:
        state = _WriterState(self)
        stop = False
        while not stop:
            timeout = self.flush_interval if self._pending_watches else self.heartbeat_interval
            try:
                first = self._queue.get(timeout=timeout)
                items = [first]
            except queue.Empty:
                items = []
            if items and not (isinstance(first, tuple) and first[0] in ("flush", "stop")):
                self._wake.wait(self.flush_interval)  # collect a batch (cut short by flush/finish)
            self._wake.clear()
            if self._pending_watches:
                self._pending_watches = False
                for watch in list(self._watches.values()):
                    self._flush_watch(watch, force=False)
                    if watch.pending is not None:
                        self._pending_watches = True
            while True:
                try:
                    items.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            controls = [item for item in items if isinstance(item, tuple) and item[0] in ("flush", "stop")]
            flushes = [item[1] for item in controls if item[0] == "flush"]
            stop = any(item[0] == "stop" for item in controls)
            state.add(items)
            try:
                state.commit()
            except Exception as e:  # the database failed: keep the rows for the next attempt
                self._write_failed(e, state)
                if stop:
                    self.lost_records += state.give_up()
            else:
                if self.last_error is not None and self.write_errors and state.failing:
                    log.warning(
                        "trace writer: run %s is written again after %d failed attempts", self.run_id, self.write_errors
                    )
                state.failing = False
            for done in flushes:
                done.set()

    def _write_failed(self, error: Exception, state: _WriterState) -> None:
        from sqlalchemy import exc as sa_exc

        self.write_errors += 1
        text = str(getattr(error, "orig", None) or error).strip()
        self.last_error = text.splitlines()[0] if text else type(error).__name__
        if not isinstance(error, sa_exc.SQLAlchemyError):
            log.exception("trace writer: could not write a batch of run %s", self.run_id)
        elif not state.failing:  # once per streak of failures: the writer retries every batch
            log.warning(
                "trace writer: cannot write to %s (%s); keeping %d rows of run %s for a retry",
                _display(self.url),
                self.last_error,
                state.backlog_size(),
                self.run_id,
            )
        state.failing = True
        self.lost_records += state.trim(BACKLOG_LIMIT)


_TASK_COLUMNS = (
    "run_id",
    "task_id",
    "parent_id",
    "name",
    "kind",
    "path",
    "thread",
    "status",
    "start",
    "end",
    "duration",
    "error_type",
    "error_message",
    "error_origin",
    "location",
)


class _WriterState:
    """Turns queued events into rows and commits them (runs only in the writer thread).

    `add(items)` takes a batch of events; `commit()` writes everything not yet written in one
    transaction -- the rows of earlier batches whose commit failed included -- and raises what
    the database raised (then nothing of it was written, and everything stays pending).
    """

    def __init__(self, recorder: Recorder) -> None:
        self.recorder = recorder
        self.run_id = recorder.run_id
        self.written: set[int] = set()  # task ids inserted
        self.thread_names: dict[int, str] = {}  # thread ident -> name (refreshed per batch)
        self.in_scope: dict[int, bool] = {}
        self.last_heartbeat = time.monotonic()
        self.failing = False  # the last commit failed
        # pending: what the next commit writes
        self.tasks: dict[int, Task] = {}  # tasks that started or ended, first seen first
        self.rows: list[tuple[Any, dict[str, Any]]] = []  # (table, row) of designators, executions, samples
        self.run_update: dict[str, Any] = {}
        # clocks: the kind of the active clock, and the kinds task/execution times were read from
        self.clock_kind: str | None = None
        self.clock_kinds: list[str] = []
        self.clock_written = ""
        dialect = recorder._engine.dialect
        mark = "?" if dialect.paramstyle == "qmark" else "%s"
        q = dialect.identifier_preparer.quote
        self.sql_insert = (
            f"INSERT INTO pycram_tasks ({', '.join(q(c) for c in _TASK_COLUMNS)}) "
            f"VALUES ({', '.join([mark] * len(_TASK_COLUMNS))})"
        )
        self.sql_update = (
            f"UPDATE pycram_tasks SET {', '.join(f'{q(c)} = {mark}' for c in _TASK_COLUMNS[7:])} "
            f"WHERE run_id = {mark} AND task_id = {mark}"
        )

    def _task_row(self, task: Task) -> tuple:
        """The row of `task` in `_TASK_COLUMNS` order (hot path: kept cheap)."""
        parent = task.parent
        status = task.status.get_value().value
        exception = task.exception
        if exception is not None and status != "succeeded":
            error_type, error_message = _error_fields(exception)
            origin = error_origin(task)
        else:
            error_type = error_message = origin = None
        runner = task._runner
        thread = self.thread_names.get(runner.ident) if runner is not None and runner.ident is not None else None
        name = task.name
        start, end = task.start_time, task.end_time
        return (
            self.run_id,
            task.id,
            parent.id if parent is not None else None,
            name if len(name) <= 512 else name[:511] + "…",
            task.kind,
            task.path,
            thread,
            status,
            start,
            end,
            end - start if start is not None and end is not None else None,
            error_type,
            error_message,
            origin,
            task.location,
        )

    def _wanted(self, task: Task) -> bool:
        scope = self.recorder.scope
        if scope is None:
            return True
        chain: list[int] = []
        node: Task | None = task
        answer = False
        while node is not None:
            known = self.in_scope.get(node.id)
            if known is not None:
                answer = known
                break
            chain.append(node.id)
            if node is scope:
                answer = True
                break
            node = node.parent
        for task_id in chain:
            self.in_scope[task_id] = answer
        return answer

    def _saw_clock(self) -> None:
        kind = self.clock_kind
        if kind is not None and kind not in self.clock_kinds:
            self.clock_kinds.append(kind)

    def add(self, items: Iterable[Any]) -> None:
        """Turn a batch of queued events into pending rows (nothing is written yet)."""
        from pycram.trace.db import designators_table, executions_table, fluent_samples_table

        run_id = self.run_id
        tasks, rows = self.tasks, self.rows
        for item in items:
            if not isinstance(item, tuple):
                if item.id not in tasks and self._wanted(item):
                    tasks[item.id] = item
                    self._saw_clock()
                continue
            tag = item[0]
            if tag == "f":
                _, name, value, t = item
                rows.append(
                    (
                        fluent_samples_table,
                        {"run_id": run_id, "name": name, "time": t, "value": _text(value), "number": _number(value)},
                    )
                )
            elif tag == "d":
                _, task, t, designator, solution, error = item
                error_type, error_message = _error_fields(error)
                rows.append(
                    (
                        designators_table,
                        {
                            "run_id": run_id,
                            "task_id": task.id if task is not None else None,
                            "time": t,
                            "designator_class": type(designator).__name__,
                            "designator_type": _designator_type(designator),
                            "designator": _text(designator),
                            "solution": _text(_solution_text(solution)),
                            "error_type": error_type,
                            "error_message": error_message,
                        },
                    )
                )
            elif tag == "x":
                _, task, module, designator, outcome, start, end, error = item
                error_type, error_message = _error_fields(error)
                rows.append(
                    (
                        executions_table,
                        {
                            "run_id": run_id,
                            "task_id": task.id if task is not None else None,
                            "module": _short(str(getattr(module, "name", module)), 255),
                            "designator_type": _designator_type(designator),
                            "designator": _text(designator),
                            "outcome": _text(outcome),
                            "start": start,
                            "end": end,
                            "duration": (end - start) if start is not None and end is not None else None,
                            "error_type": error_type,
                            "error_message": error_message,
                        },
                    )
                )
                self._saw_clock()
            elif tag == "clock":
                self.clock_kind = item[1]
            elif tag == "r":
                _, plan, robot, info = item
                self.run_update.update(
                    plan=_short(plan, 255) if plan else None,
                    robot=robot,
                    info=json.dumps(info, default=str) if info else None,
                )
            elif tag == "end":
                _, outcome, duration, error = item
                self.run_update.update(
                    outcome=outcome,
                    duration=duration,
                    error=error,
                    ended_at=_now_utc(),
                    lost_records=self.recorder.lost_records,
                )

    def commit(self) -> None:
        """Write every pending row in one transaction; raises what the database raised."""
        from pycram.trace.db import runs_table

        self.thread_names = {t.ident: t.name for t in threading.enumerate() if t.ident is not None}
        run_id = self.run_id
        inserts: dict[int, tuple] = {}
        updates: dict[int, tuple] = {}

        def ensure(task: Task) -> None:  # insert the task (and unrecorded ancestors, e.g. thread roots)
            chain = []
            node: Task | None = task
            while node is not None and node.id not in self.written and node.id not in inserts:
                chain.append(node)
                if self.recorder.scope is not None and node is self.recorder.scope:
                    break
                node = node.parent
            for node in reversed(chain):
                inserts[node.id] = self._task_row(node)

        # One row per task per commit, read after the whole batch was taken from the queue: a
        # task's event is queued after its state was set, so the row holds at least that state.
        for task in self.tasks.values():
            if task.id in inserts:
                continue  # inserted as an ancestor of an earlier task, from its current state
            if task.id in self.written:
                updates[task.id] = self._task_row(task)
            else:
                ensure(task)

        clock = "+".join(self.clock_kinds)
        if clock != self.clock_written:
            self.run_update["clock"] = clock
        now = time.monotonic()
        heartbeat_due = now - self.last_heartbeat >= min(1.0, self.recorder.heartbeat_interval)
        if not (inserts or updates or self.rows or self.run_update or heartbeat_due):
            return
        if heartbeat_due or self.run_update:
            self.run_update["last_seen_at"] = _now_utc()
        rows: dict[Any, list[dict[str, Any]]] = {}
        for table, row in self.rows:
            rows.setdefault(table, []).append(row)
        with self.recorder._engine.begin() as conn:
            if inserts:  # plain DB-API executemany: no per-row SQLAlchemy processing
                conn.exec_driver_sql(self.sql_insert, list(inserts.values()))
            if updates:
                conn.exec_driver_sql(self.sql_update, [row[7:] + (run_id, row[1]) for row in updates.values()])
            for table, table_rows in rows.items():
                conn.execute(table.insert(), table_rows)
            if self.run_update:
                conn.execute(runs_table.update().where(runs_table.c.id == run_id).values(**self.run_update))
        self.last_heartbeat = now
        self.written.update(inserts)
        self.clock_written = clock
        self.tasks, self.rows, self.run_update = {}, [], {}

    def backlog_size(self) -> int:
        """How many rows the next commit would write (tasks counted once each)."""
        return len(self.tasks) + len(self.rows) + (1 if set(self.run_update) - {"last_seen_at", "clock"} else 0)

    def trim(self, limit: int) -> int:
        """Drop the oldest pending rows beyond `limit`; returns how many were dropped."""
        excess = len(self.rows) - limit
        if excess <= 0:
            return 0
        del self.rows[:excess]
        return excess

    def give_up(self) -> int:
        """Forget everything pending (the last attempt failed); returns how many rows that was."""
        lost = self.backlog_size()
        self.tasks, self.rows, self.run_update = {}, [], {}
        return lost


def _solution_text(solution: Any) -> Any:
    if callable(solution) and hasattr(solution, "__qualname__"):
        return f"{getattr(solution, '__module__', '')}.{solution.__qualname__}"
    return solution


def _display(url: str) -> str:
    from pycram.trace.db import display_url

    return display_url(url)


_live_recorders: weakref.WeakSet[Recorder] = weakref.WeakSet()


@atexit.register
def _finish_live_recorders() -> None:
    for recorder in list(_live_recorders):
        try:
            recorder.finish("interrupted")
        except Exception:
            log.exception("could not finish recording run %s at exit", recorder.run_id)


def start_recording(
    url: str | None = None, plan: str | None = None, robot: str | None = None, **kwargs: Any
) -> Recorder:
    """Create and start a `Recorder` (see its docstring); raises `TraceDatabaseError`."""
    return Recorder(url, plan=plan, robot=robot, **kwargs).start()


def active_recorders() -> list[Recorder]:
    """The recorders of this process that are started and not finished."""
    return [r for r in list(_live_recorders) if r._engine is not None and not r._finished]


def watch(fluent: Fluent, name: str | None = None, max_rate_hz: float | None | Literal["default"] = "default") -> int:
    """Record `fluent` in every active recorder (see `Recorder.watch`); returns how many.

    For plan scripts run by `pycram run` (recorded by default): `pycram.trace.watch(pose,
    "robot pose", max_rate_hz=5)`. Does nothing (returns 0) when nothing records, so library
    code may call it unconditionally. Raises ValueError like `Recorder.watch`.
    """
    recorders = active_recorders()
    for recorder in recorders:
        recorder.watch(fluent, name, max_rate_hz)
    return len(recorders)
