"""`FollowView`: a free camera that keeps some bodies (e.g. the robot and the item) in the picture.

A named camera of the model sits still; a `FollowView` computes a MuJoCo free camera
(`mujoco.MjvCamera`) from the current body positions: it looks at the middle of the bodies from
a fixed direction (`azimuth`, `elevation`) and backs off far enough for all of them to fit
(`margin`), never closer than `min_distance`. Bodies outside `region` (e.g. an item put aside out
of the kitchen) are not framed. Given the view of the previous frame, it moves only part of the
way (`smoothing`), so an animation pans instead of jumping.

`World.snapshot(camera=view)` and `World.start_recording(camera=view)` take one wherever they
take a camera name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np


@dataclass(frozen=True)
class FollowView:
    """Frame `bodies` (body names) from direction `azimuth` [deg, MuJoCo's: 0 looks along +x,
    90 along +y] and `elevation` [deg, negative looks down].

    With `side_of` (x, y) [m], e.g. the middle of the room, the camera looks at the first two
    framed bodies from the side instead (perpendicular to the line between them, from the side
    where `side_of` is), so that neither hides the other; `azimuth` is used while fewer than two
    are framed or they are closer than 0.25 m to each other.

    `min_distance` [m]: closest the camera comes to the middle of the bodies. `margin`: how much
    wider than the bodies' extent the picture is (1 = edge to edge; the bodies are points, so
    leave room for the robot's size). `region` (x_min, y_min, x_max, y_max) [m]: only bodies
    inside it are framed (None: all). `smoothing` in (0, 1]: the fraction of the way to the
    new view that one frame goes (1: no smoothing). `height` [m]: the height looked at when
    framing a body, so the camera looks at the robot's middle rather than its feet.
    """

    bodies: tuple[str, ...]
    azimuth: float = 225.0
    elevation: float = -40.0
    min_distance: float = 2.0
    margin: float = 1.6
    region: tuple[float, float, float, float] | None = None
    smoothing: float = 0.35
    height: float = 0.8
    side_of: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if not self.bodies:
            raise ValueError("FollowView needs at least one body to frame")
        if not 0.0 < self.smoothing <= 1.0:
            raise ValueError(f"smoothing must be in (0, 1], got {self.smoothing}")

    def __str__(self) -> str:
        return f"a view following {', '.join(self.bodies)}"

    def check(self, model: mujoco.MjModel) -> None:
        """Raise ValueError naming a body of `bodies` that `model` does not have."""
        names = [model.body(i).name for i in range(model.nbody)]
        for body in self.bodies:
            if body not in names:
                raise ValueError(f"FollowView: no body {body!r} in the model (bodies: {', '.join(names)})")

    def view(
        self, model: mujoco.MjModel, data: mujoco.MjData, previous: mujoco.MjvCamera | None = None
    ) -> mujoco.MjvCamera:
        """The free camera for the body poses in `data` (kinematics computed), smoothed towards
        from `previous` if given."""
        points = []
        for body in self.bodies:
            x, y, z = (float(v) for v in data.xpos[model.body(body).id])
            if self.region is None or (self.region[0] <= x <= self.region[2] and self.region[1] <= y <= self.region[3]):
                points.append((x, y, max(z, self.height)))
        if not points:  # nothing in the region: keep looking where we looked
            if previous is not None:
                return previous
            x, y, z = (float(v) for v in data.xpos[model.body(self.bodies[0]).id])
            points = [(x, y, z)]
        pts = np.asarray(points, dtype=float)
        lookat = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
        azimuth = self._azimuth(pts, lookat)
        extent = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
        half_fov = math.radians(float(model.vis.global_.fovy)) / 2.0
        distance = max(self.min_distance, self.margin * extent / (2.0 * math.tan(half_fov)))
        if previous is not None:
            a = self.smoothing
            lookat = np.asarray(previous.lookat) + a * (lookat - np.asarray(previous.lookat))
            distance = previous.distance + a * (distance - previous.distance)
            turn = (azimuth - previous.azimuth + 180.0) % 360.0 - 180.0  # the short way round
            azimuth = previous.azimuth + a * turn
        camera = mujoco.MjvCamera()
        camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        camera.lookat[:] = lookat
        camera.distance = distance
        camera.azimuth = azimuth % 360.0
        camera.elevation = self.elevation
        return camera

    def _azimuth(self, pts: np.ndarray, lookat: np.ndarray) -> float:
        """The viewing direction [deg]: from the side of the first two points, or `azimuth`."""
        if self.side_of is None or len(pts) < 2:
            return self.azimuth
        along = pts[1, :2] - pts[0, :2]
        if float(np.linalg.norm(along)) < 0.25:
            return self.azimuth
        normal = np.array([-along[1], along[0]])
        if float(np.dot(normal, np.asarray(self.side_of, float) - lookat[:2])) < 0:
            normal = -normal  # the camera stands on the side of `side_of` ...
        return math.degrees(math.atan2(-normal[1], -normal[0]))  # ... and looks the other way


__all__ = ["FollowView"]
