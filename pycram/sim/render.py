"""Rendering in the simulation thread (RGB and segmentation images) and writing image files.

Renderers are created lazily in the simulation thread (GL contexts belong to a thread) and
closed by it. Animation frames are rendered elsewhere, by a recorder thread of their own
(`pycram.sim.recording`). Writing files happens in the caller's thread from plain arrays.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Sequence

import mujoco
import numpy as np

_log = logging.getLogger(__name__)


class Renderers:
    """One `mujoco.Renderer` per image size, owned by the simulation thread."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}

    def get(self, width: int, height: int) -> mujoco.Renderer:
        key = (width, height)
        r = self._renderers.get(key)
        if r is None:
            r = mujoco.Renderer(self.model, height=height, width=width)
            self._renderers[key] = r
        return r

    def rgb(self, data: mujoco.MjData, camera: int | str, width: int, height: int) -> np.ndarray:
        """An RGB image (height x width x 3, uint8) from `camera`."""
        r = self.get(width, height)
        r.disable_segmentation_rendering()
        r.update_scene(data, camera=camera)
        return r.render().copy()

    def segmentation(self, data: mujoco.MjData, camera: int | str, width: int, height: int) -> np.ndarray:
        """Geom ids per pixel (height x width, int; -1 for background) from `camera`."""
        r = self.get(width, height)
        r.enable_segmentation_rendering()
        try:
            r.update_scene(data, camera=camera)
            seg = r.render()
        finally:
            r.disable_segmentation_rendering()
        ids = seg[:, :, 0].astype(np.int64)
        ids[seg[:, :, 1] != int(mujoco.mjtObj.mjOBJ_GEOM)] = -1
        return ids

    def depth(self, data: mujoco.MjData, camera: int | str, width: int, height: int) -> np.ndarray:
        """Distance along the optical axis per pixel [m] (height x width, float32) from `camera`."""
        r = self.get(width, height)
        r.enable_depth_rendering()
        try:
            r.update_scene(data, camera=camera)
            depth = r.render().copy()
        finally:
            r.disable_depth_rendering()
        return depth

    def close(self) -> None:
        for r in self._renderers.values():
            try:
                r.close()
            except Exception:  # pragma: no cover - best effort at shutdown
                _log.debug("renderer close failed", exc_info=True)
        self._renderers.clear()


def write_png(path: str | Path, image: np.ndarray) -> Path:
    """Write an RGB image to a PNG file; returns the path."""
    import imageio.v3 as iio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, image)
    return path


def write_animation(path: str | Path, frames: Sequence[np.ndarray], fps: float) -> Path:
    """Write frames (RGB arrays of one size) to an animation at `fps` [frames per s of the video].

    ".gif" always works (our own `GifEncoder` on Pillow): frames returned by
    `World.stop_recording` (`RecordedFrames`) were encoded while they were recorded and are
    written at once; other frames are encoded here (a few ms per frame, palette from up to 8
    of them). ".mp4" and other video formats need a video backend (`pip install
    imageio-ffmpeg` or `av`) and raise `SimulationError` saying so when none is installed.
    Raises ValueError when there are no frames.
    """
    from .errors import SimulationError
    from .gif import GifEncoder
    from .recording import RecordedFrames

    if not len(frames):
        raise ValueError("no frames recorded")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".gif":
        encoder = frames.encoded_gif() if isinstance(frames, RecordedFrames) else None
        if encoder is None:
            samples = [frames[i] for i in np.linspace(0, len(frames) - 1, min(8, len(frames))).round().astype(int)]
            encoder = GifEncoder(palette_from=[s[::2, ::2] for s in samples])
            for frame in frames:
                encoder.add(frame)
        return encoder.write(path, fps)
    import imageio.v3 as iio

    try:
        iio.imwrite(path, np.stack(frames), fps=fps)
    except Exception as exc:  # imageio raises several types when no plugin can write the format
        raise SimulationError(f"cannot write {path.suffix!r} animations ({type(exc).__name__}: {exc}); "
                              "use a .gif path, or install imageio-ffmpeg (or av) for video") from exc
    return path
