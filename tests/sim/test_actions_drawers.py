"""Picking objects out of drawers and transporting them from a closed drawer to the table (issue
16), on both robots in the apartment, judged with the simulator's truth.

A drawer's walls rise above the side grasps of what lies in it: cups and mugs are taken from the
top by their body, bowls by the rim; the robot stands in front of the pulled-out drawer with its
torso lowered where the reasoning found that it must. Objects lie at (0.4, 2.9) in the closed
drawer's frame: 20 cm behind its front panel, mid-width.
"""

from __future__ import annotations

import math

import pytest
from action_helpers import apartment_with, holding, rests_upright_at, run_as_task, tasks_named

from pycram.actions import MoveTorso, Open, ParkArms, PickUp, Place, Transport
from pycram.designator import ObjectDesignator, perform
from pycram.failures import ObjectOutOfReach

#: Where the objects lie: in the closed drawer's frame (x, y) [m] (see the module docstring).
IN_DRAWER = (0.4, 2.9)


def opening_of(world, name: str) -> float:
    return world.container_states.get_value()[name]


def ready() -> None:
    perform(ParkArms())
    perform(MoveTorso("up"))


def in_drawer(number: int) -> tuple[str, tuple[float, float]]:
    return (f"drawer {number} inside", IN_DRAWER)


@pytest.mark.parametrize(
    ("robot_name", "type_name", "drawer", "arm"),
    [
        ("pr2", "cup", 2, None),
        ("pr2", "cup", 3, "left"),
        ("pr2", "mug", 2, None),
        ("tiago", "cup", 2, None),
        ("tiago", "cup", 3, None),
        ("tiago", "mug", 2, None),
    ],
)
def test_a_cup_or_mug_is_picked_from_the_top_out_of_an_opened_drawer_and_placed_upright(
    robot_name, type_name, drawer, arm
):
    name = f"drawer {drawer}"
    with apartment_with(robot_name, {type_name: in_drawer(drawer)}) as (world, robot):
        ready()
        perform(Open(name))  # 0.3 m: the object is still under the drawer above
        held = perform(PickUp(ObjectDesignator(type=type_name), arm=arm))
        assert held.grasp.approach == "top" and holding(world) == {type_name}
        assert arm is None or held.arm == arm
        rim = world.environment.container(name).rim_height
        assert world.item_poses.get_value()[type_name].position[2] > rim  # out of the drawer
        assert opening_of(world, name) > 0.3  # pulled out further: the object came out from under
        obj = perform(Place(held, "table"))
        assert rests_upright_at(world, type_name, "table", obj.pose[:2])


@pytest.mark.parametrize("robot_name", ["pr2"])
def test_a_bowl_is_picked_by_its_rim_out_of_an_opened_drawer(robot_name):
    with apartment_with(robot_name, {"bowl": in_drawer(2)}) as (world, robot):
        ready()
        perform(Open("drawer 2"))
        held = perform(PickUp(ObjectDesignator(type="bowl")))
        assert held.grasp.approach == "top" and holding(world) == {"bowl"}
        assert world.item_poses.get_value()["bowl"].position[2] > world.environment.container("drawer 2").rim_height


@pytest.mark.parametrize(("robot_name", "close"), [("pr2", True), ("tiago", False)])
def test_transport_from_a_closed_drawer_to_the_table(robot_name, close):
    # The PR2 closes the drawer with its free arm right after the pick. Not asked of the TIAGo:
    # it closes the drawer once the cup is placed, and missed the handle (HandleMissed) in 2 of 7
    # runs; see docs/actions.md.
    with apartment_with(robot_name, {"cup": in_drawer(2)}) as (world, robot):
        ready()
        assert opening_of(world, "drawer 2") < 0.01
        obj, task = run_as_task(
            lambda: perform(Transport(ObjectDesignator(type="cup"), "table", close_container=close))
        )
        assert rests_upright_at(world, "cup", "table", obj.pose[:2])
        assert holding(world) == set()
        assert any("opening drawer 2" in str(t.name) for t in task.walk())  # the search opened it
        closings = tasks_named(task, "perform closing")
        if close:
            assert closings and closings[-1].status.get_value().value == "succeeded"
            assert opening_of(world, "drawer 2") < 0.03  # closed again
        else:
            # closed only by the search: a drawer it looked into first and found empty
            assert all("/search_for/" in repr(t) for t in closings), closings
            assert opening_of(world, "drawer 2") > 0.15


def test_an_object_without_a_grasp_over_the_walls_is_out_of_reach_and_says_why():
    with apartment_with("pr2", {"milk": in_drawer(3)}) as (world, robot):
        ready()
        perform(Open("drawer 3", opening=0.4))
        with pytest.raises(ObjectOutOfReach, match=r"walls rise to 0\.86 m") as caught:
            perform(PickUp(ObjectDesignator(type="milk")))
        assert caught.value.designator is not None
        assert holding(world) == set()
        assert math.isclose(world.environment.container("drawer 3").rim_height, 0.86)
