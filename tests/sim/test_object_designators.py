"""Object designators grounded in the robot's belief (issue 15): they resolve only what was
perceived, by type, colour, surface, container and belief name, best match first; an effective
designator stays equated to its description across re-perception; believed poses are fluents a
plan waits on.

The plans under test perform designators only; the tests set the world up directly.
"""

from __future__ import annotations

import math

import pytest
from belief_helpers import apartment, put
from sim_helpers import ok

from pycram import robots
from pycram.designator import MotionDesignator, NoSolutionError, ObjectDesignator, perform
from pycram.language import State, par
from pycram.world.belief import PerceivedObject

TABLE_SOUTH = (4.3, 0.9, math.pi / 2)
T = 30.0


@pytest.fixture
def table_scene():
    """The PR2 south of the table with a cup, a bowl and a milk carton on it, cereal in the
    closed fridge; nothing perceived yet."""
    world = apartment(TABLE_SOUTH)
    put(world, "cup", "table", (4.0, 2.0))
    put(world, "bowl", "table", (4.35, 2.1))
    put(world, "milk", "table", (4.7, 1.9))
    put(world, "cereal", "fridge middle shelf", (3.05, 4.62))
    robot = robots.load("pr2", world)
    with robot:
        yield world, robot
    robot.shutdown()
    world.close()


def look_at_table():
    perform(MotionDesignator(type="pointing_head", coordinates=(4.3, 2.0, 0.8)))
    return perform(MotionDesignator(type="detecting"))


def test_an_object_never_perceived_cannot_be_resolved(table_scene):
    world, robot = table_scene
    with pytest.raises(NoSolutionError):
        ObjectDesignator(type="cup").reference()  # nothing perceived yet
    seen = look_at_table()
    assert sorted(o.type for o in seen) == ["bowl", "cup", "milk"]
    assert isinstance(ObjectDesignator(type="cup").reference(), PerceivedObject)
    assert "cereal" in [i.type for i in world.scene.items]  # it exists, in the closed fridge
    with pytest.raises(NoSolutionError, match="cereal"):
        ObjectDesignator(type="cereal").reference()


def test_designators_resolve_by_type_colour_surface_container_and_name(table_scene):
    world, robot = table_scene
    look_at_table()
    cup = ObjectDesignator(type="cup").reference()
    truth = world.item_poses.get_value()["cup"].position
    assert math.dist(cup.pose[:2], truth[:2]) < 0.04
    assert ObjectDesignator(color="red").reference() is cup
    assert ObjectDesignator([("type", "cup"), ("on", "table")]).reference() is cup
    assert ObjectDesignator([("type", "cup"), ("on", world.environment.surface("table"))]).reference() is cup
    assert ObjectDesignator([("type", "cup"), ("in", None)]).reference() is cup
    assert ObjectDesignator(name=cup.name).reference() is cup
    assert {o.type for o in ObjectDesignator(on="table").solutions()} == {"cup", "bowl", "milk"}
    for wrong in (
        [("type", "cup"), ("color", "blue")],
        [("type", "cup"), ("on", "counter")],
        [("in", "fridge")],
        [("name", "cup")],
    ):  # "cup" is the simulator's name, not the belief's
        with pytest.raises(NoSolutionError):
            ObjectDesignator(wrong).reference()


def test_reference_is_the_best_match_and_next_solution_the_next(table_scene):
    world, robot = table_scene
    put(world, "bowl", "table", (4.2, 2.15))
    ok(world.move_item("milk", (4.45, 1.75, 0.75 + 0.102)))
    look_at_table()
    on_table = ObjectDesignator(on="table")
    order = [on_table.reference()]
    desig = on_table.next_solution()
    while desig is not None:
        order.append(desig.reference())
        assert desig.equal(on_table)
        desig = desig.next_solution()
    assert len(order) == 3 and len(set(map(id, order))) == 3
    pixels = [o.properties["pixels"] for o in order]
    assert pixels == sorted(pixels, reverse=True)  # seen in the same look: the most visible first
    # the milk is taken away; the next two looks mark it gone and it is no solution any more
    ok(world.take_item(item="milk"))
    look_at_table()  # one look that misses it is no proof that it is gone
    again = look_at_table()
    assert sorted(o.type for o in again) == ["bowl", "cup"]
    assert [o.type for o in ObjectDesignator(on="table").solutions()] == [o.type for o in again]
    assert order[[o.type for o in order].index("milk")].gone


def test_a_designator_stays_equated_across_re_perception_and_the_pose_is_a_fluent(table_scene):
    world, robot = table_scene
    cup = ObjectDesignator(type="cup")
    perform(MotionDesignator(type="pointing_head", coordinates=(4.3, 2.0, 0.8)))
    (seen,) = perform(MotionDesignator(type="detecting", object=cup))
    first_effective = cup.current()
    assert first_effective is not cup and first_effective.equal(cup)
    assert first_effective.reference() is seen and cup.reference() is seen
    before = seen.pose
    moved = seen.moved(0.05)
    errors: list = []

    def watcher():
        assert moved.wait_for(T), "the cup's believed pose never moved"

    def mover():  # a person moves the cup; the robot looks again
        put(world, "cup", "table", (4.05, 1.75))
        perform(MotionDesignator(type="detecting", object=cup))

    assert par(watcher, mover, errors=errors).get_value() is State.SUCCEEDED, errors
    truth = world.item_poses.get_value()["cup"].position
    assert math.dist(seen.pose[:2], truth[:2]) < 0.04 and math.dist(seen.pose, before) > 0.2
    assert cup.reference() is seen  # before and after: the same believed object, its pose refreshed
    assert cup.current() is not first_effective and cup.current().reference() is seen
    assert cup.current().timestamp > first_effective.timestamp
    assert ObjectDesignator([("type", "cup"), ("pose", lambda p: p[1] < 1.9)]).reference() is seen
