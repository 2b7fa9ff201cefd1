"""The simulated head camera's object perception: segmentation, depth and colour images in,
`pycram.world.belief.Detection`s out, with configurable faults.

The recogniser names an object's type from the object its segmented pixels belong to (as a
trained detector would); everything else is measured: the pixels are back-projected with the
depth image into map points, whose extent gives the size and centre, whose mean colour gives the
colour name, and whose lowest point, with the environment's description, gives the supporting
surface. Objects inside a closed drawer or behind the fridge door are hidden by the furniture's
geometry in the rendering; objects hidden behind others likewise.

`PerceptionFaults` (per world, all off by default) add Gaussian noise to the measured centre,
drop detections with a probability, and name a wrong colour with a probability, drawn from a
random generator seeded per world so that runs repeat.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, cast

import numpy as np

from pycram.world.belief import (
    COLOR_NAMES,
    CameraView,
    Detection,
    Vec3,
    color_name,
    support_of,
)
from pycram.world.environment import Environment
from pycram.world.objects import OBJECT_TYPES

__all__ = ["MAX_RANGE", "MIN_PIXELS", "PerceptionFaults", "measure_detections", "side_direction", "view_of"]

#: Objects farther from the camera than this [m] are not detected.
MAX_RANGE = 3.5
#: Fewest visible pixels for a detection.
MIN_PIXELS = 20


@dataclass(frozen=True)
class PerceptionFaults:
    """Faults of the simulated object perception (all off by default).

    `pose_noise`: standard deviation [m] of Gaussian noise on each coordinate of a measured
    centre; `miss_probability`: probability that a visible object is not reported;
    `wrong_color_probability`: probability that another colour name is reported; `seed` seeds
    the world's fault generator.
    """

    pose_noise: float = 0.0
    miss_probability: float = 0.0
    wrong_color_probability: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.pose_noise < 0.0:
            raise ValueError(f"pose_noise must be >= 0 [m], got {self.pose_noise}")
        for name in ("miss_probability", "wrong_color_probability"):
            p = getattr(self, name)
            if not 0.0 <= p <= 1.0:
                raise ValueError(f"{name} is a probability in [0, 1], got {p}")

    @property
    def any(self) -> bool:
        return bool(self.pose_noise or self.miss_probability or self.wrong_color_probability)


def _back_project(view: CameraView, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Map points [m] (n x 3) of the pixels (rows, cols) with the view's depth."""
    width, height = view.size
    focal = 0.5 * height / math.tan(math.radians(view.fovy) / 2.0)
    depth = view.depth[rows, cols]
    local = np.stack(
        [(cols + 0.5 - width / 2.0) / focal * depth, -(rows + 0.5 - height / 2.0) / focal * depth, -depth], axis=1
    )
    return local @ np.asarray(view.rotation, float).reshape(3, 3).T + np.asarray(view.position, float)


#: A round object's rim counts as seen when its highest point seen is at most this far [m] below
#: its top (standing on the surface under it).
RIM_SLACK = 0.015
#: A pixel beside an object's that is this much [m] nearer the camera hides part of the object.
OCCLUDER_GAP = 0.02
#: An object's pixels this close [m] to its extent's end on one side make up that side's edge ...
EDGE_BAND = 0.015
#: ... which is hidden when at least this share of its outline pixels there border something
#: nearer the camera (or the image's border).
HIDDEN_SHARE = 0.5


def hidden_outline(labels: np.ndarray, depth: np.ndarray, index: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Per pixel (`rows`, `cols`) of object `index` in the per-pixel object `labels`: (outline,
    hidden) -- whether it borders a pixel that is not the object's, and whether that neighbour
    is something nearer the camera by more than `OCCLUDER_GAP` (`depth` [m]) or lies beyond the
    image's border: the object may go on behind it."""
    height, width = labels.shape
    near = depth[rows, cols] - OCCLUDER_GAP
    outline = np.zeros(len(rows), bool)
    hidden = np.zeros(len(rows), bool)
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        r, c = rows + dr, cols + dc
        off_image = (r < 0) | (r >= height) | (c < 0) | (c >= width)
        r, c = np.clip(r, 0, height - 1), np.clip(c, 0, width - 1)
        other = off_image | (labels[r, c] != index)
        outline |= other
        hidden |= off_image | (other & (depth[r, c] < near))
    return np.stack([outline, hidden])


def _cut(values: np.ndarray, outline: np.ndarray, hidden: np.ndarray) -> tuple[bool, bool]:
    """Whether the object's extent along `values` [m] (one value per pixel) is cut short at its
    low end and at its high end: most outline pixels at that end border an occluder."""
    ends = []
    for band in (values <= values.min() + EDGE_BAND, values >= values.max() - EDGE_BAND):
        edge = band & outline
        ends.append(bool(edge.any()) and float(hidden[edge].mean()) >= HIDDEN_SHARE)
    return ends[0], ends[1]


def _uncut_centre(
    low: float, high: float, cut: tuple[bool, bool], extent: float | None, exact: bool
) -> tuple[float, float]:
    """The centre [m] of an extent seen from `low` to `high` and how far off it may be [m],
    knowing the object is at most `extent` long there (None: not known), `exact`ly so for a
    round one: where one end of a round object is hidden, it reaches on behind it from the seen
    end; where both ends are hidden, or a box's (its extent in view depends on its turn), the
    middle of what is seen, off by up to half of what is missing."""
    middle = (low + high) / 2.0
    if extent is None or high - low >= extent or not any(cut):
        return middle, 0.0
    if exact and cut[0] != cut[1]:
        return (high - extent / 2.0 if cut[0] else low + extent / 2.0), 0.0
    return middle, (extent - (high - low)) / 2.0


def _footprint_extent(type_name: str) -> tuple[float | None, bool]:
    """The longest a type's footprint can be in any horizontal direction [m] and whether that is
    its extent in every direction (a round object's diameter: a cup, a bowl, a plate) -- a box's
    is its footprint's diagonal; (None, False) for an unknown type."""
    otype = OBJECT_TYPES.get(type_name)
    if otype is None:
        return None, False
    if otype.shape != "box":
        return 2.0 * otype.size[0], True
    return 2.0 * math.hypot(otype.size[0], otype.size[1]), False


def _measure(
    view: CameraView,
    type_name: str,
    points: np.ndarray,
    colours: np.ndarray,
    environment: Environment,
    container_states: dict[str, float],
    outline: np.ndarray | None = None,
) -> Detection:
    """A detection from an object's visible pixels: their map `points` [m] and `colours`;
    `outline`: per pixel, whether it borders something else and whether that hides the object
    (`hidden_outline`). A round object's extent cut short by something nearer the camera (a
    shelf above, a fridge's side wall, another object) is completed from its seen side with its
    type's diameter where its rim is seen (measured: a bowl on a fridge shelf half hidden by the
    wall was believed 4.7 cm off its centre, and the gripper closed beside it). Where what is
    seen cannot say where the centre is (both ends hidden, a box's end, the rim not seen), the
    detection's `slack` says how far off its centre may be."""
    # horizontal axes of the view: across it and along it (away from the camera)
    rotation = np.asarray(view.rotation, float).reshape(3, 3)
    across = rotation[:2, 0] / max(np.linalg.norm(rotation[:2, 0]), 1e-9)
    along = -rotation[:2, 2] / max(np.linalg.norm(rotation[:2, 2]), 1e-9)  # the view's heading
    a, b = points[:, :2] @ across, points[:, :2] @ along
    top, lowest = float(points[:, 2].max()), float(points[:, 2].min())
    extent, is_round = _footprint_extent(type_name)
    # the seen end of a round object is its outline only where its rim is seen: below it, the
    # pixels may be its inside (measured: a cup under the PR2's hand, 2 cm of its inner wall seen)
    middle = ((a.max() + a.min()) / 2.0 * across + (b.max() + b.min()) / 2.0 * along).tolist()
    under = support_of(environment, middle[0], middle[1], lowest, container_states)
    otype = OBJECT_TYPES.get(type_name)
    rim_seen = otype is not None and top >= (under.height if under else lowest) + otype.height - RIM_SLACK
    exact = is_round and rim_seen
    diameter = extent if is_round else None
    no_cut = (False, False)
    cut_a = _cut(a, outline[0], outline[1]) if outline is not None else no_cut
    cut_b = _cut(b, outline[0], outline[1]) if outline is not None else no_cut
    width = float(a.max() - a.min())
    centre_a, slack_a = _uncut_centre(float(a.min()), float(a.max()), cut_a, extent, exact)
    if diameter is not None and any(cut_a):
        width = max(width, diameter)
    slack_b = 0.0
    if view.position[2] > top + 0.05:  # seen from above: the top shows the object's full depth
        centre_b, slack_b = _uncut_centre(float(b.min()), float(b.max()), cut_b, extent, exact)
        depth = float(b.max() - b.min())
        if diameter is not None and any(cut_b):
            depth = max(depth, diameter)
    else:  # only the near side is seen: assume the object is as deep as it is wide
        centre_b = float(b.min()) + (diameter or width) / 2.0
        depth = diameter or width
    x, y = (centre_a * across + centre_b * along).tolist()
    surface = support_of(environment, x, y, lowest, container_states)
    bottom = surface.height if surface is not None else max(0.0, lowest)
    axis = None
    if view.position[2] > top + 0.05:  # the top is seen: its longer axis, or how a square one is turned
        # a box standing on its square base has no longer axis on top (seen in part it looks
        # oblong): its sides' direction; lying on its side, it has one
        standing_square = (
            otype is not None
            and otype.shape == "box"
            and otype.size[0] == otype.size[1]
            and top - bottom > otype.height - SQUARE_STANDING_SLACK
        )
        axis = side_direction(points, top) if standing_square else _major_axis(points, top)
    container = None if surface is None else environment.container_of(surface.name)
    mean = colours.mean(axis=0) / 255.0
    return Detection(
        type_name,
        (x, y, (top + bottom) / 2.0),
        (width, depth, top - bottom),
        color_name(mean),
        cast(Vec3, tuple(float(c) for c in mean)),  # the mean of the three channels
        None if surface is None else surface.name,
        None if container is None else container.name,
        int(len(points)),
        axis,
        math.hypot(slack_a, slack_b),
    )


#: The top's horizontal extent must be this much longer along its major axis than across it
#: (ratio of the standard deviations) for `_major_axis` to name an axis.
ELONGATION = 1.5


def _major_axis(points: np.ndarray, top: float) -> float | None:
    """The direction [rad, in [-pi/2, pi/2)] of the longer horizontal axis of the object's top
    (its points within 1 cm of the highest), seen from above; None when the top is not clearly
    longer one way than the other (round or square objects) or too few points show it."""
    upper = points[points[:, 2] > top - 0.01, :2]
    if len(upper) < 10:
        return None
    xy = upper - upper.mean(axis=0)
    values, vectors = np.linalg.eigh(xy.T @ xy / len(xy))
    if values[1] < ELONGATION**2 * max(float(values[0]), 1e-12):
        return None
    angle = math.atan2(float(vectors[1, 1]), float(vectors[0, 1]))
    return (angle + math.pi / 2) % math.pi - math.pi / 2


#: Directions [rad] `side_direction` tries, over a quarter turn (1 deg apart).
_SIDE_ANGLES = np.radians(np.arange(-45.0, 45.0, 1.0))
#: A top counts as square (not round) when its bounding rectangle at the worst direction is this
#: much larger than at the best one (a square's: 2x; a disc's: 1x, up to pixel noise).
SQUARENESS = 1.25
#: ... when that best rectangle is about as long as it is wide (its shorter side at least this
#: share of its longer one: a top seen in part, cut by an edge of the view or by the robot's arm,
#: looks oblong and turned -- measured: a milk carton standing square, seen in part from 3 m,
#: showed a 10 x 5 cm top whose longer axis read 54 deg) ...
SIDE_ASPECT = 0.75
#: ... and at least this many points of the top show it.
SIDE_POINTS = 60
#: A box of a square base counts as standing on it while its measured height is at most this
#: much [m] less than its type's height (lying, a milk carton is 13 cm lower).
SQUARE_STANDING_SLACK = 0.04


def side_direction(points: np.ndarray, top: float) -> float | None:
    """The direction [rad, in [-pi/4, pi/4)] of the sides of a top that is about as long as it
    is wide (its points within 1 cm of the highest, seen from above), up to quarter turns: where
    the rectangle around the top, turned that way, is smallest; None when the top is round (the
    rectangle hardly changes with the direction), not seen whole (that rectangle is oblong) or
    too few points show it. What `_major_axis` cannot say of a square box: how it is turned."""
    upper = points[points[:, 2] > top - 0.01, :2]
    if len(upper) < SIDE_POINTS:
        return None
    xy = upper - upper.mean(axis=0)
    c, s = np.cos(_SIDE_ANGLES), np.sin(_SIDE_ANGLES)
    along = np.ptp(xy[:, :1] * c + xy[:, 1:] * s, axis=0)  # the rectangle's sides at each direction
    across = np.ptp(-xy[:, :1] * s + xy[:, 1:] * c, axis=0)
    areas = along * across
    best = int(np.argmin(areas))
    if float(areas.max()) < SQUARENESS * float(areas[best]):
        return None  # round
    if min(along[best], across[best]) < SIDE_ASPECT * max(along[best], across[best]):
        return None  # not seen whole
    return float(_SIDE_ANGLES[best])


def measure_detections(
    ids: np.ndarray,
    depth: np.ndarray,
    rgb: np.ndarray | Callable[[], np.ndarray],
    view: CameraView,
    objects: dict[str, tuple[str, list[int]]],
    environment: Environment,
    container_states: dict[str, float],
    faults: PerceptionFaults,
    rng: np.random.Generator,
    min_pixels: int = MIN_PIXELS,
) -> list[Detection]:
    """The detections in one look: `ids` geom ids per pixel (-1: none), `depth` [m] and `rgb`
    images of the same camera (`rgb` may be a function that renders it: called only when an
    object is in view, at most once); `objects` maps each object to (type, its geoms). Most
    visible first."""
    types = [type_name for type_name, _ in objects.values()]
    last = int(max((max(g) for _, g in objects.values() if g), default=0))
    lookup = np.full(last + 2, -1, np.int64)  # geom id -> object index; the extra last entry: none
    for object_index, (_, geoms) in enumerate(objects.values()):
        lookup[geoms] = object_index
    labels = lookup[np.where((ids >= 0) & (ids <= last), ids, last + 1)]
    counts = np.bincount(labels[labels >= 0], minlength=len(types))
    detections = []
    for index in np.nonzero(counts >= min_pixels)[0]:
        rows, cols = np.nonzero(labels == index)
        points = _back_project(view, rows, cols)
        if float(np.median(np.linalg.norm(points - np.asarray(view.position), axis=1))) > view.max_range:
            continue
        if faults.miss_probability and rng.random() < faults.miss_probability:
            continue
        if callable(rgb):
            rgb = rgb()
        outline = hidden_outline(labels, depth, int(index), rows, cols)
        detection = _measure(view, types[index], points, rgb[rows, cols], environment, container_states, outline)
        if faults.pose_noise:
            noisy = tuple(float(v) for v in np.asarray(detection.position) + rng.normal(0.0, faults.pose_noise, 3))
            detection = _replace(detection, position=noisy)
        if faults.wrong_color_probability and rng.random() < faults.wrong_color_probability:
            others = [c for c in COLOR_NAMES if c != detection.color]
            detection = _replace(detection, color=others[int(rng.integers(len(others)))])
        detections.append(detection)
    return sorted(detections, key=lambda d: -d.pixels)


def _replace(detection: Detection, **changes: Any) -> Detection:
    return replace(detection, **changes)


def view_of(
    position: np.ndarray, rotation: np.ndarray, fovy: float, depth: np.ndarray, max_range: float = MAX_RANGE
) -> CameraView:
    """A `CameraView` from a camera's map position, rotation matrix and depth image."""
    return CameraView(
        cast(Vec3, tuple(float(v) for v in position)),
        np.asarray(rotation, float).reshape(3, 3).copy(),
        float(fovy),
        depth,
        max_range,
    )
