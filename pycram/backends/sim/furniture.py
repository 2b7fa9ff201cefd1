"""Articulated furniture in the simulation thread: container joint positions, the "stuck" fault,
and a hand that pushes or pulls a container (used by fault injection and tests).

Drawers and doors are driven by contact only: their joints have no actuator, only damping and
friction loss (see `environment_builder`), so they move when something pushes them hard enough
and stay where they are left. A stuck container is held where it is by its joint equality.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from pycram.world.types import Outcome

from .controllers import Controller, ok
from .engine import Engine
from .environment_builder import stuck_equality


class Furniture:
    """Index data of the scene's containers; used by the simulation thread only."""

    def __init__(self, engine: Engine) -> None:
        scene, model = engine.scene, engine.model
        self.containers = {c.name: c for c in scene.environment.containers}
        self.qpos = {n: scene.joint_qpos(c.joint_name) for n, c in self.containers.items()}
        self.dof = {n: scene.joint_dof(c.joint_name) for n, c in self.containers.items()}
        self.body = {n: scene.body(n) for n in self.containers}
        self.handle = {n: scene.site(c.handle_site) for n, c in self.containers.items()}
        self.stuck_eq = {n: scene.equality(stuck_equality(n)) for n in self.containers}
        self.model = model

    def positions(self, data: mujoco.MjData) -> dict[str, float]:
        """Joint position of every container [m or rad], 0 when closed."""
        return {n: float(data.qpos[a]) for n, a in self.qpos.items()}

    def set_stuck(self, data: mujoco.MjData, name: str, stuck: bool) -> None:
        """Hold container `name` at its current position (stuck) or let it move again."""
        eq = self.stuck_eq[name]
        self.model.eq_data[eq, :] = 0.0
        self.model.eq_data[eq, 0] = data.qpos[self.qpos[name]]  # qpos0 of a container joint is 0
        data.eq_active[eq] = 1 if stuck else 0

    def is_stuck(self, data: mujoco.MjData, name: str) -> bool:
        return bool(data.eq_active[self.stuck_eq[name]])


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


__all__ = ["Furniture", "ContainerPush"]
