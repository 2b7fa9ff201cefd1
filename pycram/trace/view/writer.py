"""The writing side of a run's view: `ViewWriter` turns view events (plain values) into Rerun
data, and ``python -m pycram.trace.view.writer`` runs one in a process of its own.

A `ViewSession` (`pycram.trace.view.session`) collects the run's events in the run's process and
hands them on as plain, picklable values; by default a writer process does everything else --
the bodies' poses from each state in its own `MjData`, the camera images with its own renderer,
the task tree, Rerun's encoding --, so that the run's threads do not share Python's interpreter
lock with that work (measured: the thesis demo's run was ~10-14 % slower with the writer in a
thread of the run's process; `benchmarks/view.py`).

Events (tuples, the first element names the kind; times are [s] on the ``sim`` timeline and
[s since the epoch] on the ``wall`` one):

- ``("attach", model, root_link, items, camera, robot, run_id)``: the world to log (a
  `mujoco.MjModel`); its geometry is logged at once;
- ``("task", rows)``: task-status changes, ``(time, wall, task_id, parent_id, name, kind, path,
  status, error, origin)`` each (ancestors never announced come first, as running);
- ``("world", t, wall, state, belief, maps, candidates)``: a `StateSnapshot`, a belief snapshot
  (`belief_snapshot`), the latest costmaps (name -> `CostmapData`) and candidates, or None;
- ``("motion", t, wall, arm, joints, path, tool)``, ``("look", t, wall, state, seen)``,
  ``("log", t, wall, level, text)``.

The process protocol (`serve`): the parent writes `send_message` frames to the child's standard
input -- first ``(rrd, connect, recording_id, name)``, then batches (lists) of events, then
``"stop"`` --; the child answers on its standard output with ``("ready", counts)`` after each batch
holding an ``attach`` (the geometry is logged), and ``("done", counts, spent, error)`` once it
stopped and the recording is flushed and closed. End of input without ``"stop"`` (the run's
process died) closes the recording too.
"""

from __future__ import annotations

import logging
import pickle
import struct
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

from . import paths

__all__ = ["ViewWriter", "CostmapData", "send_message", "read_message", "serve", "FLUSH_TIMEOUT", "TRANSFORM_BATCH"]

log = logging.getLogger(__name__)

#: At most this many [s of the sim timeline] between two logs of the task tree's graph.
GRAPH_PERIOD = 1.0
#: Body poses and task-status changes are logged in columns every this many [s] of wall time (a
#: live view lags by as much): one Rerun call per body (and one for the statuses) per batch.
TRANSFORM_BATCH = 1.0
#: Wall time [s] closing a writer waits for its data to reach the file and the viewer.
FLUSH_TIMEOUT = 60.0

_HEADER = struct.Struct("!Q")


class CostmapData:
    """A costmap as the view logs it (plain arrays, picklable): its `layers` (name -> costs
    over the grid), their sum (`total()`), and the grid's cell centres (`grid.x`, `grid.y` [m])."""

    __slots__ = ("layers", "_total", "grid")

    def __init__(self, costmap: Any) -> None:
        import types

        import numpy as np

        self.layers = {str(k): np.asarray(v, float) for k, v in costmap.layers.items()}
        self._total = np.asarray(costmap.total(), float)
        self.grid = types.SimpleNamespace(x=np.asarray(costmap.grid.x), y=np.asarray(costmap.grid.y))

    def total(self) -> Any:
        return self._total

    def __getstate__(self) -> tuple[Any, Any, Any, Any]:
        return self.layers, self._total, self.grid.x, self.grid.y

    def __setstate__(self, state: tuple[Any, Any, Any, Any]) -> None:
        import types

        self.layers, self._total, x, y = state
        self.grid = types.SimpleNamespace(x=x, y=y)


def costmap_data(maps: Mapping[str, Any]) -> dict[str, CostmapData]:
    """`maps` (name -> `Costmap`) as plain `CostmapData`."""
    return {str(name): CostmapData(costmap) for name, costmap in maps.items()}


class ViewWriter:
    """Logs view events (see the module docstring) into a new Rerun recording whose sinks are
    `rrd` (a file; None: none) and `connect` (a viewer's gRPC URL; None: none). Use from one
    thread only. `counts`: what was logged, by kind; `spent`: wall time [s] per kind of event;
    `error`: why logging stopped, if it failed (the first error; the run is never failed)."""

    def __init__(self, rrd: str | Path | None, connect: str | None, recording_id: str, name: str) -> None:
        import rerun as rr

        from .blueprint import default_blueprint
        from .tree import TreeLog

        rec = rr.RecordingStream(paths.APPLICATION_ID, recording_id=recording_id)
        sinks: list[Any] = []
        if rrd is not None:
            sinks.append(rr.FileSink(str(rrd)))
        if connect is not None:
            sinks.append(rr.GrpcSink(connect))
        rec.set_sinks(*sinks)
        rec.send_recording_name(name)
        rec.send_blueprint(default_blueprint())
        self.rec = rec
        self.counts: dict[str, int] = {}
        self.spent: dict[str, float] = {}
        self.error: str | None = None
        self._world: Any = None  # WorldLog, once attached
        self._belief_names: list[str] = []
        self._tree = TreeLog(rec, objects=lambda: self._belief_names, graph_period=GRAPH_PERIOD)
        self._now = 0.0
        self._flushed_at = -1e18  # time.monotonic() of the last flush of body poses
        self._failing = False

    def _count(self, kind: str, n: int = 1) -> None:
        self.counts[kind] = self.counts.get(kind, 0) + n

    def _times(self, t: float, wall: float) -> float:
        self.rec.set_time(paths.SIM_TIMELINE, duration=float(t))
        self.rec.set_time(paths.WALL_TIMELINE, timestamp=wall)
        return float(t)

    def handle(self, item: tuple[Any, ...]) -> None:
        """Log one event; never raises (the first error is kept in `error` and logged)."""
        tag = item[0]
        began = time.perf_counter()
        try:
            self._handle(tag, item)
        except Exception as error:  # never fail the run; say once why the view is missing parts
            if not self._failing:
                log.warning("the view could not log a %s event: %s", tag, error, exc_info=True)
                self.error = f"{type(error).__name__}: {error}"
            self._failing = True
        if time.monotonic() - self._flushed_at >= TRANSFORM_BATCH:  # what was noted, in columns
            try:
                self._tree.flush()
                if self._world is not None:
                    self._count("pose columns", self._world.flush())
            except Exception as error:  # noqa: BLE001 - never fail the run
                log.warning("the view could not log a batch: %s", error)
            self._flushed_at = time.monotonic()
        self.spent[tag] = self.spent.get(tag, 0.0) + time.perf_counter() - began

    def _handle(self, tag: str, item: tuple[Any, ...]) -> None:
        tree, world_log = self._tree, self._world
        if tag == "task":
            for t, wall, task_id, parent_id, name, kind, path, status, error, origin in item[1]:
                self._now = self._times(t if t is not None else self._now, wall)
                tree.change(self._now, wall, task_id, parent_id, name, kind, path, status, error, origin)
                self._count("task status")
        elif tag == "world":
            _, t, wall, state, belief, maps, candidates = item
            self._now = self._times(t, wall)
            if world_log is not None and state is not None:
                self._count("body poses", world_log.log_state(state, t, wall))
            if world_log is not None and belief is not None:
                objects, containers = belief
                self._belief_names = [o.name for o in objects]
                world_log.log_belief(objects, containers)
            if maps:
                from .reasoning import log_costmaps

                log_costmaps(self.rec, maps)
                self._count("costmaps")
            if candidates is not None:
                from .reasoning import log_candidates

                log_candidates(self.rec, candidates)
                self._count("candidates")
            tree.log_current()
            tree.log_graph(self._now)
            self._count("world states")
        elif tag == "motion":
            _, t, wall, arm, joints, path, tool = item
            self._now = self._times(t, wall)
            if world_log is not None and world_log.log_motion(arm, joints, path, tool):
                self._count("motion plans")
        elif tag == "look":
            _, t, wall, state, seen = item
            self._now = self._times(t, wall)
            if world_log is not None and world_log.log_look(state, seen):
                self._count("camera images")
        elif tag == "log":
            _, t, wall, level, text = item
            self._now = self._times(t if t is not None else self._now, wall)
            import rerun as rr

            self.rec.log(paths.LOG, rr.TextLog(text, level=level))
            self._count("log lines")
        elif tag == "attach":
            _, model, root, items, camera, robot, run_id = item
            import rerun as rr

            from .world import WorldLog

            self._world = WorldLog(self.rec, model, root, items, camera)
            self._count("geoms", self._world.log_geometry())
            about = f"robot: {robot}" + (f"  \ntrace database run: {run_id}" if run_id is not None else "")
            self.rec.log(paths.RUN, rr.TextDocument(about, media_type="text/markdown"), static=True)
        else:
            raise ValueError(f"unknown view event {tag!r}")

    def finish(self) -> None:
        """Log what is still noted, then flush and close the recording (the .rrd is complete on
        return). Call once, last."""
        tree = self._tree
        try:
            tree.flush()
            tree.log_current()
            tree.log_graph(self._now, force=True)
            if self._world is not None:
                self._world.flush()
        except Exception as error:  # noqa: BLE001 - closing: say it, do not fail the run
            log.warning("the view could not log the last poses: %s", error)
        if self._world is not None:
            self._world.close()
        try:
            self.rec.flush(timeout_sec=FLUSH_TIMEOUT)
            self.rec.disconnect()
        except Exception as error:  # noqa: BLE001 - the run is over; say it, do not fail it
            log.warning("closing the view's recording: %s", error)


# -- the writer process ------------------------------------------------------------------------------


def send_message(stream: IO[bytes], value: Any) -> None:
    """Write `value` to `stream` as one frame: its pickle's length (8 bytes), then the pickle."""
    data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(_HEADER.pack(len(data)))
    stream.write(data)
    stream.flush()


def read_message(stream: IO[bytes]) -> Any:
    """Read one frame written by `send_message`; raises EOFError at the end of the stream."""
    header = stream.read(_HEADER.size)
    if len(header) < _HEADER.size:
        raise EOFError("the view's pipe was closed")
    (size,) = _HEADER.unpack(header)
    data = stream.read(size)
    if len(data) < size:
        raise EOFError("the view's pipe was closed in the middle of a message")
    return pickle.loads(data)


def serve(incoming: IO[bytes], outgoing: IO[bytes]) -> int:
    """Run a writer on the frames of `incoming`, answering on `outgoing` (see the module
    docstring); returns the process's exit code (0)."""
    rrd, connect, recording_id, name = read_message(incoming)
    writer = ViewWriter(rrd, connect, recording_id, name)
    try:
        while True:
            try:
                batch = read_message(incoming)
            except EOFError:
                break
            if batch == "stop":
                break
            for item in batch:
                writer.handle(item)
            if any(item[0] == "attach" for item in batch):
                send_message(outgoing, ("ready", writer.counts))
    finally:
        writer.finish()
        try:
            send_message(outgoing, ("done", writer.counts, writer.spent, writer.error))
        except OSError:  # the run's process is gone: nobody to tell
            pass
    return 0


def main() -> int:
    """``python -m pycram.trace.view.writer``: serve the frames of standard input. Ctrl-C in a
    terminal reaches the whole process group: the writer ignores it and ends with its input, so
    an interrupted run still closes its recording."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    logging.basicConfig(level=logging.WARNING, format="pycram view writer: %(levelname)s %(name)s: %(message)s")
    incoming, outgoing = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # nothing but frames on the answer pipe
    return serve(incoming, outgoing)


if __name__ == "__main__":
    sys.exit(main())
