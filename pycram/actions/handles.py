"""Moving a container by its handle: one attempt from a standing pose (`_move_handle`).

The robot drives there (the torso set for the handle's height), looks at the handle (perception
measures how far the container is open), grasps the handle, moves it to the goal, lets go, backs
off and looks again.

- A drawer: the fingers close vertically on its horizontal bar, and the handle is moved along
  the slide in `PULL_STEPS` steps (closing: on to `PUSH_BEYOND` [m] past closed, against the
  stop); the drawer is believed where the hand lets go of it (`BeliefState.moved_container`:
  the arm's way off the handle is planned with it there) until the look measures it; afterwards
  the handles of the containers next to it are looked at too.
- A door (`_swing_door`): the fingers close horizontally on its vertical bar, the tool pointing
  into the door, and the handle is carried along its arc around the hinge in `DOOR_STEPS` tool
  poses, the wrist turning with the door (``reaching`` with an ``orientation``). Letting go, the
  hand backs off the door and out round its free edge, the base backs off and the arm is parked
  (an arm coming back round an open door pushes it shut).

Raises `HandleMissed` (the gripper closed beside the handle -- below `HANDLE_OPENING` [m] -- or,
for a door, on something wider than its bar), `ContainerStuck` (the container did not follow) or
`ContainerFailure` (the handle not seen afterwards). Openings in m for drawers, rad for doors.
"""

from __future__ import annotations

import logging
import math
from typing import Any

from pycram.execution.failures import ContainerFailure, ContainerStuck, HandleMissed
from pycram.execution.robot import current_robot
from pycram.reasoning.locations.opening import DRAWER_PUSH_BEYOND

from .container_poses import _torso_and_drive
from .container_state import (
    CLOSED,
    DOOR_CLOSED,
    DOOR_TOLERANCE,
    DOOR_USEFUL,
    OPEN_TOLERANCE,
    USEFUL_OPENING,
    _look_at_neighbours,
    _measure,
)
from .core import RECOVERABLE, base_pose_fluent, best_effort, gripper_of, motion, unwrap

__all__ = ["HANDLE_OPENING", "PULL_STEPS", "DOOR_STEPS"]

log = logging.getLogger("pycram.actions")

#: Steps of the pull along the drawer's slide.
PULL_STEPS = 4
#: Below this measured opening [m] the gripper closed beside the handle (the bar is 24 mm thick).
HANDLE_OPENING = 0.008
#: Closing pushes the handle this far [m] beyond closed (the slide's stop holds the drawer; the
#: standing poses are checked for it).
PUSH_BEYOND = DRAWER_PUSH_BEYOND
#: Tool poses along a door's arc (about 9 deg apart for `DOOR_OPENING`).
DOOR_STEPS = 8
#: Closing pushes the handle this far [rad] beyond closed (the door's stop holds it).
DOOR_PUSH_BEYOND = 0.03
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
        if reached_q != start:  # it moved: the arm's way off the handle is planned with it there
            belief.moved_container(container.name, let_go_at)
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
    description = getattr(current_robot(), "description", None)  # (a robot without one: default grip)
    grip_opening = description.DOOR_GRIP_OPENING if description is not None else None
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
