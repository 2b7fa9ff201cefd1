"""Articulated furniture in the simulation thread: container joint positions and the "stuck" fault.

Drawers and doors are driven by contact only: their joints have no actuator, only damping and
friction loss (see `environment_builder`), so they move when something pushes them hard enough
and stay where they are left. A stuck container is held where it is by its joint equality.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco

from .environment_builder import stuck_equality

if TYPE_CHECKING:
    from .engine import Engine


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


__all__ = ["Furniture"]
