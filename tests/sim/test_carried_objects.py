"""Objects the robot carries arrive with it: `Prospection.in_collision(..., carried=...)` moves
them rigidly with the base, so base poses are checked with what the robot holds (one model of the
robot for location reasoning and for navigation's goal check); with ``objects=True`` the other
objects are obstacles too, and the base's drives keep off them."""

from __future__ import annotations

import math

import pytest
from sim_helpers import T, ok

from pycram.sim import ItemSpec, World
from pycram.world.objects import object_type

#: A cup on the apartment's counter, 10 cm in front of the north wall (y = 5 m).
CUP = (1.0, 4.9, None)
#: A milk carton standing on the floor, in the open.
MILK = (2.0, 2.6, None)  # 1.1 m ahead of the PR2's start (2.0, 1.5), facing north


@pytest.fixture(scope="module")
def world():
    items = [ItemSpec.of(object_type("cup"), "cup", CUP, 0.0), ItemSpec.of(object_type("milk"), "milk", MILK, 0.0)]
    w = World("pr2", items, environment="apartment")
    yield w
    w.close()


def test_a_carried_object_moves_with_the_base_and_counts_as_the_robot(world):
    p = world.prospection()
    here = world.base_pose.get_value()
    # 10 and 20 cm north, the robot alone is free; the cup, moved along, is in the wall
    for dy in (0.1, 0.2):
        north = (here.x, here.y + dy, here.yaw)
        assert not p.in_collision(north)
        assert p.in_collision(north, carried=["cup"])
    # where it stands now, and 20 cm south, the cup is not in anything
    assert not p.in_collision(here, carried=["cup"])
    assert not p.in_collision((here.x, here.y - 0.2, here.yaw), carried=["cup"])


def test_a_carried_object_turns_with_the_base(world):
    p = world.prospection()
    here = world.base_pose.get_value()
    cup = world.item_poses.get_value()["cup"].position
    dx, dy = cup[0] - here.x, cup[1] - here.y  # about (-1.0, 3.4) m
    for turn in (-0.1, 0.1):  # turning in place swings the cup about the base's centre
        c, s = math.cos(turn), math.sin(turn)
        swung_y = here.y + s * dx + c * dy
        in_place = (here.x, here.y, here.yaw + turn)
        assert not p.in_collision(in_place)
        # clockwise the cup swings 8 cm north, into the wall; anticlockwise 12 cm south, free
        assert p.in_collision(in_place, carried=["cup"]) == (swung_y > cup[1]), (turn, swung_y)


def test_objects_are_obstacles_when_asked_except_the_carried_ones(world):
    p = world.prospection()
    milk = world.item_poses.get_value()["milk"].position
    on_the_carton = (milk[0], milk[1], 0.0)
    assert not p.in_collision(on_the_carton)  # the environment alone: free floor
    assert p.in_collision(on_the_carton, objects=True)
    beside = (milk[0] + 1.0, milk[1], 0.0)
    assert not p.in_collision(beside, objects=True)
    # carried, the carton moves with the base (from the start pose): no longer in the way there
    assert not p.in_collision(on_the_carton, carried=["milk"], objects=True)


def test_an_unknown_carried_object_is_refused_naming_the_known_ones(world):
    with pytest.raises(ValueError, match="unknown object 'mugg'.*known objects"):
        world.prospection().in_collision(world.base_pose.get_value(), carried=["mugg"])


def test_a_drive_goes_round_an_object_standing_in_its_way(world):
    start = world.base_pose.get_value()
    milk = world.item_poses.get_value()["milk"]
    goal = (milk.position[0], milk.position[1] + 1.0, start.yaw)  # straight ahead, past the carton
    handle = world.drive_to(*goal)
    out = handle.wait(T)
    assert out is not None and out.succeeded, out
    after = world.item_poses.get_value()["milk"]
    assert math.dist(after.position, milk.position) < 0.005  # not touched
    assert math.hypot(out.value.x - goal[0], out.value.y - goal[1]) < 0.05
    ok(world.drive_to(start.x, start.y, start.yaw))
    assert math.dist(world.item_poses.get_value()["milk"].position, milk.position) < 0.005
