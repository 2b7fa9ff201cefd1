"""Opening and closing doors (a cupboard's, the fridge's): how a door is worked, and pushing a
door with the hand.

Opening (`_operate_door`): by the handle along its arc (`pycram.actions.handles`). A robot whose
grip carries a door only part of the way (its description's `DOOR_PULL_LIMIT` [rad], the TIAGo)
pulls it that far by the handle, lets go, and pushes it on from inside with its hand (no grasp)
from a standing pose of its own (``('to_open', door), ('pushing', 'inside')``, tool poses from
`pycram.reasoning.locations.doors` and the robot's `DOOR_PUSH`). Closing: by the handle back
along the arc from the pose the door was opened from by its handle alone; else (opened by
pushing, after a failed opening, or by someone else) pushed shut by its outside face from where
location reasoning finds, at most `DOOR_PUSH_ARC` [rad] per standing pose; a robot without
`DOOR_PUSH` closes by the handle from a new standing pose. A door never measured is looked at
first. Angles in rad; a door counts as closed below `DOOR_CLOSED`
(`pycram.actions.container_state`).
"""

from __future__ import annotations

import logging
import math
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.location import LocationDesignator
from pycram.execution.failures import ContainerFailure, ContainerStuck
from pycram.execution.robot import current_robot
from pycram.reasoning.locations import doors

from .container_poses import CONTAINER_ATTEMPTS, _opened_from, _standing_poses, _torso_and_drive, _try_poses
from .container_state import DOOR_CLOSED, DOOR_TOLERANCE, DOOR_USEFUL, _measure
from .core import RECOVERABLE, arms, best_effort, gripper_of, motion, solutions, unwrap
from .handles import _move_handle

__all__ = ["DOOR_PUSH_ARC"]

log = logging.getLogger("pycram.actions")

#: Pushing a door shut by its outside face, at most this far [rad] (46 deg) from one standing pose
#: (from further open no pose was found for the TIAGo's arm: it closes in stages).
DOOR_PUSH_ARC = 0.8


def _operate_door(
    action: str, designator: ActionDesignator, belief: Any, container: Any, arm: str | None, goal: float
) -> float:
    """Open or close the door `container` to `goal` [rad].

    Opening: by the handle along the arc -- for a robot whose grip carries a door only part of
    the way (its description's `DOOR_PULL_LIMIT`), by the handle that far and then pushed on
    from inside (`pycram.reasoning.locations.doors`) from a standing pose of its own. Closing: by the
    handle from the pose it was opened from (when it was opened by the handle alone), else
    pushed shut by its outside face from where location reasoning finds, else by the handle
    from a new standing pose."""
    move = partial(_move_handle, belief=belief, container=container)
    if container.name not in belief.container_states:  # never seen: how far is it open?
        best_effort("looking at a door", partial(_measure, belief, container))
    if action == "closing":
        remembered = _remembered_handle_pose(container, arm)
        if remembered:
            try:
                return _try_poses(action, designator, container, remembered, partial(move, goal=0.0))
            except RECOVERABLE as error:
                log.info("%s: closing by the handle from where it was opened: %s", container.name, unwrap(error))
        if _door_push() is None:
            return _try_poses(
                action, designator, container, _standing_poses(container, arm, 0.0), partial(move, goal=0.0)
            )
        # pushed shut by its outside face, at most `DOOR_PUSH_ARC` per standing pose
        measured = belief.container_states.get(container.name, 0.0)
        for _ in range(CONTAINER_ATTEMPTS):
            if measured < DOOR_CLOSED:
                break
            target = max(0.0, measured - DOOR_PUSH_ARC)
            target = 0.0 if target < DOOR_TOLERANCE else target
            measured = _try_poses(
                action,
                designator,
                container,
                _push_poses(container, arm, target, "outside"),
                lambda location, target=target: _push_door(location, belief, container, target),
            )
        if measured >= DOOR_CLOSED:  # never silently: still open after every stage
            raise ContainerStuck(
                f"closing {container.name!r}: still open {math.degrees(measured):.0f} deg after "
                f"{CONTAINER_ATTEMPTS} pushes",
                container.name,
                designator,
            )
        return measured
    limit = _door_pull_limit()
    if limit is None or goal <= limit:
        return _pull_open(designator, belief, container, arm, goal, move)
    if belief.container_states.get(container.name, 0.0) < limit - DOOR_TOLERANCE / 2:
        # as far as the grip carries the door (measured at least `limit - DOOR_TOLERANCE`)
        _try_poses(
            action,
            designator,
            container,
            _standing_poses(container, arm, limit),
            partial(move, goal=limit),
            remember=False,
        )
    return _try_poses(
        action,
        designator,
        container,
        _push_poses(container, arm, goal, "inside"),
        lambda location: _push_door(location, belief, container, goal),
        remember=False,
    )


def _pull_open(
    designator: ActionDesignator, belief: Any, container: Any, arm: str | None, goal: float, move: Any
) -> float:
    """Open the door `container` to `goal` [rad] by its handle. A pull that moved the door at
    least `DOOR_TOLERANCE` but stopped short (the arm's reach along the arc ends: measured, the
    PR2's at 50 of 69 deg from one standing pose) goes on from where the door now stands, with
    standing poses found anew for the rest of the arc, up to `CONTAINER_ATTEMPTS` times."""
    for pull in range(1, CONTAINER_ATTEMPTS + 2):
        before = belief.container_states.get(container.name, 0.0)
        try:
            return _try_poses(
                "opening", designator, container, _standing_poses(container, arm, goal), partial(move, goal=goal)
            )
        except ContainerStuck:
            now = belief.container_states.get(container.name, 0.0)
            if now < before + DOOR_TOLERANCE or pull > CONTAINER_ATTEMPTS:
                raise  # it did not move (stuck), or it moved on every pull and is still short
            log.info(
                "%s: pulled from %.0f to %.0f deg of %.0f; going on from there",
                container.name,
                math.degrees(before),
                math.degrees(now),
                math.degrees(goal),
            )
    raise AssertionError("unreachable: the last pull returns or raises")


def _remembered_handle_pose(container: Any, arm: str | None) -> list[Any]:
    """The standing pose the door `container` was last opened from by its handle alone (valid
    for closing it by the handle), if any."""
    remembered = _opened_from.get(current_robot(), {}).get(container.name)
    if (
        remembered is None
        or getattr(remembered, "push", None) is not None
        or (arm is not None and remembered.arm != arm)
    ):
        return []
    return [remembered]


def _door_push() -> Any:
    """The active robot's ``DOOR_PUSH`` (how its hand meets a door's faces); ``None`` when it has
    none, or no description at all."""
    description = getattr(current_robot(), "description", None)
    return description.DOOR_PUSH if description is not None else None


def _door_pull_limit() -> float | None:
    """How far [rad] the active robot's grip carries a door by its handle (its description's
    `DOOR_PULL_LIMIT`; None: all the way)."""
    description = getattr(current_robot(), "description", None)  # (a robot without one: no limit)
    limit = description.DOOR_PULL_LIMIT if description is not None else None
    return None if limit is None else float(limit)


def _door_push_contact() -> Any:
    """How the active robot's hand meets a door's faces (its description's `DOOR_PUSH`)."""
    contact = _door_push()
    if contact is None:
        raise ContainerFailure(f"the {getattr(current_robot(), 'name', 'robot')} does not push doors (no DOOR_PUSH)")
    return contact


def _push_poses(container: Any, arm: str | None, goal: float, side: str) -> Any:
    """Solutions of ``('to_open', door), ('pushing', side)``: where to stand to push the door's
    `side` face from its believed angle to `goal` [rad]. The grippers are set as the robot
    pushes with them first (``DOOR_PUSH[side]['gripper']``, a fraction open; default closed),
    the torso to ``DOOR_PUSH[side]['torso']`` (if given): the reasoning checks the robot as it
    is."""
    contact = _door_push_contact()[side]
    fraction = float(contact.get("gripper", 0.0))
    if contact.get("torso") is not None:  # the reasoning checks the robot at the height it pushes at
        motion(type="setting_torso", position=contact["torso"])
    for hand in [arm] if arm is not None else arms():
        best_effort(
            "setting a hand to push",
            partial(motion, type="setting_gripper", gripper=gripper_of(hand), position=fraction),
        )
    properties: list[tuple[str, Any]] = [("to_open", container.name), ("opening", goal), ("pushing", side)]
    if arm is not None:
        properties.append(("arm", arm))
    yield from solutions(LocationDesignator(properties))


def _push_door(location: Any, belief: Any, container: Any, goal: float) -> float:
    """One attempt: stand at `location`, look, push the door's `location.push` face along its arc
    from where it is measured to `goal` [rad] with the hand (no grasp; the gripper as the robot's
    `DOOR_PUSH` says), back off, arm parked, look. Returns the measured angle [rad]: opened at
    least `DOOR_USEFUL` or within `DOOR_TOLERANCE` of `goal`, shut below `DOOR_CLOSED`, part of the
    way shut at most `DOOR_TOLERANCE` beyond `goal` -- else `ContainerStuck`."""
    arm, side = location.arm, location.push
    contact = _door_push_contact()
    gripper = gripper_of(arm)
    fraction = float(contact[side].get("gripper", 0.0))
    best_effort(
        "before pushing a door",
        lambda: motion(type="setting_arm_configuration", arm=arm, configuration="park"),
        lambda: motion(type="setting_gripper", gripper=gripper, position=fraction),
    )
    _torso_and_drive(location)
    start = _measure(belief, container)
    start = belief.container_states.get(container.name, 0.0) if start is None else start
    closing = goal <= 0.0
    if abs(start - goal) < DOOR_TOLERANCE / 2 or (closing and start < DOOR_CLOSED):
        return start
    reached = start
    try:
        for pose in doors.push_sequence(container, contact, start, goal, side):
            try:
                motion(
                    type="reaching",
                    arm=arm,
                    target=list(pose.position),
                    orientation=list(pose.orientation),
                    contact=pose.phase == "push",
                )
            except RECOVERABLE as error:
                if getattr(unwrap(error), "reason", None) != "blocked":
                    raise
                # an approach that brushed the door goes on; a push that stopped: the door stopped
                log.info("%s: %s pose stopped short: %s", container.name, pose.phase, unwrap(error))
                if pose.phase == "push":
                    break
                continue
            if pose.phase == "push":
                reached = pose.angle
    finally:
        q = max(min(reached, container.limits[1]), 0.0)
        retreat = [
            partial(motion, type="reaching", arm=arm, target=list(p.position), orientation=list(p.orientation))
            for p in doors.retreat_sequence(container, contact, q, side)
        ]
        best_effort(
            "letting go of a door",
            *retreat,
            lambda: motion(type="setting_arm_configuration", arm=arm, configuration="park"),
        )
    measured = _measure(belief, container, expected=reached)
    if measured is None:
        raise ContainerFailure(f"could not see the handle of {container.name!r} after pushing it", container.name)
    if closing:
        done = measured < DOOR_CLOSED
    elif goal < start:  # part of the way shut
        done = measured <= goal + DOOR_TOLERANCE
    else:
        done = measured >= min(goal - DOOR_TOLERANCE, DOOR_USEFUL)
    if not done:
        raise ContainerStuck(
            f"{container.name!r} is open {math.degrees(measured):.0f} deg after pushing its {side} face from "
            f"{math.degrees(start):.0f} towards {math.degrees(goal):.0f} deg",
            container.name,
        )
    return measured
