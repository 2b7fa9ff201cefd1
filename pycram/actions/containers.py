"""Opening and closing drawers: grasp the handle, pull (or push) it along the drawer's slide.

`Open("drawer 2")`: ``('to_open', container)`` chooses where to stand, which arm and -- for a
handle too low or too high for the torso as it is -- the torso height.
One attempt drives there, looks at the handle (perception measures how far the drawer is open),
grasps the handle (fingers closing vertically on its horizontal bar), pulls it along the opening
trajectory in steps, lets go, backs off and looks again: the drawer must be measured open (within
6 cm of the goal, or at least 15 cm out: enough to look and reach in).
`Close("drawer 2")` is the same, pushing back to closed.

Failures, after `CONTAINER_ATTEMPTS` standing poses: `HandleMissed` (the gripper closed beside
the handle), `ContainerStuck` (the drawer did not follow the pull), `ObjectOutOfReach` (no
standing pose). Doors (the fridge) are not opened by a robot yet: ``Open('fridge')`` raises
`ContainerFailure` with reason ``'door_not_supported'`` -- a door's handle swings on an arc that
the fixed-orientation ``reaching`` motion cannot follow.

The environment's description (handle positions, slide directions, limits) is map knowledge the
plan may read; how far a drawer is open comes only from perception (the belief's
``container_states``).
"""

from __future__ import annotations

import logging
import math
import weakref
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.location import LocationDesignator
from pycram.failures import ContainerFailure, ContainerStuck, HandleMissed, ObjectOutOfReach
from pycram.robot import current_robot

from .core import (
    RECOVERABLE,
    ActionParameterError,
    action_plan,
    arm_name,
    attempt,
    base_pose_fluent,
    best_effort,
    gripper_of,
    make_action,
    motion,
    solutions,
    unwrap,
)

__all__ = ["Open", "Close", "DRAWER_OPENING", "CONTAINER_ATTEMPTS", "PULL_STEPS", "HANDLE_OPENING"]

log = logging.getLogger("pycram.actions")

#: How far [m] `Open` pulls a drawer out when not told.
DRAWER_OPENING = 0.3
#: Standing poses tried per opening or closing.
CONTAINER_ATTEMPTS = 4
#: Steps of the pull along the drawer's slide.
PULL_STEPS = 4
#: Below this measured opening [m] the gripper closed beside the handle (the bar is 24 mm thick).
HANDLE_OPENING = 0.008
#: The robot counts as standing at a pose within this [m, rad] (it does not drive there again).
AT_POSE = 0.03
#: A push that stopped short goes on from this much [m] nearer to the drawer.
STEP_IN = 0.15
#: Closing pushes the handle this far [m] beyond closed (the slide's stop holds the drawer).
PUSH_BEYOND = 0.03
#: A drawer counts as closed below this opening [m], as opened when within this of its goal --
#: or at least `USEFUL_OPENING` [m] out (enough to look and reach in).
CLOSED, OPEN_TOLERANCE, USEFUL_OPENING = 0.03, 0.06, 0.15


def Open(container: str, arm: str | None = None, opening: float | None = None) -> ActionDesignator:
    """Open the drawer `container` (its name in the environment) by `opening` [m] (default
    `DRAWER_OPENING`) with `arm` (None: the reasoning chooses). Returns the measured opening."""
    return make_action("opening", container=container, arm=arm, opening=opening)


def Close(container: str, arm: str | None = None) -> ActionDesignator:
    """Close the drawer `container`. Returns the measured opening [m] afterwards."""
    return make_action("closing", container=container, arm=arm)


def _environment() -> Any:
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if environment is None:
        raise ContainerFailure("opening and closing need a robot whose belief knows the environment")
    return belief, environment


def _container(action: str, designator: ActionDesignator) -> tuple[Any, Any, Any]:
    name = designator.prop_value("container")
    belief, environment = _environment()
    names = [c.name for c in environment.containers]
    if name not in names:
        raise ActionParameterError(action, "container", f"the environment has no container {name!r}", names)
    container = environment.container(name)
    if container.kind != "drawer":
        raise ContainerFailure(
            f"{action} {name!r}: robots open and close drawers only so far (a door's "
            f"handle swings on an arc the reaching motion cannot follow)",
            name,
            designator,
            "door_not_supported",
        )
    return belief, environment, container


def _measure(belief: Any, container: Any) -> float | None:
    """Look at the handle; the opening [m] perception measured (None when it could not)."""
    q = belief.container_states.get(container.name, 0.0)
    # standing close, the head may not turn all the way: it looks as near as it can
    best_effort(
        "looking at a handle", lambda: motion(type="pointing_head", coordinates=list(container.handle_position(q)))
    )
    motion(type="detecting")
    measured = belief.container_states.get(container.name)
    return None if measured is None else float(measured)


def _move_handle(location: Any, belief: Any, container: Any, goal: float) -> float:
    """One attempt: stand at `location`, grasp the handle, move it to `goal` [m], let go, look."""
    arm, grasp = location.arm, location.grasp
    gripper = gripper_of(arm)
    motion(type="setting_gripper", gripper=gripper, position=1)
    try:
        motion(type="setting_arm_configuration", arm=arm, configuration="carry")
    except RECOVERABLE as error:  # e.g. close to the furniture after a failed attempt
        log.info("%s: arm up before driving: %s", container.name, unwrap(error))
    if location.torso is not None:  # the handle is too low or too high for the torso as it was
        motion(type="setting_torso", position=location.torso)
    here = base_pose_fluent().get_value()
    if (
        here is None
        or math.hypot(here.x - location.x, here.y - location.y) > AT_POSE
        or abs(math.remainder(here.yaw - location.yaw, math.tau)) > AT_POSE
    ):
        motion(type="moving", pose=location)
    start = _measure(belief, container)
    start = 0.0 if start is None else start
    if abs(start - goal) < OPEN_TOLERANCE / 2:
        return start
    handle = list(container.handle_position(start))
    motion(type="reaching", arm=arm, target=handle, phase="pre_grasp", grasp=grasp)
    motion(type="reaching", arm=arm, target=handle, phase="grasp", grasp=grasp)
    opening = float(motion(type="setting_gripper", gripper=gripper, position=0))
    if opening < HANDLE_OPENING:
        _release(arm, gripper, handle, grasp)
        raise HandleMissed(
            f"the {gripper} gripper closed beside the handle of {container.name!r} (opening {opening * 1000:.1f} mm)",
            container.name,
        )
    reached = handle
    try:
        for k in range(1, PULL_STEPS + 1):
            q = start + (goal - start) * k / PULL_STEPS
            beyond = goal == 0.0 and k == PULL_STEPS
            if beyond:
                q = -PUSH_BEYOND  # against the stop: a drawer pushed exactly to 0 stays ajar
            reached = list(container.handle_position(q))
            try:
                motion(type="reaching", arm=arm, target=reached, grasp=grasp)
            except RECOVERABLE as error:
                if getattr(unwrap(error), "reason", None) != "blocked" and not beyond:
                    raise
                log.info("%s: the handle stopped moving at step %d: %s", container.name, k, unwrap(error))
                break
    finally:
        _release(arm, gripper, reached, grasp)
    measured = _measure(belief, container)
    if measured is None:
        raise ContainerFailure(f"could not see the handle of {container.name!r} after moving it", container.name)
    done = measured < CLOSED if goal == 0.0 else measured >= min(goal - OPEN_TOLERANCE, USEFUL_OPENING)
    if not done:
        raise ContainerStuck(
            f"{container.name!r} is at {measured:.2f} m after moving its handle from "
            f"{start:.2f} m towards {goal:.2f} m",
            container.name,
        )
    return measured


def _release(arm: str, gripper: str, handle: list[float], grasp: str) -> None:
    """Let go of the handle and back off (best effort), the arm up for driving."""
    best_effort(
        "letting go of a handle",
        lambda: motion(type="setting_gripper", gripper=gripper, position=1),
        lambda: motion(type="reaching", arm=arm, target=handle, phase="retreat", grasp=grasp),
        lambda: motion(type="setting_arm_configuration", arm=arm, configuration="carry"),
    )


#: Per robot: container name -> the standing pose it was last opened from (valid for closing:
#: it was checked for the whole slide while the drawer was closed).
_opened_from: weakref.WeakKeyDictionary[Any, dict[str, Any]] = weakref.WeakKeyDictionary()


def _standing_poses(container: Any, arm: str | None, travel: float, closing: bool = False) -> Any:
    """Solutions of ``('to_open', container)`` for a travel of `travel` [m] (a solution may
    need another torso height: `_move_handle` sets it). For closing, the pose the drawer was opened from
    comes first (the reasoning checks the slide against the drawer as it is: open, in the way)."""
    remembered = _opened_from.get(current_robot(), {}).get(container.name)
    if closing and remembered is not None and (arm is None or remembered.arm == arm):
        yield remembered
        for step in (1, 2):  # the drawer is further in after each push: push on from nearer
            closer = _stepped_in(remembered, step * STEP_IN)
            if closer is not None:
                yield closer
    properties: list[tuple[str, Any]] = [("to_open", container.name), ("opening", travel)]
    if arm is not None:
        properties.append(("arm", arm))
    yield from solutions(LocationDesignator(properties))


def _stepped_in(location: Any, distance: float) -> Any:
    """`location` moved `distance` [m] forward along its heading, if the robot fits there
    (prospection); else None."""
    from dataclasses import replace

    from pycram.robot import current_prospection

    x = location.x + distance * math.cos(location.yaw)
    y = location.y + distance * math.sin(location.yaw)
    prospection = current_prospection()
    if prospection is not None and prospection.in_collision((x, y, location.yaw)):
        return None
    return replace(location, x=x, y=y)


def _operate(action: str, designator: ActionDesignator, goal_of: Any) -> float:
    belief, _, container = _container(action, designator)
    arm = arm_name(action, designator.prop_value("arm"))
    goal = goal_of(container)
    attempts: list[str] = []
    last: BaseException | None = None
    travel = max(goal, belief.container_states.get(container.name, 0.0), 0.05)
    try:
        poses = _standing_poses(container, arm, min(travel, container.limits[1]), closing=action == "closing")
        for number, location in enumerate(poses, start=1):
            if number > CONTAINER_ATTEMPTS:
                break
            try:
                measured = attempt(
                    f"{action} {container.name} from ({location.x:.2f}, {location.y:.2f}) with the {location.arm} arm",
                    partial(_move_handle, location, belief, container, goal),
                )
                if action == "opening":
                    _opened_from.setdefault(current_robot(), {})[container.name] = location
                return float(measured)
            except RECOVERABLE as error:
                last = unwrap(error)
                attempts.append(f"from ({location.x:.2f}, {location.y:.2f}): {last}")
    except RECOVERABLE as error:
        if not attempts:
            raise ObjectOutOfReach(
                f"{action} {container.name!r}: no standing pose: {error}", designator, attempts=[str(error)]
            ) from error
        attempts.append(f"no further standing pose: {error}")
    message = f"{action} {container.name!r} failed: " + "; ".join(attempts)
    if isinstance(last, ContainerFailure):
        raise type(last)(message, container.name, designator, last.reason, attempts) from last
    raise ContainerStuck(message, container.name, designator, getattr(last, "reason", None), attempts) from last


@action_plan("opening")
def opening(designator: ActionDesignator) -> float:
    wanted = designator.prop_value("opening")

    def goal_of(container: Any) -> float:
        low, high = container.limits
        goal = DRAWER_OPENING if wanted is None else float(wanted)
        if not low < goal <= high:
            raise ActionParameterError(
                "opening", "opening", f"{goal} m is outside the slide of {container.name!r} ({low}..{high} m)"
            )
        return goal

    return _operate("opening", designator, goal_of)


@action_plan("closing")
def closing(designator: ActionDesignator) -> float:
    return _operate("closing", designator, lambda container: 0.0)
