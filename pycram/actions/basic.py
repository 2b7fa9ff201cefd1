"""The simple actions: navigating, looking, parking the arms, the torso, a gripper, detecting,
searching. Each is a typed constructor returning an `ActionDesignator` and the plan it resolves
to; all of them use motion designators, location designators and the robot's belief only.

=================  ========================================  =====================================
constructor        plan does                                 raises (after its attempts)
=================  ========================================  =====================================
`Navigate`         drive to a pose or to a location           `GoalUnreachable`, `PathBlocked`
                   designator's solutions, next solution
                   when one cannot be driven to (3 at most)
`LookAt`           point the head at a point, a believed      `MotionFailure`
                   object or a named place
`ParkArms`         every arm to its ``park`` configuration    `MotionFailure`
`MoveTorso`        the torso to a named position or height    `MotionFailure`
`SetGripper`       open (1) or close (0) a gripper            `MotionFailure`
`Detect`           one look; the objects seen                 `ObjectNotVisible` (object asked, not
                                                              seen)
`Search`           `pycram.actions.search.search_for`,         `ObjectNotFound`
                   opening closed drawers with `Open`
=================  ========================================  =====================================
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

from pycram.core.expressions import State, par
from pycram.designators.action import ActionDesignator
from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import GoalUnreachable, NavigationFailure, ObjectNotVisible, PathBlocked, PlanFailure

from .core import (
    RECOVERABLE,
    ActionParameterError,
    action_plan,
    arms,
    attempt,
    check_object_type,
    gripper_name,
    make_action,
    motion,
    unwrap,
)
from .core import solutions as location_solutions
from .search import search_for

__all__ = [
    "Navigate",
    "LookAt",
    "ParkArms",
    "MoveTorso",
    "SetGripper",
    "Detect",
    "Search",
    "NAVIGATION_ATTEMPTS",
    "point_of",
]

#: Standing poses (solutions of a location designator) tried before navigating gives up.
NAVIGATION_ATTEMPTS = 3


# -- constructors -------------------------------------------------------------------------------


def Navigate(target: Any) -> ActionDesignator:
    """Drive the base to `target`: a base pose ((x [m], y [m], yaw [rad]), a `Pose2D`, a
    `BaseLocation`), the name of a place of the environment (``'table north'``: its base pose)
    or a `LocationDesignator` (e.g. ``('to_see', cup)``), whose next solution is tried when one
    cannot be driven to. Returns the reached base pose."""
    return make_action("navigating", target=target)


def LookAt(target: Any) -> ActionDesignator:
    """Point the head camera at `target`: a point (x, y, z) [m, map], a believed object or an
    object designator (its believed centre), or the name of a surface or place."""
    return make_action("looking_at", target=target)


def ParkArms() -> ActionDesignator:
    """Move every arm of the robot to its ``park`` configuration (concurrently)."""
    return make_action("parking_arms")


def MoveTorso(position: str | float) -> ActionDesignator:
    """Move the torso to a named position (``'up'``, ``'down'``) or a height [m]."""
    return make_action("moving_torso", position=position)


def SetGripper(gripper: str, position: float) -> ActionDesignator:
    """Open (`position` 1) or close (0) `gripper`; returns the measured opening [m]."""
    return make_action("setting_gripper", gripper=gripper, position=position)


def Detect(object: Any = None) -> ActionDesignator:
    """Take one look with the head camera and update the belief; returns the believed objects
    seen (`PerceivedObject`), only those matching `object` (a type name or an object designator)
    when given -- then none seen raises `ObjectNotVisible`. An object designator of an unknown
    type raises `ActionParameterError` at once."""
    check_object_type("detecting", object, names_too=True)
    return make_action("detecting", object=object)


def Search(object: ObjectDesignator) -> ActionDesignator:
    """Find an object matching `object` (look around, then visit likely places); returns the
    believed object. Raises `ObjectNotFound` naming where it looked. An unknown object type
    raises `ActionParameterError` at once."""
    check_object_type("searching", object)
    return make_action("searching", object=object)


# -- plans ----------------------------------------------------------------------------------------


def _navigation_failure(error: BaseException, goal: Any, designator: Any, attempts: list[str]) -> PlanFailure:
    cause = unwrap(error)
    reason = getattr(cause, "reason", "failed")
    message = f"cannot drive to {goal!r}: {cause}"
    if reason in ("blocked", "collision"):
        return PathBlocked(message, designator, reason, attempts)
    return GoalUnreachable(message, designator, reason, attempts)


@action_plan("navigating")
def navigating(designator: ActionDesignator) -> Any:
    target = designator.prop_value("target")
    if target is None:
        raise ActionParameterError("navigating", "target", "missing: a base pose or a location designator")
    if isinstance(target, str):
        target = _place_pose(target)
    if not isinstance(target, LocationDesignator):
        try:
            return motion(type="moving", pose=target)
        except RECOVERABLE as error:
            raise _navigation_failure(error, target, designator, [str(unwrap(error))]) from error
    attempts: list[str] = []
    last: BaseException | None = None
    try:
        solutions = iter(location_solutions(target))
        for number in range(1, NAVIGATION_ATTEMPTS + 1):
            pose = next(solutions, None)
            if pose is None:
                break
            try:
                return attempt(f"drive to solution {number}", partial(motion, type="moving", pose=pose))
            except RECOVERABLE as error:
                if not isinstance(unwrap(error), NavigationFailure) and not _is_motion_failure(error):
                    raise
                last = error
                attempts.append(f"{_short_pose(pose)}: {unwrap(error)}")
    except NoSolutionError as error:
        attempts.append(str(error))
        last = error
    if last is None:
        raise GoalUnreachable(f"{target!r} has no solution to drive to", designator, "no_solution", attempts)
    raise _navigation_failure(last, target, designator, attempts) from last


def _place_pose(name: str) -> tuple[float, float, float]:
    """The base pose (x [m], y [m], yaw [rad]) of the environment's place `name`;
    `ActionParameterError` naming the places otherwise (and how to stand at a surface)."""
    from pycram.execution.robot import current_robot

    environment = getattr(getattr(current_robot(), "belief", None), "environment", None)
    places = {p.name: p for p in getattr(environment, "places", ())}
    if name not in places:
        hint = "a place of the environment"
        if environment is not None and any(s.name == name for s in environment.all_surfaces()):
            hint = f"a place, not a surface (to stand at {name!r}: LocationDesignator([('to_see', {name!r})]))"
        raise ActionParameterError("navigating", "target", f"{name!r} is not {hint}", sorted(places))
    return places[name].pose


def _is_motion_failure(error: BaseException) -> bool:
    from pycram.execution.failures import MotionFailure

    return isinstance(unwrap(error), MotionFailure)


def _short_pose(pose: Any) -> str:
    x, y, yaw = (pose.x, pose.y, pose.yaw) if hasattr(pose, "x") else tuple(pose)
    return f"({x:.2f}, {y:.2f}, {math.degrees(yaw):.0f} deg)"


def point_of(target: Any) -> tuple[float, float, float]:
    """The point [m, map] of a look or reach target: a point, a believed object's centre, an
    object designator's (its reference), a surface or place of the robot's environment."""
    if isinstance(target, ObjectDesignator):
        target = target.reference()
    pose = getattr(target, "pose", None)
    if pose is not None and not callable(pose) and len(pose) == 3:
        return (float(pose[0]), float(pose[1]), float(pose[2]))
    if isinstance(target, str):
        from pycram.execution.robot import current_robot
        from pycram.reasoning.locations.targets import as_target

        belief = getattr(current_robot(), "belief", None)
        environment = getattr(belief, "environment", None)
        return tuple(as_target(target, environment).position)  # type: ignore[return-value]
    if hasattr(target, "position"):
        return tuple(float(v) for v in target.position)  # type: ignore[return-value]
    values = tuple(float(v) for v in target)
    if len(values) != 3:
        raise ValueError(f"{target!r} is not a point (x, y, z)")
    return values


@action_plan("looking_at")
def looking_at(designator: ActionDesignator) -> Any:
    target = designator.prop_value("target")
    if target is None:
        raise ActionParameterError("looking_at", "target", "missing: a point, an object or a place")
    try:
        point = point_of(target)
    except (ValueError, TypeError) as error:
        raise ActionParameterError("looking_at", "target", str(error)) from error
    return motion(type="pointing_head", coordinates=list(point))


@action_plan("parking_arms")
def parking_arms(designator: ActionDesignator) -> None:
    errors: list[BaseException] = []
    branches = [lambda a=a: motion(type="setting_arm_configuration", arm=a, configuration="park") for a in arms()]
    state = par(*branches, errors=errors, name="park every arm")
    if state.get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure("parking the arms failed", designator)


@action_plan("moving_torso")
def moving_torso(designator: ActionDesignator) -> Any:
    position = designator.prop_value("position")
    if position is None:
        raise ActionParameterError("moving_torso", "position", "missing: a named position or a height [m]")
    return motion(type="setting_torso", position=position)


@action_plan("setting_gripper")
def setting_gripper(designator: ActionDesignator) -> Any:
    gripper, position = designator.prop_value("gripper"), designator.prop_value("position")
    if gripper is None or position is None:
        raise ActionParameterError("setting_gripper", "gripper" if gripper is None else "position", "missing")
    gripper = gripper_name("setting_gripper", gripper)  # a clear error for a gripper it does not have
    return motion(type="setting_gripper", gripper=gripper, position=position)


@action_plan("detecting")
def detecting(designator: ActionDesignator) -> Any:
    wanted = designator.prop_value("object")
    if wanted is None:
        return motion(type="detecting")
    seen = motion(type="detecting", object=wanted)
    if not seen:
        raise ObjectNotVisible(f"no object matching {wanted!r} in view", designator)
    return seen


@action_plan("searching")
def searching(designator: ActionDesignator) -> Any:
    wanted = designator.prop_value("object")
    if isinstance(wanted, str):
        wanted = ObjectDesignator(type=wanted)
    if not isinstance(wanted, ObjectDesignator):
        raise ActionParameterError("searching", "object", f"needs an object designator or a type name, got {wanted!r}")
    from .containers import opening_one_at_a_time

    return search_for(wanted, open_container=opening_one_at_a_time())
