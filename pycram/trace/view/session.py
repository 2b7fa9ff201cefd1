"""A run's view, logged while it runs: `ViewSession`.

    session = ViewSession(rrd=Path("output/run.rrd"), connect=server.grpc_url).start()
    ...run the plan (the session finds the simulated world and the belief by itself)...
    session.close()        # writes everything still queued; the .rrd is complete

What it logs is listed in `pycram.trace.view.paths`. How, so that viewing changes nothing in the
run and costs it little:

- Every hook that runs in a plan thread or in the simulation thread only puts a tuple on a queue
  (O(1), never blocks); the session's own thread hands the queue on, as plain values in
  batches, to a `ViewWriter` in a process of its own (`pycram.trace.view.writer`), which turns
  them into Rerun data -- so the view's work does not hold this process's interpreter lock
  while the run computes (`process=False`, or a process that cannot start: the writer runs in
  the session's thread). No hook changes a value the run reads, so a lock-step run has the
  same fingerprint with a view as without one (`pycram.trace.fingerprint`). A writer that dies
  costs the rest of the recording, never the run.
- The task tree comes from the runtime's task listeners (like the trace recorder); log lines from
  a `logging` record factory (what the run logs at the levels it set, INFO and above).
- The world: once a task starts while a simulated robot is active (`current_robot()`, with a
  ``world`` and a ``belief``) -- or before the plan starts, by `attach_views` --, the session
  attaches to that world: a child fluent of its
  ``sim_time`` (set by the simulation thread at every sensor publication) takes, at most every
  1/`world_rate_hz` s of simulated time (10 Hz by default), the state the simulation thread last
  published (`StateSnapshot`, already a copy) and a snapshot of the belief; a child fluent of
  the belief's ``updated`` takes each look of the camera. The writer computes the bodies' poses
  from the state in its own `MjData` and renders the camera image with its own renderer. The
  location reasoner's latest costmaps (and candidates, where it keeps them) and
  each arm's latest motion plan (the tool path, by forward kinematics in the view's own data)
  are taken at the same ticks.
- Times: the ``sim`` timeline is the run's clock (simulated time in a simulation), ``wall`` the
  wall clock when the event happened.
"""

from __future__ import annotations

import logging
import queue
import shutil
import threading
import time
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pycram.core.fluent import Fluent
from pycram.core.runtime import Task, add_task_listener, current_clock, remove_task_listener

from .writer import FLUSH_TIMEOUT, TRANSFORM_BATCH, ViewWriter, costmap_data, read_message, send_message

__all__ = [
    "ViewSession",
    "DEFAULT_WORLD_RATE",
    "FLUSH_TIMEOUT",
    "TRANSFORM_BATCH",
    "find_run_folder",
    "attach_views",
    "viewed_run",
    "VIEW_CONNECT_ENV",
    "VIEW_RUN_ENV",
]

log = logging.getLogger(__name__)

#: How often [Hz of simulated time] the world's state is logged by default.
DEFAULT_WORLD_RATE = 10.0
#: At most this many events go to the writer in one batch.
BATCH_LIMIT = 500
#: Wall time [s] `attach_views` waits at most for a session to log the world's geometry.
ATTACH_TIMEOUT = 30.0

_active: list[ViewSession] = []  # the started, not yet closed sessions (in start order)
_active_lock = threading.Lock()


class _Tick(Fluent):
    """A child fluent whose pulse calls the session (in the thread that pulsed the parent)."""

    __slots__ = ("_call",)
    _call: Callable[[], None] | None

    def pulse(self) -> None:
        call = self._call
        if call is not None:
            call()

    def get_value(self) -> Any:
        return None


class _LogRecords:
    """Puts the run's log records on the session's queue: a `logging` record factory (it sees
    every record a logger creates -- the levels the run set decide which -- and, unlike a handler
    on the root logger, leaves `logging.basicConfig` in a plan script working)."""

    def __init__(self, session: ViewSession) -> None:
        self.session = session
        self.previous = logging.getLogRecordFactory()
        self.active = True

    def __call__(self, *args: Any, **kwargs: Any) -> logging.LogRecord:
        record = self.previous(*args, **kwargs)
        if self.active and record.levelno >= logging.INFO and not record.name.startswith("pycram.trace.view"):
            try:
                now: float | None = current_clock().now()
                text = f"{record.name}: {record.getMessage()}"
            except Exception:  # noqa: BLE001 - a log line must never fail the run
                now, text = None, f"{record.name}: {record.msg!r}"
            self.session._put(("log", now, time.time(), _LEVELS.get(record.levelno, "INFO"), text))
        return record


class ViewSession:
    """Logs a run into a Rerun recording (see the module docstring).

    `rrd`: a file to save the recording to (None: none); `connect`: a gRPC URL of a viewer
    server to stream to (`ViewerServer.grpc_url`; None: none); at least one of the two.
    `recording_id`: the recording's id (default: a new one; recordings with the same id are
    merged by the viewer); `name`: the recording's name as the viewer shows it;
    `world_rate_hz`: how often the world's state is logged [Hz of simulated time]; `process`:
    write the recording in a process of its own (the default: the run's threads then do not
    share Python's interpreter lock with the view's work; see `pycram.trace.view.writer`), else
    in a thread of this process (also the fallback when no process can be started)."""

    def __init__(
        self,
        *,
        rrd: str | Path | None = None,
        connect: str | None = None,
        recording_id: str | None = None,
        name: str = "pycram run",
        world_rate_hz: float = DEFAULT_WORLD_RATE,
        process: bool = True,
    ) -> None:
        if rrd is None and connect is None:
            raise ValueError("a view needs somewhere to go: an .rrd file (rrd=...) or a viewer (connect=...)")
        if not world_rate_hz > 0:
            raise ValueError(f"world_rate_hz must be > 0 [Hz], not {world_rate_hz}")
        self.rrd = Path(rrd) if rrd is not None else None
        self.connect = connect
        self.recording_id = recording_id or f"pycram-{uuid.uuid4()}"
        self.name = name
        self.period = 1.0 / world_rate_hz
        self.process = process
        self._sink: _ProcessSink | _ThreadSink | None = None
        self._queue: queue.SimpleQueue[tuple[Any, ...]] = queue.SimpleQueue()
        self._put = self._queue.put
        self._thread: threading.Thread | None = None
        self._records: _LogRecords | None = None
        self._attached = False
        self._attach_lock = threading.Lock()
        self._ticks: list[_Tick] = []  # held: fluents keep their children weakly
        self._world: Any = None
        self._belief: Any = None
        self._reasoner: Any = None
        self._next_tick = 0.0
        self._last_maps: Any = None
        self._last_tried: Any = None
        self._arms: list[Any] = []
        self._plans_seen: dict[int, int] = {}
        self._tried_count = 0
        self._closed = False
        self.started_wall = 0.0
        #: The trace database's run this view belongs to (found when it attaches), or None.
        self.run_id: int | None = None
        #: What the writer logged: counts by kind (known once the session is closed; "geoms" as
        #: soon as `attach_views` returned).
        self.counts: dict[str, int] = {}
        #: Wall time [s] the writer spent per kind of event ("task", "world", "look", "log",
        #: "attach"), known once the session is closed.
        self.spent: dict[str, float] = {}
        #: Why the writer stopped logging, if it failed ("Type: message"; None: it did not).
        self.error: str | None = None

    # -- life cycle ------------------------------------------------------------------------------

    def start(self) -> ViewSession:
        """Open the recording (its sinks: the file, the viewer), send the layout, start listening.
        Raises `ViewError` if the ``view`` extra is missing or the file cannot be written."""
        from .server import ViewError

        try:
            import rerun  # noqa: F401 - the writer needs it: fail here, with a clear message
        except ImportError as e:
            raise ViewError(f"the view needs the 'view' extra (pip install 'pycram[view]'): {e}") from None
        self.started_wall = time.time()
        if self.rrd is not None:
            try:
                self.rrd.parent.mkdir(parents=True, exist_ok=True)
                self.rrd.touch()
            except OSError as e:
                raise ViewError(f"cannot write the recording {self.rrd}: {e.strerror or e}") from None
        opening = (str(self.rrd) if self.rrd is not None else None, self.connect, self.recording_id, self.name)
        sink: _ProcessSink | _ThreadSink | None = None
        if self.process:
            try:
                sink = _ProcessSink(opening)
            except OSError as e:
                log.warning("cannot start the view's writer process (%s); writing in a thread", e)
        self._sink = sink or _ThreadSink(opening)
        self._thread = threading.Thread(target=self._forward, name="pycram-view", daemon=True)
        self._thread.start()
        add_task_listener(self)
        self._records = _LogRecords(self)
        logging.setLogRecordFactory(self._records)
        with _active_lock:
            _active.append(self)
        return self

    def close(self, timeout: float = 120.0) -> Path | None:
        """Stop listening, log everything still queued, close the recording (the .rrd is complete
        on return); returns the .rrd's path (None without one). Idempotent."""
        if self._closed:
            return self.rrd
        self._closed = True
        with _active_lock:
            if self in _active:
                _active.remove(self)
        remove_task_listener(self)
        if self._records is not None:
            self._records.active = False  # (another factory may have wrapped ours since)
            if logging.getLogRecordFactory() is self._records:
                logging.setLogRecordFactory(self._records.previous)
        for tick in self._ticks:
            tick._call = None
        done = threading.Event()
        self._put(("stop", done))
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                log.warning("the view did not finish logging within %.0f s; the recording may be incomplete", timeout)
                if isinstance(self._sink, _ProcessSink):
                    self._sink.kill()
        return self.rrd

    def move_rrd(self, folder: Path, name: str = "run.rrd") -> Path | None:
        """Move the closed session's .rrd into `folder` (as `name`); returns its new path."""
        if self.rrd is None or not self.rrd.exists():
            return None
        target = Path(folder) / name
        if target.resolve() != self.rrd.resolve():
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.move(str(self.rrd), target)
            self.rrd = target
        return self.rrd

    # -- hooks (plan threads, the simulation thread: O(1), never block) ----------------------------

    def task_started(self, task: Task) -> None:
        self._put(("task", task, task.status.get_value().value, task.start_time, time.time()))
        if not self._attached:
            self._try_attach()

    def task_ended(self, task: Task) -> None:
        self._put(("task", task, task.status.get_value().value, task.end_time, time.time()))

    def _try_attach(self) -> None:
        from pycram.execution.robot import current_robot

        robot = current_robot()
        world = getattr(robot, "world", None)
        if world is None or not hasattr(world, "sim_time"):
            return
        self.attach(world, getattr(robot, "belief", None), robot)

    def attach(self, world: Any, belief: Any = None, robot: Any = None) -> threading.Event:
        """Log `world` (a simulated `World`) from now on, with `belief` (the robot's
        `BeliefState`) and the location reasoner of `robot`; once per session (later calls do
        nothing). Called by itself when a task starts with a simulated robot active, or before
        the plan starts by `attach_views`. Returns an event set once the session's thread logged
        the world's geometry (already set when the session was attached before or is closed)."""
        ready = threading.Event()
        with self._attach_lock:
            if self._attached or self._closed:
                ready.set()
                return ready
            self._attached = True
        from pycram.trace.recorder import active_recorders

        recorders = active_recorders()
        if recorders:
            self.run_id = recorders[0].run_id
        self._world, self._belief = world, belief
        # the arm modules that plan their motions (`ArmMotionPlanner`: its latest plans)
        modules = (getattr(robot, "process_modules", {}) or {}).values()
        self._arms = [m for m in modules if hasattr(m, "_motions")]
        generators = getattr(robot, "location_generators", ()) or ()
        self._reasoner = next((g.reasoner for g in generators if hasattr(g, "reasoner")), None)
        scene = world.scene
        camera = None
        try:
            from pycram.backends.sim.robot_model import HEAD_CAMERA

            camera = HEAD_CAMERA if HEAD_CAMERA in scene.camera_names() else None
        except Exception:  # noqa: BLE001 - no camera: no images
            camera = None
        self._put(
            (
                "attach",
                scene.model,
                scene.description.ROOT_LINK,
                [it.name for it in scene.items],
                camera,
                str(getattr(robot, "name", scene.robot)),
                self.run_id,
                ready,
            )
        )
        self._next_tick = 0.0
        tick = _Tick(name="view tick")
        tick._call = self._on_tick
        self._ticks.append(tick)
        world.sim_time.add_child(tick)
        if belief is not None and hasattr(belief, "updated"):
            look = _Tick(name="view look")
            look._call = self._on_look
            self._ticks.append(look)
            belief.updated.add_child(look)
        self._on_tick()  # the world as it stands when the view attaches
        return ready

    def _on_tick(self) -> None:
        """(Simulation thread, at every sensor publication.) Take the state at most every
        `period` of simulated time."""
        world = self._world
        t = world.sim_time.get_value()
        if t < self._next_tick:
            return
        self._next_tick = (int(t / self.period + 1e-9) + 1) * self.period
        belief = None
        if self._belief is not None:
            from .world import belief_snapshot

            belief = belief_snapshot(self._belief)
        maps = candidates = None
        reasoner = self._reasoner
        if reasoner is not None:
            latest = getattr(reasoner, "last_costmaps", None)
            if latest is not None and latest is not self._last_maps:
                self._last_maps = maps = latest
            tried = getattr(reasoner, "last_candidates", None)  # grows while its search goes on
            if tried is not None and (tried is not self._last_tried or len(tried) != self._tried_count):
                self._last_tried, self._tried_count = tried, len(tried)
                candidates = list(tried)
        self._put(("world", t, time.time(), world._state, belief, maps, candidates))
        for module in self._arms:  # each arm's latest motion plan, once
            motions = getattr(module, "_motions", None)
            made = getattr(motions, "plans", 0)
            if motions is None or made == self._plans_seen.get(id(module)):
                continue
            self._plans_seen[id(module)] = made
            plans = list(getattr(motions, "last_plans", ()) or ())
            plan = next((p for p in reversed(plans) if getattr(p, "ok", False)), None)
            if plan is not None:
                arm = str(getattr(motions, "arm", "arm"))
                tool = str(motions.description.ARMS[arm]["tool_link"])
                self._put(("motion", t, time.time(), arm, tuple(plan.joints), tuple(plan.path), tool))

    def _on_look(self) -> None:
        """(The thread that updated the belief.) A look of the camera: the state it saw, and the
        objects seen in it (those last seen at the look's time stamp)."""
        from .world import belief_snapshot

        stamp = self._belief.updated.get_value()
        objects, _ = belief_snapshot(self._belief)
        seen = [o for o in objects if o.last_seen is not None and abs(o.last_seen - stamp) < 1e-9]
        self._put(("look", stamp, time.time(), self._world._state, seen))

    # -- the session's thread ----------------------------------------------------------------------

    def _forward(self) -> None:
        """(The session's thread.) Hand the queued events on to the writer as plain values, in
        batches of what is queued; set each attach's event once the writer logged the geometry;
        at "stop", finish the writer and keep what it reports."""
        from pycram.trace.recorder import error_origin

        sink = self._sink
        assert sink is not None
        announced: set[int] = set()  # tasks whose first status went out
        broken = False

        def task_rows(task: Task, status: str, t: float | None, wall: float) -> list[tuple[Any, ...]]:
            # ancestors never announced (a thread's root task): as the trace recorder does, they
            # enter the tree as running from their start
            rows: list[tuple[Any, ...]] = []
            chain, node = [], task.parent
            while node is not None and node.id not in announced:
                chain.append(node)
                node = node.parent
            for ancestor in reversed(chain):
                if ancestor.start_time is not None:
                    above = ancestor.parent
                    announced.add(ancestor.id)
                    rows.append(
                        (
                            ancestor.start_time,
                            wall,
                            ancestor.id,
                            above.id if above is not None else None,
                            ancestor.name,
                            ancestor.kind,
                            ancestor.path,
                            "running",
                            None,
                            False,
                        )
                    )
            error = origin = None
            if status in ("failed", "evaporated") and task.exception is not None:
                error = f"{type(task.exception).__name__}: {task.exception}"
                origin = error_origin(task) == task.id
            parent = task.parent
            announced.add(task.id)
            rows.append(
                (
                    t,
                    wall,
                    task.id,
                    parent.id if parent is not None else None,
                    task.name,
                    task.kind,
                    task.path,
                    status,
                    error,
                    bool(origin),
                )
            )
            return rows

        def plain(item: tuple[Any, ...]) -> tuple[Any, ...]:
            tag = item[0]
            if tag == "task":
                _, task, status, t, wall = item
                return ("task", task_rows(task, status, t, wall))
            if tag == "world":
                _, t, wall, state, belief, maps, candidates = item
                if maps:
                    maps = costmap_data(maps)
                if candidates is not None:
                    candidates = [
                        (float(c[0]), float(c[1]), c[2], None if c[3] is None else str(c[3]), *c[4:5])
                        for c in candidates
                    ]
                return ("world", t, wall, state, belief, maps, candidates)
            if tag == "attach":
                return item[:-1]  # (its event stays here)
            return item

        while True:
            item = self._queue.get()
            batch, ready, stop = [], [], None
            while True:
                if item[0] == "stop":
                    stop = item[1]
                    break
                if item[0] == "attach":
                    ready.append(item[-1])
                try:
                    batch.append(plain(item))
                except Exception as error:  # noqa: BLE001 - never fail the run
                    log.warning("the view could not take a %s event: %s", item[0], error)
                if len(batch) >= BATCH_LIMIT:
                    break
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    break
            if batch and not broken:
                try:
                    sink.send(batch)
                    if ready:
                        sink.wait_ready()
                        self.counts.update(sink.counts)
                except (OSError, EOFError, ValueError) as error:
                    log.warning("the view's writer stopped (%s); the rest of the run is not logged", error)
                    self.error = self.error or f"{type(error).__name__}: {error}"
                    broken = True
            for event in ready:
                event.set()
            if stop is not None:
                try:
                    sink.finish()
                except (OSError, EOFError, ValueError) as error:
                    log.warning("the view's writer did not close the recording (%s)", error)
                self.counts.update(sink.counts)
                self.spent.update(sink.spent)
                self.error = self.error or sink.error
                stop.set()
                return


class _ThreadSink:
    """The writer in this process: the session's thread logs each batch itself."""

    def __init__(self, opening: tuple[Any, ...]) -> None:
        self.writer = ViewWriter(*opening)

    @property
    def counts(self) -> dict[str, int]:
        return self.writer.counts

    @property
    def spent(self) -> dict[str, float]:
        return self.writer.spent

    @property
    def error(self) -> str | None:
        return self.writer.error

    def send(self, batch: list[tuple[Any, ...]]) -> None:
        for item in batch:
            self.writer.handle(item)

    def wait_ready(self) -> None:
        pass

    def finish(self) -> None:
        self.writer.finish()


class _ProcessSink:
    """The writer in a process of its own (``python -m pycram.trace.view.writer``), fed through
    its standard input; raises OSError when the process cannot be started."""

    def __init__(self, opening: tuple[Any, ...]) -> None:
        import os
        import subprocess
        import sys

        import pycram

        here = str(Path(pycram.__file__).resolve().parent.parent)  # this pycram, not another one
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH", "")) if p)
        self.counts: dict[str, int] = {}
        self.spent: dict[str, float] = {}
        self.error: str | None = None
        self.process = subprocess.Popen(
            [sys.executable, "-m", "pycram.trace.view.writer"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            start_new_session=True,  # Ctrl-C in a terminal stops the run, which then closes the writer
        )
        assert self.process.stdin is not None and self.process.stdout is not None
        self._in, self._out = self.process.stdin, self.process.stdout
        send_message(self._in, opening)

    def send(self, batch: list[tuple[Any, ...]]) -> None:
        send_message(self._in, batch)

    def _answer(self, kind: str) -> tuple[Any, ...]:
        answer = read_message(self._out)
        if not (isinstance(answer, tuple) and answer and answer[0] == kind):
            raise ValueError(f"the view's writer answered {answer!r}, not {kind!r}")
        return answer

    def wait_ready(self) -> None:
        self.counts = dict(self._answer("ready")[1])

    def finish(self, timeout: float = FLUSH_TIMEOUT + 30.0) -> None:
        try:
            send_message(self._in, "stop")
            self._in.close()
            _, counts, spent, error = self._answer("done")
            self.counts, self.spent, self.error = dict(counts), dict(spent), error
        finally:
            try:
                self.process.wait(timeout)
            except Exception:  # noqa: BLE001 - a writer that does not end is stopped
                self.kill()

    def kill(self) -> None:
        """Stop the writer process at once (the recording may be incomplete)."""
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


_LEVELS = {
    logging.DEBUG: "DEBUG",
    logging.INFO: "INFO",
    logging.WARNING: "WARN",
    logging.ERROR: "ERROR",
    logging.CRITICAL: "CRITICAL",
}


def attach_views(world: Any, belief: Any = None, robot: Any = None, timeout: float = ATTACH_TIMEOUT) -> None:
    """Attach every active view session to `world` (with `belief` and `robot`, as
    `ViewSession.attach`) and wait until each has logged the world's geometry, at most `timeout`
    [s of wall time] in all. A run calls it after building its world and before starting its
    plan, so that this one-time start-up cost (~0.1 s for the apartment) is paid before the plan
    runs rather than by the plan's first seconds. Does nothing (and imports nothing) without an
    active session; a session that attached before is left as it is."""
    with _active_lock:
        sessions = list(_active)
    deadline = time.monotonic() + timeout
    for session in sessions:
        ready = session.attach(world, belief, robot)
        if not ready.wait(max(0.0, deadline - time.monotonic())):
            log.warning("the view did not log the world's geometry within %.0f s; the run goes on", timeout)
            return


def find_run_folder(since: float, root: Path = Path("output")) -> Path | None:
    """The folder below `root` in which a run's pictures (start.png or end.png) were written at or
    after `since` [s since the epoch], the newest first; None when there is none."""
    best: tuple[float, Path] | None = None
    if not root.is_dir():
        return None
    for folder in root.iterdir():
        for picture in ("end.png", "start.png"):
            path = folder / picture
            try:
                mtime = path.stat().st_mtime
            except OSError:
                continue
            if mtime >= since - 1.0 and (best is None or mtime > best[0]):
                best = (mtime, folder)
    return best[1] if best else None


#: The environment variables that make a worker process stream one run into a viewer (set by
#: `pycram experiment --view`): the viewer's gRPC URL, and which run ("SEED" or "ROBOT:SEED").
VIEW_CONNECT_ENV = "PYCRAM_VIEW_CONNECT"
#: See `VIEW_CONNECT_ENV`.
VIEW_RUN_ENV = "PYCRAM_VIEW_RUN"


def viewed_run(function: Callable[..., Any], robot: str, seed: int, name: str = "run") -> Callable[..., Any]:
    """`function` (a scenario's run), logged into the viewer named by ``$PYCRAM_VIEW_CONNECT``
    while it runs when ``$PYCRAM_VIEW_RUN`` names this run (its seed, or ``ROBOT:SEED``);
    `function` itself otherwise. For `pycram experiment --view`: its worker processes inherit the
    variables. The wrapper keeps `function`'s signature (`inspect.signature` follows it)."""
    import functools
    import os

    connect, wanted = os.environ.get(VIEW_CONNECT_ENV), os.environ.get(VIEW_RUN_ENV)
    if not connect or not wanted:
        return function
    robot_wanted, _, seed_wanted = wanted.rpartition(":")
    if seed_wanted.strip() != str(seed) or (robot_wanted and robot_wanted != robot):
        return function

    @functools.wraps(function)
    def run(*args: Any, **kwargs: Any) -> Any:
        try:
            session = ViewSession(connect=connect, name=f"{name}: {robot}, seed {seed}").start()
        except Exception as error:  # noqa: BLE001 - no view: the run goes on without one
            log.warning("cannot stream %s seed %s into the viewer: %s", robot, seed, error)
            return function(*args, **kwargs)
        try:
            return function(*args, **kwargs)
        finally:
            session.close()

    return run
