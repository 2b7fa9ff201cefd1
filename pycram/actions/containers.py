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

This module holds the `Open` and `Close` designators and their plans, which dispatch by the
container's kind. What they use is split by concept: `pycram.actions.container_state` (how open
a container is measured and believed; the thresholds), `pycram.actions.container_poses` (where
to stand, attempt by attempt), `pycram.actions.handles` (one attempt by the handle: a drawer
along its slide, a door along its arc), `pycram.actions.drawers` (closing a drawer in stages)
and `pycram.actions.doors` (doors: by the handle, pushing).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.execution.failures import ContainerFailure
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot

from .container_poses import _standing_poses, _try_poses
from .container_state import _environment
from .core import RECOVERABLE, ActionParameterError, action_plan, arm_name, make_action, unwrap
from .doors import _operate_door
from .drawers import _close_drawer
from .handles import _move_handle

__all__ = [
    "Open",
    "Close",
    "opening_one_at_a_time",
    "DRAWER_OPENING",
    "DOOR_OPENING",
]

log = logging.getLogger("pycram.actions")

#: How far [m] `Open` pulls a drawer out when not told.
DRAWER_OPENING = 0.3
#: How far [rad] `Open` swings a door when not told (69 deg).
DOOR_OPENING = 1.2


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
