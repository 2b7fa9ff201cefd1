"""Physics faults: the simulator's watchdog over its free objects.

A simulated grasp or push can go wrong in a way no real kitchen does: the contact solver flings
a cup across the map (measured: a cup thrown to (-97.9, -138.8) m, after which a run searched
for it for 778 s of simulated time and reported `ObjectNotFound`). `PhysicsWatchdog` looks at
the simulator's truth every `CHECK_PERIOD` of simulated time -- vectorised over every free
object, under 0.1 ms of wall time (2 % of the physics) -- and names what broke:

- ``left_world``: the object's centre is outside the world's bounds (`world_bounds`: the
  environment's plan and picture extents, `MARGIN` [m] around them, up to `CEILING` [m]);
- ``too_fast``: it moved faster than `SPEED_LIMIT` [m/s] at `FAST_CHECKS` checks in a row
  (a fall from the top of the fridge lands at under 6 m/s);
- ``below_floor``: its centre is more than `FLOOR_TOLERANCE` [m] below the floor;
- ``sunk``: its centre is inside a solid piece of furniture (a colliding static box of the
  environment, shrunk by `SINK_TOLERANCE` [m]): sunk into a counter, a shelf board, a wall.

Objects held in a gripper are not checked for sinking (the hand may press them into a surface
while it puts them down). The first fault found ends the run: the world keeps it in its
``physics_fault`` fluent (a `pycram.failures.SimulationFault` naming the object, what happened,
where and when), ends every motion running then with an `Outcome` of reason
`FAULT_REASON`, and every motion after it too; the simulated process modules
(`pycram.robots.common.sim_modules`) raise the fault itself for every command after it -- motions
and looks alike -- and no recovery of a plan handles it. The world's tools
(pictures, recordings, interventions) keep working, so a run can still be judged and drawn.

`fling` gives an object a velocity, as a glitch would (fault injection and tests).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from pycram.execution.failures import PHYSICS_FAULT_KINDS, SimulationFault
from pycram.world.environment import Environment
from pycram.world.types import Outcome

from .engine import ASIDE_DISTANCE, Engine
from .handle import CommandHandle

if TYPE_CHECKING:
    from .world import World

__all__ = [
    "PhysicsWatchdog",
    "world_bounds",
    "fling",
    "CHECK_PERIOD",
    "SPEED_LIMIT",
    "FAST_CHECKS",
    "MARGIN",
    "CEILING",
    "FLOOR_TOLERANCE",
    "SINK_TOLERANCE",
    "FAULT_REASON",
]

log = logging.getLogger(__name__)

#: Simulated time [s] between two checks.
CHECK_PERIOD = 0.05
#: An object moving faster than this [m/s] ...
SPEED_LIMIT = 6.0
#: ... at this many checks in a row has been flung (a single contact impulse is not counted).
FAST_CHECKS = 2
#: The world reaches this far [m] beyond the environment's extents (objects set aside by
#: `take_item` lie `ASIDE_DISTANCE` beyond them).
MARGIN = ASIDE_DISTANCE + 2.0
#: The world's top [m above the floor].
CEILING = 4.0
#: An object's centre this far [m] below the floor has fallen through it.
FLOOR_TOLERANCE = 0.02
#: Furniture boxes are shrunk by this much [m] on every side before an object's centre in them
#: counts as sunk (thin boards are shrunk by at most a third of their half size).
SINK_TOLERANCE = 0.002
#: An object that moved less than this [m] since the last check is not tested for sinking again.
MOVED = 1e-4
#: The `Outcome` reason of commands ended by a physics fault.
FAULT_REASON = "simulation_fault"


def world_bounds(environment: Environment, items: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The lower and upper corner (x, y, z) [m] of the box a free object must stay in: the
    environment's `plan_bounds` and `extent`, `MARGIN` [m] around them (further north by 0.3 m
    per item: where `take_item` sets items aside), from `FLOOR_TOLERANCE` below the floor to
    `CEILING` (or 1 m above the highest furniture)."""
    rects = [environment.plan_bounds, environment.extent]
    x0, y0 = min(r[0] for r in rects) - MARGIN, min(r[1] for r in rects) - MARGIN
    x1, y1 = max(r[2] for r in rects) + MARGIN, max(r[3] for r in rects) + MARGIN + 0.3 * items
    top = max([CEILING] + [b.z_range[1] + 1.0 for b in environment.static])
    return np.array([x0, y0, -FLOOR_TOLERANCE]), np.array([x1, y1, top])


class PhysicsWatchdog:
    """Checks the free objects of an `Engine`'s scene for broken physics (see the module).

    Use from the simulation thread only: ``check(engine)`` at any rate; it looks every
    `CHECK_PERIOD` of simulated time and returns the first `SimulationFault` found (None while
    everything is sound). After a fault it returns that same fault on every call.
    """

    def __init__(self, engine: Engine, environment: Environment) -> None:
        self._names = list(engine.item_bodies)
        self._bodies = np.array([engine.item_bodies[n] for n in self._names], dtype=np.int64)
        dofs = [engine.item_dof[n] for n in self._names]
        self._linear = np.array([[d, d + 1, d + 2] for d in dofs], dtype=np.int64).reshape(-1, 3)
        self._low, self._high = world_bounds(environment, len(self._names))
        boxes = [b for b in environment.static if b.collides]
        self._box_names = [b.name for b in boxes]
        centres = np.array([b.center for b in boxes], dtype=float).reshape(-1, 3)
        halves = np.array([b.half for b in boxes], dtype=float).reshape(-1, 3)
        shrink = np.minimum(SINK_TOLERANCE, halves / 3.0)
        self._box_low, self._box_high = centres - halves + shrink, centres + halves - shrink
        self._fast = np.zeros(len(self._names), dtype=np.int64)
        self._seen = np.full((len(self._names), 3), np.inf)  # positions at the last look [m]
        self._next = 0.0
        self.fault: SimulationFault | None = None

    def check(self, engine: Engine) -> SimulationFault | None:
        """The physics fault of the state now (see the class), or None."""
        if self.fault is not None or not self._names:
            return self.fault
        t = engine.time
        if t < self._next - 1e-9:
            return None
        self._next = t + CHECK_PERIOD
        data = engine.data
        positions = data.xpos[self._bodies]
        velocities = data.qvel[self._linear]
        squared = np.einsum("ij,ij->i", velocities, velocities)  # speeds squared [m^2/s^2]
        self._fast = np.where(squared > SPEED_LIMIT * SPEED_LIMIT, self._fast + 1, 0)
        index, kind, detail = -1, "", ""
        outside = ((positions < self._low) | (positions > self._high)).any(axis=1)
        if outside.any():
            index = int(np.flatnonzero(outside)[0])
            below = positions[index, 2] < self._low[2]
            inside_xy = np.all((positions[index, :2] >= self._low[:2]) & (positions[index, :2] <= self._high[:2]))
            kind = "below_floor" if below and inside_xy else "left_world"
            (x0, y0, _), (x1, y1, z1) = self._low, self._high
            detail = (
                "below the floor"
                if kind == "below_floor"
                else f"outside the world (x {x0:.1f}..{x1:.1f}, y {y0:.1f}..{y1:.1f}, z up to {z1:.1f} m)"
            )
        elif self._fast.max(initial=0) >= FAST_CHECKS:
            index = int(np.flatnonzero(self._fast >= FAST_CHECKS)[0])
            kind, detail = "too_fast", f"at {math.sqrt(squared[index]):.1f} m/s (more than {SPEED_LIMIT:.0f} m/s)"
        elif len(self._box_names):
            # only objects that moved since the last look can have sunk into something
            moved = np.flatnonzero((np.abs(positions - self._seen) > MOVED).any(axis=1))
            self._seen = positions
            if moved.size:
                index, kind, detail = self._sunk(engine, positions, moved)
        if index < 0:
            return None
        name = self._names[index]
        x, y, z = (float(v) for v in positions[index])
        message = (
            f"{name} {PHYSICS_FAULT_KINDS[kind]} at t={t:.2f} s of simulated time: "
            f"at ({x:.2f}, {y:.2f}, {z:.2f}) m, {detail}"
        )
        self.fault = SimulationFault(message, name, kind, t, (x, y, z), math.sqrt(float(squared[index])))
        log.error("physics fault: %s", message)
        return self.fault

    def _sunk(self, engine: Engine, positions: np.ndarray, candidates: np.ndarray) -> tuple[int, str, str]:
        """The first of the objects `candidates` (indices) whose centre is inside a solid piece
        of furniture, no gripper holding it: (index, "sunk", detail), or (-1, "", "")."""
        points = positions[candidates]
        inside = np.all(
            (points[:, None, :] > self._box_low[None]) & (points[:, None, :] < self._box_high[None]),
            axis=2,
        )
        if not inside.any():
            return -1, "", ""
        held = {g.holding for g in engine.grippers.values() if g.holding is not None}
        for i, j in zip(*np.nonzero(inside), strict=True):
            index = int(candidates[int(i)])
            if self._names[index] not in held:
                return index, "sunk", f"its centre inside {self._box_names[int(j)]!r}"
            self._seen[index] = np.inf  # held: looked at again at each check (it may be let go there)
        return -1, "", ""

    def apply(self, world: World) -> None:
        """Run by the simulation thread each control tick, after the commands were started:
        look for a fault (`check`); once there is one, publish it (``world.physics_fault``) and
        end every running motion with it (reason `FAULT_REASON`; motions started later too)."""
        known = self.fault
        fault = self.check(world._engine)
        if fault is None:
            return
        if known is None:
            world.physics_fault.set_value(fault)
        outcome = Outcome(False, FAULT_REASON, str(fault), fault)
        for channel in list(world._active):
            world._end(channel, outcome, stop=True)


def fling(world: World, item: str, velocity: Sequence[float]) -> CommandHandle:
    """Give `item` the linear `velocity` (x, y, z) [m/s], as a glitch of the contact solver
    would (fault injection, tests). Returns the command's handle at once."""
    world.scene.item(item)  # an unknown name raises here, listing the items
    vx, vy, vz = (float(v) for v in velocity)

    def fn(eng: Engine) -> None:
        d = eng.item_dof[item]
        eng.data.qvel[d : d + 3] = (vx, vy, vz)

    return world._call(f"fling:{item}", fn)
