"""The faults of the household task suite: set-table's simulated person and flaky camera
(`pycram.apps.scenarios.set_table.faults.Faults`), with spots drawn from the scene's own surfaces.

`TaskFaults` is set-table's `Faults` (``moved``, ``taken``, ``stuck``, ``obstacle``; ``missed`` is
perception's, set when the world is built) for any scene: a person who moves an object, or takes
it out of the gripper, puts it on the surface it started on at a free spot some standing pose of
the robot reaches (drawn with the scene's `ReachabilityFilter`), not into set-table's start
regions of the apartment. `check_task_faults` parses fault names against a scenario's list.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from typing import Any

from pycram.apps.scenarios.common.scene import Goal
from pycram.apps.scenarios.set_table.faults import Faults

__all__ = ["TaskFaults", "check_task_faults"]


def check_task_faults(faults: Any, known: Sequence[str], scenario: str) -> frozenset[str]:
    """The fault names of `faults` (an iterable or a comma-separated string) as a set; raises
    `ValueError` naming the valid choices of `scenario` for an unknown one."""
    if isinstance(faults, str):
        faults = [f.strip() for f in faults.split(",") if f.strip()]
    names = frozenset(faults or ())
    unknown = sorted(names - set(known))
    if unknown:
        raise ValueError(
            f"unknown fault(s) {', '.join(map(repr, unknown))} for {scenario}; valid faults: {', '.join(known)}"
        )
    return names


class TaskFaults(Faults):
    """Set-table's faults for a task scene (see the module docstring): `goals` name the objects
    (by type), `placements` where they started, `reach` the scene's reachability filter (None:
    any free spot)."""

    def __init__(
        self,
        world: Any,
        kinds: frozenset[str],
        rng: random.Random,
        goals: list[Goal],
        placements: list[Any],
        reach: Any = None,
    ) -> None:
        super().__init__(world, kinds, rng, goals, placements)  # type: ignore[arg-type]
        self.reach = reach
        self.supports = {p.name: p.support for p in placements}
        self.types = {p.name: p.type for p in placements}
        self.starts = {p.name: tuple(p.position) for p in placements}

    def _free_counter_spot(self, name: str, near: tuple[float, float] | None = None) -> tuple[float, float, float]:
        """A spot [m] for `name` standing upright on the surface it started on, clear of every
        object standing around (objects in a gripper do not count), where some standing pose
        reaches it; `near` is not used (the spot is drawn from the whole surface). Where no such
        spot is drawn, any free one; else where the object started."""
        from pycram.apps.scenarios.reachability import draw_spot
        from pycram.world.objects import object_type
        from pycram.world.scenes import Placement

        environment = self.world.environment
        support = self.supports[name]
        held = self._holding()
        others = []
        for other, pose in self.world.item_poses.get_value().items():
            if other == name or other in held or other not in self.types:
                continue
            otype = object_type(self.types[other])
            others.append(
                Placement(other, otype.name, support, None, tuple(pose.position), 0.0, otype.footprint_radius)
            )
        for reach in (self.reach, None):
            spot, _ = draw_spot(self.rng, environment, self.types[name], [support], others, reach, max_draws=100)
            if spot is not None:
                return (spot.position[0], spot.position[1], spot.position[2] + 0.001)
        x, y, z = self.starts[name]
        return (x, y, z)
