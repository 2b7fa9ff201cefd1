"""What picking up and placing share: the arm configuration an object is carried in
(`carry_configuration`), reaching one phase of a grasp or place sequence (`_reach`), backing
the base away from the furniture (`back_away`, `BACK_AWAY` [m]), parking the arms that hold
nothing (`park_empty_arms`), and looking at an object again before believing what a look tells
(`_look_again`, at most `LOOKS_TO_CONFIRM` looks).

Everything here moves the robot through motion designators (`pycram.actions.core.motion`);
`back_away` is best effort (a failure is logged, not raised).
"""

from __future__ import annotations

import logging
from typing import Any

from pycram.execution.robot import current_robot
from pycram.world.belief import PerceivedObject
from pycram.world.objects import Grasp

from .core import RECOVERABLE, _description, arms, best_effort, motion, unwrap
from .held import held_objects

__all__ = ["carry_configuration", "back_away", "park_empty_arms", "BACK_AWAY", "LOOKS_TO_CONFIRM"]

log = logging.getLogger("pycram.actions")

#: Looks at an object that should be in view before the action believes what they tell: it is
#: looked at again while it is missed but not believed gone yet (`BeliefState.misses_to_gone`).
LOOKS_TO_CONFIRM = 3
#: After picking up or putting down at a surface, the base backs straight away from it by this
#: much [m] before it drives on: the arm in its carry pose still reaches ~0.65 m ahead, over the
#: surface, and the path planner keeps only the base off a counter the arms reach over -- driving
#: along the counter from there, the carried plate swept a milk carton over (measured: PR2,
#: set-table seed 31 with faults; the carton was then picked up lying and could not be placed).
BACK_AWAY = 0.3


def carry_configuration(arm: str, grasp: Grasp) -> str:
    """The named arm configuration to carry an object held with `grasp` in: ``carry_top`` (the
    tool pointing down, the object level) for a grasp `Grasp.held_from_above` when the robot's
    description has it, else ``carry``. The arm comes to the grasp in it too (location reasoning
    checks the grasp from there)."""
    named = _description().ARM_CONFIGURATIONS.get(arm, {})
    return "carry_top" if grasp.held_from_above and "carry_top" in named else "carry"


def park_empty_arms(keep: str | None = None) -> bool:
    """Park each arm but `keep` that holds nothing (best effort: a failure is logged; an arm
    parked already is there at once); whether any was parked."""
    parked = False
    for arm in arms():
        if arm == keep or arm in held_objects():
            continue
        try:
            motion(type="setting_arm_configuration", arm=arm, configuration="park")
            parked = True
        except RECOVERABLE as error:
            log.info("parking the empty %s arm: %s", arm, unwrap(error))
    return parked


def _reach(arm: str, location: Any, index: int, phase: str, point: list[float] | None, grasping: Any = None) -> Any:
    """Reach phase `phase` of a sequence: the `index`-th validated tool pose of `location` when
    it has them (top grasps: the tool's orientation matters), else `point` with the phase's
    offset along the base's heading. `grasping`: the believed object being grasped (it may touch
    the fingers on the way: the motion's ``object``), None for none. The arm's joints validated
    for that pose (`location.joints`) go along as IK's first guess (the motion's ``joints``).
    Returns what the motion returns (the reached tool pose)."""
    poses = getattr(location, "tool_poses", ())
    extra = {} if grasping is None else {"object": grasping}
    validated = getattr(location, "joints", ())
    if len(validated) > index:
        extra["joints"] = list(validated[index])
    if location.grasp == "top" and len(poses) > index:
        position, orientation = poses[index]
        return motion(
            type="reaching", arm=arm, target=list(position), orientation=list(orientation), phase=phase, **extra
        )
    return motion(type="reaching", arm=arm, target=point, phase=phase, **extra)


def _pose_text(location: Any) -> str:
    return f"({location.x:.2f}, {location.y:.2f})"


def back_away(why: str, distance: float = BACK_AWAY) -> None:
    """Best effort: drive the base `distance` [m] straight back (a planned drive, so it stops
    short of anything behind it rather than touching it); a failure is logged, not raised (the
    object is held or down already)."""
    best_effort(
        f"backing away after {why}",
        lambda: motion(type="moving", pose=(-distance, 0.0, 0.0), frame="base_footprint"),
    )


def _look_again(obj: PerceivedObject, point: Any = None) -> bool:
    """Point the head at the believed object (or at `point` [m, map]) and look; True when it was
    seen. The belief is refreshed, or counts a miss when the object should have been seen (not
    hidden, e.g. by the robot's own arm) and was not: then the robot looks again, until the
    object is seen or has been missed as often in a row as the belief needs to hold it gone
    (`BeliefState.misses_to_gone`: one missed detection is no proof that the object is not
    there), at most `LOOKS_TO_CONFIRM` looks."""
    belief = getattr(current_robot(), "belief", None)
    needed = int(getattr(belief, "misses_to_gone", 1))
    seen_before, missed_before = obj.times_seen, obj.misses
    target = list(obj.pose if point is None else point)
    for _ in range(LOOKS_TO_CONFIRM):
        misses = obj.misses
        motion(type="pointing_head", coordinates=target)
        motion(type="detecting", object=obj.type)
        if obj.times_seen > seen_before:
            return True
        if obj.misses == misses or obj.misses - missed_before >= needed:
            return False  # hidden from this view (looking again will not tell), or missed enough
    return False


def _xyz(p: Any) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"
