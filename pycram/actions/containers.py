"""Opening and closing drawers and doors: grasp the handle, move it along the drawer's slide
or the door's arc.

`Open("drawer 2")`: ``('to_open', container)`` chooses where to stand, which arm and -- for a
handle too low or too high for the torso as it is -- the torso height.
One attempt drives there, looks at the handle (perception measures how far the drawer is open),
grasps the handle (fingers closing vertically on its horizontal bar), pulls it along the opening
trajectory in steps, lets go, backs off and looks again (at the handles of the containers next
to it too, `NEIGHBOUR_RADIUS`): the drawer must be measured open (within 6 cm of the goal, or at
least 15 cm out: enough to look and reach in).
`Close("drawer 2")` is the same, pushing back to closed.

`Open("fridge")` (a door, `DOOR_OPENING` = 69 deg unless told): the arms parked, the robot
drives to the standing pose, looks, grasps the vertical handle bar with the fingers closing
horizontally (the tool pointing into the door), and carries the handle along its arc around the
hinge in `DOOR_STEPS` tool poses, the wrist turning with the door (``reaching`` with an
``orientation``). Letting go it backs the hand off the door and out round the door's free edge,
backs the base off and parks the arm (an arm coming back round an open door pushes it shut). The
door must be measured at least 60 deg open (`DOOR_USEFUL`) or within 10 deg of the goal; closed,
below 4 deg (`DOOR_CLOSED`). A robot whose grip carries a door only part of the way (its
description's `DOOR_PULL_LIMIT`, the TIAGo) pulls it that far by the handle, lets go, and pushes
it on from inside with its hand (no grasp) from a standing pose of its own
(``('to_open', door), ('pushing', 'inside')``, tool poses from `pycram.reasoning.locations.doors` and the
robot's `DOOR_PUSH`). `Close("fridge")` pushes the handle back along the arc from the pose the
door was opened from by its handle alone; else (opened by pushing, after a failed opening, or
by someone else) it pushes the door shut by its outside face from where location reasoning
finds, at most `DOOR_PUSH_ARC` per standing pose; a robot without `DOOR_PUSH` closes by the
handle from a new standing pose. A door never measured is looked at first.

Failures, after `CONTAINER_ATTEMPTS` standing poses: `HandleMissed` (the gripper closed beside
the handle -- or, for a door, on something wider than its bar), `ContainerStuck` (the drawer or
door did not follow), `ObjectOutOfReach` (no standing pose).

The environment's description (handle positions, slide directions, hinges, limits) is map
knowledge the plan may read; how far a container is open comes only from perception (the
belief's ``container_states``).
"""

from __future__ import annotations

import logging
import math
import weakref
from collections.abc import Callable
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.location import LocationDesignator
from pycram.execution.failures import ContainerFailure, ContainerStuck, HandleMissed, ObjectOutOfReach
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.reasoning.locations import doors
from pycram.reasoning.locations.reasoning import DRAWER_PUSH_BEYOND

from .core import (
    RECOVERABLE,
    ActionParameterError,
    action_plan,
    arm_name,
    arms,
    attempt,
    base_pose_fluent,
    best_effort,
    gripper_of,
    make_action,
    motion,
    solutions,
    unwrap,
)

__all__ = [
    "Open",
    "Close",
    "opening_one_at_a_time",
    "DRAWER_OPENING",
    "DOOR_OPENING",
    "CONTAINER_ATTEMPTS",
    "PULL_STEPS",
    "DOOR_STEPS",
    "HANDLE_OPENING",
    "NEIGHBOUR_RADIUS",
    "believed_open",
]

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
#: A stage of closing a drawer (`_close_drawer`) counts as progress when it pushes it in this far [m].
MIN_PUSH_GAIN = 0.05
#: Closing pushes the handle this far [m] beyond closed (the slide's stop holds the drawer; the
#: standing poses are checked for it).
PUSH_BEYOND = DRAWER_PUSH_BEYOND
#: A drawer counts as closed below this opening [m], as opened when within this of its goal --
#: or at least `USEFUL_OPENING` [m] out (enough to look and reach in).
CLOSED, OPEN_TOLERANCE, USEFUL_OPENING = 0.03, 0.06, 0.15
#: How far [rad] `Open` swings a door when not told (69 deg).
DOOR_OPENING = 1.2
#: Tool poses along a door's arc (about 9 deg apart for `DOOR_OPENING`).
DOOR_STEPS = 8
#: A door counts as closed below this angle [rad] (4 deg), as opened when within this of its
#: goal -- or at least `DOOR_USEFUL` [rad] open (60 deg: enough to look and reach in).
DOOR_CLOSED, DOOR_TOLERANCE, DOOR_USEFUL = math.radians(4), math.radians(10), math.radians(60)
#: Pushing a door shut by its outside face, at most this far [rad] (46 deg) from one standing pose
#: (from further open no pose was found for the TIAGo's arm: it closes in stages).
DOOR_PUSH_ARC = 0.8
#: Closing pushes the handle this far [rad] beyond closed (the door's stop holds it).
DOOR_PUSH_BEYOND = 0.03
#: After a hand worked a drawer, the containers whose handles are within this distance [m] of
#: its handle are looked at too: an arm going up from a low drawer can catch the handle of one
#: above and pull it out unnoticed (the TIAGo, closing drawer 1: drawer 3 left 6 cm out in 16 of
#: 200 faulted seeds). The apartment's stacked drawers are 0.26 m apart.
NEIGHBOUR_RADIUS = 0.6
#: Backing off from a door's handle [m] when the standing pose does not say (its pre-grasp offset).
DOOR_BACK_OFF = 0.1
#: Above this measured opening [m] the gripper closed on something wider than a handle's bar.
DOOR_HANDLE_WIDEST = 0.04
#: Letting go, the hand moves out this far [m] past the door's free edge before the arm goes up.
DOOR_EDGE_CLEARANCE = 0.12
#: ... when the door is open more than this [rad] (30 deg; less open, the arm comes back in front of it)
DOOR_AROUND_FROM = math.radians(30)
#: ... and the base backs off this far [m] (the elbow clear of the door) before the arm goes up.
DOOR_BASE_BACK_OFF = 0.3


def Open(container: str, arm: str | None = None, opening: float | None = None) -> ActionDesignator:
    """Open the drawer or door `container` (its name in the environment) by `opening` [m, rad for
    a door] (default `DRAWER_OPENING`, `DOOR_OPENING`) with `arm` (None: the reasoning chooses).
    Returns the measured opening."""
    return make_action("opening", container=container, arm=arm, opening=opening)


def Close(container: str, arm: str | None = None) -> ActionDesignator:
    """Close the drawer or door `container`. Returns the measured opening [m or rad] afterwards."""
    return make_action("closing", container=container, arm=arm)


def opening_one_at_a_time() -> Callable[[str], Any]:
    """An ``open_container`` for `pycram.actions.search.search_for`: opens a container with
    `Open` after closing the one it opened before, if that is still believed open (a search
    looking into one drawer after another leaves at most the last one open: an open drawer
    stands in the way of the robot and of opening the drawers below it). A container that will
    not close is logged and left."""
    opened: list[str] = []

    def open_next(name: str) -> Any:
        belief = getattr(current_robot(), "belief", None)
        while opened:
            previous = opened.pop()
            if previous != name and belief is not None and belief.container_open(previous) is True:
                try:
                    perform(Close(previous))
                except RECOVERABLE as error:
                    log.warning("could not close %s before opening %s: %s", previous, name, unwrap(error))
        result = perform(Open(name))
        opened.append(name)
        return result

    return open_next


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
    if container.kind not in ("door", "drawer"):
        raise ContainerFailure(
            f"{action} {name!r}: robots open and close drawers and doors only, not a {container.kind!r}",
            name,
            designator,
            "not_supported",
        )
    return belief, environment, container


def _torso_and_drive(location: Any) -> None:
    """Set the torso `location` needs (if any), then drive there -- unless the base already
    stands at it (within `AT_POSE` [m, rad])."""
    if location.torso is not None:
        motion(type="setting_torso", position=location.torso)
    here = base_pose_fluent().get_value()
    if (
        here is None
        or math.hypot(here.x - location.x, here.y - location.y) > AT_POSE
        or abs(math.remainder(here.yaw - location.yaw, math.tau)) > AT_POSE
    ):
        motion(type="moving", pose=location)


def _measure(belief: Any, container: Any, expected: float | None = None) -> float | None:
    """Look at the handle; the opening [m or rad] perception measured (None when these looks did
    not measure it: an older value of the belief is no measurement).

    With `expected` (where the container should be now, far from where it is believed to be) the
    head looks there first and then where it was believed to be: perception measures the
    container whenever its handle is in view, so the belief ends with what was seen."""
    believed = belief.container_states.get(container.name, 0.0)
    before = belief.container_stamps.get(container.name)
    looks = [believed]
    if expected is not None and abs(expected - believed) > DOOR_TOLERANCE:
        looks.insert(0, expected)
    for q in looks:
        # standing close, the head may not turn all the way: it looks as near as it can
        best_effort(
            "looking at a handle",
            partial(motion, type="pointing_head", coordinates=list(container.handle_position(q))),
        )
        motion(type="detecting")
    if belief.container_stamps.get(container.name) == before:  # not measured by these looks
        return None
    return float(belief.container_states[container.name])


def believed_open(name: str) -> bool | None:
    """Whether the current robot believes the container `name` open: a drawer measured out
    `CLOSED` [m] or more, a door `DOOR_CLOSED` [rad] or more -- the thresholds `Close` pushes
    below. None when it was never measured (or the robot has no belief of the environment)."""
    belief: Any = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if environment is None or name not in belief.container_states:
        return None
    closed = CLOSED if environment.container(name).kind == "drawer" else DOOR_CLOSED
    return abs(belief.container_states[name]) >= closed


def _look_at_neighbours(belief: Any, container: Any) -> None:
    """Look at the handles of the containers within `NEIGHBOUR_RADIUS` of `container`'s (best
    effort): the belief ends with how far each is open now, so that one pulled out by the arm
    is closed again."""
    _, environment = _environment()
    here = container.handle_position(belief.container_states.get(container.name, 0.0))
    for other in environment.containers:
        there = other.handle_position(belief.container_states.get(other.name, 0.0))
        if other.name != container.name and math.dist(here, there) <= NEIGHBOUR_RADIUS:
            best_effort(f"looking at the handle of {other.name}", partial(_measure, belief, other))


def _move_handle(location: Any, *, belief: Any, container: Any, goal: float) -> float:
    """One attempt: stand at `location`, grasp the handle, move it to `goal` [m], let go, look."""
    arm, grasp = location.arm, location.grasp
    gripper = gripper_of(arm)
    motion(type="setting_gripper", gripper=gripper, position=1)
    # a door stands open beside the pose: the arm goes in (the standing pose was checked with the
    # arms parked); for a drawer it is up, ready
    raised = "park" if container.kind == "door" else "carry"
    try:
        motion(type="setting_arm_configuration", arm=arm, configuration=raised)
    except RECOVERABLE as error:  # e.g. close to the furniture after a failed attempt
        log.info("%s: arm up before driving: %s", container.name, unwrap(error))
    _torso_and_drive(location)  # the torso: the handle may be too low or too high for it as it was
    start = _measure(belief, container)
    start = belief.container_states.get(container.name, 0.0) if start is None else start  # as last seen
    if container.kind == "door":
        if abs(start - goal) < DOOR_TOLERANCE / 2:
            return start
        return _swing_door(location, belief, container, start, goal)
    # closing: nothing to do only when closed (the criterion below); a drawer ajar by less than
    # `OPEN_TOLERANCE / 2` was not pushed at all, and a push that stopped short left it so
    if (start < CLOSED) if goal == 0.0 else (abs(start - goal) < OPEN_TOLERANCE / 2):
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
    # The hand lets go where it is: between the last handle position reached and the one it
    # went for. It backs off from the one nearer the robot (the larger opening), so that the
    # fingers come off the bar -- backing off from a push's unreached goal left them round it,
    # and the arm going up pulled the drawer out again.
    steps = [start + (goal - start) * k / PULL_STEPS for k in range(1, PULL_STEPS + 1)]
    if goal == 0.0:
        steps.append(-PUSH_BEYOND)  # against the stop (best effort): a drawer pushed to 0 may stay ajar
    reached_q = start
    let_go_at = start
    try:
        for k, q in enumerate(steps, start=1):
            beyond = q < 0.0
            let_go_at = max(reached_q, q)
            try:
                motion(type="reaching", arm=arm, target=list(container.handle_position(q)), grasp=grasp)
            except RECOVERABLE as error:
                if getattr(unwrap(error), "reason", None) != "blocked" and not beyond:
                    raise
                log.info("%s: the handle stopped moving at step %d: %s", container.name, k, unwrap(error))
                break
            reached_q = let_go_at = q
    finally:
        _release(arm, gripper, list(container.handle_position(let_go_at)), grasp)
    measured = _measure(belief, container)
    _look_at_neighbours(belief, container)
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


def _yaw_quat(yaw: float) -> list[float]:
    """Orientation (w, x, y, z) of a tool pointing along `yaw` [rad], fingers opening horizontally."""
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def _door_heading(container: Any, q: float) -> float:
    """Tool heading [rad] at the handle of the door `container` opened by `q` [rad]: into the
    door, against its opening direction (which turns with the door)."""
    dx, dy = container.opening_direction
    a = container.hinge_sign * q
    dx, dy = math.cos(a) * dx - math.sin(a) * dy, math.sin(a) * dx + math.cos(a) * dy
    return math.atan2(-dy, -dx)


def _door_pose(container: Any, q: float, back: float = 0.0) -> tuple[list[float], list[float]]:
    """Tool (position [m], orientation) at the handle of the door opened by `q` [rad], `back` [m]
    away from it against the tool's heading."""
    heading = _door_heading(container, q)
    x, y, z = container.handle_position(q)
    return [x - back * math.cos(heading), y - back * math.sin(heading), z], _yaw_quat(heading)


def _swing_door(location: Any, belief: Any, container: Any, start: float, goal: float) -> float:
    """Grasp the handle of the door `container` (measured open by `start` [rad]), carry it along
    its arc around the hinge to `goal` [rad] in `DOOR_STEPS` tool poses (the wrist turning with
    the door), let go, back off along the tool's heading, look. Returns the measured angle."""
    arm = location.arm
    gripper = gripper_of(arm)
    poses: tuple[Any, ...] = tuple(getattr(location, "tool_poses", ()) or ())
    back = math.dist(poses[0][0], poses[1][0]) if len(poses) >= 2 else DOOR_BACK_OFF
    pre, orientation = _door_pose(container, start, back)
    handle, _ = _door_pose(container, start)
    grip_opening = getattr(getattr(current_robot(), "description", None), "DOOR_GRIP_OPENING", None)
    if grip_opening is not None:  # the robot closes on a handle's bar best from this far open
        motion(type="setting_gripper", gripper=gripper, position=float(grip_opening))
    motion(type="reaching", arm=arm, target=pre, phase="pre_grasp", orientation=orientation)
    motion(type="reaching", arm=arm, target=handle, phase="grasp", orientation=orientation)
    opening = float(motion(type="setting_gripper", gripper=gripper, position=0))
    reached = start
    if not HANDLE_OPENING <= opening <= DOOR_HANDLE_WIDEST:  # beside the bar, or on its standoffs
        _let_go_of_door(arm, gripper, container, reached, back)
        where = "beside the handle" if opening < HANDLE_OPENING else "on something wider than the handle's bar"
        raise HandleMissed(
            f"the {gripper} gripper closed {where} of {container.name!r} (opening {opening * 1000:.1f} mm)",
            container.name,
        )
    closing = goal == 0.0
    try:
        for k in range(1, DOOR_STEPS + 1 + closing):
            q = start + (goal - start) * min(k, DOOR_STEPS) / DOOR_STEPS
            beyond = k > DOOR_STEPS
            if beyond:
                q = -DOOR_PUSH_BEYOND  # against the stop, if the arm gets there: the hand lags the door
            target, turned = _door_pose(container, q)
            try:
                motion(type="reaching", arm=arm, target=target, orientation=turned)
            except RECOVERABLE as error:
                if getattr(unwrap(error), "reason", None) != "blocked" and not beyond:
                    raise
                log.info("%s: the handle stopped moving at step %d: %s", container.name, k, unwrap(error))
                break
            reached = q
    finally:
        _let_go_of_door(arm, gripper, container, reached, back)
    measured = _measure(belief, container)
    if measured is None:
        raise ContainerFailure(f"could not see the handle of {container.name!r} after moving it", container.name)
    done = measured < DOOR_CLOSED if closing else measured >= min(goal - DOOR_TOLERANCE, DOOR_USEFUL)
    if not done:
        raise ContainerStuck(
            f"{container.name!r} is open {math.degrees(measured):.0f} deg after moving its handle from "
            f"{math.degrees(start):.0f} towards {math.degrees(goal):.0f} deg",
            container.name,
        )
    return measured


def _let_go_of_door(arm: str, gripper: str, container: Any, q: float, back: float) -> None:
    """Let go of a door's handle (at `q` [rad]), back off the door's face along the tool's heading
    and out past the door's free edge (an arm reaching round an open door would push it shut on
    its way back), arm up."""
    q = max(q, 0.0)
    away, orientation = _door_pose(container, q, back)
    beyond, _ = _door_pose(container, q, -back)
    hx, hy = container.hinge
    handle = container.handle_position(q)
    radius = math.hypot(handle[0] - hx, handle[1] - hy)
    width = max(math.hypot(x - hx, y - hy) for x, y in _corners(container.body.footprint))
    scale = (width + DOOR_EDGE_CLEARANCE) / radius

    def past_edge(point: list[float]) -> list[float]:
        return [hx + (point[0] - hx) * scale, hy + (point[1] - hy) * scale, point[2]]

    around = [
        lambda: motion(type="reaching", arm=arm, target=past_edge(away), phase="retreat", orientation=orientation),
        lambda: motion(type="reaching", arm=arm, target=past_edge(beyond), phase="retreat", orientation=orientation),
    ]

    def back_off() -> None:
        try:
            motion(type="reaching", arm=arm, target=away, phase="retreat", orientation=orientation)
        except RECOVERABLE as error:  # e.g. no IK solution that close to the base: the base backs off
            log.info("%s: backing the hand off %.2f m: %s", container.name, back, unwrap(error))
            here = base_pose_fluent().get_value()
            heading = _door_heading(container, q) - (here.yaw if here is not None else 0.0)
            motion(
                type="moving", pose=(-back * math.cos(heading), -back * math.sin(heading), 0.0), frame="base_footprint"
            )

    best_effort(
        "letting go of a handle",
        lambda: motion(type="setting_gripper", gripper=gripper, position=1),
        back_off,
        # a door open only a little: the arm comes back in front of it; else round its free edge
        *(around if q > DOOR_AROUND_FROM else []),
        lambda: motion(type="moving", pose=(-DOOR_BASE_BACK_OFF, 0.0, 0.0), frame="base_footprint"),
        lambda: motion(type="setting_arm_configuration", arm=arm, configuration="park"),
    )


def _corners(footprint: tuple[float, float, float, float]) -> list[tuple[float, float]]:
    x0, y0, x1, y1 = footprint
    return [(x0, y0), (x0, y1), (x1, y0), (x1, y1)]


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
        # the drawer is further in after each push: push on from nearer (a door: from where it was opened)
        for step in (1, 2) if container.kind == "drawer" else ():
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

    from pycram.execution.robot import current_prospection

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
    if container.kind == "door":
        return _operate_door(action, designator, belief, container, arm, goal)
    if action == "closing":
        return _close_drawer(designator, belief, container, arm)
    # the trajectory the reasoning checks: from where the drawer is believed to be to the goal
    travel = max(goal, belief.container_states.get(container.name, 0.0), 0.05)
    poses = _standing_poses(container, arm, min(travel, container.limits[1]))
    measured = _try_poses(
        action, designator, container, poses, partial(_move_handle, belief=belief, container=container, goal=goal)
    )
    return measured


def _close_drawer(designator: ActionDesignator, belief: Any, container: Any, arm: str | None) -> float:
    """Push the drawer `container` home from a standing pose that reaches the whole push (to
    `DRAWER_PUSH_BEYOND` past closed: checking only where the handle is found poses from which
    the arm could not push it home). A drawer far out may leave no such pose (the base keeps
    clear of the drawer as it is): then it is pushed in as far as it goes from a pose reaching
    its handle where it is, and the whole push is sought again -- stages while each gains at least
    `MIN_PUSH_GAIN`, at most `CONTAINER_ATTEMPTS`. Raises the last stage's typed failure."""
    move = partial(_move_handle, belief=belief, container=container, goal=0.0)
    for _stage in range(CONTAINER_ATTEMPTS):
        start = belief.container_states.get(container.name, 0.0)
        try:
            return _try_poses("closing", designator, container, _standing_poses(container, arm, 0.0, True), move)
        except (ContainerFailure, ObjectOutOfReach) as whole:
            if belief.container_states.get(container.name, 0.0) < start - MIN_PUSH_GAIN:
                continue  # it went part of the way in: seek the whole push again from there
            log.info("%s: no pose pushes it home from %.2f m: pushing it in part of the way", container.name, start)
            try:
                return _try_poses(
                    "closing",
                    designator,
                    container,
                    _standing_poses(container, arm, min(start, container.limits[1])),
                    move,
                )
            except (ContainerFailure, ObjectOutOfReach):
                if belief.container_states.get(container.name, 0.0) >= start - MIN_PUSH_GAIN:
                    raise whole from None  # neither way moved it
    measured = belief.container_states.get(container.name, 0.0)
    raise ContainerStuck(
        f"closing {container.name!r}: still open {measured:.2f} m after {CONTAINER_ATTEMPTS} stages of pushing",
        container.name,
        designator,
    )


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
        if getattr(getattr(current_robot(), "description", None), "DOOR_PUSH", None) is None:
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
        measured = _try_poses(
            action, designator, container, _standing_poses(container, arm, goal), partial(move, goal=goal)
        )
        return measured
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


def _try_poses(
    action: str, designator: ActionDesignator, container: Any, poses: Any, run: Any, remember: bool = True
) -> float:
    """Try `run(location)` from each standing pose of `poses` in turn (at most
    `CONTAINER_ATTEMPTS`), each as an attempt of its own; the measured opening of the first that
    succeeds (opening: its pose remembered for closing, with `remember`). Raises the last typed
    failure with every attempt's reason, `ObjectOutOfReach` when there was no standing pose."""
    attempts: list[str] = []
    last: BaseException | None = None
    try:
        for number, location in enumerate(poses, start=1):
            if number > CONTAINER_ATTEMPTS:
                break
            how = "pushing" if getattr(location, "push", None) else f"with the {location.arm} arm"
            try:
                measured = attempt(
                    f"{action} {container.name} from ({location.x:.2f}, {location.y:.2f}) {how}",
                    partial(run, location),
                )
                if action == "opening" and remember:
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


def _door_pull_limit() -> float | None:
    """How far [rad] the active robot's grip carries a door by its handle (its description's
    `DOOR_PULL_LIMIT`; None: all the way)."""
    limit = getattr(getattr(current_robot(), "description", None), "DOOR_PULL_LIMIT", None)
    return None if limit is None else float(limit)


def _door_push_contact() -> Any:
    """How the active robot's hand meets a door's faces (its description's `DOOR_PUSH`)."""
    contact = getattr(getattr(current_robot(), "description", None), "DOOR_PUSH", None)
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
                motion(type="reaching", arm=arm, target=list(pose.position), orientation=list(pose.orientation))
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


@action_plan("opening")
def opening(designator: ActionDesignator) -> float:
    wanted = designator.prop_value("opening")

    def goal_of(container: Any) -> float:
        low, high = container.limits
        default = DOOR_OPENING if container.kind == "door" else DRAWER_OPENING
        goal = default if wanted is None else float(wanted)
        unit, travel = ("rad", "hinge's range") if container.kind == "door" else ("m", "slide")
        if not low < goal <= high:
            raise ActionParameterError(
                "opening",
                "opening",
                f"{goal} {unit} is outside the {travel} of {container.name!r} ({low}..{high} {unit})",
            )
        return goal

    return _operate("opening", designator, goal_of)


@action_plan("closing")
def closing(designator: ActionDesignator) -> float:
    return _operate("closing", designator, lambda container: 0.0)
