"""Judging a set-table run with the simulator's ground truth (never an input to the plan).

`judge` fills a `SetTableResult` (one `ObjectResult` per object: placed upright at its place
setting within `TOLERANCE` [m] and `MAX_TILT` [rad], resting on the table, no gripper holding
it; every drawer and door closed, below `CLOSED` [m]) from the simulator's truth and the typed
failures of the plan's outcomes. `_HeldAtOnce` measures, with the same truth, the most objects
the robot's grippers held at the same time.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pycram.apps.scenarios.set_table.data import CLOSED, MAX_TILT, TOLERANCE
from pycram.apps.scenarios.set_table.plan import PlaceSetting, SettingOutcome

__all__ = [
    "ObjectResult",
    "SetTableResult",
    "judge",
]


@dataclass
class ObjectResult:
    """One object's result: `placed` (judged with the simulator's truth), the typed `failure`
    (its class name) that stopped it and a `reason`; where it ended and how far off it is."""

    name: str
    placed: bool
    failure: str | None
    reason: str
    position: tuple[float, float, float] | None = None
    distance: float | None = None
    tilt_deg: float | None = None

    def as_dict(self) -> dict[str, Any]:
        return {
            "placed": self.placed,
            "failure": self.failure,
            "reason": self.reason,
            "position": list(self.position) if self.position is not None else None,
            "distance": self.distance,
            "tilt_deg": self.tilt_deg,
        }


@dataclass
class SetTableResult:
    """The judged outcome of a scenario run."""

    robot: str
    seed: int
    faults: frozenset[str]
    objects: dict[str, ObjectResult] = field(default_factory=dict)
    open_containers: dict[str, float] = field(default_factory=dict)
    sim_time: float = 0.0
    wall_time: float = 0.0
    faults_injected: list[str] = field(default_factory=list)
    error: str | None = None  # what stopped the plan as a whole (a time limit, a bug), if anything
    #: What the plan's concurrency did (`PlanRecord.as_dict`), and -- measured with the
    #: simulator's truth -- the most objects the robot's grippers held at the same time.
    concurrency: dict[str, Any] = field(default_factory=dict)
    #: Object -> the closed container it started in (the others started on open surfaces).
    started_in: dict[str, str] = field(default_factory=dict)
    #: The robot's base and every object at the end (the simulator's truth; for fingerprints).
    final_poses: dict[str, Any] = field(default_factory=dict)
    #: The world's state every simulated second (`pycram.sim.World.trajectory`; for fingerprints).
    trajectory: list[Any] = field(default_factory=list)
    #: With `until`: the simulated time [s] the run was stopped at, and the folder the pictures
    #: and the task tree of that moment went to (None: the run was not stopped so).
    stopped_at: float | None = None
    stop_folder: Path | None = None

    @property
    def success(self) -> bool:
        return (
            self.error is None
            and bool(self.objects)
            and all(o.placed for o in self.objects.values())
            and not self.open_containers
        )

    @property
    def failure_causes(self) -> list[str]:
        # an object the plan believed placed that is not at its place: "not_at_place"
        causes = [o.failure or "not_at_place" for o in self.objects.values() if not o.placed]
        causes += [f"open:{c}" for c in self.open_containers]
        if self.error is not None:
            causes.append(self.error.split(":")[0])
        return causes

    def summary(self) -> str:
        """One line per object not placed, and per container left open."""
        lines = [
            f"{name}: {o.failure or 'not at its place'} ({o.reason})"
            for name, o in self.objects.items()
            if not o.placed
        ]
        lines += [f"{c} left open ({q:.2f} m)" for c, q in self.open_containers.items()]
        if self.error:
            lines.append(f"plan stopped: {self.error}")
        return "; ".join(lines) if lines else "every object at its place setting, containers closed"

    def as_dict(self) -> dict[str, Any]:
        return {
            "success": self.success,
            "robot": self.robot,
            "seed": self.seed,
            "faults": sorted(self.faults),
            "objects": {n: o.as_dict() for n, o in self.objects.items()},
            "failure_causes": self.failure_causes,
            "open_containers": dict(self.open_containers),
            "faults_injected": list(self.faults_injected),
            "started_in": dict(self.started_in),
            "sim_time": self.sim_time,
            "wall_time": self.wall_time,
            "error": self.error,
            "summary": self.summary(),
            "concurrency": dict(self.concurrency),
        }


def _tilt(quaternion: tuple[float, float, float, float]) -> float:
    w, x, y, z = quaternion
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y))))


def judge(
    world: Any, settings: list[PlaceSetting], outcomes: list[SettingOutcome] | None, result: SetTableResult
) -> None:
    """Fill `result.objects` and `result.open_containers` from the simulator's ground truth
    (judging only: the plan never sees it) and the plan's `outcomes` (the typed failures)."""
    poses = world.item_poses.get_value()
    held = {s.get_value().holding for s in world.gripper_states.values()}
    by_type = {o.setting.type: o for o in outcomes or []}
    for setting in settings:
        pose = poses.get(setting.type)
        outcome = by_type.get(setting.type)
        failure = type(outcome.failure).__name__ if outcome is not None and outcome.failure is not None else None
        if pose is None:
            result.objects[setting.type] = ObjectResult(setting.type, False, failure, "not in the world")
            continue
        x, y, z = pose.position
        distance = math.hypot(x - setting.point[0], y - setting.point[1])
        tilt = _tilt(pose.orientation)
        resting = abs(z - setting.point[2]) < 0.03
        placed = distance <= TOLERANCE and tilt <= MAX_TILT and resting and setting.type not in held
        if placed:
            reason = "at its place setting"
            failure = None
        elif outcome is not None and outcome.failure is not None:
            reason = str(outcome.failure).split("\n")[0][:300]
        elif outcome is None:
            reason = "not brought (the plan stopped before)"
        else:
            reason = f"{distance:.3f} m from its setting, tilted {math.degrees(tilt):.0f} deg" + (
                ", held" if setting.type in held else ""
            )
        result.objects[setting.type] = ObjectResult(
            setting.type, placed, failure, reason, (x, y, z), round(distance, 4), round(math.degrees(tilt), 1)
        )
    for name, q in world.container_states.get_value().items():
        kind = world.environment.container(name).kind
        if (kind == "drawer" and q > CLOSED) or (kind != "drawer" and abs(q) > 0.05):
            result.open_containers[name] = round(float(q), 3)


class _HeldAtOnce:
    """Measures, with the simulator's truth (for judging, never for the plan), the most objects
    the robot's grippers held at the same time, and which."""

    def __init__(self, world: Any) -> None:
        self.world = world
        self.most: list[str] = []
        self._lock = threading.Lock()
        self._handles = [s.on_change(self._changed) for s in world.gripper_states.values()]

    def _changed(self, _: Any) -> None:
        holding = sorted({s.get_value().holding for s in self.world.gripper_states.values()} - {None})
        with self._lock:
            if len(holding) > len(self.most):
                self.most = holding

    def stop(self) -> None:
        for handle in self._handles:
            handle.remove()
