"""The set-table plan: search, fetch and place each object of a breakfast setting, robot-agnostic.

The plan knows the objects only through perception (the robot's belief, filled by `Search`),
the table's place settings as data (`PlaceSetting`: an object type and the point [m, map] where
it should stand) and the environment's description (containers by name). It runs unchanged on
the two-armed PR2 and the one-armed TIAGo: arms, grasps and standing poses are chosen by the
action library's designators.

For each place setting, in order:

* the object is found: from the belief, else searched for (``search_for``: open surfaces first,
  then inside the drawers, one drawer open at a time) -- under ``pursue`` with a wait on a
  fluent that the looks taken while driving set, so the search ends as soon as one of them
  sees the object;
* it is brought: ``Transport(found, point)`` -- pick up, place, with the action library's
  recoveries inside (next standing pose, perceiving again, searching again when the object was
  taken). When the robot has an arm to spare once it holds this object (from its description
  and `held_objects()`: the PR2, never the one-armed TIAGo) and the next object is believed,
  the robot picks this one up, picks the next one
  up with the free arm (``PickUp(next, arm=free)``, abandoned by ``pursue`` as soon as the
  next one is believed gone: no searching with full hands) and puts it at its setting, then
  puts this one down: two objects carried at once, one trip to the table fewer;
* each round's fetching runs under `with_timeout` (a budget of simulated time, from the moment
  the object is found: the search is bounded by the places it visits, and a kitchen with more
  drawers and doors takes longer to search), with one more round for the failures that a second
  look may fix (the object was moved, missed by perception, a drawer was stuck and is free now);
* afterwards, with empty hands, every drawer and door the robot believes open is closed again
  (`Close`), so no drawer is left sticking out into the room.

Throughout, every drive of the action library has a companion (`while_driving`): the head looks
along the surfaces within reach of the camera for the objects still to be brought that the
belief does not hold yet (`look_for_the_next`) -- a person glances at the counter on the way
past. What it sees goes into the belief, so later searches end early or are not needed.
The head is used only while the base drives; the companion is evaporated when the drive ends,
before the action uses the head again.

The outcome of each setting (placed, or the typed failure that stopped it) is returned; the plan
raises nothing for a failed object, so the other objects are still brought. What the
concurrency did is written into a `PlanRecord` when one is given.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from pycram.actions import (
    Close,
    Detect,
    Held,
    LookAt,
    MoveTorso,
    Navigate,
    Open,
    ParkArms,
    PickUp,
    Place,
    Transport,
    believed_open,
    held_objects,
    lookouts,
    search_for,
)
from pycram.actions.core import arms, base_pose_fluent, motion, while_driving
from pycram.actions.search import LOOK_RANGE
from pycram.core.expressions import State, pursue, seq, with_timeout
from pycram.core.fluent import Fluent
from pycram.designators.core import DesignatorError
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import (
    GraspFailed,
    GripperEmpty,
    ObjectNotVisible,
    ObjectOutOfReach,
    ObjectSlipped,
    PlanFailure,
)
from pycram.execution.perform import perform
from pycram.execution.process_module import ProcessModuleError
from pycram.execution.robot import current_robot
from pycram.world.belief import PerceivedObject

__all__ = [
    "PlaceSetting",
    "SettingOutcome",
    "PlanRecord",
    "set_table",
    "find",
    "believed",
    "look_for_the_next",
    "close_opened_containers",
    "ROUND_TIME_BUDGET",
    "ROUNDS",
    "RESCAN_DISTANCE",
    "current_object",
    "WORLD_FAILURES",
    "objects_done",
]

log = logging.getLogger("pycram.demo")

#: What a failed step of the world raises: typed plan failures, and motions a process module
#: could not execute or designators without a solution that escaped an action's recovery.
WORLD_FAILURES = (PlanFailure, ProcessModuleError, DesignatorError)

#: Simulated time [s] one transport round may take once its object is found (fetch, place, the
#: recoveries inside). The search before is not counted: it ends when it has looked at every
#: likely place, and a kitchen's size decides how long that takes (measured: a bowl on a
#: generated fridge's shelf was found after 184 s of opening and closing the cupboard and the
#: fridge, and the round ran out while the robot picked it up; `procedural:35`, seed 1).
ROUND_TIME_BUDGET = 300.0
#: Looking from elsewhere: a named place at least this far [m] from where the robot stands.
ELSEWHERE = 0.5
#: Transport rounds per object (a second round after a failure a new search may fix).
ROUNDS = 2
#: Looking while driving: once every place in view range has been looked at, the next look
#: waits until the base has moved this far [m] (places may have come into range).
RESCAN_DISTANCE = 1.0

#: `close_opened_containers` goes over the containers at most this often (closing one may show
#: another one open).
CLOSING_PASSES = 3


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


@dataclass
class PlanRecord:
    """What the plan's concurrency did in one run (filled from several tasks; thread-safe):

    * `found_while_driving`: objects first believed from a look taken while the base drove
      ("cup-1 on counter");
    * `searches_ended_by_sighting`: searches that `pursue` ended because a look taken while
      driving turned the object up before the search itself did ("plate: plate-1");
    * `sightings`: a fluent holding the set of types seen while driving (what `find` waits on);
    * `carried_together`: (held, fetched) type pairs: the second object was brought with the
      free arm while the first was held.
    """

    found_while_driving: list[str] = field(default_factory=list)
    searches_ended_by_sighting: list[str] = field(default_factory=list)
    carried_together: list[tuple[str, str]] = field(default_factory=list)
    sightings: Fluent = field(
        default_factory=lambda: Fluent(frozenset(), name="seen while driving"), repr=False, compare=False
    )
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    def sighted(self, obj: PerceivedObject, surface: str) -> None:
        """A look taken while driving saw `obj` for the first time, on `surface`."""
        with self._lock:
            self.found_while_driving.append(f"{obj.name} on {surface}")
            self.sightings.set_value(self.sightings.get_value() | {obj.type})

    def note(self, entries: list[Any], entry: Any) -> None:
        """Append `entry` to `entries` (one of this record's lists) under the record's lock."""
        with self._lock:
            entries.append(entry)

    def as_dict(self) -> dict[str, Any]:
        """A JSON-serialisable copy."""
        with self._lock:
            return {
                "found_while_driving": list(self.found_while_driving),
                "searches_ended_by_sighting": list(self.searches_ended_by_sighting),
                "carried_together": [list(p) for p in self.carried_together],
            }


def _belief() -> Any:
    return getattr(current_robot(), "belief", None)


def believed(type_name: str) -> PerceivedObject | None:
    """The object of `type_name` the robot believes present (not gone), best first; None when
    it believes none."""
    belief = _belief()
    if belief is None:
        return None
    return next((o for o in belief.present() if o.type == type_name), None)


def close_opened_containers() -> list[str]:
    """Close every drawer and door the robot believes open (`believed_open`: from its last
    look); returns their names. A container that will not close is logged and left (its failure
    is not raised). Closing one may show another open (the looks at its neighbours after each
    push): the containers are gone over again, at most `CLOSING_PASSES` times.
    (Doors: the search opens the fridge to look inside, on a robot that opens doors.)"""
    belief = _belief()
    environment = getattr(belief, "environment", None)
    if belief is None or environment is None:
        return []
    closed: list[str] = []
    failed: set[str] = set()
    for _ in range(CLOSING_PASSES):
        todo = [
            c.name
            for c in environment.containers
            if c.kind in ("drawer", "door") and c.name not in failed and believed_open(c.name)
        ]
        if not todo:
            break
        for name in todo:
            try:
                perform(Close(name))
                closed.append(name)
            except WORLD_FAILURES as failure:
                log.warning("could not close %s: %s", name, failure)
                failed.add(name)
    return closed


def open_alone(container: str) -> Any:
    """Open `container` after closing every other container believed open: a search that looks
    into one drawer after another leaves at most one open (open drawers stand in the robot's
    way, and in the way of closing the ones below them)."""
    close_opened_containers()
    return perform(Open(container))


@dataclass(frozen=True)
class _SeenMeanwhile:
    """What the belief branch of `find` returns: the object believed meanwhile."""

    object: PerceivedObject


def find(type_name: str, record: PlanRecord | None = None) -> PerceivedObject:
    """The believed object of `type_name`: from the belief, else searched for (open surfaces
    first, then inside the drawers, one drawer open at a time).

    The search runs under ``pursue`` with a wait on the record's `PlanRecord.sightings`: as
    soon as a look taken while driving (`look_for_the_next`, concurrent with the search's
    drives) reports such an object, the search is evaporated (its drive or look stops) and
    that object is the answer -- not while the search opens or closes a drawer (an arm on a
    handle is not let go half way): then the wait fires once that is over. A search that finds
    the object with its own look returns it as usual. Raises `ObjectNotFound` (from the search)
    when the object is neither found nor seen.
    """
    record = record if record is not None else PlanRecord()
    known = believed(type_name)
    if known is not None:
        return known
    handling = Fluent(False, name="opening a drawer")

    def open_a_drawer(container: str) -> Any:
        handling.set_value(True)
        try:
            return open_alone(container)
        finally:
            handling.set_value(False)

    sightings = record.sightings

    def sighted() -> bool | None:
        seen = type_name in sightings.get_value() and believed(type_name) is not None
        return True if seen and not handling.get_value() else None

    # True once driving turned the object up (and it is still believed) and no drawer is handled
    turned_up = Fluent(sighted, name=f"{type_name} seen while driving, hands free")
    sightings.add_child(turned_up)
    handling.add_child(turned_up)

    def search() -> PerceivedObject:
        found: PerceivedObject = search_for(ObjectDesignator(type=type_name), open_container=open_a_drawer)
        return found

    def until_seen_while_driving() -> _SeenMeanwhile:
        turned_up.wait_for()
        obj = believed(type_name)
        assert obj is not None  # checked by the fluent; nothing else forgets objects meanwhile
        return _SeenMeanwhile(obj)

    errors: list[BaseException] = []
    state = pursue(search, until_seen_while_driving, errors=errors, name=f"search for the {type_name}")
    if state.get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure(f"the search for the {type_name} did not succeed")
    result = state.result
    if isinstance(result, _SeenMeanwhile):
        log.info("set table: the search for the %s ended: %s was seen while driving", type_name, result.object)
        record.note(record.searches_ended_by_sighting, f"{type_name}: {result.object.name}")
        return result.object
    assert isinstance(result, PerceivedObject)
    return result


def look_for_the_next(wanted: Callable[[], list[str]], record: PlanRecord | None = None) -> None:
    """Look along the open surfaces within the camera's range (`LOOK_RANGE` [m]) for objects
    of the `wanted()` types the belief does not hold yet: nearest place first, each looked at
    once (per call: per drive); when every place in range has been looked at, wait until the
    base has moved `RESCAN_DISTANCE` and look at the places come into range. Returns when
    every wanted type is believed. Runs alongside a drive (`while_driving`): it points the head
    and detects, nothing else; a place the head cannot turn to is skipped. Objects first seen
    here are noted with `PlanRecord.sighted` (which `find` waits on)."""
    belief = _belief()
    environment = getattr(belief, "environment", None)
    if belief is None or environment is None:
        return
    base = base_pose_fluent()
    looked: set[str] = set()
    while True:
        types = [t for t in wanted() if believed(t) is None]
        if not types:
            return
        here = base.get_value()
        if here is None:
            return
        candidates = []
        for type_name in types:
            for lookout in lookouts(environment, type_name, (here.x, here.y)):
                if lookout.container is not None or lookout.name in looked:
                    continue
                distance = math.dist((here.x, here.y), lookout.target[:2])
                if distance <= LOOK_RANGE:
                    candidates.append((distance, lookout.name, lookout))
        if not candidates:
            start = (here.x, here.y)
            moved = Fluent(
                lambda start=start: (
                    True if math.dist(start, (base.get_value().x, base.get_value().y)) > RESCAN_DISTANCE else None
                ),
                name=f"moved {RESCAN_DISTANCE} m",
            )
            base.add_child(moved)
            moved.wait_for()
            continue
        _, _, lookout = min(candidates)
        looked.add(lookout.name)
        before = {o.name for o in belief.present()}
        try:
            motion(type="pointing_head", coordinates=list(lookout.target))
            seen = motion(type="detecting")
        except WORLD_FAILURES as failure:
            log.info("set table: looking at %s while driving: %s", lookout.name, failure)
            continue
        for obj in seen:
            if obj.type in types and obj.name not in before:
                surface = str(obj.properties.get("on") or "an unknown surface")  # perceived support
                log.info("set table: saw %s on %s while driving (looking at %s)", obj.name, surface, lookout.name)
                if record is not None:
                    record.sighted(obj, surface)


def look_from_elsewhere(type_name: str) -> None:
    """Look at the believed object of `type_name` from the named place of the environment
    nearest to it that the robot does not stand at: a pose perceived from one view (the object
    partly hidden, e.g. by the robot's own arm) is measured again from another. Best effort."""
    belief = _belief()
    environment = getattr(belief, "environment", None)
    if belief is None or environment is None:
        return
    target = believed(type_name)
    if target is None:
        return
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


def _held(type_name: str) -> Held | None:
    """What a gripper holds of `type_name` (from an earlier, interrupted round), if anything."""
    return next((h for h in held_objects().values() if h.object.type == type_name), None)


def _arms_to_spare() -> int:
    """How many of the robot's arms hold nothing (from its description and `held_objects()`)."""
    holding = held_objects()
    return sum(1 for arm in arms() if arm not in holding)


def _bring_along(partner_object: PerceivedObject, arm: str, other: PlaceSetting) -> None:
    """Pick up `partner_object` with `arm` and put it at `other`'s point, while the other arm
    holds an object. The pick-up runs under ``pursue`` with a watch on the belief: as soon as
    the object is believed gone from where it was seen (a person took it, it was moved out of
    sight), the pick-up is evaporated -- before it would search for the object, opening drawers
    with an object in the other hand -- and `ObjectNotVisible` is raised. Raises what
    `PickUp` and `Place` raise."""
    lost = Fluent(lambda: True if partner_object.gone else None, name=f"{partner_object.name} gone")
    belief = _belief()
    if belief is not None:
        belief.updated.add_child(lost)

    def pick_up() -> Held:
        picked: Held = perform(PickUp(partner_object, arm=arm))
        return picked

    def until_gone() -> None:
        lost.wait_for()
        raise ObjectNotVisible(
            f"{partner_object.name} is no longer where it was seen: left for its own turn", partner_object, "lost"
        )

    errors: list[BaseException] = []
    state = pursue(pick_up, until_gone, errors=errors, name=f"pick up the {other.type} too")
    if state.get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure(f"picking up the {other.type} too did not succeed")
    held: Held = state.result
    perform(Place(held, other.point, arm=held.arm))


def _clear_to_carry(first: PerceivedObject, second: PerceivedObject) -> bool:
    """Whether the robot may go from `first` to `second` with `first` in its hand: both are
    believed where they stand. Whether the held object fits on the way and at the standing pose
    is for navigation and location reasoning to say (they check base poses with the held object
    and keep it off the objects standing around)."""
    return _belief() is not None and first.pose is not None and second.pose is not None


def _carry_two(
    found: PerceivedObject,
    outcome: SettingOutcome,
    partner: SettingOutcome,
    record: PlanRecord,
) -> Any:
    """Pick up `found` (for `outcome`'s setting); with an arm to spare, `partner`'s object
    believed and the way to it clear (`_clear_to_carry`), bring the partner's object with that
    arm while this one is held (`_bring_along`); then put this one at its setting. The
    partner's failure is noted in its outcome, not raised (it gets its own turn; an object left
    in its gripper is put down then). Raises this object's failures."""
    setting, other = outcome.setting, partner.setting
    held: Held = perform(PickUp(found))
    free = [arm for arm in arms() if arm not in held_objects()]
    partner_object = believed(other.type)
    if free and partner_object is not None and _clear_to_carry(found, partner_object):
        current_object.set_value(other.type)
        log.info("set table: the %s in the %s arm; the %s with the %s arm", setting.type, held.arm, other.type, free[0])
        try:
            _bring_along(partner_object, free[0], other)
            partner.placed, partner.failure = True, None
            record.note(record.carried_together, (setting.type, other.type))
            objects_done.set_value(objects_done.get_value() + 1)
        except WORLD_FAILURES as failure:
            partner.failure = failure
            partner.attempts.append(f"carried with the {setting.type}: {type(failure).__name__}: {failure}")
            log.warning(
                "set table: the %s with the %s: %s: %s", other.type, setting.type, type(failure).__name__, failure
            )
        finally:
            current_object.set_value(setting.type)
    try:
        return perform(Place(held, setting.point, arm=held.arm))
    except (ObjectSlipped, GripperEmpty) as error:  # taken or dropped on the way: fetch it again
        log.info("set table: the %s was lost on the way (%s); fetching it again", setting.type, error)
        return perform(Transport(ObjectDesignator(type=setting.type), setting.point))


def _bring(
    outcome: SettingOutcome,
    partner: SettingOutcome | None,
    record: PlanRecord,
) -> None:
    """Transport rounds for one setting, each bounded by the time budget; in the first round,
    `partner` (the next setting) may be brought along with an arm to spare."""
    setting = outcome.setting
    for round_number in range(1, ROUNDS + 1):
        errors: list[BaseException] = []

        def transport(round_number: int = round_number) -> Any:
            held = _held(setting.type)
            if held is not None:  # still in a gripper after an interrupted round: put it down

                def put_down(held: Held = held) -> Any:
                    return perform(Place(held, setting.point, arm=held.arm))

                try:
                    return _within_budget(put_down, f"put the {setting.type} down")
                except GripperEmpty as empty:  # lost meanwhile (taken, dropped): fetch it again
                    log.info("set table: the %s is no longer held (%s); fetching it again", setting.type, empty)
            found = find(setting.type, record)  # bounded by the places it looks at, not by the budget

            def fetch() -> Any:
                if round_number == 1 and partner is not None and not partner.placed and _arms_to_spare() >= 2:
                    return _carry_two(found, outcome, partner, record)
                return perform(Transport(found, setting.point))

            return _within_budget(fetch, f"fetch the {setting.type}")

        state = seq(transport, errors=errors, name=f"bring the {setting.type}")
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


def _within_budget(fetch: Callable[[], Any], name: str) -> None:
    """Run `fetch` as a task bounded by `ROUND_TIME_BUDGET` [s of the active clock: simulated
    time] (`with_timeout`); raise what it raised, or the `TimeoutError` when it ran out of time."""
    errors: list[BaseException] = []
    if with_timeout(ROUND_TIME_BUDGET, fetch, errors, name=name).get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure(f"{name} did not succeed")


def set_table(settings: list[PlaceSetting], record: PlanRecord | None = None) -> list[SettingOutcome]:
    """Bring every object of `settings` to its place; close the containers opened on the way.

    Every drive looks for the objects still to be brought (`look_for_the_next`); what the
    concurrency did is noted in `record` when given. Returns one `SettingOutcome` per setting,
    in order. Raises only for bugs (a failure of the world is an outcome) and evaporation.
    """
    record = record if record is not None else PlanRecord()
    objects_done.set_value(0)
    outcomes = [SettingOutcome(s) for s in settings]
    perform(ParkArms())
    perform(MoveTorso("up"))

    def still_wanted() -> list[str]:
        holding = {h.object.type for h in held_objects().values()}
        return [o.setting.type for o in outcomes if not o.placed and o.setting.type not in holding]

    with while_driving(partial(look_for_the_next, still_wanted, record)):
        for index, outcome in enumerate(outcomes):
            if outcome.placed:  # brought along with the one before
                continue
            partner = next((o for o in outcomes[index + 1 :] if not o.placed), None)
            current_object.set_value(outcome.setting.type)
            log.info("set table: bringing the %s to %s", outcome.setting.type, outcome.setting.point)
            _bring(outcome, partner, record)
            current_object.set_value(None)
            if outcome.placed:
                objects_done.set_value(objects_done.get_value() + 1)
            close_opened_containers()
        close_opened_containers()  # a drawer that would not close is tried once more, from afresh
    return outcomes
