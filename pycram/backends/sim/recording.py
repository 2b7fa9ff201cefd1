"""Animation recording off the simulation thread: state snapshots in, rendered frames out.

The simulation thread only copies the state that drawing needs (`StateSnapshot`, ~0.5 kB: joint
positions, mocap poses, time) at each frame time and offers it to a `FrameRecorder`, which never
blocks it. The recorder's own thread owns a copy of the model, its own `MjData` and its own
`mujoco.Renderer` (GL contexts belong to the thread that created them): it computes the
kinematics of each snapshot, renders it, and GIF-encodes it right away (`GifEncoder`), so that
writing the animation at the end only joins bytes. The simulation's `MjData` is never touched by
the recorder.

Rendering and encoding hardly hold the GIL (measured on 2 cores: a busy Python thread kept
~80% of its pace beside a thread rendering continuously, ~96% beside continuous GIF encoding;
the rest is CPU contention). The recorder thread runs at a lower scheduling priority (Linux:
nice +`RECORDER_NICE` for that thread only; the GL driver's rasterizer threads are shared by the
process and keep theirs), so the simulation thread is preferred when the CPU is short, and the
recorder catches up afterwards (`finish` waits for it).
"""

from __future__ import annotations

import atexit
import collections
import copy
import functools
import logging
import os
import threading
import time
import weakref
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from .camera import FollowView
from .errors import SimulationError
from .gif import GifEncoder

_log = logging.getLogger(__name__)

#: Nice increment of the recorder thread (and the GL threads it starts): background work.
RECORDER_NICE = 5
#: Default bound of snapshots waiting to be rendered; more are dropped (counted, logged).
DEFAULT_MAX_PENDING = 512
#: Recorders whose thread may still run: ended at interpreter exit, so that no recorder thread
#: is inside MuJoCo or the GL driver while the interpreter and its libraries shut down.
_LIVE_RECORDERS: weakref.WeakSet[FrameRecorder] = weakref.WeakSet()


@atexit.register
def _close_live_recorders() -> None:
    for recorder in list(_LIVE_RECORDERS):
        recorder.abort()
    for recorder in list(_LIVE_RECORDERS):
        recorder.close(timeout=5.0)


@dataclass(frozen=True)
class StateSnapshot:
    """What drawing a frame needs of the simulation state, copied at simulated `time` [s].

    Items held in a gripper (welds) and coupled joints are part of `qpos` (free and coupled
    joints); obstacles are mocap bodies.
    """

    time: float
    qpos: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray
    caption: str = ""  #: what the frame's caption says besides the time (e.g. the plan's phase)

    @classmethod
    def of(cls, data: mujoco.MjData, caption: str = "") -> StateSnapshot:
        """Copy the state of `data` (call from the thread that owns `data`; a few microseconds)."""
        return cls(float(data.time), data.qpos.copy(), data.mocap_pos.copy(), data.mocap_quat.copy(), caption)

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Set `data` to this state and compute what rendering reads (body, geom, camera and
        light poses: `mj_kinematics` + `mj_camlight`); velocities and contacts are not computed."""
        data.time = self.time
        data.qpos[:] = self.qpos
        data.mocap_pos[:] = self.mocap_pos
        data.mocap_quat[:] = self.mocap_quat
        mujoco.mj_kinematics(model, data)
        mujoco.mj_camlight(model, data)

    def picture(self, model: mujoco.MjModel, camera: str | FollowView, width: int, height: int) -> np.ndarray:
        """This state drawn from `camera` (a camera name or a `FollowView`): an RGB image (height
        x width x 3, uint8), rendered in the calling thread on a copy of `model` with a renderer
        of its own (made and closed here: ~0.1 s), so no simulation thread is asked or waited
        for. Thread-safe as copying `model` is while a simulation steps (it writes only weld
        parameters and force ranges, which drawing never reads)."""
        model = copy.copy(model)  # mj_copyModel: nothing shared with the simulation afterwards
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        data = mujoco.MjData(model)
        self.apply(model, data)
        renderer = mujoco.Renderer(model, height=height, width=width)
        try:
            renderer.update_scene(data, camera=camera.view(model, data) if isinstance(camera, FollowView) else camera)
            return renderer.render().copy()
        finally:
            renderer.close()


class RecordedFrames(list):
    """RGB frames (height x width x 3, uint8), oldest first, as recorded by a `FrameRecorder`.

    A plain list of arrays to its users; it also carries the recording's `fps` [frames per s of
    simulated time], how many frames were `dropped`, their GIF encoding (`gif`), which
    `pycram.backends.sim.render.write_animation` uses to write a GIF at once, and each frame's simulated
    time [s] and caption text (`captions`, "" without a caption function).
    """

    def __init__(
        self,
        frames: Iterable[np.ndarray] = (),
        fps: float = 1.0,
        dropped: int = 0,
        gif: GifEncoder | None = None,
        captions: Iterable[tuple[float, str]] = (),
    ) -> None:
        super().__init__(frames)
        self.fps = fps
        self.dropped = dropped
        self.gif = gif
        self.captions = list(captions)

    def encoded_gif(self) -> GifEncoder | None:
        """The GIF encoding of exactly these frames, or None (e.g. after the list was changed)."""
        gif = self.gif
        return gif if gif is not None and gif.frame_count == len(self) else None


class FrameRecorder:
    """Renders frames of `camera` at `fps` [frames per s of simulated time] in its own thread.

    `camera` is a camera name of the model or a `FollowView` (a free camera that follows some
    bodies, smoothed from frame to frame). With `caption`, a function called in the simulation
    thread at each frame time (it must be quick and must not block: e.g. read a fluent), every
    frame carries a caption line: its text and the simulated time.

    The owner of the simulation calls `due(t)` and `capture(data)` from its thread; neither ever
    blocks for rendering. At most `max_pending` snapshots wait for rendering: a snapshot offered
    while that many wait is dropped (counted in `dropped`). `finish` renders the rest and ends
    the thread; `abort` ends it without rendering the rest. The thread exists from construction
    until `finish`/`abort`/`close`; none of them may be called from the simulation thread if it
    must not block (`abort` never blocks).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        camera: str | FollowView,
        fps: float,
        width: int,
        height: int,
        max_pending: int = DEFAULT_MAX_PENDING,
        name: str = "pycram-recorder",
        caption: Callable[[], str] | None = None,
    ) -> None:
        if fps <= 0:
            raise ValueError(f"fps must be positive, got {fps}")
        if width <= 0 or height <= 0:
            raise ValueError(f"frame size must be positive, got {width}x{height}")
        if max_pending < 1:
            raise ValueError(f"max_pending must be at least 1, got {max_pending}")
        self.camera, self.fps, self.size = camera, float(fps), (int(width), int(height))
        self.max_pending = max_pending
        self.caption = caption
        self._caption_failed = False
        self._model = model
        self._period = 1.0 / self.fps
        self._next: float | None = None  # simulated time of the next frame [s]; None: not started
        self._last: float | None = None  # simulated time of the last frame captured [s]
        self._pending: collections.deque[StateSnapshot] = collections.deque()
        self._cond = threading.Condition()
        self._finishing = False  # render what is pending, then end
        self._aborted = False  # end now
        self._frames: list[np.ndarray] = []
        self._captions: list[tuple[float, str]] = []
        self._gif = GifEncoder()
        self.dropped = 0  #: snapshots dropped because `max_pending` were waiting, or not rendered
        self.error: BaseException | None = None  #: why the recorder thread failed, if it did
        self.render_time = 0.0  #: wall time the thread spent on rendering and encoding [s]
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()
        _LIVE_RECORDERS.add(self)

    # ------------------------------------------------------------------ simulation side
    def start_at(self, sim_time: float) -> None:
        """Record the first frame at `sim_time` [s] and then every 1/fps s (simulation thread)."""
        self._next = sim_time

    def due(self, sim_time: float) -> bool:
        """True when a frame is due at `sim_time` [s] (exactly `fps` frames per simulated second)."""
        return self._next is not None and sim_time >= self._next - 1e-9

    def capture(self, data: mujoco.MjData) -> bool:
        """Snapshot `data` for the frame that is due and hand it to the recorder thread.

        Call from the thread that owns `data`. Never blocks on rendering (only on a lock held for
        microseconds). Returns False when the snapshot was dropped.
        """
        assert self._next is not None, "start_at() first"
        self._next += self._period
        if self._next <= data.time:  # far behind (e.g. stepped in big chunks): no burst of frames
            self._next = float(data.time) + self._period
        self._last = float(data.time)
        snapshot = StateSnapshot.of(data, self._caption_text())
        with self._cond:
            if self._finishing or self._aborted:
                return False
            if len(self._pending) >= self.max_pending:
                self.dropped += 1
                return False
            self._pending.append(snapshot)
            self._cond.notify_all()
        return True

    def capture_last(self, data: mujoco.MjData) -> bool:
        """Capture the state of `data` as the recording's last frame, unless the last frame
        captured already shows this simulated time (simulation thread; as `capture`)."""
        if self._next is None or self._last == float(data.time):
            return False
        return self.capture(data)

    def _caption_text(self) -> str:
        if self.caption is None or self._caption_failed:
            return ""
        try:
            return str(self.caption())
        except Exception:  # noqa: BLE001 - a broken caption must not stop the simulation
            self._caption_failed = True
            _log.exception("recording: the caption function failed; frames get no caption text from now on")
            return ""

    # ------------------------------------------------------------------ ending
    @property
    def running(self) -> bool:
        """True while the recorder thread runs."""
        return self._thread.is_alive()

    def abort(self) -> None:
        """Ask the thread to end without rendering what is pending (never blocks)."""
        with self._cond:
            self._aborted = True
            self._cond.notify_all()

    def finish(self, timeout: float | None = None) -> RecordedFrames:
        """Render what is pending, end the thread and return the frames.

        Waits up to `timeout` [s of wall time] (None: until done) for the pending frames; what is
        still pending then is dropped (logged). Raises `SimulationError` if rendering failed.
        On return the thread has ended (or, if a single render hangs, is abandoned: logged).
        """
        with self._cond:
            self._finishing = True
            self._cond.notify_all()
        self._thread.join(timeout)
        if self._thread.is_alive():
            with self._cond:
                left = len(self._pending)
            _log.warning("recording: %d frames still to render after %.1f s; dropping them", left, timeout)
            self.close()
        if self.error is not None:
            raise SimulationError(f"recording failed: {type(self.error).__name__}: {self.error}") from self.error
        level = logging.WARNING if self.dropped else logging.INFO
        _log.log(
            level,
            "recorded %d frames of %s at %.1f fps, %dx%d (%d dropped; %.2f s of rendering)",
            len(self._frames),
            self.camera if isinstance(self.camera, FollowView) else repr(self.camera),
            self.fps,
            *self.size,
            self.dropped,
            self.render_time,
        )
        return RecordedFrames(self._frames, self.fps, self.dropped, self._gif, self._captions)

    def close(self, timeout: float = 10.0) -> None:
        """`abort` and wait up to `timeout` [s of wall time] for the thread to end; idempotent."""
        self.abort()
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout)
            if self._thread.is_alive():  # pragma: no cover - a render that hangs in the GL driver
                _log.error("recorder thread did not stop within %.1f s", timeout)

    # ------------------------------------------------------------------ recorder thread
    def _take(self) -> StateSnapshot | None:
        """The next snapshot to render, or None when the thread must end."""
        with self._cond:
            self._cond.wait_for(lambda: self._pending or self._finishing or self._aborted)
            if self._aborted or not self._pending:
                self.dropped += len(self._pending)
                self._pending.clear()
                return None
            return self._pending.popleft()

    def _run(self) -> None:
        _lower_priority()
        renderer = None
        try:
            # A deep copy (mj_copyModel), so nothing is shared with the simulation thread afterwards.
            # The simulation only writes weld parameters and force ranges into its model while it
            # runs, which drawing never reads, so copying from here while it steps is harmless.
            model = copy.copy(self._model)
            model.vis.quality.offsamples = 0  # no multisampling: ~3x cheaper with a software renderer
            model.vis.global_.offwidth, model.vis.global_.offheight = self.size
            data = mujoco.MjData(model)
            renderer = mujoco.Renderer(model, height=self.size[1], width=self.size[0])
            view = None  # the free camera of the previous frame (FollowView)
            while (snapshot := self._take()) is not None:
                t0 = time.perf_counter()
                snapshot.apply(model, data)
                if isinstance(self.camera, FollowView):
                    view = self.camera.view(model, data, view)
                    renderer.update_scene(data, camera=view)
                else:
                    renderer.update_scene(data, camera=self.camera)
                rgb = renderer.render()
                if self.caption is not None:
                    rgb = draw_caption(rgb, snapshot.caption, snapshot.time)
                self._frames.append(rgb)
                self._captions.append((snapshot.time, snapshot.caption))
                self._gif.add(rgb)
                self.render_time += time.perf_counter() - t0
        except BaseException as exc:  # noqa: BLE001 - reported by finish()
            self.error = exc
            _log.exception("recorder thread failed")
            with self._cond:
                self._aborted = True
                self.dropped += len(self._pending)
                self._pending.clear()
        finally:
            if renderer is not None:
                renderer.close()


def draw_caption(rgb: np.ndarray, text: str, sim_time: float) -> np.ndarray:
    """`rgb` with a caption band along its bottom edge: `text` on the left, the simulated time
    `sim_time` [s] on the right (white on a dark band; a new array, `rgb` is not changed)."""
    from PIL import Image, ImageDraw

    height, width = rgb.shape[:2]
    font = _caption_font(max(10, height // 24))
    band = min(height, max(14, height // 14))
    strip = Image.new("RGB", (width, band), (20, 20, 24))  # only the band is drawn: ~4x cheaper
    draw = ImageDraw.Draw(strip)
    clock = f"t = {sim_time:5.1f} s"
    draw.text((6, band / 2), text, fill=(255, 255, 255), font=font, anchor="lm")
    draw.text(
        (width - 6 - draw.textlength(clock, font=font), band / 2), clock, fill=(255, 255, 255), font=font, anchor="lm"
    )
    captioned = rgb.copy()
    captioned[height - band :] = np.asarray(strip)
    return captioned


@functools.cache
def _caption_font(size: int):  # noqa: ANN202 - a PIL font
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def _lower_priority() -> None:
    """Lower this thread's scheduling priority by `RECORDER_NICE` (Linux: nice is per thread)."""
    try:
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + RECORDER_NICE)
    except (AttributeError, OSError):  # pragma: no cover - other systems, or not permitted
        _log.debug("could not lower the recorder's priority", exc_info=True)


__all__ = ["FrameRecorder", "RecordedFrames", "StateSnapshot", "draw_caption", "RECORDER_NICE", "DEFAULT_MAX_PENDING"]
