"""Judging the household tasks with the simulator's truth (never an input to the plan).

`judge_put_away` checks each object upright (`MAX_TILT`) and resting on a surface inside one of
its goal's containers (its bottom within `RESTING` [m] of that surface, the containers as they
are at the end), no gripper holding it; `judge_serve` each object upright on the table within
`SERVE_RADIUS` [m] of its goal's point in front of the seat, and next to another served object
(within `NEXT_TO` [m], centre to centre). `open_containers` lists the drawers out `CLOSED` [m] or
more and the doors open `DOOR_CLOSED` [rad] or more. Results are `TaskResult`s: the set-table
result (`pycram.apps.scenarios.set_table.judge.SetTableResult`: success, failure causes, summary)
with the scenario's and the environment's names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pycram.apps.scenarios.common.scene import Goal
from pycram.apps.scenarios.set_table.data import CLOSED, MAX_TILT
from pycram.apps.scenarios.set_table.judge import ObjectResult, SetTableResult, _tilt

if TYPE_CHECKING:  # the plan imports set-table's, whose driver imports this module's users
    from pycram.apps.scenarios.common.plan import ErrandOutcome

__all__ = [
    "TaskResult",
    "judge_put_away",
    "judge_serve",
    "open_containers",
    "DOOR_CLOSED",
    "RESTING",
    "SERVE_RADIUS",
    "NEXT_TO",
]

#: A door counts as closed below this angle [rad].
DOOR_CLOSED = math.radians(4.0)
#: An object rests on a surface with its bottom within this [m] of it.
RESTING = 0.03
#: Served: within this distance [m] (horizontal) of the goal's point in front of the seat ...
SERVE_RADIUS = 0.5
#: ... and within this distance [m] (centre to centre) of another served object.
NEXT_TO = 0.35


@dataclass
class TaskResult(SetTableResult):
    """The judged outcome of a run of a household task: `SetTableResult` with the `scenario`'s
    and the `environment`'s names."""

    scenario: str = ""
    environment: str = ""
    done_text: str = "every object where it belongs, containers closed"

    def summary(self) -> str:
        text = super().summary()
        return self.done_text if self.success else text

    def as_dict(self) -> dict[str, Any]:
        out = super().as_dict()
        out.update(scenario=self.scenario, environment=self.environment)
        return out


def open_containers(world: Any) -> dict[str, float]:
    """The containers left open (the simulator's truth): name -> opening [m or rad]."""
    out = {}
    for name, q in world.container_states.get_value().items():
        limit = CLOSED if world.environment.container(name).kind == "drawer" else DOOR_CLOSED
        if abs(q) >= limit:
            out[name] = round(float(q), 3)
    return out


def _outcome_failure(outcome: ErrandOutcome | None) -> tuple[str | None, str | None]:
    """(the failure's type name, its first line) of an errand's outcome."""
    if outcome is None or outcome.failure is None:
        return None, None
    return type(outcome.failure).__name__, str(outcome.failure).split("\n")[0][:300]


def _judge_each(
    world: Any, goals: list[Goal], outcomes: list[ErrandOutcome] | None, result: TaskResult, check: Any
) -> None:
    """Fill `result.objects` with `check(goal, pose) -> (ok, where, distance)` for each goal and
    the plan's outcomes (their typed failures); then the containers left open."""
    poses = world.item_poses.get_value()
    held = {s.get_value().holding for s in world.gripper_states.values()}
    by_type = {o.errand.type: o for o in outcomes or []}
    for goal in goals:
        outcome = by_type.get(goal.type)
        failure, why = _outcome_failure(outcome)
        pose = poses.get(goal.name)
        if pose is None:
            result.objects[goal.name] = ObjectResult(goal.name, False, failure, "not in the world")
            continue
        tilt = _tilt(pose.orientation)
        ok, where, distance = check(goal, pose)
        placed = ok and tilt <= MAX_TILT and goal.name not in held
        if placed:
            failure, reason = None, where
        elif why is not None:
            reason = why
        elif outcome is None:
            reason = "not brought (the plan stopped before)"
        else:
            reason = f"{where}, tilted {math.degrees(tilt):.0f} deg" + (", held" if goal.name in held else "")
        result.objects[goal.name] = ObjectResult(
            goal.name,
            placed,
            failure,
            reason,
            tuple(pose.position),
            None if distance is None else round(distance, 4),
            round(math.degrees(tilt), 1),
        )
    result.open_containers.update(open_containers(world))


def judge_put_away(world: Any, goals: list[Goal], outcomes: list[ErrandOutcome] | None, result: TaskResult) -> None:
    """Fill `result` (see the module docstring): each object inside one of its goal's containers."""
    from pycram.world.belief import support_of
    from pycram.world.objects import object_type

    environment = world.environment
    states = dict(world.container_states.get_value())

    def check(goal: Goal, pose: Any) -> tuple[bool, str, float | None]:
        x, y, z = pose.position
        bottom = z - object_type(goal.type).half_height
        support = support_of(environment, x, y, bottom, states)
        if support is None:
            return False, f"on the floor at ({x:.2f}, {y:.2f}, {z:.2f})", None
        container = environment.container_of(support.name)
        resting = abs(bottom - support.height) < RESTING
        where = f"on {support.name}" if resting else f"{bottom - support.height:.2f} m above {support.name}"
        ok = resting and container is not None and container.name in goal.containers
        return ok, (f"in {container.name}" if ok and container is not None else where), None

    _judge_each(world, goals, outcomes, result, check)


def _by(pose: Any, point: tuple[float, float, float]) -> bool:
    """Whether `pose` stands within `SERVE_RADIUS` (horizontally) of `point`."""
    return math.hypot(pose.position[0] - point[0], pose.position[1] - point[1]) <= SERVE_RADIUS


def judge_serve(world: Any, goals: list[Goal], outcomes: list[ErrandOutcome] | None, result: TaskResult) -> None:
    """Fill `result` (see the module docstring): each object on the table by the seat, next to
    another served object."""
    from pycram.world.objects import object_type

    table = world.environment.surface("table")
    poses = world.item_poses.get_value()

    def check(goal: Goal, pose: Any) -> tuple[bool, str, float | None]:
        assert goal.point is not None
        x, y, z = pose.position
        distance = math.hypot(x - goal.point[0], y - goal.point[1])
        on_table = table.contains(x, y, 0.0) and abs(z - object_type(goal.type).half_height - table.height) < RESTING
        others = [  # the other objects by the seat
            math.hypot(x - poses[g.name].position[0], y - poses[g.name].position[1])
            for g in goals
            if g.name != goal.name and g.name in poses and g.point is not None and _by(poses[g.name], g.point)
        ]
        beside = not others or min(others) <= NEXT_TO
        ok = on_table and distance <= SERVE_RADIUS and beside
        if ok:
            return True, f"on the table {distance:.2f} m from its point at the seat", distance
        if not on_table:
            return False, f"not on the table: at ({x:.2f}, {y:.2f}, {z:.2f})", distance
        if distance > SERVE_RADIUS:
            return (
                False,
                f"on the table {distance:.2f} m from its point (at most {SERVE_RADIUS} m)",
                distance,
            )
        return False, f"on the table but {min(others):.2f} m from the nearest other (at most {NEXT_TO} m)", distance

    _judge_each(world, goals, outcomes, result, check)
