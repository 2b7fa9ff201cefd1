"""Rendering in the simulation thread (RGB and segmentation images) and writing image files.

Renderers are created lazily in the simulation thread (GL contexts belong to a thread) and
closed by it. Animation frames are rendered elsewhere, by a recorder thread of their own
(`pycram.backends.sim.recording`). Writing files happens in the caller's thread from plain arrays.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np

from .camera import FollowView

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

    def rgb(
        self, data: mujoco.MjData, camera: int | str | FollowView, width: int, height: int, shadows: bool = True
    ) -> np.ndarray:
        """An RGB image (height x width x 3, uint8) from `camera` (id, name or `FollowView`);
        `shadows` False also leaves out reflections (faster: what object perception uses)."""
        r = self.get(width, height)
        r.disable_segmentation_rendering()
        r.update_scene(data, camera=camera.view(self.model, data) if isinstance(camera, FollowView) else camera)
        if shadows:
            return r.render().copy()
        flags = r.scene.flags.copy()
        r.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        r.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        try:
            return r.render().copy()
        finally:
            np.copyto(r.scene.flags, flags)

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

    def segmentation_and_depth(
        self, data: mujoco.MjData, camera: int | str, width: int, height: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Geom ids per pixel (-1: background or not a geom) and the distance along the optical
        axis per pixel [m] (float32), both height x width, from one render of `camera`.

        Reads colour and depth buffers of the same segmentation render (mujoco's `Renderer`
        needs two renders for them, and maps ids in a slower Python loop); uses the Renderer's
        GL context, viewport and mjr context (mujoco 3/4 `Renderer` internals, version pinned).
        """
        r = self.get(width, height)
        r.update_scene(data, camera=camera)
        scene = r.scene
        flags = scene.flags.copy()
        scene.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = True
        scene.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = True
        colour = np.empty((height, width, 3), np.uint8)
        depth = np.empty((height, width), np.float32)
        try:
            if r._gl_context:
                r._gl_context.make_current()
            mujoco.mjr_render(r._rect, scene, r._mjr_context)
            mujoco.mjr_readPixels(colour, depth, r._rect, r._mjr_context)
        finally:
            np.copyto(scene.flags, flags)
        colour, depth = colour[::-1], depth[::-1]  # GL images are upside down
        segid = (
            colour[:, :, 0].astype(np.int64)
            | (colour[:, :, 1].astype(np.int64) << 8)
            | (colour[:, :, 2].astype(np.int64) << 16)
        )
        n = scene.ngeom
        geoms = scene.geoms[:n]
        lookup = np.full(n + 1, -1, np.int64)  # segid 0 is the background; segid i + 1 is scene geom i
        lookup[1:] = [g.objid if g.objtype == int(mujoco.mjtObj.mjOBJ_GEOM) else -1 for g in geoms]
        ids = lookup[np.clip(segid, 0, n)]
        # reversed-Z depth buffer values to metric depth (as mujoco.Renderer does)
        extent = self.model.stat.extent
        near, far = np.float32(self.model.vis.map.znear * extent), np.float32(self.model.vis.map.zfar * extent)
        c = np.float32(-0.5) * (-(far + near) / (far - near)) - np.float32(0.5)
        d = np.float32(-0.5) * (-(np.float32(2) * far * near) / (far - near))
        metric = (d / (depth.astype(np.float64) + c)).astype(np.float32)
        return ids, metric

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
        raise SimulationError(
            f"cannot write {path.suffix!r} animations ({type(exc).__name__}: {exc}); "
            "use a .gif path, or install imageio-ffmpeg (or av) for video"
        ) from exc
    return path
