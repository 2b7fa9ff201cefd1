"""`ContainerPush`: a person's hand pushes or pulls a drawer or door (a controller of the
simulation thread, used by fault injection and tests).

The force [N, map frame] acts at the container's handle or at a point on it [m, map frame] for a
duration [s of simulated time]; the container moves only as far as the force overcomes its
friction (see `furniture`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pycram.world.types import Outcome

from .controllers import Controller, ok
from .engine import Engine


class ContainerPush(Controller):
    """A hand pushes container `name` with `force` [N, map frame] for `duration` [s].

    The force acts at the handle's grasp point (default) or at `point` [m, map frame, taken with
    the container as it is at the start], which moves with the container. Value: the container's
    joint position at the end [m or rad].
    """

    def __init__(
        self, name: str, force: Sequence[float], duration: float, point: Sequence[float] | None = None
    ) -> None:
        self.name, self.force, self.duration = name, np.asarray(force, float), float(duration)
        self.point = None if point is None else np.asarray(point, float)
        self.channel = f"hand:{name}"

    def start(self, eng: Engine) -> Outcome | None:
        f = eng.furniture
        self.body = f.body[self.name]
        if self.point is not None:  # the point in the body's frame
            rot = eng.data.xmat[self.body].reshape(3, 3)
            self.local = rot.T @ (self.point - eng.data.xpos[self.body])
        self.end = eng.time + self.duration
        return None

    def _point(self, eng: Engine) -> np.ndarray:
        if self.point is None:
            return eng.data.site_xpos[eng.furniture.handle[self.name]].copy()
        return eng.data.xpos[self.body] + eng.data.xmat[self.body].reshape(3, 3) @ self.local

    def update(self, eng: Engine, t: float) -> Outcome | None:
        if t >= self.end - 1e-9:
            self.stop(eng)
            return ok(eng.furniture.positions(eng.data)[self.name])
        arm = self._point(eng) - eng.data.xipos[self.body]
        eng.data.xfrc_applied[self.body, :3] = self.force
        eng.data.xfrc_applied[self.body, 3:] = np.cross(arm, self.force)
        return None

    def stop(self, eng: Engine) -> None:
        eng.data.xfrc_applied[self.body, :] = 0.0


__all__ = ["ContainerPush"]
