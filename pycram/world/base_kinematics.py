"""How a robot's base can move: omnidirectional, or a differential drive that cannot go sideways.

A robot description's ``BASE["kind"]`` names its kinematics (:data:`KINDS`); :class:`BaseKinematics`
holds it with the numbers a differential drive needs. Backend-neutral (no simulator, no numpy):
the path planner (`pycram.world.navigation.PathPlanner`), the simulated drives
(`pycram.backends.sim.controllers`) and location reasoning read it.

An **omnidirectional** base (PR2, TIAGo Pro) drives any straight line while turning: one move
from pose ``a`` to pose ``b`` is that line.

A **differential drive** (TIAGo) moves only along its heading (forwards or backwards): straight,
on an arc (constant wheel speeds, `arc_radius`) or turning on the spot. A move from ``a`` to ``b``
that lies on one arc is one move; otherwise it is a chain of straight drives and turns;
:func:`move_options` lists the chains that realise it, in the order a planner should prefer them:

1. turn to face ``b``, drive forwards, turn to ``b``'s heading;
2. the same backwards (only up to ``max_reverse`` [m]: the robot has no eyes behind it); this
   comes first when it turns less (a step back from a counter);
3. arrive straight: drive (as 1) to the point ``approach`` [m] behind ``b`` along ``b``'s
   heading, turn to that heading, drive the last ``approach`` metres straight in -- the way to
   a pose facing a counter when turning on the spot there would sweep a carried object or an
   arm over it;
4. leave straight: back out ``approach`` metres along ``a``'s heading first, then as 1;
5. leave and arrive straight (4 and 3).

Every pose of a chain but the last is an intermediate stop; consecutive poses differ either in
position along the common heading (a straight drive) or in heading alone (a turn on the spot).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .prospection import BasePose

__all__ = [
    "KINDS",
    "OMNIDIRECTIONAL",
    "DIFFERENTIAL",
    "BaseKinematics",
    "move_options",
    "is_primitive",
    "arc_radius",
    "arc_pose",
    "arc_point",
    "drive_moves",
    "POSITION_EPS",
    "HEADING_EPS",
]

#: The kind of a base that moves in any direction and turns at once (PR2, TIAGo Pro).
OMNIDIRECTIONAL = "omnidirectional"
#: The kind of a base that drives along its heading and turns on the spot or on arcs (TIAGo).
DIFFERENTIAL = "differential"
#: The base kinematics a robot description may name (``BASE["kind"]``).
KINDS = (OMNIDIRECTIONAL, DIFFERENTIAL)
#: Moves shorter than this [m] are turns on the spot.
POSITION_EPS = 1e-3
#: Headings closer than this [rad] need no turn.
HEADING_EPS = 1e-3
#: `drive_moves` reaches a goal by an arc when its position lies within this [rad] of straight
#: ahead or behind (the arc then turns the robot by twice as much).
MAX_TANGENT = math.pi / 6
#: A move is an arc when its chord points within this [rad] of the mean of its end headings.
ARC_TOLERANCE = 1e-3


@dataclass(frozen=True)
class BaseKinematics:
    """A base's kinematics: `kind` (one of `KINDS`); for a differential drive the longest
    backwards drive `max_reverse` [m] and the straight run `approach` [m] of arriving at or
    leaving a pose along its heading."""

    kind: str = OMNIDIRECTIONAL
    max_reverse: float = 0.5
    approach: float = 0.3

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"base kind {self.kind!r} is unknown; valid kinds: {', '.join(KINDS)}")
        for name in ("max_reverse", "approach"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0.0:
                raise ValueError(f"base {name} must be a finite length >= 0 [m], not {value!r}")

    @property
    def holonomic(self) -> bool:
        """Whether the base can move in any direction (omnidirectional)."""
        return self.kind == OMNIDIRECTIONAL

    @classmethod
    def of(cls, base: Mapping[str, Any]) -> BaseKinematics:
        """The kinematics of a description's ``BASE`` mapping: ``kind`` (default
        omnidirectional), ``max_reverse`` and ``approach`` [m] (defaults 0.5 and 0.3)."""
        defaults = cls()
        return cls(
            kind=base.get("kind", defaults.kind),
            max_reverse=base.get("max_reverse", defaults.max_reverse),
            approach=base.get("approach", defaults.approach),
        )


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _turn_and_drive(chain: list[BasePose], goal_x: float, goal_y: float, backwards: bool) -> None:
    """Append to `chain` the turn (if needed) and the straight drive from its last pose to
    (goal_x, goal_y), facing the way of travel (or away from it, `backwards`)."""
    here = chain[-1]
    dx, dy = goal_x - here.x, goal_y - here.y
    if math.hypot(dx, dy) < POSITION_EPS:
        return
    heading = math.atan2(dy, dx) + (math.pi if backwards else 0.0)
    heading = here.yaw + _wrap(heading - here.yaw)  # the nearer way round, yaw kept continuous
    if abs(heading - here.yaw) > HEADING_EPS:
        chain.append(BasePose(here.x, here.y, heading))
    chain.append(BasePose(goal_x, goal_y, heading))


def _turn_to(chain: list[BasePose], yaw: float) -> None:
    here = chain[-1]
    if abs(_wrap(yaw - here.yaw)) > HEADING_EPS:
        chain.append(BasePose(here.x, here.y, here.yaw + _wrap(yaw - here.yaw)))


def _chain(a: BasePose, b: BasePose, backwards: bool, leave: float, arrive: float) -> list[BasePose]:
    chain = [a]
    if leave > 0.0:
        _turn_and_drive(chain, a.x - leave * math.cos(a.yaw), a.y - leave * math.sin(a.yaw), backwards=True)
    if arrive > 0.0:
        px, py = b.x - arrive * math.cos(b.yaw), b.y - arrive * math.sin(b.yaw)
        _turn_and_drive(chain, px, py, backwards)
        _turn_to(chain, b.yaw)
    _turn_and_drive(chain, b.x, b.y, backwards)
    _turn_to(chain, b.yaw)
    out = chain[1:]
    if out:
        last = out[-1]
        out[-1] = BasePose(last.x, last.y, b.yaw)  # the goal's own yaw value, not an unwrapped one
    return out or [b]


def _turning(a: BasePose, chain: list[BasePose]) -> float:
    """The total turn [rad] of a chain of moves from ``a``."""
    total, yaw = 0.0, a.yaw
    for pose in chain:
        total += abs(_wrap(pose.yaw - yaw))
        yaw = pose.yaw
    return total


def move_options(a: BasePose, b: BasePose, kinematics: BaseKinematics) -> list[list[BasePose]]:
    """The chains of poses (``a`` excluded, ``b`` last) that move a base of `kinematics` from
    ``a`` to ``b``, preferred first (see the module docstring). An omnidirectional base has one:
    ``[b]``. Deterministic: the same question gives the same chains."""
    if kinematics.holonomic:
        return [[b]]
    rho = arc_radius(a, b)
    if rho is not None and (rho > 0 or abs(rho * _wrap(b.yaw - a.yaw)) <= kinematics.max_reverse + 1e-6):
        return [[b]]  # on an arc: one move with constant wheel speeds
    dist = math.hypot(b.x - a.x, b.y - a.y)
    options = [_chain(a, b, False, 0.0, 0.0)]
    if POSITION_EPS <= dist <= kinematics.max_reverse + 1e-6:
        backwards = _chain(a, b, True, 0.0, 0.0)
        # a short way back (e.g. stepping back from a counter): backwards first if it turns less
        options.insert(0 if _turning(a, backwards) < _turning(a, options[0]) else 1, backwards)
    d = kinematics.approach
    if d > 0.0 and dist >= POSITION_EPS:
        options.append(_chain(a, b, False, 0.0, d))
        if d <= kinematics.max_reverse:
            options.append(_chain(a, b, False, d, 0.0))
            options.append(_chain(a, b, False, d, d))
    unique: list[list[BasePose]] = []
    for option in options:
        if option not in unique:
            unique.append(option)
    return unique


def arc_radius(a: BasePose, b: BasePose) -> float | None:
    """The signed ratio [m/rad] of distance to turn of the arc from ``a`` to ``b`` -- the arc a
    differential drive follows with constant wheel speeds (positive: forwards, negative:
    backwards) -- or None when ``b`` is not on such an arc from ``a`` (a sideways step), and
    for a straight drive or a turn on the spot (they have no finite turn radius)."""
    dist = math.hypot(b.x - a.x, b.y - a.y)
    turn = _wrap(b.yaw - a.yaw)
    if dist < POSITION_EPS or abs(turn) < HEADING_EPS or abs(turn) > math.pi / 2:
        return None
    chord = math.atan2(b.y - a.y, b.x - a.x)
    mean = a.yaw + turn / 2.0  # an arc's chord points along the mean of its end headings
    forwards = abs(_wrap(chord - mean)) <= ARC_TOLERANCE
    if not forwards and abs(_wrap(chord - mean - math.pi)) > ARC_TOLERANCE:
        return None
    length = dist * (abs(turn) / 2.0) / math.sin(abs(turn) / 2.0)
    return (length if forwards else -length) / turn


def arc_pose(a: BasePose, b: BasePose, s: float) -> BasePose:
    """The pose at fraction `s` (0..1) of the move from ``a`` to ``b``: on the arc between them
    when there is one (`arc_radius`), else on the straight line, turning uniformly."""
    rho = arc_radius(a, b)
    yaw = a.yaw + s * _wrap(b.yaw - a.yaw)
    if rho is None:
        return BasePose(a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), yaw)
    x, y = arc_point(a.x, a.y, a.yaw, rho, yaw)
    return BasePose(x, y, yaw)


def arc_point(x0: float, y0: float, yaw0: float, rho: float, yaw: float) -> tuple[float, float]:
    """The position [m] reached on the arc that leaves (`x0`, `y0`) at heading `yaw0` [rad] with
    the signed ratio `rho` [m/rad] of distance to turn (`arc_radius`) once the heading is `yaw`."""
    return x0 + rho * (math.sin(yaw) - math.sin(yaw0)), y0 - rho * (math.cos(yaw) - math.cos(yaw0))


def drive_moves(
    here: BasePose, goal: BasePose, kinematics: BaseKinematics, tolerance: float = 0.02, reach: float = 0.0
) -> list[BasePose]:
    """The moves a differential drive makes from where it is (``here``) to ``goal``, ``goal``
    last: the move itself when it is one a differential drive makes (`is_primitive`, within
    `tolerance` [rad]); a turn on the spot to ``goal``'s heading, ending at ``here``'s position,
    when ``goal``'s position is within `reach` [m] (it counts as reached: a drive that stopped
    a few millimetres off its goal must not turn towards that offset, drive it and turn back --
    such turns, up to half a circle, were never checked for what the arm holds); else, when
    ``goal`` lies within `MAX_TANGENT` of straight ahead (or behind, up to ``max_reverse``),
    the arc that leaves ``here`` along its heading through ``goal``'s position, then a turn to
    ``goal``'s heading (how a drive that ended a little off its line makes its next straight
    move); else turn, drive, turn (`move_options`). An omnidirectional base makes the move
    itself."""
    if kinematics.holonomic or is_primitive(here, goal, tolerance):
        return [goal]
    dist = math.hypot(goal.x - here.x, goal.y - here.y)
    if dist <= reach:
        return [BasePose(here.x, here.y, goal.yaw)]
    chord = math.atan2(goal.y - here.y, goal.x - here.x)
    for backwards in (False, True):
        off = _wrap(chord - here.yaw - (math.pi if backwards else 0.0))
        if abs(off) <= MAX_TANGENT and (not backwards or dist <= kinematics.max_reverse + 1e-6):
            end = BasePose(goal.x, goal.y, here.yaw + 2.0 * off)  # the chord is the mean heading
            return [end, goal] if abs(_wrap(goal.yaw - end.yaw)) > HEADING_EPS else [goal]
    return move_options(here, goal, kinematics)[0]


def is_primitive(a: BasePose, b: BasePose, tolerance: float = 0.02) -> bool:
    """Whether the move from ``a`` to ``b`` is one a differential drive makes without a
    sideways step: a turn on the spot, a straight drive along ``a``'s heading (forwards or
    backwards) to within `tolerance` [rad] of heading, or an arc (`arc_radius`)."""
    dist = math.hypot(b.x - a.x, b.y - a.y)
    if dist < POSITION_EPS:
        return True
    if arc_radius(a, b) is not None:
        return True
    heading = math.atan2(b.y - a.y, b.x - a.x)
    along = min(abs(_wrap(heading - a.yaw)), abs(_wrap(heading - a.yaw - math.pi)))
    return along <= tolerance and abs(_wrap(b.yaw - a.yaw)) <= tolerance
