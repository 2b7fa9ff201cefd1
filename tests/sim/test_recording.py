"""Animation recording: frames are rendered by a recorder thread of their own from state
snapshots (never from the simulation's MjData), the thread ends with the recording or the world,
full queues drop frames instead of blocking the simulation, and GIFs are encoded frame by frame.

No assertion here is about wall-clock speed.
"""

from __future__ import annotations

import threading

import imageio.v3 as iio
import mujoco
import numpy as np
import pytest
from PIL import Image
from sim_helpers import ok, wait_wall

from pycram.backends.sim.gif import TRANSPARENT, GifEncoder
from pycram.backends.sim.recording import FrameRecorder, RecordedFrames, StateSnapshot
from pycram.backends.sim.render import write_animation
from pycram.backends.sim.scene import build_scene, initial_state
from pycram.sim import World


def recorder_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name.startswith("pycram-recorder")]


def test_recording_runs_in_its_own_thread_and_ends_with_it(world, tmp_path, monkeypatch):
    """While recording, a recorder thread renders; the simulation's MjData is only ever used by
    the simulation thread; after `stop_recording` no recorder thread is left; the frames move."""
    sim_data = world._engine.data
    calls: list[tuple[int, bool]] = []  # (thread, is the simulation's data)
    lock = threading.Lock()

    def spy(fn, data_position):
        def wrapper(*args, **kwargs):
            with lock:
                calls.append((threading.get_ident(), args[data_position] is sim_data))
            return fn(*args, **kwargs)

        return wrapper

    monkeypatch.setattr(mujoco, "mj_kinematics", spy(mujoco.mj_kinematics, 1))
    monkeypatch.setattr(mujoco, "mj_camlight", spy(mujoco.mj_camlight, 1))
    monkeypatch.setattr(mujoco.Renderer, "update_scene", spy(mujoco.Renderer.update_scene, 1))

    before = set(threading.enumerate())
    assert recorder_threads() == []
    ok(world.start_recording(fps=20, width=200, height=150))
    (recorder,) = recorder_threads()
    assert recorder is not world._thread and recorder.is_alive()
    base = world.base_pose.get_value()
    ok(world.drive_to(base.x + 0.3, base.y, base.yaw))
    frames = world.stop_recording(tmp_path / "run.gif")

    assert not recorder.is_alive() and recorder_threads() == []
    assert set(threading.enumerate()) <= before
    assert isinstance(frames, RecordedFrames) and frames.fps == 20 and frames.dropped == 0
    assert len(frames) >= 5 and all(f.shape == (150, 200, 3) and f.dtype == np.uint8 for f in frames)
    first = frames[0].astype(int)
    assert any(np.abs(first - f.astype(int)).max() > 30 for f in frames[1:])  # it moves
    changed = [np.abs(a.astype(int) - b.astype(int)).max() > 30 for a, b in zip(frames, frames[1:])]
    assert sum(changed) >= 3  # not a single jump: the motion is spread over several frames
    assert Image.open(tmp_path / "run.gif").n_frames >= 5
    on_recorder = [is_sim for ident, is_sim in calls if ident == recorder.ident]
    assert on_recorder and not any(on_recorder)  # the recorder rendered, from its own data
    assert {ident for ident, is_sim in calls if is_sim} <= {world._thread.ident}
    ok(world.drive_to(base.x, base.y, base.yaw))


def test_close_ends_a_running_recording():
    before = set(threading.enumerate())
    with World("pr2") as w:
        ok(w.start_recording(fps=10, width=160, height=120))
        (recorder,) = recorder_threads()
        t0 = w.sim_time.get_value()
        assert wait_wall(lambda: w.sim_time.get_value() > t0 + 0.5, [w.sim_time])
    assert not recorder.is_alive()
    assert set(threading.enumerate()) <= before


def test_frames_may_be_larger_than_the_offscreen_size():
    with World("tiago", offscreen_size=(320, 240)) as w:
        ok(w.start_recording(fps=10, width=400, height=300))
        t0 = w.sim_time.get_value()
        assert wait_wall(lambda: w.sim_time.get_value() > t0 + 0.2, [w.sim_time])
        frames = w.stop_recording()
    assert frames and frames[0].shape == (300, 400, 3) and frames[0].std() > 5


def test_stop_without_recording_returns_no_frames(world):
    assert world.stop_recording() == []
    with pytest.raises(ValueError, match="no frames"):
        world.stop_recording("/nonexistent/never-written.gif")


@pytest.fixture(scope="module")
def scene():
    return build_scene("pr2")


def test_a_snapshot_poses_what_is_drawn_like_the_simulation(scene):
    """`StateSnapshot.apply` on another MjData gives the body, geom, camera and light poses of
    the simulation's own data (items and obstacles included)."""
    model = scene.model
    sim = initial_state(scene, (0.8, 0.6, 0.4))
    sim.mocap_pos[0] = (1.5, 2.0, 0.0)
    mujoco.mj_step(model, sim, nstep=50)
    mujoco.mj_forward(model, sim)  # poses of the current qpos
    copy = mujoco.MjData(model)
    StateSnapshot.of(sim).apply(model, copy)
    for field in ("xpos", "xquat", "geom_xpos", "geom_xmat", "cam_xpos", "cam_xmat", "light_xpos", "light_xdir"):
        np.testing.assert_allclose(getattr(copy, field), getattr(sim, field), atol=1e-9, err_msg=field)
    assert copy.time == sim.time


def test_a_full_queue_drops_frames_instead_of_blocking(scene, monkeypatch):
    """With the recorder stuck on a frame, `capture` still returns at once; beyond `max_pending`
    snapshots are dropped and counted, and every captured frame is either rendered or dropped."""
    release = threading.Event()
    original = StateSnapshot.apply

    def stuck_apply(self, model, data):
        release.wait(60)
        original(self, model, data)

    monkeypatch.setattr(StateSnapshot, "apply", stuck_apply)
    data = initial_state(scene, (0.8, 0.6, 0.0))
    recorder = FrameRecorder(scene.model, "overview", fps=10, width=64, height=48, max_pending=2)
    try:
        recorder.start_at(0.0)
        captured = 0
        for step in range(20):
            data.time = 0.1 * step
            assert recorder.due(data.time)
            captured += 1
            recorder.capture(data)
            assert not recorder.due(data.time)
        assert recorder.dropped >= captured - 3  # one may be taken, two wait
        release.set()
        frames = recorder.finish(timeout=60)
    finally:
        release.set()
        recorder.close()
    assert not recorder.running
    assert len(frames) + frames.dropped == captured and len(frames) >= 2


def test_gif_encoder_round_trip(tmp_path):
    """Frames decode to what was added (exact here: few colours); identical frames are merged
    into one longer frame; delays add up to the exact duration; a colour that was not in the
    first frame still comes out close to itself."""
    a = np.full((40, 60, 3), 255, np.uint8)
    a[:10] = (200, 30, 30)
    b = a.copy()
    b[20:30, 20:30] = (10, 20, 240)  # not in the first frame: the colour cube catches it
    c = a.copy()
    c[0:5, 50:60] = 255
    frames = [a, b, b, c, a]
    encoder = GifEncoder()
    for f in frames:
        encoder.add(f)
    assert encoder.frame_count == 5
    path = encoder.write(tmp_path / "x.gif", fps=3.0)
    gif = Image.open(path)
    assert gif.n_frames == 4 and gif.info["loop"] == 0
    durations, decoded = [], []
    for i in range(gif.n_frames):
        gif.seek(i)
        durations.append(gif.info["duration"])
        decoded.append(np.asarray(gif.convert("RGB")).astype(int))
    assert sum(durations) == pytest.approx(1000 * 5 / 3.0, abs=10)
    assert durations[1] >= 2 * durations[0] - 10  # b shown for two frames
    for got, want in zip(decoded, [a, b, c, a]):
        assert np.abs(got - want).max() <= 64
    np.testing.assert_array_equal(decoded[0], a)
    np.testing.assert_array_equal(decoded[2], c)
    with pytest.raises(ValueError):
        encoder.add(np.zeros((10, 10, 3), np.uint8))
    with pytest.raises(ValueError):
        GifEncoder().write(tmp_path / "empty.gif", 10)
    assert TRANSPARENT == 255


def test_write_animation_of_plain_and_recorded_frames(tmp_path):
    rng = np.random.default_rng(0)
    frames = []
    for i in range(6):
        f = np.full((48, 64, 3), 90, np.uint8)
        f[10:20, 5 + 8 * i : 15 + 8 * i] = (250, 200, 40)
        f[30:, :] = rng.integers(0, 60, (18, 64, 3), dtype=np.uint8)  # static noise
        if i == 5:
            f[30:, :] = 0
        frames.append(f)
    plain = write_animation(tmp_path / "plain.gif", frames, 10)
    encoder = GifEncoder()
    for f in frames:
        encoder.add(f)
    recorded = write_animation(tmp_path / "recorded.gif", RecordedFrames(frames, 10, 0, encoder), 10)
    for path in (plain, recorded):
        out = iio.imread(path, index=None)
        assert out.shape[0] == 6 and out.shape[1:3] == (48, 64)
        assert np.abs(out[..., :3].astype(int) - np.stack(frames).astype(int)).mean() < 8
    # a RecordedFrames whose list was changed is encoded again, from its frames
    changed = RecordedFrames(frames, 10, 0, encoder)
    changed.pop()
    assert changed.encoded_gif() is None
    assert iio.imread(write_animation(tmp_path / "changed.gif", changed, 10), index=None).shape[0] == 5


# -- interrupted recordings (issue 12: Ctrl-C shortly after the plan ended crashed with SIGSEGV) --

_INTERRUPT_PROBE = r'''
import sys, threading
from pycram.sim import World

class InterruptAt:
    """A trace function raising KeyboardInterrupt at the k-th new line run in pycram/backends/sim/ (this
    thread). A line already run in the same frame is skipped: that is a loop, or the end of a
    `with` block, where an exception from a trace function lands after the lock was taken and
    before the block's exit runs (which Python's own `with lock:` cannot survive either)."""
    def __init__(self, k):
        self.k, self.lines, self.hit = k, 0, False
    def __call__(self, frame, event, arg):
        if "/pycram/backends/sim/" not in frame.f_code.co_filename:
            return None
        seen = set()
        def line(frame, event, arg):
            if event == "line" and not self.hit and frame.f_lineno not in seen:
                seen.add(frame.f_lineno)
                self.lines += 1
                if self.lines == self.k:
                    self.hit = True
                    raise KeyboardInterrupt(f"line {frame.f_lineno} of {frame.f_code.co_name}")
            return line
        return line

first, stride = int(sys.argv[1]), int(sys.argv[2])
k, points = first, 0
while True:
    world = World("pr2", [], offscreen_size=(64, 48))
    world.start_recording(fps=50, width=64, height=48, caption=lambda: "probe").wait(5.0)
    assert (world.sim_time > 0.4).wait_for(30.0), "the simulation does not advance"
    probe = InterruptAt(k)
    sys.settrace(probe)
    try:
        world.stop_recording()
    except KeyboardInterrupt as e:
        print("interrupted at", e)
    finally:
        sys.settrace(None)
    world.close()
    left = [t.name for t in threading.enumerate() if t.name.startswith("pycram-")]
    assert not left, f"threads left after close() (interrupted at point {k}): {left}"
    if not probe.hit:
        break
    points += 1
    k += stride
print(f"interrupted at {points} points of {probe.lines}")
'''


def test_an_interrupted_stop_recording_leaves_no_thread_after_close(tmp_path):
    """`stop_recording` is interrupted (KeyboardInterrupt raised by a trace hook) at every third
    line it runs in pycram/backends/sim/ — in the world, the handle, the recorder's `finish` — each time in
    a fresh world; `close()` must then leave no thread of ours, and the process must exit normally
    (before the fix the recorder thread outlived `close()`, and a daemon thread still inside MuJoCo
    at interpreter shutdown crashed the process with SIGSEGV)."""
    import os
    import subprocess
    import sys

    script = tmp_path / "probe.py"
    script.write_text(_INTERRUPT_PROBE)
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    done = subprocess.run([sys.executable, str(script), "1", "3"], capture_output=True, text=True, timeout=240, env=env)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-4000:]
    points = done.stdout.count("interrupted at ")
    assert points >= 10, done.stdout
    assert "of finish" in done.stdout and "of stop_recording" in done.stdout


def test_captions_are_taken_when_the_frame_is_due_and_drawn_on_it(world, tmp_path):
    """The caption function runs in the simulation thread at each frame time; each frame keeps
    its text and simulated time, and carries a dark caption band with light text."""
    from pycram.sim import FollowView

    callers: set[int] = set()
    count = iter(range(10_000))

    def caption() -> str:
        callers.add(threading.get_ident())
        return f"frame {next(count)}"

    view = FollowView((world.description.ROOT_LINK,), min_distance=2.5)
    ok(world.start_recording(view, fps=20, width=160, height=120, caption=caption))
    base = world.base_pose.get_value()
    ok(world.drive_to(base.x + 0.2, base.y, base.yaw))
    frames = world.stop_recording()

    assert callers == {world._thread.ident}
    assert len(frames.captions) == len(frames) >= 5
    assert [text for _, text in frames.captions] == [f"frame {i}" for i in range(len(frames))]
    times = [t for t, _ in frames.captions]
    assert all(0 < b - a < 0.1 for a, b in zip(times, times[1:]))
    band = frames[0][-12:]
    assert band.mean() < 80 and (band.min(axis=2) > 200).any()


def test_a_follow_view_of_an_unknown_body_is_refused(world):
    from pycram.sim import FollowView

    with pytest.raises(ValueError, match="no body 'teapot'"):
        world.start_recording(FollowView(("teapot",)))
    with pytest.raises(ValueError, match="no body 'teapot'"):
        world.request_image(FollowView(("teapot",)))
