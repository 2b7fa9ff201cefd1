"""The plans of the household task suite: bring each object somewhere, robot-agnostic.

An `Errand` is one object's job: its type (the plan finds it by type, through perception) and
where it may go, best first, as location designators' properties -- ``('in', container)`` to put
it away (`Transport` opens a closed container first), ``('on', 'table'), ('near', ...)`` to serve
it. `run_errands` does them in order with the action library and the plan language, the way the
set-table plan does (and with its pieces, `pycram.apps.scenarios.set_table.plan`):

* every drive looks for the objects still to be brought (`while_driving` with
  `look_for_the_next`), and an object not believed yet is searched for (`find`);
* each errand runs in rounds (`ROUNDS`), each under `with_timeout` (`ROUND_TIME_BUDGET` [s of
  simulated time]); after a failed round an object still in the hand is put down where it was
  seen before (`put_down`) and the containers believed open are closed, so the next round starts
  with empty hands; when the object had been picked up, the next round tries the same target with
  another arm (a robot that has one), then the next target of the errand (another drawer); when
  the target's container or placing there failed, the next target; into a drawer the object is
  carried with a top grasp (`_grasp_into`: a side grasp cannot pass over the drawer's walls), and
  when no standing pose takes it with that grasp where it stands, the next target that does not
  want it (a cup goes into the cupboard instead);
* after each errand, with empty hands, every drawer and door the robot believes open is closed
  (`close_opened_containers`).

The outcome of each errand (done, or the typed failure that stopped it) is returned; the plan
raises nothing for a failed object. `put_away` and `serve` make the errands of the scenarios
from their goals (`pycram.apps.scenarios.common.scene.Goal`): the plan is told object types,
container names and a seat, never where anything is.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from pycram.actions import Held, MoveTorso, ParkArms, Place, Transport, believed_open, held_objects
from pycram.actions.core import arms, while_driving
from pycram.apps.scenarios.common.scene import Goal
from pycram.apps.scenarios.set_table.plan import (
    WORLD_FAILURES,
    PlanRecord,
    believed,
    close_opened_containers,
    current_object,
    find,
    look_for_the_next,
    objects_done,
)
from pycram.core.expressions import State, with_timeout
from pycram.designators.location import LocationDesignator
from pycram.execution.failures import ContainerFailure, ObjectOutOfReach, PlacingFailed, PlanFailure
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.world.objects import object_type

__all__ = [
    "Errand",
    "ErrandOutcome",
    "ROUND_TIME_BUDGET",
    "ROUNDS",
    "run_errands",
    "put_away",
    "serve",
    "put_down",
]

log = logging.getLogger("pycram.demo")

#: Simulated time [s] one round of an errand may take (search, open the target, fetch, place).
ROUND_TIME_BUDGET = 420.0
#: Rounds per errand (each after a failure the target's next choice or a new look may fix).
ROUNDS = 3

#: Properties of a location designator: [("in", "drawer 3"), ("for", "cup")].
Properties = list[tuple[str, Any]]


@dataclass(frozen=True)
class Errand:
    """One object's job: bring an object of `type` to one of `targets` (best first): each a
    function of nothing returning the properties of a location designator (asked when the round
    starts: a target may name an object served before)."""

    type: str
    targets: tuple[Callable[[], Properties], ...]


@dataclass
class ErrandOutcome:
    """What became of an errand: `done` (the plan believes the object there), with the `target`
    it went to, or the `failure` that stopped it (a typed failure of `pycram.failures`, or
    `TimeoutError`) and every round's failure in `attempts`."""

    errand: Errand
    done: bool = False
    target: str | None = None
    failure: BaseException | None = None
    attempts: list[str] = field(default_factory=list)


def _container(properties: Properties) -> str | None:
    return next((str(v) for k, v in properties if k == "in"), None)


def _describe(properties: Properties) -> str:
    return ", ".join(f"{k} {v}" for k, v in properties if k != "for")


def _grasp_into(properties: Properties, type_name: str) -> str | None:
    """The grasp approach to carry an object of `type_name` with into the target: ``'top'`` into a
    drawer (its walls rise above side grasps: the object must come down from above), when the
    type has a top grasp; None (any) elsewhere."""
    container = _container(properties)
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if container is None or environment is None or environment.container(container).kind != "drawer":
        return None
    return "top" if any(g.approach == "top" for g in object_type(type_name).grasps) else None


def _held(type_name: str) -> Held | None:
    return next((h for h in held_objects().values() if h.object.type == type_name), None)


def put_down(held: Held) -> None:
    """Put `held` down on a free spot of the surface it was seen on before it was picked up (the
    table when the belief does not say): a hand is freed to open a container."""
    support = str(held.object.properties.get("on") or "table")
    properties: Properties = [("on", support), ("for", held.object.type)]
    perform(Place(held, LocationDesignator(properties), arm=held.arm))


def _deliver_held(held: Held, properties: Properties) -> Any:
    """The object is still in the hand after a failed round: into the target when it is believed
    open, else put down (`put_down`) and None (it is fetched anew)."""
    container = _container(properties)
    if container is None or believed_open(container):
        return perform(Place(held, LocationDesignator(properties), arm=held.arm))
    log.info("errand: putting the %s down before %s is opened", held.object.type, container)
    put_down(held)
    return None


def _let_go(type_name: str) -> str | None:
    """After a failed round: put the object down if it is still held (best effort) and close the
    containers believed open; returns the arm that held it (None: it was not held)."""
    held = _held(type_name)
    if held is None:
        close_opened_containers()
        return None
    try:
        put_down(held)
    except WORLD_FAILURES as failure:
        log.warning("errand: could not put the %s down: %s: %s", type_name, type(failure).__name__, failure)
        return held.arm
    close_opened_containers()
    return held.arm


def _do(outcome: ErrandOutcome, record: PlanRecord) -> None:
    """The rounds of one errand: after a failure with the object in the hand (it was picked up,
    but not put there), the same target with another arm if the robot has one, then the next
    target; after a failure of the target's container or of placing, the next target; when the
    object cannot be reached with the grasp the target wants, the next target that wants none."""
    errand = outcome.errand
    choice, arm, other_arm_tried = 0, None, False
    for round_number in range(1, ROUNDS + 1):
        properties = errand.targets[choice]()
        errors: list[BaseException] = []
        grasp = _grasp_into(properties, errand.type)

        def transport(properties: Properties = properties, arm: str | None = arm, grasp: str | None = grasp) -> Any:
            held = _held(errand.type)
            if held is not None:
                placed = _deliver_held(held, properties)
                if placed is not None:
                    return placed
            found = find(errand.type, record)
            return perform(Transport(found, LocationDesignator(list(properties)), arm=arm, grasp=grasp))

        state = with_timeout(ROUND_TIME_BUDGET, transport, errors, name=f"bring the {errand.type}")
        if state.get_value() is State.SUCCEEDED:
            outcome.done, outcome.failure, outcome.target = True, None, _describe(properties)
            return
        error = errors[0] if errors else PlanFailure(f"bringing the {errand.type} did not succeed")
        outcome.failure = error
        with_arm = f", {arm} arm" if arm else ""
        outcome.attempts.append(
            f"round {round_number} ({_describe(properties)}{with_arm}): {type(error).__name__}: {error}"
        )
        log.warning("errand: the %s, round %d: %s: %s", errand.type, round_number, type(error).__name__, error)
        if not isinstance(error, (*WORLD_FAILURES, TimeoutError)):
            raise error  # a bug, not a failure of the world
        held_by = _let_go(errand.type)  # the next round starts with empty hands and the room closed
        others = [a for a in arms() if a != held_by]
        if held_by is None and grasp is not None and isinstance(error, ObjectOutOfReach):
            # not to be taken with that grasp where it stands: the next target that wants no such grasp
            later = [
                i
                for i in range(choice + 1, len(errand.targets))
                if _grasp_into(errand.targets[i](), errand.type) != grasp
            ]
            if later:
                choice, arm, other_arm_tried = later[0], None, False
        elif held_by is not None and others and not other_arm_tried:
            arm, other_arm_tried = others[0], True  # the same target with the other arm
        elif (held_by is not None or isinstance(error, (ContainerFailure, PlacingFailed))) and choice + 1 < len(
            errand.targets
        ):
            choice, arm, other_arm_tried = choice + 1, None, False


def run_errands(
    errands: list[Errand],
    record: PlanRecord | None = None,
    on_done: Callable[[ErrandOutcome], None] | None = None,
) -> list[ErrandOutcome]:
    """Do every errand in order (see the module docstring); close the containers opened on the
    way; `on_done` is told of each errand done (before the next one starts). Returns one
    `ErrandOutcome` per errand; raises only for bugs and evaporation."""
    record = record if record is not None else PlanRecord()
    objects_done.set_value(0)
    outcomes = [ErrandOutcome(e) for e in errands]
    perform(ParkArms())
    perform(MoveTorso("up"))

    def still_wanted() -> list[str]:
        holding = {h.object.type for h in held_objects().values()}
        return [o.errand.type for o in outcomes if not o.done and o.errand.type not in holding]

    with while_driving(partial(look_for_the_next, still_wanted, record)):
        for outcome in outcomes:
            current_object.set_value(outcome.errand.type)
            log.info("errand: bringing the %s", outcome.errand.type)
            _do(outcome, record)
            current_object.set_value(None)
            if outcome.done:
                objects_done.set_value(objects_done.get_value() + 1)
                if on_done is not None:
                    on_done(outcome)
            close_opened_containers()
        close_opened_containers()  # a container that would not close is tried once more
    return outcomes


def _fixed(properties: Properties) -> Callable[[], Properties]:
    return lambda: list(properties)


def put_away(goals: list[Goal], record: PlanRecord | None = None) -> list[ErrandOutcome]:
    """Put every object of `goals` into one of its goal's containers (best first: the next one
    after a failure at the first), closing every container afterwards."""
    errands = [Errand(g.type, tuple(_fixed([("in", c), ("for", g.type)]) for c in g.containers)) for g in goals]
    return run_errands(errands, record)


def serve(goals: list[Goal], record: PlanRecord | None = None) -> list[ErrandOutcome]:
    """Bring every object of `goals` to the table at its goal's seat, next to each other: the
    first one at the spot of the table nearest the goal's point in front of the seat (else the
    seat), each next one nearest the one served before it (as the robot believes it), else
    nearest that point."""
    served: list[str] = []

    def at_seat(goal: Goal) -> Any:
        return goal.point if goal.point is not None else goal.seat

    def target(goal: Goal) -> Properties:
        before = next((believed(t) for t in reversed(served) if believed(t) is not None), None)
        near: Any = before.name if before is not None else at_seat(goal)
        return [("on", "table"), ("near", near), ("for", goal.type)]

    def seat_only(goal: Goal) -> Properties:
        return [("on", "table"), ("near", at_seat(goal)), ("for", goal.type)]

    errands = []
    for goal in goals:
        if goal.seat is None:
            raise ValueError(f"serving the {goal.type}: its goal names no seat")
        errands.append(Errand(goal.type, (partial(target, goal), partial(seat_only, goal))))
    return run_errands(errands, record, on_done=lambda outcome: served.append(outcome.errand.type))
