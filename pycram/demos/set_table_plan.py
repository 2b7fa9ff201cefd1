"""The set-table plan: search, fetch and place each object of a breakfast setting, robot-agnostic.

The plan knows the objects only through perception (the robot's belief, filled by `Search`),
the table's place settings as data (`PlaceSetting`: an object type and the point [m, map] where
it should stand) and the environment's description (containers by name). It runs unchanged on
the two-armed PR2 and the one-armed TIAGo: arms, grasps and standing poses are chosen by the
action library's designators.

For each place setting, in order:

* ``Transport(ObjectDesignator(type=...), point)`` -- search (drawers are opened when the
  object is not found on open surfaces), pick up, place; the action library recovers inside
  (next standing pose, perceiving again, searching again when the object was taken);
* each transport round runs under `with_timeout` (a budget of simulated time), with one more
  round for the failures that a second look may fix (the
  object was moved, missed by perception, a drawer was stuck and is free now);
* afterwards, with empty hands, every container the robot believes open is closed again
  (`Close`), so no drawer is left sticking out into the room.

The outcome of each setting (placed, or the typed failure that stopped it) is returned; the plan
raises nothing for a failed object, so the other objects are still brought.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Any

from pycram.actions import Close, Detect, LookAt, MoveTorso, Navigate, Open, ParkArms, Transport, search_for
from pycram.actions.core import base_pose_fluent
from pycram.designator import ObjectDesignator, perform
from pycram.designators.core import DesignatorError
from pycram.failures import GraspFailed, ObjectOutOfReach, PlanFailure
from pycram.fluent import Fluent
from pycram.language import State, with_timeout
from pycram.process_module import ProcessModuleError
from pycram.robot import current_robot

__all__ = [
    "PlaceSetting",
    "SettingOutcome",
    "set_table",
    "close_opened_containers",
    "ROUND_TIME_BUDGET",
    "ROUNDS",
    "current_object",
    "WORLD_FAILURES",
    "objects_done",
]

log = logging.getLogger("pycram.demo")

#: What a failed step of the world raises: typed plan failures, and motions a process module
#: could not execute or designators without a solution that escaped an action's recovery.
WORLD_FAILURES = (PlanFailure, ProcessModuleError, DesignatorError)

#: Simulated time [s] one transport round may take (search, fetch, place, the recoveries inside;
#: a search through the three drawers alone takes about 150 s).
ROUND_TIME_BUDGET = 300.0
#: Looking from elsewhere: a named place at least this far [m] from where the robot stands.
ELSEWHERE = 0.5
#: Transport rounds per object (a second round after a failure a new search may fix).
ROUNDS = 2

#: The object type being brought now (None between objects), for people watching and for the
#: simulated person of the scenario's faults.
current_object = Fluent(None, name="set_table.current_object")
#: How many objects are at their place settings.
objects_done = Fluent(0, name="set_table.objects_done")


@dataclass(frozen=True)
class PlaceSetting:
    """Where an object of type `type` should stand on the table: `point` [m, map frame] is the
    object's centre standing upright there; `seat` names the seat the setting belongs to."""

    type: str
    point: tuple[float, float, float]
    seat: str = ""


@dataclass
class SettingOutcome:
    """What became of one place setting: `placed`, or the `failure` that stopped it (a typed
    failure of `pycram.failures`, or `TimeoutError` when the budget ran out) and every round's
    failure in `attempts`."""

    setting: PlaceSetting
    placed: bool = False
    failure: BaseException | None = None
    attempts: list[str] = field(default_factory=list)


def close_opened_containers() -> list[str]:
    """Close every container the robot believes open (from its last look); returns their
    names. A container that will not close is logged and left (its failure is not raised)."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if belief is None or environment is None:
        return []
    closed = []
    for container in environment.containers:
        if container.kind != "drawer" or belief.container_open(container.name) is not True:
            continue
        try:
            perform(Close(container.name))
            closed.append(container.name)
        except WORLD_FAILURES as failure:
            log.warning("could not close %s: %s", container.name, failure)
    return closed


def open_alone(container: str) -> Any:
    """Open `container` after closing every other container believed open: a search that looks
    into one drawer after another leaves at most one open (open drawers stand in the robot's
    way, and in the way of closing the ones below them)."""
    close_opened_containers()
    return perform(Open(container))


def find(type_name: str) -> Any:
    """The believed object of `type_name`: from the belief, else searched for (open surfaces
    first, then inside the drawers, one drawer open at a time)."""
    return search_for(ObjectDesignator(type=type_name), open_container=open_alone)


def look_from_elsewhere(type_name: str) -> None:
    """Look at the believed object of `type_name` from the named place of the environment
    nearest to it that the robot does not stand at: a pose perceived from one view (the object
    partly hidden, e.g. by the robot's own arm) is measured again from another. Best effort."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if belief is None or environment is None:
        return
    believed = [o for o in belief.present() if o.type == type_name]
    if not believed:
        return
    target = believed[0]
    here = base_pose_fluent().get_value()
    places = [
        p.pose
        for p in environment.places
        if here is None or math.hypot(p.pose[0] - here.x, p.pose[1] - here.y) > ELSEWHERE
    ]
    if not places:
        return
    place = min(places, key=lambda pose: math.dist(pose[:2], target.pose[:2]))
    try:
        perform(Navigate(place))
        perform(LookAt(target))
        perform(Detect(type_name))
    except WORLD_FAILURES as failure:
        log.info("set table: looking at the %s from elsewhere: %s", type_name, failure)


def _bring(setting: PlaceSetting, outcome: SettingOutcome) -> None:
    """Transport rounds for one setting, each bounded by the time budget."""
    for round_number in range(1, ROUNDS + 1):
        errors: list[BaseException] = []

        def transport() -> Any:
            found = find(setting.type)
            return perform(Transport(found, setting.point))

        state = with_timeout(ROUND_TIME_BUDGET, transport, errors, name=f"bring the {setting.type}")
        if state.get_value() is State.SUCCEEDED:
            outcome.placed, outcome.failure = True, None
            return
        error = errors[0] if errors else PlanFailure(f"bringing the {setting.type} did not succeed")
        outcome.failure = error
        outcome.attempts.append(f"round {round_number}: {type(error).__name__}: {error}")
        log.warning("set table: the %s, round %d: %s: %s", setting.type, round_number, type(error).__name__, error)
        if not isinstance(error, (*WORLD_FAILURES, TimeoutError)):
            raise error  # a bug, not a failure of the world
        close_opened_containers()  # the next round starts with the room as it should be
        if isinstance(error, (ObjectOutOfReach, GraspFailed)):
            look_from_elsewhere(setting.type)  # perceived from one view only: measure it again


def set_table(settings: list[PlaceSetting]) -> list[SettingOutcome]:
    """Bring every object of `settings` to its place; close the containers opened on the way.

    Returns one `SettingOutcome` per setting, in order. Raises only for bugs (a failure of the
    world is an outcome) and evaporation.
    """
    objects_done.set_value(0)
    outcomes = [SettingOutcome(s) for s in settings]
    perform(ParkArms())
    perform(MoveTorso("up"))
    for outcome in outcomes:
        current_object.set_value(outcome.setting.type)
        log.info("set table: bringing the %s to %s", outcome.setting.type, outcome.setting.point)
        _bring(outcome.setting, outcome)
        current_object.set_value(None)
        if outcome.placed:
            objects_done.set_value(objects_done.get_value() + 1)
        close_opened_containers()
    close_opened_containers()  # a drawer that would not close is tried once more, from afresh
    return outcomes
