"""Where the robot stands to work a container's handle, attempt by attempt.

`_standing_poses` are the solutions of ``('to_open', container)`` for a travel of the handle
(for closing, the pose the container was last opened from first: remembered per robot by
`_try_poses`, and for a drawer that pose stepped in by `STEP_IN` [m]); `_torso_and_drive` sets
the torso a pose needs and drives there unless the base stands there already (within `AT_POSE`
[m, rad]); `_try_poses` runs one attempt from each standing pose in turn, at most
`CONTAINER_ATTEMPTS`, and raises the last typed failure with every attempt's reason
(`ObjectOutOfReach` when there was no standing pose).
"""

from __future__ import annotations

import math
import weakref
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.location import LocationDesignator
from pycram.execution.failures import ContainerFailure, ContainerStuck, ObjectOutOfReach
from pycram.execution.robot import current_robot

from .core import RECOVERABLE, attempt, base_pose_fluent, motion, solutions, unwrap

__all__ = ["CONTAINER_ATTEMPTS"]

#: Standing poses tried per opening or closing.
CONTAINER_ATTEMPTS = 4
#: The robot counts as standing at a pose within this [m, rad] (it does not drive there again).
AT_POSE = 0.03
#: A push that stopped short goes on from this much [m] nearer to the drawer.
STEP_IN = 0.15


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
