"""The bounded search for candidates shared by the location vocabularies.

`CandidateSearch` is the base of the vocabularies (`pycram.reasoning.locations.reach`, ``see``,
``opening``, ``spots``) that `LocationReasoner` combines: it declares the reasoner's inputs (the
robot's geometry and the callables that describe the world at resolution time) and walks the
cells of costmaps cheapest first, validating each candidate with prospection. Guarantees: at most
`MAX_CANDIDATES` (the reasoner's ``max_candidates``) candidates are checked per designator;
solutions keep `SPACING` [m] apart; when none passes, `NoSolutionError` says how many were tried
and what ruled them out (counted by `_Tally`).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from pycram.designators.core import NoSolutionError
from pycram.world.environment import Environment

from .costmap import Costmap
from .robot_geometry import RobotGeometry
from .solutions import BaseLocation
from .targets import KnownObject, Target, as_target

__all__ = [
    "CandidateSearch",
    "MAX_CANDIDATES",
    "SPACING",
    "FAILED_SPACING",
    "BASE_CLEARANCE",
    "DRIVE_ROOM",
    "NO_WAY_IN",
    "LIFT_STEP",
]

#: Free space [m] kept between the base's inscribed circle and the furniture: the base must be
#: able to drive there (navigation keeps its own clearance of a few cm, on a 5 cm grid).
BASE_CLEARANCE = 0.1
#: Room [m] a base pose must leave around the robot for navigation to drive there: the robot
#: moved this far ahead, back or to either side still touches no furniture (`has_no_room`).
#: Navigation keeps its footprint 3 cm plus half a 5 cm cell's diagonal (6.5 cm) off occupied
#: cells; prospection tolerates 1.5 cm of penetration, so 8 cm here. The occupancy layer keeps
#: the base's inscribed circle `BASE_CLEARANCE` off the furniture, room enough around a round or
#: square base but not ahead of and behind a long one (measured: the TIAGo Pro's 0.72 x 0.50 m
#: base, offered poses 0.38-0.40 m in front of the furniture behind it -- navigation refused
#: them, goal_in_collision, in 4 of set-table dev seeds 1-10).
DRIVE_ROOM = 0.08
#: Why a candidate failed `CandidateSearch.cannot_drive_in`.
NO_WAY_IN = "no way in (no room to drive there, or no straight way for a differential drive)"
#: Candidates checked with prospection per designator before giving up.
MAX_CANDIDATES = 100
#: Distance [m] between two solutions of one designator (base poses or spots).
SPACING = 0.1
#: Cells closer than this [m] to a candidate that failed for the same arm are not checked (the
#: cells around it: their answer is almost always the same).
FAILED_SPACING = 0.075


class _Tally:
    """Why candidates failed, for the error message."""

    def __init__(self) -> None:
        self.tried = 0
        self.reasons: Counter[str] = Counter()
        self.details: dict[str, Counter[str]] = {}

    def fail(self, reason: str, detail: str | None = None) -> None:
        self.reasons[reason] += 1
        if detail:
            self.details.setdefault(reason, Counter())[detail] += 1

    def summary(self) -> str:
        parts = []
        for reason, n in self.reasons.most_common():
            if not n:
                continue
            detail = self.details.get(reason)
            more = (
                f" ({', '.join(f'{k} {v}' for k, v in detail.most_common() if v)})"
                if detail and any(detail.values())
                else ""
            )
            parts.append(f"{n} {reason}{more}")
        return f"{self.tried} candidates: " + ", ".join(parts) if parts else f"{self.tried} candidates"


#: Lifting a held object clear of the furniture to arrive at a base pose: the tool goes up in
#: steps of this much [m] until the robot fits there (or the arm reaches no higher).
LIFT_STEP = 0.05


class CandidateSearch:
    """The inputs of location reasoning and the search over ranked candidates (base of the
    vocabularies; `LocationReasoner` sets the inputs, see its docstring)."""

    #: The robot's numbers (its description).
    geometry: RobotGeometry
    #: The environment's description, asked at resolution time.
    environment: Callable[[], Environment]
    #: The robot's `Prospection` in the current world, asked at resolution time.
    prospection: Callable[[], Any]
    #: The objects believed to be around (`KnownObject`s).
    known_objects: Callable[[], Sequence[KnownObject]]
    #: How far each container is believed open [m or rad] (perceived; missing: closed).
    container_states: Callable[[], Mapping[str, float]]
    #: The objects the robot's grippers hold now (believed): arm -> the object's name.
    holding: Callable[[], Mapping[str, str]]
    #: Candidates checked with prospection per designator before giving up.
    max_candidates: int
    #: The costmaps of the latest base-pose resolution by name (for pictures; not for reasoning).
    last_costmaps: dict[str, Costmap]
    #: The candidates of the latest search, in the order checked: (x [m], y [m], arm, why it was
    #: ruled out or None when accepted, yaw [rad] when accepted) -- for views; not for reasoning.
    last_candidates: list[tuple[float, float, str | None, str | None, float | None]]

    @property
    def _base_radius(self) -> float:
        """The base's inscribed radius plus the clearance it keeps [m] (the occupancy inflation)."""
        return self.geometry.inscribed_radius + BASE_CLEARANCE

    def arrival_configuration(self, prospection: Any) -> dict[str, float]:
        """The robot's arms as they arrive at a base pose (joint name -> position [rad or m]):
        every free arm tucked (its park configuration), every arm holding an object as it is now
        (its carry configuration: the base drives with it so). A base pose is checked with this
        configuration -- the one navigation will drive the robot to it in -- so that reasoning
        never offers a pose the robot does not fit at as it comes."""
        configuration = dict(self.geometry.tucked)
        for arm in self.holding():
            for joint in self.geometry.arm_joints.get(arm, ()):
                configuration[joint] = float(prospection.joint_position(joint))
        return configuration

    def _lifted_arrival(
        self, prosp: Any, arm: str, base: tuple[float, float, float], configuration: Mapping[str, float]
    ) -> tuple[float, ...]:
        """Joint positions [rad] of `arm` (holding an object) that lift its tool straight up
        from where `configuration` has it, in steps of `LIFT_STEP`, until the robot at `base`
        with what it carries touches nothing (`Prospection.in_collision` with the objects);
        empty when no lift within the arm's reach does. A tall object held from the top hangs
        below the counter's top in the carry configuration: lifted, it comes over the counter."""
        if arm not in self.holding() or prosp.in_collision(base, configuration, objects=True):
            return ()  # nothing held, or the robot itself is in the way: lifting will not help
        try:
            tool = prosp.tool_pose(arm, base, configuration)
        except NotImplementedError:
            return ()
        joints = self.geometry.arm_joints[arm]
        x, y, z = tool.position
        step = 1
        while True:
            goal = ((x, y, z + step * LIFT_STEP), tool.orientation)
            answer = prosp.solve_ik(arm, goal, base, configuration, avoid_collisions=False)
            if not answer:
                return ()  # out of the arm's reach: higher is out of reach too
            lifted = {**configuration, **dict(zip(joints, answer.positions))}
            if not prosp.in_collision(base, lifted, self.carried(), objects=True):
                return tuple(float(v) for v in answer.positions)
            step += 1

    def no_way_in(self, prosp: Any, base: tuple[float, float, float], configuration: Mapping[str, float]) -> bool:
        """Whether a differential drive cannot get to `base` (x [m], y [m], yaw [rad]) in
        `configuration` with what it carries: it can neither have come straight along its heading
        (the robot touches something `approach`/2 or `approach` behind the pose) nor turn there on
        the spot (it touches something at one of the other seven eighths of a turn). The pose
        itself is checked by the caller (and `has_no_room`). Always False for an omnidirectional
        base, which may come in any direction."""
        kinematics = self.geometry.base_kinematics
        if kinematics.holonomic:
            return False
        x, y, yaw = base
        carried = self.carried()
        d = kinematics.approach
        behind = [(x - f * d * math.cos(yaw), y - f * d * math.sin(yaw), yaw) for f in (0.5, 1.0)]
        if d > 0.0 and not any(prosp.in_collision(p, configuration, carried, objects=True) for p in behind):
            return False
        turns = [(x, y, yaw + k * math.pi / 4) for k in range(1, 8)]
        return any(prosp.in_collision(p, configuration, carried, objects=True) for p in turns)

    def cannot_drive_in(self, prosp: Any, base: tuple[float, float, float], configuration: Mapping[str, float]) -> bool:
        """Whether navigation would not drive the robot into `base` (x [m], y [m], yaw [rad]) in
        `configuration`: `has_no_room`, `no_way_in`, or navigation's own goal check refuses it
        (`Prospection.drivable`: its floor model, footprint and clearance in the believed world).
        The pose itself is checked by the caller."""
        drivable = getattr(prosp, "drivable", None)  # (a prospection without it: the checks above)
        return (
            self.has_no_room(prosp, base, configuration)
            or self.no_way_in(prosp, base, configuration)
            or (drivable is not None and not drivable(base, configuration, self.carried()))
        )

    def has_no_room(self, prosp: Any, base: tuple[float, float, float], configuration: Mapping[str, float]) -> bool:
        """Whether the robot in `configuration`, with what it carries, touches the furniture when
        moved `DRIVE_ROOM` from `base` (x [m], y [m], yaw [rad]) ahead, back, left or right:
        navigation keeps that much room and does not drive into such a pose. The pose itself is
        checked by the caller."""
        x, y, yaw = base
        c, s = math.cos(yaw), math.sin(yaw)
        carried = self.carried()
        for ahead, left in ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)):
            dx, dy = DRIVE_ROOM * (c * ahead - s * left), DRIVE_ROOM * (s * ahead + c * left)
            if prosp.in_collision((x + dx, y + dy, yaw), configuration, carried):
                return True
        return False

    def carried(self) -> list[str]:
        """The names of the objects the robot holds now (believed), to check base poses with:
        they arrive with the robot (`Prospection.in_collision`'s ``carried``)."""
        return sorted(self.holding().values())

    def _fail(self, desig: Any, what: str) -> NoSolutionError:
        return NoSolutionError(f"Cannot resolve {desig!r}: {what}", designator=desig)

    def _target(self, value: Any) -> Target:
        return as_target(value, self.environment(), self.known_objects())

    def _empty_costmap(self, maps: dict[str, Costmap], target: Target) -> str:
        """Why no cell of the costmaps is left: the layer that alone rules out every cell, or
        the layers that do together."""
        env = self.environment()
        where = "(" + ", ".join(f"{v:.1f}" for v in target.position) + ") [m, map]"
        alone = sorted(
            {
                name
                for m in maps.values()
                for name, layer in m.layers.items()
                if name != "occupancy" and bool(np.isinf(layer).all())
            }
        )
        if alone:
            return (
                f"{target.describe()} at {where} is outside the environment: no cell of the floor of "
                f"{env.name} lies within the layer {alone[0]!r} around it"
            )
        return (
            f"every cell of the floor of {env.name} within reach of {target.describe()} at {where} is "
            f"occupied (layer 'occupancy': furniture and walls inflated by the {self.geometry.name}'s "
            f"{self._base_radius:.2f} m footprint radius with clearance; {_layer_summary(maps)})"
        )

    # ------------------------------------------------------------------ the search
    def _search(
        self,
        desig: Any,
        cells: Iterator[tuple],
        validate: Callable,
        kind: str,
        target: Target,
        maps: dict[str, Costmap],
        tally: _Tally | None = None,
    ) -> Iterator[BaseLocation]:
        """Walk `cells` (cost, tie, arm, row, col) cheapest first; validate each; yield the valid
        ones at least `SPACING` apart; after `max_candidates` checks or when the costmap is used
        up, stop -- with `NoSolutionError` naming what ruled the candidates out if nothing passed
        (counted in `tally` when given)."""
        tally = _Tally() if tally is None else tally
        given: list[BaseLocation] = []
        tried: list[tuple[float, float, str | None, str | None, float | None]] = []
        self.last_candidates = tried
        failed: list[tuple[str | None, float, float]] = []
        for cell in cells:
            if tally.tried >= self.max_candidates:
                break
            cost, _, arm, r, c = cell
            x, y = next(iter(maps.values())).xy(r, c)
            if any(math.hypot(x - g.x, y - g.y) < SPACING for g in given):
                continue
            if any(a == arm and math.hypot(x - fx, y - fy) < FAILED_SPACING for a, fx, fy in failed):
                continue
            tally.tried += 1
            solution, failure = validate(cell)
            if solution is not None:
                given.append(solution)
                tried.append((x, y, arm, None, getattr(solution, "yaw", None)))
                yield solution
            else:
                failed.append((arm, x, y))
                tried.append((x, y, arm, failure[0], None))
                tally.fail(*failure)
        if not given:
            if tally.tried == 0:
                raise self._fail(desig, self._empty_costmap(maps, target))
            raise self._fail(
                desig, f"no base pose for {kind} {target.describe()} with the {self.geometry.name}: {tally.summary()}"
            )


def _layer_summary(maps: dict[str, Costmap]) -> str:
    out = []
    for name, costmap in maps.items():
        out.append(f"{name}: " + ", ".join(f"{k} forbids {v} cells" for k, v in costmap.ruled_out_by().items()))
    return "; ".join(out)


def _ranked(costmap: Costmap, tie: int, arm: str | None) -> Iterator[tuple]:
    """The cells of `costmap` cheapest first as (cost, tie, arm, row, column)."""
    for r, c, cost in costmap.cells():
        yield cost, tie, arm, r, c
