"""Recording commands of a `World`: record frames of a camera while the simulation runs, and
stop to get them (and write a GIF).

The recorders themselves (`FrameRecorder`: copies of the state taken by the simulation thread,
rendered and encoded in a thread of their own) are in `recording`; these are the world's
commands that start and stop them. Frame times are in seconds of simulated time.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .camera import FollowView
from .commands import CommandQueue
from .engine import Engine
from .errors import WorldClosedError
from .handle import CommandHandle, _wait_wall
from .recording import DEFAULT_MAX_PENDING, FrameRecorder, RecordedFrames
from .render import write_animation

# (the world's logger: these messages keep the name they were logged under before the split)
_log = logging.getLogger("pycram.backends.sim.world")


class RecordingCommands(CommandQueue):
    """The recording commands of a `World` (a part of it: `World` inherits them)."""

    robot: str
    _recorder: FrameRecorder | None
    _recorders: list[FrameRecorder]

    def start_recording(
        self,
        camera: str | FollowView = "overview",
        fps: float = 10.0,
        width: int = 320,
        height: int = 240,
        *,
        max_pending: int = DEFAULT_MAX_PENDING,
        caption: Callable[[], str] | None = None,
    ) -> CommandHandle:
        """Start recording frames of `camera` (width x height [px]) every 1/`fps` s of simulated
        time, from the simulated time at which the command runs; a recording already running is
        discarded.

        The simulation thread only copies the state at each frame time (microseconds); a
        recorder thread of its own renders and GIF-encodes the frames (`FrameRecorder`), so the
        simulation never waits for rendering. If `max_pending` frames wait to be rendered, a new
        one is dropped (counted and logged when the recording stops). Frames are not limited by
        the world's `offscreen_size`, and are rendered without multisampling.

        `camera` is a camera name or a `FollowView` (a free camera that keeps bodies in view).
        With `caption` (called in the simulation thread at each frame time; it must be quick and
        never block, e.g. read a fluent), each frame carries a caption: its text and the
        simulated time.
        """
        self._check_camera(camera)
        recorder = FrameRecorder(
            self.scene.model,
            camera,
            fps,
            width,
            height,
            max_pending,
            name=f"pycram-recorder-{self.robot}",
            caption=caption,
        )
        with self._lock:
            self._recorders.append(recorder)

        def fn(eng: Engine) -> None:
            previous, self._recorder = self._recorder, recorder
            if previous is not None:
                _log.warning("start_recording: discarding the recording that was running")
                previous.abort()
            recorder.start_at(eng.time)

        try:
            return self._call("start_recording", fn)
        except WorldClosedError:
            self._forget_recorder(recorder, abort=True)
            raise

    def _forget_recorder(self, recorder: FrameRecorder, abort: bool) -> None:
        """Stop tracking `recorder` for `close()`; with `abort`, end its thread first. A recorder
        whose thread still runs is never forgotten (`close()` must end it)."""
        if abort:
            recorder.close()
        if recorder.running:
            return
        with self._lock:
            if recorder in self._recorders:
                self._recorders.remove(recorder)

    def stop_recording(self, path: str | Path | None = None, timeout: float = 30.0) -> list[np.ndarray]:
        """Stop recording; write the animation to `path` (GIF by suffix) if given; return the frames.
        The last frame shows the state at the simulated time the recording stopped.

        Waits for the recorder thread to render the frames still pending and ends it. Blocks up
        to `timeout` [s of wall time]; frames not rendered by then are dropped (logged). Returns
        a `RecordedFrames` (a list of RGB arrays, height x width x 3 uint8, which also carries
        the GIF encoding, so `write_animation` of these frames to a GIF is fast). Raises
        `WorldClosedError` if the world is closed and `SimulationError` if rendering failed;
        `ValueError` from writing when `path` is given but nothing was recorded.
        """
        deadline = time.monotonic() + timeout

        def fn(eng: Engine) -> FrameRecorder | None:
            recorder, self._recorder = self._recorder, None
            if recorder is not None:
                recorder.capture_last(eng.data)  # the animation ends with the state it stopped in
            return recorder

        handle = self._call("stop_recording", fn)
        _wait_wall(handle, timeout)
        out = handle.outcome
        if out is None or not out.succeeded:
            raise WorldClosedError(f"stop_recording failed: {out}")
        recorder: FrameRecorder | None = out.value
        if recorder is None:
            frames = RecordedFrames()
        else:
            try:
                frames = recorder.finish(max(0.0, deadline - time.monotonic()))
            finally:  # if `finish` was interrupted (Ctrl-C), its thread runs on until close()
                self._forget_recorder(recorder, abort=False)
        if path is not None:
            write_animation(path, frames, frames.fps)
        return frames


__all__ = ["RecordingCommands"]
