"""Transporting: search, fetch, deliver -- one action, with the recoveries of its parts.

`Transport(object=ObjectDesignator(type='cup'), target=LocationDesignator([('on', 'table')]))`
finds the object (search when the belief does not hold it), picks it up (`PickUp`) and places it
(`Place`). When the object is lost on the way -- it slipped or was taken from the gripper --
it is searched for and fetched again, at most `TRANSPORT_ROUNDS` times; then the failure of the
last round is raised (`ObjectSlipped`, `GraspFailed`, `ObjectNotFound`, ...). Returns the
believed object where it was put.

A target inside a container (``('in', 'drawer 2')``, or the name of a drawer's, a shelf's or the
fridge's inside) that the robot does not believe open is opened first (`Open`), before the object
is fetched: the hand that opens it is free then, also on a one-armed robot. Into a container with
a door, the object is taken from the side (`SIDE`) unless `grasp` says otherwise: the hand comes
in through the door, under the shelf above. Where no standing pose takes it from the side where
it stands, it is picked up as it can be, put down within reach and taken again from the side.

With ``close_container=True`` the container the object was taken from (a drawer the search
opened) is closed again with `Close`, unless it was believed open before the transport: right
after picking up, with a free arm (the PR2), or once the object is placed (a one-armed robot).
Its failures are raised (the transport is not done while it stands open). Other containers the
search opened on the way stay open.
"""

from __future__ import annotations

import logging
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import GripperEmpty, ObjectOutOfReach, ObjectSlipped
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.world.objects import OBJECT_TYPES, SIDE, approach_matches, object_type

from .container_state import CLOSED, DOOR_CLOSED
from .containers import Close, Open
from .core import (
    ActionParameterError,
    action_plan,
    arm_name,
    arms,
    attempt,
    check_grasp,
    check_object_type,
    make_action,
    solutions,
)
from .held import held_objects
from .pick_up import PickUp, believed_object
from .place import Place

__all__ = ["Transport", "TRANSPORT_ROUNDS"]

log = logging.getLogger("pycram.actions")

#: A container counts as open above this believed opening [m or rad] (a drawer: 3 cm, a door: 4 deg).
OPEN_ABOVE = max(CLOSED, DOOR_CLOSED)
#: Fetch-and-deliver rounds (the object lost on the way starts a new round).
TRANSPORT_ROUNDS = 3


def Transport(
    object: Any, target: Any, arm: str | None = None, close_container: bool = False, grasp: str | None = None
) -> ActionDesignator:
    """Bring `object` (an object designator, a believed object or a type name) to `target` (as
    for `Place`: a location designator, a `Spot`, a point or a surface's name) with `arm`
    (None: chosen by the reasoning) and `grasp` (as for `PickUp`: an approach such as
    ``'side'`` or ``'top'``; None: any the robot can execute); with `close_container`, close
    the container it was taken from when the transport opened it. An unknown grasp approach or
    object type raises `ActionParameterError` at once, an arm the robot does not have when
    performed."""
    check_object_type("transporting", object)
    return make_action(
        "transporting",
        object=object,
        target=target,
        arm=arm,
        close_container=close_container,
        grasp=check_grasp("transporting", grasp),
    )


def _open_containers() -> dict[str, float]:
    """The containers the active robot believes open (name -> measured opening [m or rad])."""
    belief = getattr(current_robot(), "belief", None)
    states = dict(getattr(belief, "container_states", {}) or {})
    return {name: q for name, q in states.items() if q >= OPEN_ABOVE}


def _close(container: str, arm: str | None, obj: Any) -> None:
    log.info("transporting: closing %s, where %s was taken from", container, getattr(obj, "name", "it"))
    perform(Close(container, arm=arm))


def _target_container(target: Any) -> str | None:
    """The container `target` lies in: a location designator's ``('in', container)``, or a
    surface name of a container's inside; None for anything else."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    containers = {c.name: c for c in getattr(environment, "containers", ())}
    prop_value = getattr(target, "prop_value", None)
    if callable(prop_value):
        inside = prop_value("in")
        return str(inside) if isinstance(inside, str) and inside in containers else None
    if isinstance(target, str):
        for container in containers.values():
            if target == container.name or any(s.name == target for s in container.interior):
                return container.name
    return None


def _grasp_for(container: str | None, type_name: str | None) -> str | None:
    """The grasp an object of `type_name` must be held with to be put into `container`, by the
    way into it: through a door (the fridge, a cupboard) the hand comes in from the front, so from
    the side (`SIDE`: a hand that held it from the top finds no way in under the shelf above) --
    when its type has a grasp from the side (a bowl or a plate, held by its rim from the top, has
    none: any grasp then); None (any grasp) for a drawer, for no container and for an unknown
    type."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if container is None or environment is None or type_name not in OBJECT_TYPES:
        return None
    if environment.container(container).kind != "door":
        return None
    return SIDE if any(approach_matches(g.approach, SIDE) for g in object_type(type_name).grasps) else None


def _type_of(wanted: Any) -> str | None:
    """The object type `wanted` names (an object designator's ``type``, a believed object's
    ``type``), None when it names none."""
    prop_value = getattr(wanted, "prop_value", None)
    if callable(prop_value):
        found = prop_value("type")
        return str(found) if isinstance(found, str) else None
    found = getattr(wanted, "type", None)
    return str(found) if isinstance(found, str) else None


def _open_wide_enough(container: str, type_name: str | None, arm: str | None) -> None:
    """A drawer opened part of the way (`Open` counts a drawer out `USEFUL_OPENING` as open) may
    leave no room out from under the furniture for an object of `type_name`: then pull it out
    to the end of its slide once more (measured: the TIAGo pulled drawer 2 out 18 cm, and a
    spoon, 16 cm long, found no spot in it)."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if type_name is None or belief is None or environment is None:
        return
    drawer = next((c for c in environment.containers if c.name == container), None)
    if drawer is None or drawer.kind != "drawer":
        return
    spots = LocationDesignator([("in", container), ("for", type_name)])
    try:
        next(iter(solutions(spots)))
        return
    except (NoSolutionError, StopIteration) as why:
        log.info(
            "transporting: no room for a %s in %s as it is open (%s); pulling it out further", type_name, container, why
        )
    perform(Open(container, arm=arm, opening=float(drawer.limits[1])))


def _pick_up(obj: Any, arm: str | None, grasp: str | None, regrasp: bool) -> Any:
    """`PickUp` of `obj` with `grasp`. With `regrasp` (the grasp was chosen for the target, not
    asked for), where no standing pose takes the object with that grasp where it stands (e.g. a
    cereal box deep on the counter, for the cupboard from the side), it is picked up as it can be,
    put down on its surface on the side facing the robot, and taken again with the grasp."""
    try:
        return perform(PickUp(obj, arm=arm, grasp=grasp))
    except ObjectOutOfReach as error:
        if not regrasp:
            raise
        log.info("transporting: %s cannot be taken %s where it stands (%s); moving it within reach", obj, grasp, error)
    held = perform(PickUp(obj, arm=arm))
    support = str(held.object.properties.get("on") or "table")
    moved = perform(Place(held, support, arm=held.arm))
    return perform(PickUp(moved, arm=arm, grasp=grasp))


@action_plan("transporting")
def transporting(designator: ActionDesignator) -> Any:
    wanted = designator.prop_value("object")
    target = designator.prop_value("target")
    if wanted is None or target is None:
        raise ActionParameterError("transporting", "object" if wanted is None else "target", "missing")
    check_object_type("transporting", wanted)
    arm = arm_name("transporting", designator.prop_value("arm"))
    grasp = check_grasp("transporting", designator.prop_value("grasp"))
    opened_before = set(_open_containers())
    into = _target_container(target)
    if grasp is None:
        grasp = _grasp_for(into, _type_of(wanted))
        chosen_for_target = grasp is not None
    else:
        chosen_for_target = False
    if into is not None and into not in opened_before:
        log.info("transporting: opening %s first, to put the object in", into)
        perform(Open(into, arm=arm))
        _open_wide_enough(into, _type_of(wanted), arm)
    last: BaseException | None = None
    for round_number in range(1, TRANSPORT_ROUNDS + 1):
        if round_number > 1 and isinstance(wanted, ObjectDesignator):
            wanted = wanted.copy()  # the old one is equated to the object that was lost

        def fetch_and_deliver(wanted: Any = wanted) -> Any:
            obj = believed_object("transporting", wanted)
            container = str(obj.properties.get("in") or "")
            close = (
                bool(designator.prop_value("close_container")) and bool(container) and container not in opened_before
            )
            held = _pick_up(obj, arm, grasp, chosen_for_target)
            free = [a for a in arms() if a not in held_objects()]
            if close and free:  # a free hand closes it at once, standing there
                _close(container, free[0], obj)
            placed = perform(Place(held, target, arm=held.arm))
            if close and not free:  # a one-armed robot closes it once its hand is free again
                _close(container, None, obj)
            return placed

        try:
            placed = attempt(f"fetch and deliver (round {round_number})", fetch_and_deliver)
        except (ObjectSlipped, GripperEmpty) as error:
            log.info("transporting: %s; fetching it again", error)
            last = error
            continue
        return placed
    assert last is not None
    raise last
