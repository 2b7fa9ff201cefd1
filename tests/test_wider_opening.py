"""How far `PickUp` opens a container whose inside it cannot reach into (`_wider_opening`)."""

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
