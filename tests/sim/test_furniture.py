"""Articulated furniture in the apartment: drawers and the fridge door move only when pushed or
pulled hard enough at their handle, stay where they are left, and do not move when stuck."""

from __future__ import annotations

import pytest
from sim_helpers import ok

from pycram.sim import World
from pycram.world.errors import UnknownNameError


@pytest.fixture(scope="module")
def world():
    with World("pr2", [], environment="apartment") as w:
        yield w


def _q(world, name):
    return world.container_states.get_value()[name]


def _wait(world, seconds):
    """Let `seconds` of simulated time pass."""
    t = world.sim_time.get_value() + seconds
    assert (world.sim_time >= t).wait_for(seconds + 5.0)


def test_containers_are_closed_and_stay_closed_by_themselves(world):
    names = {c.name for c in world.environment.containers}
    assert names == {"drawer 1", "drawer 2", "drawer 3", "fridge", "cupboard"}
    _wait(world, 1.5)  # gravity, the robot standing by: nothing opens
    assert all(abs(q) < 1e-3 for q in world.container_states.get_value().values())
    assert not any(j.startswith("drawer") for j in world.joint_states.get_value().position)


def test_a_nudge_elsewhere_or_a_weak_pull_does_not_open_a_drawer(world):
    drawer = world.environment.container("drawer 1")
    front = (0.61, 2.5, drawer.body.center[2])  # a corner of the drawer front, away from the handle
    ok(world.push_container("drawer 1", (0.0, 40.0, 0.0), 0.5, point=front))  # sideways
    ok(world.push_container("drawer 1", (0.0, 0.0, -60.0), 0.5, point=front))  # pressed down
    ok(world.push_container("drawer 1", (-40.0, 0.0, 0.0), 0.5, point=front))  # pushed shut
    ok(world.push_container("drawer 1", (2.5, 0.0, 0.0), 0.5))  # a weak pull, below its friction
    _wait(world, 0.5)
    assert abs(_q(world, "drawer 1")) < 0.003


def test_a_drawer_opens_when_pulled_at_its_handle_and_stays_open(world):
    drawer = world.environment.container("drawer 2")
    ok(world.push_container("drawer 2", (40.0, 0.0, 0.0), 0.4))
    _wait(world, 1.0)  # damped: it glides a little and stops
    opened = _q(world, "drawer 2")
    assert 0.08 < opened <= drawer.limits[1] + 1e-3
    _wait(world, 2.0)
    assert abs(_q(world, "drawer 2") - opened) < 0.002
    ok(world.push_container("drawer 2", (-40.0, 0.0, 0.0), 0.6))  # and pushed shut again
    _wait(world, 1.0)
    assert _q(world, "drawer 2") < 0.01


def test_the_fridge_door_swings_open_on_its_hinge_and_stays(world):
    door = world.environment.container("fridge")
    assert door.joint == "hinge" and door.hinge is not None
    ok(world.push_container("fridge", (0.0, -25.0, 0.0), 0.5))
    _wait(world, 1.0)
    opened = _q(world, "fridge")
    assert 0.2 < opened <= door.limits[1] + 1e-3
    _wait(world, 2.0)
    assert abs(_q(world, "fridge") - opened) < 0.005


def test_a_stuck_drawer_does_not_open_until_freed(world):
    ok(world.set_container_stuck("drawer 3"))
    ok(world.push_container("drawer 3", (60.0, 0.0, 0.0), 0.5))
    _wait(world, 0.5)
    assert abs(_q(world, "drawer 3")) < 0.005
    ok(world.set_container_stuck("drawer 3", False))
    ok(world.push_container("drawer 3", (40.0, 0.0, 0.0), 0.4))
    _wait(world, 1.0)
    assert _q(world, "drawer 3") > 0.08


def test_unknown_containers_are_named_with_the_valid_choices(world):
    with pytest.raises(
        UnknownNameError, match="container 'oven' does not exist. Available: cupboard, drawer 1, drawer 2"
    ):
        world.push_container("oven", (1.0, 0.0, 0.0), 0.1)
    with pytest.raises(KeyError, match="fridge"):
        world.set_container_stuck("freezer")
