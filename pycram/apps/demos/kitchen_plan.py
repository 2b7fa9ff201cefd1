"""The thesis demo plan (ch. 4.2.3, fig. 4.1): fetch an item at cooker #2, place it on cooker #1.

Written in the thesis' block syntax, robot-agnostic: the plan talks to the world only through
designators, process modules and fluents. Which arm moves, how far the base stands from the
counter, what "park" means in joint angles — all of that lives in the active robot's resolvers
and process modules, so this file runs unchanged on the two-armed PR2 and the one-armed TIAGo.

Structure (as in the thesis):

* `reset_robot()`: a `par` of both grippers, both arms and the torso, then drive to the start.
* a `par` of (a) `whenever(pose.pulsed())` pointing the head at the current look goal, and (b)
  a `seq` of the task: a `try_in_order` over three positions in front of cooker #2 (each an
  `if True:` group that sets the goal and calls `grab_item()`), a clear failure when no grasp
  succeeded, the transport under `failure_handling` (recovering when the item is taken from the
  gripper: the robot asks for help with the head tracking suspended, `with_task_suspended`),
  and `place_item()` on cooker #1.

Where the thesis polled (`while True: ... rospy.sleep(0.1)`), this plan waits on fluent
networks: `within(0.1).wait_for()` wakes exactly when the robot gets close.
"""

from __future__ import annotations

import logging
import math
from typing import Any

# The thesis demo is written as a user writes a plan: through the public faces.
from pycram.designator import LocationDesignator, MotionDesignator, perform
from pycram.fluent import Fluent, whenever
from pycram.language import State, failure_handling, par, plan, retry, seq, try_in_order, with_task_suspended
from pycram.runtime import as_task, current_task, sleep

log = logging.getLogger("pycram.demo")

#: The thesis used the right arm and gripper; a one-armed robot serves them with its only arm.
ARM = "right"
GRIPPER = "right"
#: The gripper is considered empty below this opening [m] (thesis: `r_gripper_state < 0.01`).
EMPTY_GRIPPER = 0.01
#: Start grasping when the base is this close to its goal [m] (thesis: 10 cm).
CLOSE_ENOUGH = 0.1
#: The item the demo fetches, by the name the world knows it by (its spot on cooker #1 must fit it).
ITEM = "mug"


class GraspFailed(Exception):
    """The gripper closed on nothing."""


class NoItemGrasped(Exception):
    """No grasp succeeded at any of the positions in front of cooker #2."""


class ItemLost(Exception):
    """The item was taken from the gripper during the transport."""


class ResetFailed(Exception):
    """The robot could not be brought into its start configuration."""


# -- the robot's state, as fluents (the thesis subscribed to ROS topics) -------------------------

pose = Fluent(name="pose")  # base pose (x, y, yaw) in the map frame
r_gripper_state = Fluent(name="r_gripper_state")  # opening of the gripper [m]
goal = Fluent(name="goal")  # where the base goes next
look_goal = Fluent(name="look_goal")  # the point the head keeps looking at
phase = Fluent("initialising", name="phase")  # for people watching the run
head_tracking = Fluent(name="head tracking")  # the task pointing the head at `look_goal`
head_suspensions = Fluent(0, name="head suspensions")  # times it was suspended to ask for help

item_lost = r_gripper_state < EMPTY_GRIPPER


def forget_state() -> None:
    """Clear goals and phase before a new run in the same process."""
    for fluent in (goal, look_goal, head_tracking):
        fluent.set_value(None)
    phase.set_value("initialising")
    head_suspensions.set_value(0)


def within(tolerance: float) -> Fluent:
    """A fluent network valued True while the base is within `tolerance` [m] of `goal`."""

    def near() -> bool | None:
        here, there = pose.get_value(), goal.get_value()
        if here is None or there is None:
            return None
        return True if math.hypot(there.x - here.x, there.y - here.y) < tolerance else None

    network = Fluent(near)
    pose.add_child(network)
    goal.add_child(network)
    return network


def motion(**properties) -> Any:
    """Perform a motion designator described by `properties`; return the module's result."""
    return perform(MotionDesignator(**properties))


def location(*properties: tuple) -> Any:
    """Resolve a location designator (robot- or world-specific resolvers decide)."""
    return LocationDesignator(list(properties)).reference()


# -- helpers, as in the thesis ----------------------------------------------------------------------


@as_task
@plan
def reset_robot() -> None:
    """Grippers open, arms parked, torso up — concurrently; then drive to the start pose."""
    phase.set_value("resetting")
    with par as state:
        motion(type="setting_gripper", gripper="left", position=1)
        motion(type="setting_gripper", gripper="right", position=1)
        motion(type="setting_arm_configuration", arm="left", configuration="park")
        motion(type="setting_arm_configuration", arm="right", configuration="park")
        motion(type="setting_torso", position="up")
    if state.get_value() is State.FAILED:
        raise ResetFailed("could not bring the robot into its start configuration")
    goal.set_value(location(("named", "start")))
    motion(type="moving", pose=goal.get_value(), frame="map")


@as_task
@plan
def grab_item() -> None:
    """Drive to `goal` and, once within 10 cm, grasp what lies at `look_goal` (thesis `grab_item`).

    Raises `GraspFailed` when the gripper closed on nothing.
    """
    target = look_goal.get_value()
    errors: list[BaseException] = []
    with par(errors) as state:
        motion(type="moving", pose=goal.get_value(), frame="map")
        if True:
            within(CLOSE_ENOUGH).wait_for()
            motion(type="setting_gripper", gripper=GRIPPER, position=1)
            motion(type="setting_arm_configuration", arm=ARM, configuration="carry")
    if state.get_value() is State.FAILED:
        raise GraspFailed(f"could not get into position: {errors[0]}")
    with seq(errors) as grasped:
        motion(type="reaching", arm=ARM, target=target, phase="pre_grasp")
        motion(type="reaching", arm=ARM, target=target, phase="grasp")
        motion(type="setting_gripper", gripper=GRIPPER, position=0)
    if grasped.get_value() is State.FAILED or r_gripper_state.get_value() < EMPTY_GRIPPER:
        motion(type="setting_gripper", gripper=GRIPPER, position=1)
        motion(type="reaching", arm=ARM, target=target, phase="retreat")
        motion(type="setting_arm_configuration", arm=ARM, configuration="carry")
        reason = errors[-1] if errors else "the gripper closed on nothing"
        raise GraspFailed(f"no item at {_point(target)}: {reason}")
    motion(type="reaching", arm=ARM, target=target, phase="lift")
    motion(type="setting_arm_configuration", arm=ARM, configuration="carry")
    log.info("grasped the item at %s", _point(target))


@as_task
@plan
def place_item() -> None:
    """Put the held item down at `look_goal` and take the arm back (thesis `place_item`)."""
    target = look_goal.get_value()
    motion(type="reaching", arm=ARM, target=target, phase="pre_place")
    motion(type="reaching", arm=ARM, target=target, phase="place")
    motion(type="setting_gripper", gripper=GRIPPER, position=1)
    motion(type="reaching", arm=ARM, target=target, phase="retreat")
    motion(type="setting_arm_configuration", arm=ARM, configuration="carry")
    log.info("placed the item at %s", _point(target))


def _point(p) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"


def aim_at(place: tuple) -> None:
    """Set the base goal to a pose from which the arm reaches `place`, and look at `place`."""
    look_goal.set_value(place)
    goal.set_value(location(("to_reach", place), ("arm", ARM)))


# -- the demo --------------------------------------------------------------------------------------------


@plan
def fetch_and_place() -> None:
    """The whole demo (thesis ch. 4.2.3). Raises what stopped the task when it failed."""
    log.info("initialising the demo")
    motion(type="subscribing_pose", fl=pose)
    motion(type="subscribing_gripper", gripper=GRIPPER, fl=r_gripper_state)
    reset_robot()
    errors: list[BaseException] = []
    with par(errors) as s:
        with whenever(pose.pulsed()):
            if head_tracking.get_value() is None:
                head_tracking.set_value(current_task())  # so that asking for help can suspend it
            if phase.get_value() == "done":
                return  # the task succeeded: leave the loop, so that the par can end
            if look_goal.get_value() is not None:
                motion(type="pointing_head", coordinates=look_goal.get_value(), wait=False, frame="map")
            sleep(0.2)
        if True:
            task_errors = []  # type: list[BaseException]  # (a branch's names cannot be annotated)
            with seq(task_errors) as task:
                if True:
                    phase.set_value("fetching")
                    grasp_errors = []  # type: list[BaseException]
                    with try_in_order(grasp_errors) as state:
                        if True:
                            log.info("trying to grasp at position 1 in front of cooker #2")
                            aim_at(location(("on", "cooker #2"), ("slot", 1)))
                            grab_item()
                        if True:
                            log.info("trying to grasp at position 2 in front of cooker #2")
                            aim_at(location(("on", "cooker #2"), ("slot", 2)))
                            grab_item()
                        if True:
                            log.info("trying to grasp at position 3 in front of cooker #2")
                            aim_at(location(("on", "cooker #2"), ("slot", 3)))
                            grab_item()
                    if state.get_value() is State.FAILED:
                        raise NoItemGrasped(
                            "could not grasp an item at any of the 3 positions in front of cooker #2: "
                            + "; ".join(str(e) for e in grasp_errors)
                        )
                if True:
                    phase.set_value("transporting")
                    aim_at(location(("on", "cooker #1"), ("for", ITEM)))
                    transport()
                if True:
                    phase.set_value("placing")
                    place_item()
                    phase.set_value("done")
            if task.get_value() is State.FAILED:
                raise task_errors[0]  # fail the par, which evaporates the head tracking
    if s.get_value() is State.FAILED:
        phase.set_value("failed")
        raise errors[0]  # what stopped the task, e.g. NoItemGrasped


def ask_for_help(request: str) -> None:
    """Ask a person for help and wait until it came, with the head tracking suspended meanwhile
    (CRAM's `with-task-suspended`): the head stops following the look goal while the robot
    faces the person, and goes on after the wake-up."""
    tracker = head_tracking.get_value()
    if tracker is None or tracker.done:
        motion(type="waiting_for_help", request=request, gripper=GRIPPER)
        return
    with with_task_suspended(tracker, timeout=5.0):
        head_suspensions.set_value(head_suspensions.get_value() + 1)
        log.info("head tracking suspended while asking for help")
        motion(type="waiting_for_help", request=request, gripper=GRIPPER)


def get_the_item_back() -> None:
    """The item was taken from the gripper: stop, ask for it back, close the gripper on it, and
    raise `ItemLost` (for `transport` to retry)."""
    log.warning("the item was taken from the gripper: stopping")
    motion(type="cancelling_movement")
    motion(type="setting_gripper", gripper=GRIPPER, position=1)
    ask_for_help("Put the item back into the gripper")
    motion(type="setting_gripper", gripper=GRIPPER, position=0)
    raise ItemLost("the item was taken from the gripper")


@as_task
@plan
def transport() -> None:
    """Drive to `goal` holding the item; whenever it is taken away, stop, get it back, retry."""
    with failure_handling():
        try:
            drive = None
            if r_gripper_state.get_value() > EMPTY_GRIPPER:
                drive = motion(type="moving", pose=goal.get_value(), wait=False, frame="map")
            arrived = within(CLOSE_ENOUGH)
            item_lost.OR(arrived).wait_for()
            if item_lost.get_value():
                get_the_item_back()
            assert drive is not None  # started above: the gripper held the item, or it was lost
            drive.wait()  # the last 10 cm
            if item_lost.get_value():  # taken on the last stretch (or its news came late, over ROS)
                get_the_item_back()
        except ItemLost:
            retry()
