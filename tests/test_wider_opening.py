"""Picking up behind a door: how far `PickUp` opens a container whose inside it cannot reach into
(`_wider_opening`), and how it takes a lifted object out (`_withdraw`)."""

import math

import pytest

from pycram.actions.container_state import DOOR_USEFUL
from pycram.actions.containers import DOOR_OPENING
from pycram.actions.pick_up import DOOR_WIDE, _wider_opening
from pycram.environments import load
from pycram.execution.robot import Robot
from pycram.world.belief import BeliefState, PerceivedObject

APARTMENT = load("apartment")


def _bowl_in_the_fridge(fridge_opening: float) -> tuple[Robot, PerceivedObject]:
    robot = Robot("believer")
    robot.belief = BeliefState(APARTMENT)  # type: ignore[attr-defined]
    robot.belief.container_states["fridge"] = fridge_opening  # type: ignore[attr-defined]
    bowl = PerceivedObject("bowl-1", "bowl", (4.3, 5.0, 0.66), {"in": "fridge", "on": "fridge middle shelf"})
    return robot, bowl


@pytest.mark.parametrize("opening", [0.0, math.radians(50)])
def test_a_door_closed_or_stuck_part_way_is_opened_as_open_opens_it_before_a_grasp(opening):
    robot, bowl = _bowl_in_the_fridge(opening)
    with robot:
        assert _wider_opening(bowl, as_far_as_needed=True) == DOOR_OPENING


def test_a_door_open_as_open_opens_it_is_opened_wide_when_the_object_is_out_of_reach():
    robot, bowl = _bowl_in_the_fridge(math.radians(67))  # Open's 69 deg, measured 67
    with robot:
        assert _wider_opening(bowl, as_far_as_needed=True) is None  # useful: try it as it is
        assert _wider_opening(bowl) == pytest.approx(min(DOOR_WIDE, APARTMENT.container("fridge").limits[1]))
    robot, bowl = _bowl_in_the_fridge(DOOR_WIDE)
    with robot:
        assert _wider_opening(bowl) is None  # as wide as it goes: out of reach stays out of reach
    assert DOOR_OPENING < DOOR_WIDE and DOOR_USEFUL < DOOR_OPENING


class _Motions:
    """`motion` for `_withdraw`: records each motion asked for."""

    def __init__(self) -> None:
        self.asked: list[dict] = []

    def __call__(self, **kwargs):
        self.asked.append(kwargs)


def test_an_object_lifted_off_a_shelf_behind_a_door_is_taken_straight_out_past_the_front(monkeypatch):
    from pycram.actions import pick_up
    from pycram.world.objects import object_type
    from pycram.world.prospection import ToolPose

    fridge = APARTMENT.container("fridge")  # opens towards -y; its front at y = 4.33
    robot, bowl = _bowl_in_the_fridge(DOOR_WIDE)
    bowl.pose = (3.05, 4.7, 0.66)
    motions = _Motions()
    monkeypatch.setattr(pick_up, "motion", motions)
    lifted = ToolPose((3.0, 4.65, 0.8), (0.0, 0.7071, 0.7071, 0.0))
    with robot:
        assert pick_up._withdraw("left", bowl, lifted)
    (asked,) = motions.asked
    out = 4.7 - (-fridge.front - pick_up.WITHDRAW_MARGIN - object_type("bowl").footprint_radius)
    assert asked["type"] == "reaching" and asked["phase"] == "lift" and asked["arm"] == "left"
    assert asked["target"] == pytest.approx([3.0, 4.65 - out, 0.8])  # along the opening direction
    assert asked["orientation"] == pytest.approx([0.0, 0.7071, 0.7071, 0.0])  # the tool as lifted
    # out already, in a drawer (open above: the lift takes it out), or on no container: nothing
    for properties, pose in (
        ({"in": "fridge"}, (3.05, 4.0, 0.66)),
        ({"in": "drawer 2"}, (3.05, 4.7, 0.66)),
        ({"on": "counter"}, (3.05, 4.7, 0.66)),
    ):
        robot, obj = _bowl_in_the_fridge(DOOR_WIDE)
        obj.properties, obj.pose = properties, pose
        with robot:
            assert not pick_up._withdraw("left", obj, lifted)
    assert len(motions.asked) == 1
