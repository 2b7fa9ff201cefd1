"""Failures with meaning, after CRAM's taxonomy: what went wrong, about which designator, why.

Plans catch these by kind (``except ManipulationFailure``, ``except ObjectNotFound``); each
carries the designator it is about (``designator``) and the reason as data (``reason``, a short
machine-readable word such as ``'no_path'`` or ``'closed_on_nothing'``). Stdlib only.

::

    PlanFailure
    ├── MotionFailure              a process module could not execute a motion
    ├── NavigationFailure          the base cannot get where it should
    │   ├── GoalUnreachable        no path, goal occupied, no standing pose
    │   └── PathBlocked            the way is blocked and no other way was found
    ├── ManipulationFailure
    │   ├── ObjectOutOfReach       no standing pose from which an arm reaches the object
    │   ├── GraspFailed            the gripper closed on nothing
    │   ├── ObjectSlipped          the object left the gripper while carried
    │   ├── GripperEmpty           placing, but the gripper holds nothing
    │   └── PlacingFailed          the object does not rest where it was put
    ├── PerceptionFailure
    │   ├── ObjectNotFound         a search did not find it
    │   └── ObjectNotVisible       it should be visible from here but is not
    └── ContainerFailure           a drawer or door
        ├── ContainerStuck         does not move when pulled
        └── HandleMissed           the gripper did not get the handle

    SimulationFault                the simulated physics broke (not a PlanFailure: see below)

An action that gives up after its bounded attempts raises the failure of its last attempt;
``attempts`` lists what every attempt ran into (strings, oldest first). Every failure says
what to try in ``hint`` (one sentence; the class' default unless given), and ``summary()``
says what failed, why and what to try in at most two short lines (`failure_summary` for any
exception): what a terminal shows; the whole message and the chain of causes stay in the
exception and in the trace.

`SimulationFault` is raised when the simulator's physics broke -- an object left the world,
flew faster than anything in a household moves, or sank into the furniture or through the
floor (`pycram.backends.sim.physics_faults`). No plan can recover from that, so it derives from
`BaseException`, like evaporation: the recoveries of plans and actions (``except PlanFailure``,
``except Exception``) let it pass, and the run ends with it, named, at once -- not after a
search for an object that is no longer in the world.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any, ClassVar

__all__ = [
    "PlanFailure",
    "MotionFailure",
    "NavigationFailure",
    "GoalUnreachable",
    "PathBlocked",
    "ManipulationFailure",
    "ObjectOutOfReach",
    "GraspFailed",
    "ObjectSlipped",
    "GripperEmpty",
    "PlacingFailed",
    "PerceptionFailure",
    "ObjectNotFound",
    "ObjectNotVisible",
    "ContainerFailure",
    "ContainerStuck",
    "HandleMissed",
    "SimulationFault",
    "PHYSICS_FAULT_KINDS",
    "failure_summary",
    "failure_chain",
    "SUMMARY_LINE",
]

#: The longest line [characters] of a `failure_summary`.
SUMMARY_LINE = 160


class PlanFailure(Exception):
    """Base class of the failures plans raise and handle.

    ``designator``: what it is about (or None); ``reason``: a short word saying why (the class'
    default when not given); ``attempts``: what earlier attempts ran into (oldest first).
    """

    #: The reason when none is given.
    default_reason = "failed"
    #: What to try, by reason (a reason not listed: `default_hint`).
    hints: ClassVar[dict[str, str]] = {}
    #: What to try when `hints` has nothing for the reason ("" for nothing to say).
    default_hint = ""

    def __init__(
        self,
        message: str,
        designator: Any = None,
        reason: str | None = None,
        attempts: Sequence[str] = (),
        hint: str | None = None,
    ) -> None:
        super().__init__(message)
        self.designator = designator
        self.reason = reason if reason is not None else self.default_reason
        self.attempts = list(attempts)
        self._hint = hint

    @property
    def hint(self) -> str:
        """What to try (one sentence): given to the constructor, else the class' hint for the
        reason, else its `default_hint`."""
        if self._hint is not None:
            return self._hint
        return self.hints.get(self.reason, self.default_hint)

    def summary(self) -> str:
        """What failed, why and what to try, in at most two lines of at most `SUMMARY_LINE`
        characters (see `failure_summary`)."""
        return failure_summary(self)


class MotionFailure(PlanFailure):
    """A process module could not execute a motion designator (the backend's reason)."""

    default_reason = "motion_failed"
    default_hint = "a part of the robot could not move as asked: `pycram show RUN` names the part and why"
    hints: ClassVar[dict[str, str]] = {
        "collision": "something was in the way: look at the scene picture, or try another standing pose",
        "blocked": "something was in the way: look at the scene picture, or try another standing pose",
        "timeout": "the motion did not end in time: the part may be stuck against something",
        "unreachable": "the target is out of the arm's reach from where the robot stands",
    }


class NavigationFailure(PlanFailure):
    """The base cannot get where it was asked to go."""

    default_reason = "navigation_failed"
    default_hint = "try another goal or standing side, or take the obstacle away"


class GoalUnreachable(NavigationFailure):
    """No way to the goal: no path, the goal occupied, or no standing pose found."""

    default_reason = "unreachable"
    hints: ClassVar[dict[str, str]] = {
        "goal_in_collision": "the robot does not fit at the goal: try another standing side or a goal farther out",
        "no_path": "no collision-free way there: try another standing side, or take the obstacle away",
        "no_solution": "the location has no solution: check its properties (`pycram costmap` draws it)",
    }


class PathBlocked(NavigationFailure):
    """The way was blocked while driving and no other way got through."""

    default_reason = "blocked"
    default_hint = "the way was blocked while driving: take the obstacle away or try another goal"


class ManipulationFailure(PlanFailure):
    """Grasping, holding or putting down an object went wrong."""

    default_reason = "manipulation_failed"


class ObjectOutOfReach(ManipulationFailure):
    """No standing pose from which an arm reaches the object (or the spot to place it)."""

    default_reason = "out_of_reach"
    default_hint = (
        "out of reach from every standing pose tried: try another grasp or arm, or a start closer to the surface's edge"
    )
    hints: ClassVar[dict[str, str]] = {
        "no_drivable_pose": "no standing pose from which it is reachable could be driven to: clear the floor there",
    }


class GraspFailed(ManipulationFailure):
    """The gripper closed on nothing (or could not get into position to grasp)."""

    default_reason = "closed_on_nothing"
    default_hint = "try another grasp or arm (PickUp(..., grasp=..., arm=...)); the object may have moved"
    hints: ClassVar[dict[str, str]] = {
        "no_executable_grasp": "ask for a grasp the object type has (`pycram.world.objects`), or leave grasp=None",
        "blocked": "the arm met the furniture on its way: try another grasp, arm or standing side",
    }


class ObjectSlipped(ManipulationFailure):
    """The object left the gripper while it was carried."""

    default_reason = "slipped"
    default_hint = "the grip was too weak or the object was taken: pick it up again (Transport does)"


class GripperEmpty(ManipulationFailure):
    """An action needed an object in the gripper, and the gripper holds nothing."""

    default_reason = "gripper_empty"
    default_hint = "pick the object up first (PickUp), or use Transport"


class PlacingFailed(ManipulationFailure):
    """The object was let go but does not rest where it was put."""

    default_reason = "not_at_target"
    default_hint = "try another spot (a location designator's next solution) or another grasp"
    hints: ClassVar[dict[str, str]] = {
        "toppled": "it fell over when put down: try a spot farther from other objects and edges",
        "not_resting": "it stands on something or stays in the gripper: try another spot",
        "no_path": "no standing pose near the spot could be driven to: try another spot or clear the floor",
    }


class PerceptionFailure(PlanFailure):
    """Perception did not deliver what the plan needed."""

    default_reason = "perception_failed"


class ObjectNotVisible(PerceptionFailure):
    """The object should be visible from where the robot looks, but is not seen."""

    default_reason = "not_visible"
    default_hint = "look from elsewhere or search for it (Search): something may hide it, or it moved"


class ObjectNotFound(PerceptionFailure):
    """A search did not find an object matching ``designator``; ``looked`` names every place it
    looked at (in order) and ``skipped`` the places it could not look into, with the reason."""

    default_reason = "not_found"
    default_hint = (
        "check the object type and that the object is in the scene (`pycram scene` draws it); "
        "the search looks only where objects of its type are found"
    )

    def __init__(self, designator: Any, looked: Sequence[str], skipped: Sequence[tuple[str, str]] = ()) -> None:
        self.looked = list(looked)
        self.skipped = list(skipped)
        message = f"no object matching {designator!r} found; looked at: {', '.join(self.looked) or 'nothing'}"
        if self.skipped:
            message += "; could not look into: " + ", ".join(f"{p} ({why})" for p, why in self.skipped)
        super().__init__(message, designator)


class ContainerFailure(PlanFailure):
    """Opening or closing a drawer or door went wrong; ``container`` names it."""

    default_reason = "container_failed"
    default_hint = "try again from another standing pose, or open it by another arm"

    def __init__(
        self,
        message: str,
        container: str | None = None,
        designator: Any = None,
        reason: str | None = None,
        attempts: Sequence[str] = (),
    ) -> None:
        super().__init__(message, designator, reason, attempts)
        self.container = container


class ContainerStuck(ContainerFailure):
    """The drawer or door does not move when its handle is pulled."""

    default_reason = "stuck"
    default_hint = "it does not move: something blocks it (a fault, an object inside), so fetch elsewhere"


class HandleMissed(ContainerFailure):
    """The gripper closed beside the handle."""

    default_reason = "handle_missed"
    default_hint = "the gripper missed the handle: try again after a new look, or from another standing pose"


#: What `SimulationFault.reason` says, for each kind of broken physics.
PHYSICS_FAULT_KINDS = {
    "left_world": "left the world",
    "too_fast": "moved faster than anything in a household moves",
    "below_floor": "fell through the floor",
    "sunk": "sank into the furniture",
}


class SimulationFault(BaseException):
    """The simulated physics broke: an object left the world, flew, or sank into the furniture
    or through the floor (`pycram.backends.sim.physics_faults` watches the simulator's truth).

    Not a `PlanFailure`: derived from `BaseException` (like evaporation), so no recovery of a
    plan or an action handles it and the run ends with it at once. The simulated world raises
    it again for every later motion or look of the robot.

    ``object``: the object's name; ``reason``: one of `PHYSICS_FAULT_KINDS`; ``sim_time``: when
    it was noticed [s of simulated time]; ``position`` (x, y, z) [m, map] and ``speed`` [m/s]
    of the object then; ``designator`` (None) and ``attempts`` (empty) as every typed failure has.
    """

    default_hint = (
        "a physics glitch, not a plan failure: replay the run (`pycram replay RUN`) and look at "
        "the grasp or push just before it"
    )

    def __init__(
        self,
        message: str,
        object: str = "",
        reason: str = "left_world",
        sim_time: float = 0.0,
        position: Sequence[float] = (0.0, 0.0, 0.0),
        speed: float = 0.0,
    ) -> None:
        if reason not in PHYSICS_FAULT_KINDS:
            raise ValueError(f"unknown physics fault {reason!r}; known: {', '.join(PHYSICS_FAULT_KINDS)}")
        super().__init__(message)
        self.object, self.reason, self.sim_time = object, reason, float(sim_time)
        self.position = tuple(float(v) for v in position)
        self.speed = float(speed)
        self.designator: Any = None
        self.attempts: list[str] = []

    @property
    def hint(self) -> str:
        """What to try (one sentence)."""
        return self.default_hint

    def again(self) -> SimulationFault:
        """A new exception saying the same (to raise it once more, from another place)."""
        return SimulationFault(str(self), self.object, self.reason, self.sim_time, self.position, self.speed)

    def summary(self) -> str:
        """What failed, why and what to try, in at most two short lines."""
        return failure_summary(self)


# -- short failure messages ---------------------------------------------------------------------


def failure_chain(error: BaseException) -> Iterator[BaseException]:
    """`error`, then what caused it, innermost last: a process module's failure's ``cause``,
    else ``__cause__`` (an explicit ``raise ... from``). Each exception once."""
    seen: set[int] = set()
    current: BaseException | None = error
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        yield current
        inner = getattr(current, "cause", None)
        current = inner if isinstance(inner, BaseException) else current.__cause__


def _typed(error: BaseException) -> BaseException:
    """The first typed failure (a `PlanFailure` or `SimulationFault`) in the chain, else `error`."""
    return next((e for e in failure_chain(error) if isinstance(e, (PlanFailure, SimulationFault))), error)


def _skip_repr(text: str, start: int) -> int:
    """The index just past a designator's repr starting at `start` (balanced brackets)."""
    depth, i = 0, start
    while i < len(text):
        c = text[i]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
            if depth <= 0:
                return i + 1
        elif c == " " and depth == 0 and i > start:
            return i
        i += 1
    return i


def innermost_clause(text: str) -> str:
    """The first line of `text` without the nested "Cannot resolve <designator>: " layers that
    failed resolutions put in front of what really failed (each layer repeats the designator)."""
    line = text.strip().split("\n", 1)[0]
    marker = "Cannot resolve "
    while True:
        at = line.find(marker)
        if at < 0:
            return line
        i = at + len(marker)
        for kind in ("location designator ", "object designator ", "action designator ", "motion designator "):
            if line.startswith(kind, i):
                i += len(kind)
        end = _skip_repr(line, i)
        rest = line[end:].lstrip(":").strip()
        if not rest:  # nothing after the designator: keep it
            return line
        line = line[:at] + rest


def _clip(text: str, width: int) -> str:
    text = " ".join(text.split())
    if len(text) <= width:
        return text
    cut = text[: width - 1]
    space = cut.rfind(" ")
    return (cut[:space] if space > width // 2 else cut).rstrip(" ,;:") + "…"


def failure_summary(error: BaseException, width: int = SUMMARY_LINE) -> str:
    """What failed, why and what to try, in at most two lines of at most `width` characters.

    Line 1: the typed failure (the first `PlanFailure` or `SimulationFault` in the chain of
    causes, else `error`), its reason and the first line of its message -- and, when the
    innermost cause says something that line does not, "because:" and its first line (both
    without the nested "Cannot resolve ..." layers, cut to share the line). Line 2 (when the
    failure has one): its hint, "try: ...". The whole message and every cause stay in the
    exception (`pycram show` and ``--verbose`` show them)."""
    typed = _typed(error)
    name = type(typed).__name__
    reason = getattr(typed, "reason", None)
    head = f"{name} ({reason})" if isinstance(reason, str) and reason else name
    first = f"{head}: {innermost_clause(str(typed)) or '(no message)'}"
    inner = list(failure_chain(error))[-1]
    why = innermost_clause(str(inner)) if inner is not typed else ""
    if why and why not in first:
        because = " — because: "
        room = max(width // 2, width - len(because) - min(len(why), width // 2))
        line1 = _clip(first, room)
        line1 += because + why
        line1 = _clip(line1, width) if len(line1) > width else line1
    else:
        line1 = _clip(first, width)
    hint = str(getattr(typed, "hint", "") or "")
    return line1 + ("\n  " + _clip(f"try: {hint}", width - 2) if hint else "")
