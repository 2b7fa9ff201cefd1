"""The belief state without a simulator: association, ranking, gone objects, container states
and the support look-up, from hand-made perception reports and camera views."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pycram.designator import NoSolutionError, ObjectDesignator
from pycram.environments import load
from pycram.robot import ResolverSet
from pycram.world.belief import (
    MISSES_TO_GONE,
    BeliefState,
    CameraView,
    Detection,
    PerceptionReport,
    color_name,
    support_of,
)

APARTMENT = load("apartment")


def cup(x, y, pixels=100, color="red"):
    return Detection("cup", (x, y, 0.795), (0.07, 0.07, 0.09), color, support="table", pixels=pixels)


def view_from_south(depth_m=10.0):
    """A camera at (4.3, 0.5, 1.3) looking north (along +y), a flat depth image `depth_m` away."""
    # camera axes in the map: x right = +x, y up = +z, looking along -z = +y  ->  z = -y
    rotation = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    return CameraView((4.3, 0.5, 1.3), rotation, 60.0, np.full((240, 320), depth_m, np.float32))


def test_new_objects_get_belief_names_and_seen_objects_are_refreshed():
    belief = BeliefState(APARTMENT)
    first = belief.update(PerceptionReport(1.0, (cup(4.0, 2.0), cup(4.6, 2.0))))
    assert [o.name for o in first.added] == ["cup-1", "cup-2"]
    second = belief.update(PerceptionReport(2.0, (cup(4.62, 2.05), cup(4.05, 1.98))))
    assert not second.added and {o.name for o in second.refreshed} == {"cup-1", "cup-2"}
    one = next(o for o in belief.present() if o.name == "cup-1")
    assert one.pose[:2] == (4.05, 1.98) and one.last_seen == 2.0 and one.times_seen == 2
    far = belief.update(PerceptionReport(3.0, (cup(1.0, 4.6),)))  # beyond the gate: another cup
    assert [o.name for o in far.added] == ["cup-3"]


def test_the_best_match_is_the_most_recently_seen_then_the_most_visible():
    belief = BeliefState(APARTMENT)
    resolvers = ResolverSet("belief")
    resolvers.object_resolvers.append(belief.resolver)
    belief.update(PerceptionReport(1.0, (cup(4.0, 2.0, 50), cup(4.6, 2.0, 300))))
    with resolvers:
        assert ObjectDesignator(type="cup").reference().name == "cup-2"
        assert ObjectDesignator(type="cup").next_solution().reference().name == "cup-1"
        belief.update(PerceptionReport(2.0, (cup(4.0, 2.0, 20),)))
        assert [o.name for o in ObjectDesignator(type="cup").solutions()] == ["cup-1", "cup-2"]


def test_an_object_expected_in_view_but_not_seen_twice_is_gone_one_hidden_behind_something_is_not():
    belief = BeliefState(APARTMENT)
    resolvers = ResolverSet("belief")
    resolvers.object_resolvers.append(belief.resolver)
    belief.update(PerceptionReport(1.0, (cup(4.3, 2.0),)))
    view = view_from_south(depth_m=0.8)  # something 0.8 m in front of the camera hides the cup
    assert view.expects_visible((4.3, 2.0, 0.8)) is False
    assert not belief.update(PerceptionReport(2.0, (), view)).gone
    view = view_from_south()
    assert view.expects_visible((4.3, 2.0, 0.8)) and not view.expects_visible((4.3, 0.2, 0.8))  # behind
    assert not view.expects_visible((8.3, 2.0, 0.8))  # outside the image
    first = belief.update(PerceptionReport(3.0, (), view))  # one miss: no proof of absence
    assert first.gone == () and [o.name for o in first.missed] == ["cup-1"]
    with resolvers:
        assert ObjectDesignator(type="cup").reference().name == "cup-1"
    (gone,) = belief.update(PerceptionReport(3.5, (), view)).gone  # missed twice in a row: gone
    with resolvers, pytest.raises(NoSolutionError):
        ObjectDesignator(type="cup").reference()
    back = belief.update(PerceptionReport(4.0, (cup(4.35, 2.1),)))
    assert back.refreshed == (gone,) and not gone.gone


def test_container_states_and_supports():
    belief = BeliefState(APARTMENT)
    assert belief.container_open("drawer 1") is None
    belief.update(PerceptionReport(1.0, (), None, {"drawer 1": 0.3, "fridge": 0.0}))
    assert belief.container_open("drawer 1") and belief.container_open("fridge") is False
    assert support_of(APARTMENT, 1.78, 4.7, 0.9).name == "cooker #1"  # the cooker, not the counter
    assert support_of(APARTMENT, 1.0, 4.7, 0.9).name == "counter"
    assert support_of(APARTMENT, 0.3, 2.9, 0.4).name == "drawer 2 inside"
    assert support_of(APARTMENT, 0.7, 2.9, 0.4, {"drawer 2": 0.4}).name == "drawer 2 inside"
    assert support_of(APARTMENT, 0.7, 2.9, 0.4) is None
    assert support_of(APARTMENT, 4.3, 2.0, 0.75).name == "table"


def test_objects_believed_in_a_drawer_move_with_it():
    belief = BeliefState(APARTMENT)
    in_drawer = Detection(
        "cup", (0.7, 2.9, 0.41), (0.07, 0.07, 0.09), "red", support="drawer 2 inside", container="drawer 2"
    )
    belief.update(PerceptionReport(1.0, (in_drawer, cup(4.3, 2.0)), None, {"drawer 2": 0.4}))
    drawer_cup, table_cup = sorted(belief.present(), key=lambda o: o.pose[0])
    # the drawer pushed in (out of view: no detection), later measured pulled out to 0.25 m
    belief.update(PerceptionReport(2.0, (), None, {"drawer 2": 0.25}))
    assert drawer_cup.pose == pytest.approx((0.55, 2.9, 0.41))  # the drawer opens along +x
    assert drawer_cup.pose_fluent.get_value() == pytest.approx((0.55, 2.9, 0.41))
    assert table_cup.pose == pytest.approx((4.3, 2.0, 0.795))  # on the table: stays
    belief.update(PerceptionReport(3.0, (), None, {"drawer 2": 0.25}))
    assert drawer_cup.pose == pytest.approx((0.55, 2.9, 0.41))  # the drawer did not move
    belief.picked_up(drawer_cup, "right")
    belief.update(PerceptionReport(4.0, (), None, {"drawer 2": 0.0}))
    assert drawer_cup.pose == pytest.approx((0.55, 2.9, 0.41))  # in hand: not carried by the drawer
    # put down on the table (believed on it, no longer in drawer 2): stays on the table
    belief.put_down(drawer_cup, (4.0, 1.8, 0.795))
    assert drawer_cup.properties["on"] == "table" and drawer_cup.properties["in"] is None
    belief.update(PerceptionReport(5.0, (), None, {"drawer 2": 0.3}))
    assert drawer_cup.pose == pytest.approx((4.0, 1.8, 0.795))


def test_an_object_put_down_is_believed_on_the_surface_under_it():
    """Until a look sees it there (a look may miss it: the arm or a drawer's front in view)."""
    belief = BeliefState(APARTMENT)
    belief.update(PerceptionReport(1.0, (cup(4.3, 2.0),), None, {"drawer 2": 0.3}))
    (table_cup,) = belief.present()
    belief.picked_up(table_cup, "right")
    belief.put_down(table_cup, (0.7, 2.9, 0.41))  # its bottom on drawer 2's, out 0.3 m
    assert table_cup.properties["on"] == "drawer 2 inside" and table_cup.properties["in"] == "drawer 2"
    assert table_cup.pose == pytest.approx((0.7, 2.9, 0.41)) and not belief.in_hand


def test_a_drawer_the_robot_moved_is_believed_where_its_hand_left_it_until_measured():
    belief = BeliefState(APARTMENT)
    in_drawer = Detection(
        "cup", (0.3, 2.9, 0.41), (0.07, 0.07, 0.09), "red", support="drawer 2 inside", container="drawer 2"
    )
    belief.update(PerceptionReport(1.0, (in_drawer,), None, {"drawer 2": 0.0}))
    (drawer_cup,) = belief.present()
    belief.moved_container("drawer 2", 0.3)  # pulled out by the hand
    assert belief.container_states["drawer 2"] == 0.3
    assert belief.container_stamps["drawer 2"] == 1.0  # not measured: the next look is a measurement
    assert drawer_cup.pose == pytest.approx((0.6, 2.9, 0.41))  # rode out with it
    belief.update(PerceptionReport(2.0, (), None, {"drawer 2": 0.27}))  # measured 3 cm less
    assert drawer_cup.pose == pytest.approx((0.57, 2.9, 0.41)) and belief.container_stamps["drawer 2"] == 2.0
    with pytest.raises(ValueError, match="finite"):
        belief.moved_container("drawer 2", math.nan)


def test_objects_on_a_fridge_shelf_stay_when_its_door_swings():
    belief = BeliefState(APARTMENT)
    on_shelf = Detection(
        "cup", (3.05, 4.62, 0.67), (0.07, 0.07, 0.09), "red", support="fridge middle shelf", container="fridge"
    )
    belief.update(PerceptionReport(1.0, (on_shelf,), None, {"fridge": 1.2}))
    belief.update(PerceptionReport(2.0, (), None, {"fridge": 0.0}))
    (cup_in_fridge,) = belief.present()
    assert cup_in_fridge.pose == pytest.approx((3.05, 4.62, 0.67))


@pytest.mark.parametrize(
    "rgb, name",
    [
        ((0.8, 0.18, 0.15), "red"),
        ((0.95, 0.82, 0.25), "yellow"),
        ((0.92, 0.55, 0.12), "orange"),
        ((0.96, 0.96, 0.93), "white"),
        ((0.5, 0.5, 0.52), "grey"),
        ((0.1, 0.1, 0.1), "black"),
        ((0.1, 0.3, 0.9), "blue"),
        ((0.2, 0.7, 0.2), "green"),
    ],
)
def test_colour_names(rgb, name):
    assert color_name(rgb) == name


def test_moved_is_a_fluent_on_the_believed_pose():
    belief = BeliefState(APARTMENT)
    (obj,) = belief.update(PerceptionReport(1.0, (cup(4.0, 2.0),))).added
    moved = obj.moved(0.05)
    belief.update(PerceptionReport(2.0, (cup(4.02, 2.0),)))
    assert moved.get_value() is None
    belief.update(PerceptionReport(3.0, (cup(4.1, 2.0),)))
    assert moved.get_value() is True and math.isclose(obj.pose[0], 4.1)


def test_a_sighting_between_two_misses_starts_the_count_again():
    """A missed detection now and then (a flaky detector) never makes an object gone: only
    `misses_to_gone` looks in a row that should have seen it and did not."""
    belief = BeliefState(APARTMENT)
    assert belief.misses_to_gone == MISSES_TO_GONE == 2
    belief.update(PerceptionReport(1.0, (cup(4.3, 2.0),)))
    (obj,) = belief.present()
    view = view_from_south()
    for stamp in (2.0, 4.0, 6.0):
        update = belief.update(PerceptionReport(stamp, (), view))
        assert update.missed == (obj,) and not obj.gone and obj.misses == 1
        belief.update(PerceptionReport(stamp + 1.0, (cup(4.31, 2.0),), view))
        assert obj.misses == 0
    strict = BeliefState(APARTMENT, misses_to_gone=1)  # the old rule: one look is enough
    strict.update(PerceptionReport(1.0, (cup(4.3, 2.0),)))
    assert len(strict.update(PerceptionReport(2.0, (), view)).gone) == 1
    with pytest.raises(ValueError):
        BeliefState(APARTMENT, misses_to_gone=0)


def test_an_object_in_hand_is_not_missed_and_its_sighting_in_the_air_is_not_a_new_object():
    belief = BeliefState(APARTMENT)
    (milk,) = belief.update(PerceptionReport(1.0, (cup(4.3, 2.0),))).added
    belief.picked_up(milk, "right")
    view = view_from_south()
    assert view.expects_visible(milk.pose)
    carried = Detection("cup", (4.4, 1.4, 1.1), (0.07, 0.07, 0.09), "red", support=None, pixels=200)
    for stamp in (2.0, 3.0, 4.0):  # the place it was taken from looked at, the hand in view
        update = belief.update(PerceptionReport(stamp, (carried,), view))
        assert update.added == () and update.missed == () and update.gone == ()
    assert [o.name for o in belief.present()] == ["cup-1"] and milk.times_seen == 1
    # on a surface, a cup of the held type is another cup
    other = belief.update(PerceptionReport(5.0, (cup(3.6, 2.0),))).added
    assert [o.name for o in other] == ["cup-2"]
    belief.put_down(milk, (4.5, 2.0, 0.795))
    assert belief.in_hand == {}
    assert belief.update(PerceptionReport(6.0, (cup(4.52, 2.01),))).refreshed == (milk,)
    # released (an attempt failed after the grasp): in no hand, believed where it was
    belief.picked_up(milk, "left")
    belief.released(milk)
    assert belief.in_hand == {} and not milk.gone and milk.pose[:2] == (4.52, 2.01)
    # lost from the gripper: no longer in hand, gone until seen again
    belief.picked_up(milk, "left")
    belief.lost(milk)
    assert belief.in_hand == {} and milk.gone


def test_an_object_in_hand_seen_over_a_surface_near_the_hand_is_not_a_new_object():
    belief = BeliefState(APARTMENT)
    (held,) = belief.update(PerceptionReport(1.0, (cup(4.3, 2.0),))).added
    belief.picked_up(held, "left")
    # carried 20 cm over the table: perception finds the table under it ("on" the table)
    over_table = Detection("cup", (3.9, 2.1, 1.0), (0.07, 0.07, 0.09), "red", support="table", pixels=200)
    hands = {"left": (3.92, 2.05, 1.02), "right": (4.5, 1.6, 1.0)}
    update = belief.update(PerceptionReport(2.0, (over_table,), hands=hands))
    assert update.added == () and [o.name for o in belief.present()] == ["cup-1"]
    # the same sighting without the hand's position, or far from the hand that holds a cup: a new cup
    assert [o.name for o in belief.update(PerceptionReport(3.0, (over_table,))).added] == ["cup-2"]
    elsewhere = Detection("cup", (3.0, 2.2, 0.8), (0.07, 0.07, 0.09), "red", support="table", pixels=200)
    assert [o.name for o in belief.update(PerceptionReport(4.0, (elsewhere,), hands=hands)).added] == ["cup-3"]
    # near a hand that holds no cup: a cup
    free_hand = Detection("cup", (4.5, 1.7, 0.8), (0.07, 0.07, 0.09), "red", support="table", pixels=200)
    assert [o.name for o in belief.update(PerceptionReport(5.0, (free_hand,), hands=hands)).added] == ["cup-4"]


def test_a_look_that_measures_no_turn_keeps_the_turn_measured_before_while_the_object_stays():
    def milk(x, axis):
        return Detection("milk", (x, 2.0, 0.85), (0.07, 0.07, 0.2), "white", support="table", pixels=500, axis=axis)

    belief = BeliefState(APARTMENT)
    (carton,) = belief.update(PerceptionReport(1.0, (milk(4.3, -math.pi / 4),))).added
    assert carton.yaw == pytest.approx(-math.pi / 4)  # a square top: its sides' direction
    belief.update(PerceptionReport(2.0, (milk(4.305, None),)))  # the top hidden this time
    assert carton.yaw == pytest.approx(-math.pi / 4)
    belief.update(PerceptionReport(3.0, (milk(4.4, None),)))  # it moved: the old turn is no proof
    assert carton.properties["axis"] is None and carton.yaw == 0.0


def test_a_look_that_sees_less_of_a_standing_objects_height_keeps_the_height_measured_before():
    def milk(x, height, support="table"):
        # the table top is at 0.75 m: the carton's bottom there, its top `height` above
        size = (0.07, 0.07, height)
        return Detection("milk", (x, 2.0, 0.75 + height / 2), size, "white", support=support, pixels=500)

    belief = BeliefState(APARTMENT)
    (carton,) = belief.update(PerceptionReport(1.0, (milk(4.3, 0.2),))).added
    belief.update(PerceptionReport(2.0, (milk(4.31, 0.12),)))  # its top hidden: 8 cm of it unseen
    assert carton.pose == pytest.approx((4.31, 2.0, 0.85))  # where it is seen, as tall as before
    assert carton.properties["size"][2] == pytest.approx(0.2)
    belief.update(PerceptionReport(3.0, (milk(4.31, 0.2),)))
    assert carton.pose[2] == pytest.approx(0.85)
    # elsewhere, or on another surface, a shorter measurement is believed: it may have toppled
    belief.update(PerceptionReport(4.0, (milk(4.36, 0.12),)))
    assert carton.pose[2] == pytest.approx(0.81) and carton.properties["size"][2] == pytest.approx(0.12)
    belief.update(PerceptionReport(5.0, (milk(4.36, 0.2),)))
    belief.update(PerceptionReport(6.0, (milk(4.36, 0.12, support="counter"),)))
    assert carton.properties["size"][2] == pytest.approx(0.12)
    # measured wider than it stands: it lies, and its height is what is measured
    belief.update(PerceptionReport(7.0, (milk(4.36, 0.2),)))
    lying = Detection("milk", (4.37, 2.0, 0.785), (0.2, 0.07, 0.07), "white", support="table", pixels=500)
    belief.update(PerceptionReport(8.0, (lying,)))
    assert carton.properties["size"][2] == pytest.approx(0.07) and carton.lying_axis is not None


def test_a_look_that_sees_an_object_only_in_part_keeps_the_centre_believed_where_it_agrees():
    def bowl(x, y, slack=0.0, size=(0.14, 0.14, 0.07)):
        return Detection("bowl", (x, y, 0.785), size, "yellow", support="table", pixels=300, slack=slack)

    belief = BeliefState(APARTMENT)
    (seen,) = belief.update(PerceptionReport(1.0, (bowl(4.3, 2.0),))).added
    # a sliver past an occluder: its centre 6 cm off, but it may be up to 7 cm off: no news
    belief.update(PerceptionReport(2.0, (bowl(4.27, 1.95, slack=0.07, size=(0.14, 0.14, 0.07)),)))
    assert seen.pose[:2] == pytest.approx((4.3, 2.0))
    # a sliver farther off than it may be: the bowl moved
    belief.update(PerceptionReport(3.0, (bowl(4.2, 1.9, slack=0.05),)))
    assert seen.pose[:2] == pytest.approx((4.2, 1.9))
    # most of it seen (a centre at most 1.5 cm off): the look is news, not the older centre
    belief.update(PerceptionReport(3.5, (bowl(4.19, 1.89, slack=0.015),)))
    assert seen.pose[:2] == pytest.approx((4.19, 1.89))
    # seen whole, a look is believed to the millimetre
    belief.update(PerceptionReport(4.0, (bowl(4.205, 1.9),)))
    assert seen.pose[:2] == pytest.approx((4.205, 1.9))
    # on another surface, a part is news too
    other = Detection("bowl", (4.21, 1.91, 0.985), (0.14, 0.14, 0.07), "yellow", support="counter", slack=0.05)
    belief.update(PerceptionReport(5.0, (other,)))
    assert seen.pose[:2] == pytest.approx((4.21, 1.91))


def test_a_partial_look_that_also_misses_the_top_keeps_the_centre_and_the_height():
    def milk(x, height, slack=0.0):
        size = (0.07, 0.07, height)
        return Detection("milk", (x, 2.0, 0.75 + height / 2), size, "white", support="table", pixels=500, slack=slack)

    belief = BeliefState(APARTMENT)
    (carton,) = belief.update(PerceptionReport(1.0, (milk(4.3, 0.2),))).added
    belief.update(PerceptionReport(2.0, (milk(4.33, 0.1, slack=0.04),)))  # a sliver of its lower half
    assert carton.pose == pytest.approx((4.3, 2.0, 0.85)) and carton.properties["size"][2] == pytest.approx(0.2)


def test_a_partial_look_that_measures_a_turn_keeps_the_centre_and_takes_the_turn():
    def milk(x, axis=None, slack=0.0):
        size = (0.07, 0.07, 0.2)
        return Detection("milk", (x, 2.0, 0.85), size, "white", support="table", pixels=500, axis=axis, slack=slack)

    belief = BeliefState(APARTMENT)
    (carton,) = belief.update(PerceptionReport(1.0, (milk(4.3),))).added  # seen from afar: no turn
    belief.update(PerceptionReport(2.0, (milk(4.32, axis=math.pi / 4, slack=0.04),)))  # from close by, in part
    assert carton.pose[:2] == pytest.approx((4.3, 2.0))
    assert abs(carton.yaw) == pytest.approx(math.pi / 4)  # a square top: up to quarter turns
