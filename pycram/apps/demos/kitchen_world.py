"""The demo's world: kitchen facts as location resolvers, a helpful person, and a thief.

Everything here may talk to the simulator — it is the *environment* of the plan, not the plan.
The plan (`kitchen_plan`) only sees its effects through designators and fluents:

* `KitchenFacts` is the world's `ResolverSet`: `('named', 'start')`, `('on', 'cooker #2'),
  ('slot', n)` and `('on', 'cooker #1')` resolve to points and poses of this kitchen.
* `Operator` is a process module for `('type', 'waiting_for_help')`: a person who puts the item
  back into the gripper — simulated (after a short delay of simulated time), or the user at the
  terminal with `--interactive`, as in the thesis (`input(...)`).
* `Thief` takes the item out of the gripper at random moments while the robot carries it.
"""

from __future__ import annotations

import logging
import random
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from pycram.core.fluent import Fluent
from pycram.core.runtime import sleep
from pycram.core.runtime.lockstep import PlanThread
from pycram.execution.process_module import ProcessModule
from pycram.execution.robot import ResolverSet

log = logging.getLogger("pycram.demo")

#: The three positions in front of cooker #2 (thesis: x = 0.1, -0.2, 0.4 next to each other),
#: as (x, y) on the back counter top [m].
SLOTS = {1: (0.1, -1.15), 2: (-0.2, -1.15), 3: (0.4, -1.15)}
#: Where the item is put down: on cooker #1 [m].
PLACE_XY = (-0.72, 1.9)
#: Where the robot starts (free floor between the counters): x, y [m], yaw [rad].
START_POSE = (0.8, 0.6, 0.0)
ITEM_NAME = "mug"


#: The mug's colour: a yellow that stands out against counters, floor and robot in the pictures.
ITEM_COLOUR = (1.0, 0.82, 0.05, 1.0)


def demo_items(item_at: int) -> list:
    """The demo's items: the mug on slot `item_at` (1, 2 or 3) of cooker #2, none for 0."""
    from pycram.backends.sim import ItemSpec

    if item_at not in (0, *SLOTS):
        raise ValueError(f"--item-at must be 0 (no item) or a position 1, 2 or 3, not {item_at}")
    if not item_at:
        return []
    return [ItemSpec(ITEM_NAME, "mug", "cylinder", (0.03, 0.05), 0.25, (*SLOTS[item_at], None), ITEM_COLOUR)]


def item_centre(xy: tuple[float, float], half_height: float, counter_height: float) -> tuple[float, float, float]:
    """The centre [m] of an item of `half_height` [m] standing on the counter at `xy`."""
    return (xy[0], xy[1], counter_height + half_height)


class KitchenFacts(ResolverSet):
    """Location generators for the places of the simulated kitchen (a world, not a robot)."""

    def __init__(self, item_half_height: float, counter_height: float, start_pose: Any) -> None:
        super().__init__("kitchen")
        self.item_half_height = item_half_height
        self.counter_height = counter_height
        self.start_pose = start_pose
        self.location_generators.append(self.places)

    def places(self, designator: Any) -> list | None:
        """Resolve named places; None for designators this kitchen does not know about."""
        if designator.check_constraints([("named", "start")]):
            return [self.start_pose]
        if designator.check_constraints([("on", "cooker #2"), "slot"]):
            slot = designator.prop_value("slot")
            if slot not in SLOTS:
                raise ValueError(f"cooker #2 has slots {sorted(SLOTS)}, not {slot!r}")
            return [item_centre(SLOTS[slot], self.item_half_height, self.counter_height)]
        if designator.check_constraints([("on", "cooker #1")]):
            return [item_centre(PLACE_XY, self.item_half_height, self.counter_height)]
        return None


@dataclass
class Helper:
    """The person near the robot: remembers what was taken so it can be given back."""

    world: Any
    interactive: bool = False
    delay: float = 1.5  # [s] of simulated time before the simulated person reacts
    taken: list[str] = field(default_factory=list)
    prompt: Callable[[str], str] = input


class Operator(ProcessModule):
    """Serves `('type', 'waiting_for_help'), ('request', text), ('gripper', g)`.

    A person puts the last taken item back between the open fingers of the gripper and holds it
    there until the robot closes its gripper on it (thesis: "Put the item into the right gripper
    and hit [Enter]", then the plan closes the gripper). Simulated: the person reacts after
    `delay` seconds of simulated time. Interactive: the user is asked at the terminal and the
    item is handed over once they press Enter -- the simulated world has no hands of its own.
    Returns once the item is held out in the gripper; the robot has `HOLD_TIME` [s] to close.
    """

    #: How long the person holds the item between the fingers, waiting for them to close [s].
    HOLD_TIME = 5.0
    #: The person's hand needs this long [s] to bring the item between the fingers.
    REACH_TIME = 0.3

    def __init__(self, helper: Helper, gripper_name: Callable[[str], str]) -> None:
        super().__init__("operator")
        self.helper = helper
        self.gripper_name = gripper_name

    def _execute(self, designator: Any) -> None:
        request = designator.prop_value("request") or "Please help"
        gripper = self.gripper_name(designator.prop_value("gripper") or "right")
        helper = self.helper
        if helper.interactive:
            answered = Fluent()
            reader = threading.Thread(
                target=lambda: answered.set_value(helper.prompt(f"{request} and press [Enter] to continue. ")),
                daemon=True,
            )
            reader.start()
            answered.wait_for()
        else:
            log.info("a helper will put the item back in %.1f s", helper.delay)
            sleep(helper.delay)
        item = helper.taken[-1] if helper.taken else ITEM_NAME
        handle = helper.world.give_item(item, gripper, close=False, timeout=self.HOLD_TIME)
        outcome = handle.wait(self.REACH_TIME)
        if outcome is not None and not outcome.succeeded:
            raise RuntimeError(f"could not put the {item} back into the {gripper} gripper: {outcome.message}")
        log.info("the %s is held out in the %s gripper", item, gripper)


def operator_resolver(operator: Operator) -> Callable[[Any], ProcessModule | None]:
    def resolve(designator: Any) -> ProcessModule | None:
        if designator.check_constraints([("type", "waiting_for_help")]):
            return operator
        return None

    return resolve


class Thief:
    """Takes the item out of the gripper `count` times while the robot carries it.

    Each theft happens at a random moment (0.3–1.0 s of simulated time) after the robot starts
    moving with the item during the "transporting" phase, and only while it is still more than
    0.6 m from its goal — so every theft interrupts a drive. Runs in a daemon thread; `stop()`
    ends it.
    """

    def __init__(
        self, world: Any, helper: Helper, phase: Fluent, goal: Fluent, gripper: str, count: int, rng: random.Random
    ) -> None:
        self.world, self.helper, self.phase, self.goal = world, helper, phase, goal
        self.gripper, self.count, self.rng = gripper, count, rng
        self.stolen = 0
        self._stop = Fluent(name="thief.stop")
        self._thread = PlanThread(target=self._run, name="pycram-demo-thief", daemon=True)

    def start(self) -> None:
        if self.count > 0:
            self._thread.start()

    def stop(self) -> None:
        self._stop.set_value(True)
        if self._thread.is_alive():
            self._thread.join(5.0)

    def _carrying_far_from_goal(self) -> bool:
        if self._stop.get_value() or self.phase.get_value() != "transporting":
            return False
        state = self.world.gripper_states[self.gripper].get_value()
        here, there = self.world.base_pose.get_value(), self.goal.get_value()
        if state.holding is None or there is None:
            return False
        return ((there.x - here.x) ** 2 + (there.y - here.y) ** 2) ** 0.5 > 0.6

    def _run(self) -> None:
        watched = (self.world.base_pose, self.world.gripper_states[self.gripper], self.phase, self._stop)
        chance = Fluent(lambda: True if self._stop.get_value() or self._carrying_far_from_goal() else None)
        for fluent in watched:  # a fluent network over the world's sensor fluents
            fluent.add_child(chance)
        while self.stolen < self.count:
            chance.wait_for()
            if self._stop.get_value():
                return
            sleep(self.rng.uniform(0.3, 1.0))
            if not self._carrying_far_from_goal():
                continue
            outcome = self.world.take_item(gripper=self.gripper).wait(5.0)
            if outcome is not None and outcome.succeeded and outcome.value:
                self.stolen += 1
                self.helper.taken.append(outcome.value)
                log.warning("someone took the %s from the gripper (%d/%d)", outcome.value, self.stolen, self.count)
