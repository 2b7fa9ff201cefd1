"""A run's view, logged while it runs: `ViewSession`.

    session = ViewSession(rrd=Path("output/run.rrd"), connect=server.grpc_url).start()
    ...run the plan (the session finds the simulated world and the belief by itself)...
    session.close()        # writes everything still queued; the .rrd is complete

What it logs is listed in `pycram.trace.view.paths`. How, so that viewing changes nothing in the
run and costs it little:

- Every hook that runs in a plan thread or in the simulation thread only puts a tuple on a queue
  (O(1), never blocks); the session's own thread turns the queue into Rerun data. No hook
  changes a value the run reads, so a lock-step run has the same fingerprint with a view as
  without one (`pycram.trace.fingerprint`).
- The task tree comes from the runtime's task listeners (like the trace recorder); log lines from
  a `logging` record factory (what the run logs at the levels it set, INFO and above).
- The world: once a task starts while a simulated robot is active (`current_robot()`, with a
  ``world`` and a ``belief``), the session attaches to that world: a child fluent of its
  ``sim_time`` (set by the simulation thread at every sensor publication) takes, at most every
  1/`world_rate_hz` s of simulated time (10 Hz by default), the state the simulation thread last
  published (`StateSnapshot`, already a copy) and a snapshot of the belief; a child fluent of
  the belief's ``updated`` takes each look of the camera. The session's thread computes the
  bodies' poses from the state in its own `MjData` and renders the camera image with its own
  renderer. The location reasoner's latest costmaps (and candidates, where it keeps them) and
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

from . import paths

__all__ = [
    "ViewSession",
    "DEFAULT_WORLD_RATE",
    "FLUSH_TIMEOUT",
    "TRANSFORM_BATCH",
    "find_run_folder",
    "viewed_run",
    "VIEW_CONNECT_ENV",
    "VIEW_RUN_ENV",
]

log = logging.getLogger(__name__)

#: How often [Hz of simulated time] the world's state is logged by default.
DEFAULT_WORLD_RATE = 10.0
#: At most this many [s of the sim timeline] between two logs of the task tree's graph.
GRAPH_PERIOD = 1.0
#: Body poses and task-status changes are logged in columns every this many [s] of wall time (a
#: live view lags by as much): one Rerun call per body (and one for the statuses) per batch.
TRANSFORM_BATCH = 1.0
#: Wall time [s] closing a session waits for its data to reach the file and the viewer.
FLUSH_TIMEOUT = 60.0


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
    `world_rate_hz`: how often the world's state is logged [Hz of simulated time]."""

    def __init__(
        self,
        *,
        rrd: str | Path | None = None,
        connect: str | None = None,
        recording_id: str | None = None,
        name: str = "pycram run",
        world_rate_hz: float = DEFAULT_WORLD_RATE,
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
        self.rec: Any = None
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
        #: What the session's thread logged: counts by kind (for tests and the benchmark).
        self.counts: dict[str, int] = {}
        #: Wall time [s] the session's thread spent per kind of event ("task", "world", "look",
        #: "log", "attach"), for the benchmark.
        self.spent: dict[str, float] = {}
        #: Why the session's thread stopped logging, if it failed (None: it did not).
        self.error: BaseException | None = None

    # -- life cycle ------------------------------------------------------------------------------

    def start(self) -> ViewSession:
        """Open the recording (its sinks: the file, the viewer), send the layout, start listening.
        Raises `ViewError` if the ``view`` extra is missing or the file cannot be written."""
        from .blueprint import default_blueprint
        from .server import ViewError

        try:
            import rerun as rr
        except ImportError as e:
            raise ViewError(f"the view needs the 'view' extra (pip install 'pycram[view]'): {e}") from None
        self.started_wall = time.time()
        rec = rr.RecordingStream(paths.APPLICATION_ID, recording_id=self.recording_id)
        sinks: list[Any] = []
        if self.rrd is not None:
            try:
                self.rrd.parent.mkdir(parents=True, exist_ok=True)
                self.rrd.touch()
            except OSError as e:
                raise ViewError(f"cannot write the recording {self.rrd}: {e.strerror or e}") from None
            sinks.append(rr.FileSink(str(self.rrd)))
        if self.connect is not None:
            sinks.append(rr.GrpcSink(self.connect))
        rec.set_sinks(*sinks)
        rec.send_recording_name(self.name)
        rec.send_blueprint(default_blueprint())
        self.rec = rec
        self._thread = threading.Thread(target=self._main, name="pycram-view", daemon=True)
        self._thread.start()
        add_task_listener(self)
        self._records = _LogRecords(self)
        logging.setLogRecordFactory(self._records)
        return self

    def close(self, timeout: float = 120.0) -> Path | None:
        """Stop listening, log everything still queued, close the recording (the .rrd is complete
        on return); returns the .rrd's path (None without one). Idempotent."""
        if self._closed:
            return self.rrd
        self._closed = True
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
        if self.rec is not None:
            try:
                self.rec.flush(timeout_sec=FLUSH_TIMEOUT)
                self.rec.disconnect()
            except Exception as e:  # noqa: BLE001 - the run is over; say it, do not fail it
                log.warning("closing the view's recording: %s", e)
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

    def attach(self, world: Any, belief: Any = None, robot: Any = None) -> None:
        """Log `world` (a simulated `World`) from now on, with `belief` (the robot's
        `BeliefState`) and the location reasoner of `robot`; once per session (later calls do
        nothing). Called by itself when a task starts with a simulated robot active."""
        with self._attach_lock:
            if self._attached or self._closed:
                return
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

    def _count(self, kind: str, n: int = 1) -> None:
        self.counts[kind] = self.counts.get(kind, 0) + n

    def _main(self) -> None:
        from .tree import TreeLog

        rec = self.rec
        world_log: Any = None
        belief_names: list[str] = []
        tree = TreeLog(rec, objects=lambda: belief_names, graph_period=GRAPH_PERIOD)
        now = 0.0
        flushed_at = -1e18  # time.monotonic() of the last flush of body poses
        failing = False
        while True:
            item = self._queue.get()
            tag = item[0]
            if tag == "stop":
                break
            began = time.perf_counter()
            try:
                if tag == "task":
                    _, task, status, t, wall = item
                    # ancestors never announced (a thread's root task): as the trace recorder
                    # does, they enter the tree as running from their start
                    chain, node = [], task.parent
                    while node is not None and node.id not in tree.tasks:
                        chain.append(node)
                        node = node.parent
                    for ancestor in reversed(chain):
                        if ancestor.start_time is not None:
                            self._times(ancestor.start_time, wall)
                            above = ancestor.parent
                            tree.change(
                                ancestor.start_time,
                                wall,
                                ancestor.id,
                                above.id if above is not None else None,
                                ancestor.name,
                                ancestor.kind,
                                ancestor.path,
                                "running",
                            )
                            self._count("task status")
                    now = self._times(t if t is not None else now, wall)
                    parent = task.parent
                    error = origin = None
                    if status in ("failed", "evaporated") and task.exception is not None:
                        from pycram.trace.recorder import error_origin

                        error = f"{type(task.exception).__name__}: {task.exception}"
                        origin = error_origin(task) == task.id
                    tree.change(
                        now,
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
                    self._count("task status")
                elif tag == "world":
                    _, t, wall, state, belief, maps, candidates = item
                    now = self._times(t, wall)
                    if world_log is not None and state is not None:
                        self._count("body poses", world_log.log_state(state, t, wall))
                    if world_log is not None and belief is not None:
                        objects, containers = belief
                        belief_names = [o.name for o in objects]
                        world_log.log_belief(objects, containers)
                    if maps:
                        from .reasoning import log_costmaps

                        log_costmaps(rec, maps)
                        self._count("costmaps")
                    if candidates is not None:
                        from .reasoning import log_candidates

                        log_candidates(rec, candidates)
                        self._count("candidates")
                    tree.log_current()
                    tree.log_graph(now)
                    self._count("world states")
                elif tag == "motion":
                    _, t, wall, arm, joints, path, tool = item
                    now = self._times(t, wall)
                    if world_log is not None and world_log.log_motion(arm, joints, path, tool):
                        self._count("motion plans")
                elif tag == "look":
                    _, t, wall, state, seen = item
                    now = self._times(t, wall)
                    if world_log is not None and world_log.log_look(state, seen):
                        self._count("camera images")
                elif tag == "log":
                    _, t, wall, level, text = item
                    now = self._times(t if t is not None else now, wall)
                    import rerun as rr

                    rec.log(paths.LOG, rr.TextLog(text, level=level))
                    self._count("log lines")
                elif tag == "attach":
                    _, model, root, items, camera, robot, run_id = item
                    from .world import WorldLog

                    world_log = WorldLog(rec, model, root, items, camera)
                    self._count("geoms", world_log.log_geometry())
                    import rerun as rr

                    about = f"robot: {robot}" + (f"  \ntrace database run: {run_id}" if run_id is not None else "")
                    rec.log(paths.RUN, rr.TextDocument(about, media_type="text/markdown"), static=True)
            except Exception as error:  # never fail the run; say once why the view is missing parts
                if not failing:
                    log.warning("the view could not log a %s event: %s", tag, error, exc_info=True)
                    self.error = error
                failing = True
            if time.monotonic() - flushed_at >= TRANSFORM_BATCH:  # what was noted, in columns
                try:
                    tree.flush()
                    if world_log is not None:
                        self._count("pose columns", world_log.flush())
                except Exception as error:  # noqa: BLE001 - never fail the run
                    log.warning("the view could not log a batch: %s", error)
                flushed_at = time.monotonic()
            self.spent[tag] = self.spent.get(tag, 0.0) + time.perf_counter() - began
        tree.flush()
        tree.log_current()
        tree.log_graph(now, force=True)
        if world_log is not None:
            try:
                world_log.flush()
            except Exception as error:  # noqa: BLE001 - closing: say it, do not fail the run
                log.warning("the view could not log the last poses: %s", error)
            world_log.close()
        item[1].set()

    def _times(self, t: float, wall: float) -> float:
        self.rec.set_time(paths.SIM_TIMELINE, duration=float(t))
        self.rec.set_time(paths.WALL_TIMELINE, timestamp=wall)
        return float(t)


_LEVELS = {
    logging.DEBUG: "DEBUG",
    logging.INFO: "INFO",
    logging.WARNING: "WARN",
    logging.ERROR: "ERROR",
    logging.CRITICAL: "CRITICAL",
}


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
