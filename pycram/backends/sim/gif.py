"""`GifEncoder`: an animated GIF built one frame at a time, so that writing the file is fast.

Each frame is quantized to one global palette, compared with the frame shown before it and
LZW-compressed right away (only the rectangle that changed; unchanged pixels inside it are
transparent). Writing the file then only joins the compressed frames with their delays, which
are chosen at write time (the playback rate need not be known while recording).

The palette has 255 colours (index 255 is the transparent index): 228 computed from the first
frame (or from sample frames given to the constructor) and a coarse 3 x 3 x 3 colour cube, so
that a colour which appears only later still maps to a colour of about the right hue. Every
pixel is mapped to its nearest palette colour (no dithering, so unchanged regions stay unchanged
from frame to frame).
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import GifImagePlugin, Image

_log = logging.getLogger(__name__)

#: Palette index of transparent pixels in delta frames; quantized frames never use it.
TRANSPARENT = 255
_ADAPTIVE_COLOURS = 228
_CUBE = bytes(c for r in (0, 128, 255) for g in (0, 128, 255) for b in (0, 128, 255) for c in (r, g, b))
_LOOP_FOREVER = b"!\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00"


@dataclass
class _Frame:
    """One compressed frame: image descriptor + LZW data, shown for `count` recorded frames."""

    block: bytes
    count: int
    transparent: bool


class GifEncoder:
    """Collects RGB frames of one size (height x width x 3, uint8) as compressed GIF frames.

    `add` costs a few milliseconds per frame (quantization, difference, LZW); `write` only joins
    bytes. Not thread-safe: one thread adds; `write` must not run concurrently with `add`.
    """

    def __init__(self, palette_from: Sequence[np.ndarray] = ()) -> None:
        """`palette_from`: frames to compute the palette from (default: the first added frame)."""
        self._palette_image: Image.Image | None = None
        self._palette_bytes = b""
        if len(palette_from):
            self._set_palette(np.concatenate([_rgb(f) for f in palette_from], axis=0))
        self._size: tuple[int, int] | None = None  # (width, height) [px]
        self._previous: np.ndarray | None = None  # palette indices of the frame shown last
        self._frames: list[_Frame] = []
        self.frame_count = 0  #: frames added (identical consecutive frames included)

    # ------------------------------------------------------------------ adding
    def _set_palette(self, rgb: np.ndarray) -> None:
        quantized = Image.fromarray(rgb).quantize(
            _ADAPTIVE_COLOURS, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
        )
        used = int(np.asarray(quantized).max()) + 1
        colours = bytes(quantized.getpalette() or [])[: 3 * used] + _CUBE
        self._palette_image = Image.new("P", (1, 1))
        self._palette_image.putpalette(colours)
        self._palette_bytes = colours

    def _indices(self, rgb: np.ndarray) -> np.ndarray:
        assert self._palette_image is not None
        image = Image.fromarray(rgb).quantize(palette=self._palette_image, dither=Image.Dither.NONE)
        return np.asarray(image)

    def add(self, frame: np.ndarray) -> None:
        """Append a frame (height x width x 3 uint8 RGB; the same size as the first frame).

        A frame identical (after quantization) to the previous one only lengthens that one's
        display time. Raises ValueError for a frame of another size or shape.
        """
        rgb = _rgb(frame)
        size = (rgb.shape[1], rgb.shape[0])
        if self._size is None:
            self._size = size
            if self._palette_image is None:
                self._set_palette(rgb)
        elif size != self._size:
            raise ValueError(f"frame of {size[0]}x{size[1]} px in an animation of {self._size[0]}x{self._size[1]} px")
        indices = self._indices(rgb)
        self.frame_count += 1
        previous = self._previous
        if previous is None:
            self._frames.append(_Frame(_compress(indices, (0, 0)), 1, False))
            self._previous = indices
            return
        changed = indices != previous
        rows = np.flatnonzero(changed.any(axis=1))
        if rows.size == 0:
            self._frames[-1].count += 1
            return
        cols = np.flatnonzero(changed.any(axis=0))
        y0, y1, x0, x1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
        patch = indices[y0:y1, x0:x1].copy()
        patch[~changed[y0:y1, x0:x1]] = TRANSPARENT
        self._frames.append(_Frame(_compress(patch, (x0, y0)), 1, True))
        self._previous = indices

    # ------------------------------------------------------------------ writing
    def write(self, path: str | Path, fps: float) -> Path:
        """Write the animation to `path`, played at `fps` [frames per s], looping; returns the path.

        Delays are rounded to the GIF's 1/100 s so that their sum stays exact (no drift).
        Raises ValueError when no frame was added or `fps` is not positive.
        """
        if not self._frames or self._size is None:
            raise ValueError("no frames recorded")
        if fps <= 0:
            raise ValueError(f"fps must be positive, got {fps}")
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        palette = self._palette_bytes.ljust(768, b"\0")
        parts = [b"GIF89a", struct.pack("<HHBBB", *self._size, 0xF7, 0, 0), palette, _LOOP_FOREVER]
        shown = 0  # recorded frames shown before this one
        for frame in self._frames:
            start, end = round(100 * shown / fps), round(100 * (shown + frame.count) / fps)
            shown += frame.count
            flags = (1 << 2) | int(frame.transparent)  # disposal 1: keep this frame under the next
            parts.append(b"!\xf9\x04" + struct.pack("<BHBB", flags, end - start, TRANSPARENT, 0))
            parts.append(frame.block)
        parts.append(b";")
        path.write_bytes(b"".join(parts))
        _log.debug("wrote %s: %d frames (%d stored) at %.1f fps", path, self.frame_count, len(self._frames), fps)
        return path


def _rgb(frame: np.ndarray) -> np.ndarray:
    array = np.asarray(frame)
    if array.dtype != np.uint8 or array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"expected height x width x 3 uint8 RGB frames, got {array.dtype} {array.shape}")
    return np.ascontiguousarray(array)


def _compress(indices: np.ndarray, offset: tuple[int, int]) -> bytes:
    """Image descriptor and LZW data of palette `indices` placed at `offset` (x, y) [px]."""
    height, width = indices.shape
    image = Image.frombytes("P", (width, height), np.ascontiguousarray(indices).tobytes())
    return b"".join(GifImagePlugin.getdata(image, offset))


__all__ = ["GifEncoder", "TRANSPARENT"]
