"""Opening and closing drawers and the fridge door (issue 16) and searching closed containers
(issue 15), judged with the simulator's truth: the drawer's slide or the door's hinge really
moved, the object really was inside."""

from __future__ import annotations

import contextlib
import math
import threading

import pytest
from action_helpers import TABLE, apartment_with, holding, run_as_task, tasks_named
from sim_helpers import ok

from pycram.actions import ActionParameterError, Close, MoveTorso, Open, ParkArms, PickUp, Search
from pycram.designator import MotionDesignator, ObjectDesignator, perform
from pycram.failures import ContainerStuck
from pycram.fluent import Fluent
from pycram.process_module import ProcessModuleFailure

ROBOTS = ("pr2", "tiago")


def opening_of(world, name: str) -> float:
    return world.container_states.get_value()[name]


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_a_drawer_is_opened_and_closed_by_pulling_and_pushing_its_handle(robot_name):
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        measured = perform(Open("drawer 3"))
        assert opening_of(world, "drawer 3") >= 0.15
        assert abs(measured - opening_of(world, "drawer 3")) < 0.01  # perceived, not assumed
        perform(Close("drawer 3"))
        assert opening_of(world, "drawer 3") < 0.03


def test_a_stuck_drawer_raises_container_stuck_after_every_standing_pose():
    with apartment_with("pr2", {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        ok(world.set_container_stuck("drawer 3"))
        with pytest.raises(ContainerStuck, match="drawer 3") as caught:
            run_as_task(lambda: perform(Open("drawer 3")))
        error = caught.value
        assert error.container == "drawer 3" and len(error.attempts) >= 2
        assert opening_of(world, "drawer 3") < 0.02


def test_the_pr2_opens_and_closes_the_fridge_door_by_its_handle_along_its_arc():
    with apartment_with("pr2", {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        measured = perform(Open("fridge"))
        assert opening_of(world, "fridge") >= math.radians(60)  # the hinge: enough to look and reach in
        assert abs(measured - opening_of(world, "fridge")) < math.radians(1)  # perceived, not assumed
        assert abs(robot.belief.container_states["fridge"] - opening_of(world, "fridge")) < math.radians(1)
        assert not holding(world)
        measured = perform(Close("fridge"))
        assert opening_of(world, "fridge") < math.radians(4)
        assert abs(measured - opening_of(world, "fridge")) < math.radians(1)
        assert robot.belief.container_states["fridge"] < math.radians(4)


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_a_stuck_fridge_door_raises_container_stuck(robot_name):
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        ok(world.set_container_stuck("fridge"))
        with pytest.raises(ContainerStuck, match="fridge") as caught:
            run_as_task(lambda: perform(Open("fridge")))
        assert caught.value.container == "fridge" and caught.value.attempts
        assert opening_of(world, "fridge") < math.radians(3)


def test_the_tiago_pulls_the_fridge_door_by_its_handle_pushes_it_open_from_inside_and_shut_from_outside():
    with apartment_with("tiago", {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        measured, task = run_as_task(lambda: perform(Open("fridge")))
        assert opening_of(world, "fridge") >= math.radians(60)  # enough to look and reach in
        assert abs(measured - opening_of(world, "fridge")) < math.radians(1)  # perceived, not assumed
        assert not holding(world)
        attempts = [str(t.name) for t in tasks_named(task, "opening fridge")]
        pulled = [n for n in attempts if "arm" in n]
        pushed = [n for n in attempts if "pushing" in n]
        assert pulled and pushed and attempts.index(pulled[0]) < attempts.index(pushed[0]), attempts
        # the torso left down (as a low drawer leaves it): pushing raises it, or the arm's way to
        # the second push stage crosses the door and knocks it open again
        perform(MoveTorso("down"))
        measured = perform(Close("fridge"))
        assert opening_of(world, "fridge") < math.radians(4)
        assert abs(measured - opening_of(world, "fridge")) < math.radians(1)
        assert robot.belief.container_states["fridge"] < math.radians(4)
        with pytest.raises(ActionParameterError, match=r"no container 'drawer 9'.*valid: drawer 1"):
            perform(Open("drawer 9"))


class StuckOnceOpen:
    """A door that sticks as soon as it is open more than `angle` [rad] (waits on the world's
    container fluent, in a thread of its own): an opening that fails half way."""

    def __init__(self, world, name: str, angle: float) -> None:
        self.world, self.name = world, name
        self.opened = Fluent(lambda: True if world.container_states.get_value()[name] > angle else None)
        world.container_states.add_child(self.opened)
        self.stuck = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True, name=f"{name} sticking")
        self._thread.start()

    def _run(self) -> None:
        if self.opened.wait_for(600.0):
            self.world.set_container_stuck(self.name).wait(10.0)
            self.stuck.set()


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_a_door_that_stuck_half_way_open_is_closed_from_a_new_standing_pose(robot_name):
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        sticking = StuckOnceOpen(world, "fridge", math.radians(30))
        with pytest.raises(ContainerStuck, match="fridge"):
            run_as_task(lambda: perform(Open("fridge")))
        assert sticking.stuck.is_set()
        left = opening_of(world, "fridge")
        assert math.radians(25) < left < math.radians(50)  # the failed opening left it part open
        ok(world.set_container_stuck("fridge", False))
        measured, task = run_as_task(lambda: perform(Close("fridge")))
        assert opening_of(world, "fridge") < math.radians(4)
        assert abs(measured - opening_of(world, "fridge")) < math.radians(1)
        assert any("pushing" in str(t.name) for t in tasks_named(task, "closing fridge"))


def test_search_opens_a_closed_drawer_and_finds_the_cup_inside():
    with apartment_with("pr2", {"cup": ("drawer 2 inside", (0.3, 2.9))}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        assert opening_of(world, "drawer 2") < 0.01
        found, task = run_as_task(lambda: perform(Search(ObjectDesignator(type="cup"))))
        assert found.type == "cup" and found.properties["in"] == "drawer 2"
        truth = world.item_poses.get_value()["cup"].position
        assert math.dist(found.pose[:2], truth[:2]) < 0.05
        assert opening_of(world, "drawer 2") >= 0.15
        openings = tasks_named(task, "perform opening")  # drawers on the way may be opened too
        assert openings and all(t.status.get_value().value == "succeeded" for t in openings)


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_search_opens_the_closed_fridge_and_finds_the_milk_inside(robot_name):
    with apartment_with(robot_name, {"milk": ("fridge middle shelf", (3.05, 4.6))}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        assert opening_of(world, "fridge") < 0.01
        found, task = run_as_task(lambda: perform(Search(ObjectDesignator(type="milk"))))
        assert found.type == "milk" and found.properties["in"] == "fridge"
        truth = world.item_poses.get_value()["milk"].position
        assert math.dist(found.pose[:2], truth[:2]) < 0.05
        assert opening_of(world, "fridge") >= math.radians(60)
        openings = tasks_named(task, "perform opening")
        assert openings and all(t.status.get_value().value == "succeeded" for t in openings)


#: Every container of the apartment, in the order one robot opens and closes them in one world.
CONTAINERS = ("drawer 1", "drawer 2", "drawer 3", "fridge", "cupboard")


@pytest.fixture(scope="module", params=ROBOTS)
def apartment(request):
    """One apartment per robot, shared by the open-and-close tests of every container (each
    leaves its container closed)."""
    with apartment_with(request.param, {"cup": TABLE}) as (world, robot):
        yield request.param, world, robot


@pytest.mark.parametrize("name", CONTAINERS)
def test_each_container_is_opened_and_closed_again(apartment, name):
    robot_name, world, robot = apartment
    # each from the ready pose: the TIAGo opening the fridge with its torso down from the start
    # leaves door and robot where closing finds no path to a push pose (see docs/actions.md)
    perform(ParkArms())
    perform(MoveTorso("up"))

    drawer = world.environment.container(name).kind == "drawer"
    opened, closed = (0.15, 0.03) if drawer else (math.radians(60), math.radians(4))
    assert opening_of(world, name) < closed, f"{name} was left open by an earlier test"
    measured = perform(Open(name))
    assert opening_of(world, name) >= opened, f"{robot_name}: {name} opened only {opening_of(world, name):.3f}"
    assert abs(measured - opening_of(world, name)) < (0.01 if drawer else math.radians(1))  # perceived
    assert not holding(world)
    measured = perform(Close(name))
    assert opening_of(world, name) < closed, f"{robot_name}: {name} still open {opening_of(world, name):.3f}"
    assert measured < closed


@pytest.mark.parametrize("robot_name", ["tiago"])
def test_a_drawer_far_out_is_pushed_home_in_stages(robot_name):
    # far out, no standing pose both keeps clear of the drawer and reaches its handle all the way
    # home (the set-table search opened drawer 2 this far to see a cup under the furniture)
    with apartment_with(robot_name, {"cup": TABLE}) as (world, robot):
        perform(Open("drawer 2"))
        ok(world.push_container("drawer 2", (30.0, 0.0, 0.0), 0.5))  # a person pulls it further out
        far = opening_of(world, "drawer 2")
        assert far >= 0.33
        drawer = world.environment.container("drawer 2")
        with contextlib.suppress(ProcessModuleFailure):  # standing close: it points as near as it can
            perform(MotionDesignator(type="pointing_head", coordinates=list(drawer.handle_position(far))))
        perform(MotionDesignator(type="detecting"))
        assert abs(robot.belief.container_states["drawer 2"] - far) < 0.01  # seen
        measured, task = run_as_task(lambda: perform(Close("drawer 2")))
        assert opening_of(world, "drawer 2") < 0.03 and measured < 0.03
        # in stages when no standing pose reaches all the way home; since the TIAGo's approach and
        # retreat motions are planned (issue 32), one push from one pose reaches it here
        assert len(tasks_named(task, "closing drawer 2")) >= 1


def test_an_object_seen_in_the_cupboard_that_was_closed_since_is_picked_up_after_opening_it_again():
    """The cup was seen on the cupboard's shelf, then the cupboard was closed (a search closes
    each container before the next): picking it up opens the door again first."""
    with apartment_with("pr2", {"cup": ("cupboard shelf", (4.2, 4.62))}, base_pose=(4.1, 3.4, math.pi / 2)) as (
        world,
        robot,
    ):
        perform(ParkArms())
        perform(MoveTorso("up"))
        found = perform(Search(ObjectDesignator(type="cup")))
        assert found.properties["in"] == "cupboard"
        perform(Close("cupboard"))
        assert opening_of(world, "cupboard") < math.radians(4)
        held, task = run_as_task(lambda: perform(PickUp(found)))
        assert holding(world) == {"cup"} and held.object is found
        assert opening_of(world, "cupboard") >= math.radians(60)
        assert tasks_named(task, "perform opening")


def test_a_look_into_a_door_container_it_opened_is_made_from_the_places_standing_pose():
    """Opening the cupboard leaves the TIAGo Pro where it held the handle, beside the door it
    swung open, which hides the shelf from there; with its empty left arm still raised to carry,
    the place's own standing pose does not fit beside the open door. The search parks the empty
    arm, stands there again and sees the cup (set-table, TIAGo Pro, dev seeds 11 and 12: the cup
    in the cupboard was never seen)."""
    from pycram.actions.containers import opening_one_at_a_time
    from pycram.actions.search import _visit, lookouts

    with apartment_with("tiago-pro", {"cup": ("cupboard shelf", (4.15, 4.65))}, base_pose=(4.35, 3.4, math.pi / 2)) as (
        world,
        robot,
    ):
        perform(ParkArms())
        perform(MoveTorso("up"))
        perform(MotionDesignator(type="setting_arm_configuration", arm="left", configuration="carry"))
        environment = robot.belief.environment
        (shelf,) = [place for place in lookouts(environment, "cup", (4.35, 3.4)) if place.container == "cupboard"]
        looked, skipped = [], {}
        description = ObjectDesignator(type="cup")
        found, task = run_as_task(
            lambda: _visit(description, shelf, environment, robot.belief, opening_one_at_a_time(), looked, skipped)
        )
        assert found is not None and found.type == "cup", (looked, skipped)
        assert opening_of(world, "cupboard") >= math.radians(45)
        base = world.base_pose.get_value()
        assert math.dist((base.x, base.y), shelf.stand[:2]) < 0.05  # looked from the place's own pose


def test_a_drawer_pulled_out_beside_the_one_closed_is_seen_and_closed_too():
    """Closing a drawer looks at its neighbours' handles: one pulled out meanwhile (by a person
    here; by the TIAGo's arm going up from drawer 1 in the faulted set-table runs) is believed
    open and `close_opened_containers` closes it as well."""
    from pycram.apps.scenarios.set_table.plan import close_opened_containers

    with apartment_with("tiago", {"cup": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        perform(Open("drawer 1"))
        assert robot.belief.container_states.get("drawer 3", 0.0) < 0.03  # closed, as far as it knows
        ok(world.push_container("drawer 3", (25.0, 0.0, 0.0), 0.3))  # a person pulls it out a little
        pulled = opening_of(world, "drawer 3")
        assert 0.04 < pulled < 0.25, pulled
        assert robot.belief.container_states.get("drawer 3", 0.0) < 0.03  # not seen
        closed = close_opened_containers()
        assert closed == ["drawer 1", "drawer 3"]
        assert opening_of(world, "drawer 1") < 0.03 and opening_of(world, "drawer 3") < 0.03


def test_a_transport_into_the_closed_cupboard_opens_it_first():
    """The target lies inside a container the robot does not believe open: the transport opens it
    first, with its one hand still free (the TIAGo), and puts the mug on the cupboard's shelf."""
    from action_helpers import rests_upright_at

    from pycram.actions import Transport
    from pycram.designator import LocationDesignator

    with apartment_with("tiago", {"mug": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        assert opening_of(world, "cupboard") < math.radians(4)
        target = LocationDesignator([("in", "cupboard"), ("for", "mug")])
        obj, task = run_as_task(lambda: perform(Transport(ObjectDesignator(type="mug"), target)))
        assert tasks_named(task, "opening cupboard")  # opened by the transport itself
        assert rests_upright_at(world, "mug", "cupboard shelf", obj.pose[:2])
        assert holding(world) == set()


class StuckForOnePull:
    """A drawer that sticks as soon as it is out more than `at` [m] (the hand pulling it stops
    there) and comes free when the hand lets go of its handle (the `gripper` opens wide again):
    a first pull that ends short (waits on the world's fluents, in a thread of its own)."""

    def __init__(self, world, name: str, at: float, gripper: str, wide: float = 0.07) -> None:
        self.world, self.name = world, name
        self.out = Fluent(lambda: True if world.container_states.get_value()[name] > at else None)
        world.container_states.add_child(self.out)
        grip = world.gripper_states[gripper]
        self.let_go = Fluent(lambda: True if grip.get_value().opening > wide else None)
        grip.add_child(self.let_go)
        self.stuck_at: float | None = None
        self.freed = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True, name=f"{name} sticking once")
        self._thread.start()

    def _run(self) -> None:
        if not self.out.wait_for(600.0):
            return
        self.world.set_container_stuck(self.name).wait(10.0)
        self.stuck_at = self.world.container_states.get_value()[self.name]
        if self.let_go.wait_for(600.0):
            self.world.set_container_stuck(self.name, False).wait(10.0)
            self.freed.set()


def test_a_transport_into_a_drawer_pulls_it_out_far_enough_for_the_object():
    """Drawer 2 sticks for the TIAGo's first pull 18 cm out -- open, as `Open` counts it, yet no
    room out from under the furniture for a 16 cm spoon: the transport pulls it out further
    before it fetches the spoon (seen in the actions benchmark, seed 32003, where the arm's way
    up from the handle, planned with the drawer still believed closed, shoved it back to 18 cm)."""
    from pycram.actions import Transport
    from pycram.designator import LocationDesignator
    from pycram.world.objects import object_type

    with apartment_with("tiago", {"spoon": TABLE}) as (world, robot):
        perform(ParkArms())
        perform(MoveTorso("up"))
        sticking = StuckForOnePull(world, "drawer 2", 0.18, "right")
        target = LocationDesignator([("in", "drawer 2"), ("for", "spoon")])
        obj, task = run_as_task(lambda: perform(Transport(ObjectDesignator(type="spoon"), target)))
        assert sticking.freed.is_set() and sticking.stuck_at is not None and sticking.stuck_at < 0.22
        assert len(tasks_named(task, "opening drawer 2")) == 2, "one pull, then one further"
        assert opening_of(world, "drawer 2") > 0.3
        # in the drawer as it is pulled out: on its bottom's height, where it was believed put down
        pose = world.item_poses.get_value()["spoon"]
        bottom = world.environment.surface("drawer 2 inside").height
        assert abs(pose.position[2] - object_type("spoon").half_height - bottom) < 0.03, pose
        assert math.dist(pose.position[:2], obj.pose[:2]) < 0.05
        assert obj.properties.get("in") == "drawer 2"
        assert holding(world) == set()
