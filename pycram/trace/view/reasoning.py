"""Location reasoning in a view: the costmap layers of a base-pose resolution, the candidates
tried with why each was ruled out, and the pose chosen.

`log_costmaps(recording, maps)` and `log_candidates(recording, candidates)` log, on the
recording's current times:

- ``reasoning/layers/NAME/LAYER``: each layer as an image over the floor (dark: cheap, light:
  costly, red: forbidden), and ``reasoning/costmap/NAME`` the sum as coloured points on the
  floor in 3D (green: cheap, red: costly; forbidden cells are left out);
- ``reasoning/candidates``: the candidates tried, as points at their base positions labelled
  with why each was ruled out (green: accepted), and ``reasoning/chosen`` the first accepted
  one, as an arrow along its heading -- when the reasoner keeps its candidates
  (``last_candidates``: (x [m], y [m], arm, reason or None) per candidate).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from . import paths

__all__ = ["log_costmaps", "log_candidates", "MAX_POINTS"]

#: At most this many cells of a sum are drawn in 3D (a coarser sample of bigger maps).
MAX_POINTS = 6000
_REASON_COLORS = [(229, 57, 53), (251, 140, 0), (142, 36, 170), (30, 136, 229), (121, 85, 72), (96, 125, 139)]


def _image(values: np.ndarray) -> np.ndarray:
    """A layer as an RGB image, north up: finite costs grey (dark: cheap), forbidden cells red."""
    finite = np.isfinite(values)
    out = np.zeros((*values.shape, 3), np.uint8)
    if finite.any():
        low, high = float(values[finite].min()), float(values[finite].max())
        scaled = (values - low) / (high - low) if high > low else np.zeros_like(values)
        grey = (40 + 200 * np.clip(np.where(finite, scaled, 0.0), 0.0, 1.0)).astype(np.uint8)
        out[..., 0] = out[..., 1] = out[..., 2] = grey
    out[~finite] = (200, 30, 30)
    return out[::-1]  # row 0 is the south edge of the grid


def log_costmaps(recording: Any, maps: Mapping[str, Any]) -> None:
    """Log the costmaps `maps` (name -> `Costmap`) of one resolution (see the module docstring)."""
    import rerun as rr
    from rerun import escape_entity_path_part as esc

    recording.log(paths.COSTMAP, rr.Clear(recursive=True))
    recording.log(paths.COSTMAP_LAYERS, rr.Clear(recursive=True))
    for name, costmap in maps.items():
        for layer, values in costmap.layers.items():
            recording.log(
                f"{paths.COSTMAP_LAYERS}/{esc(name)}/{esc(layer)}", rr.Image(_image(np.asarray(values, float)))
            )
        total = np.asarray(costmap.total(), float)
        finite = np.flatnonzero(np.isfinite(total).ravel())
        if finite.size == 0:
            continue
        step = max(1, finite.size // MAX_POINTS)
        cells = finite[::step]
        costs = total.ravel()[cells]
        low, high = float(costs.min()), float(costs.max())
        share = (costs - low) / (high - low) if high > low else np.zeros_like(costs)
        colors = np.stack([255 * share, 255 * (1 - share), np.full_like(share, 60)], axis=1).astype(np.uint8)
        xs, ys = np.asarray(costmap.grid.x).ravel()[cells], np.asarray(costmap.grid.y).ravel()[cells]
        points = np.stack([xs, ys, np.full_like(xs, 0.01)], axis=1)
        recording.log(f"{paths.COSTMAP}/{esc(name)}", rr.Points3D(points, colors=colors, radii=0.015))


def log_candidates(recording: Any, candidates: Sequence[tuple[Any, ...]]) -> None:
    """Log the candidates of one search, (x [m], y [m], arm, reason or None, yaw [rad] or None)
    each, and the first accepted one (see the module docstring)."""
    import rerun as rr

    reasons: dict[str, int] = {}
    positions, colors, labels = [], [], []
    chosen = None
    for candidate in candidates:
        x, y, arm, reason = candidate[:4]
        positions.append((float(x), float(y), 0.03))
        if reason is None:
            colors.append((67, 200, 71))
            labels.append(f"accepted{f' ({arm})' if arm else ''}")
            if chosen is None:
                chosen = candidate
        else:
            index = reasons.setdefault(str(reason), len(reasons))
            colors.append(_REASON_COLORS[index % len(_REASON_COLORS)])
            labels.append(f"{reason}{f' ({arm})' if arm else ''}")
    if positions:
        recording.log(paths.CANDIDATES, rr.Points3D(positions, colors=colors, labels=labels, radii=0.03))
    if chosen is not None and len(chosen) > 4 and chosen[4] is not None:
        yaw = float(chosen[4])
        recording.log(
            paths.CHOSEN,
            rr.Arrows3D(
                origins=[(float(chosen[0]), float(chosen[1]), 0.05)],
                vectors=[(0.4 * np.cos(yaw), 0.4 * np.sin(yaw), 0.0)],
                colors=[(67, 200, 71)],
                labels=["chosen"],
            ),
        )
    elif chosen is None:
        recording.log(paths.CHOSEN, rr.Clear(recursive=False))
