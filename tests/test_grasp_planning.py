"""Grasp planning (`pycram.reasoning.grasps`): candidates from an object's measured shape and
pose -- pure geometry, no simulator. And the belief's reading of a lying object's pose."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pycram.reasoning.grasps import (
    GRASP_DEPTH,
    MAX_TURN,
    TOP_DEPTH,
    GripperGeometry,
    ObjectPose,
    grasp_candidates,
    grasp_options,
    tool_orientation,
)
from pycram.reasoning.locations.targets import as_target
from pycram.world.belief import PerceivedObject, lying_orientation
from pycram.world.objects import object_type

GRIPPER = GripperGeometry(max_opening=0.09, fingertip_reach=0.015, top_clearance=0.003, pre_grasp=0.1)
COUNTER = 0.9  # [m] the surface the objects rest on


def _angle(a: float, b: float) -> float:
    """|a - b| [rad] wrapped to [0, pi]."""
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def _axis_angle(a: float, b: float) -> float:
    """The angle [rad] between two undirected horizontal directions, in [0, pi/2]."""
    return min(_angle(a, b), _angle(a, b + math.pi))


def _rotation(q: tuple[float, ...]) -> np.ndarray:
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _standing(type_name: str, yaw: float = 0.0, xy: tuple[float, float] = (1.0, 4.55)) -> ObjectPose:
    kind = object_type(type_name)
    return ObjectPose.upright(kind, (xy[0], xy[1], COUNTER + kind.half_height), yaw)


def _lying(type_name: str, up: str, direction: float, xy: tuple[float, float] = (1.0, 4.55)) -> ObjectPose:
    kind = object_type(type_name)
    half = kind.extents["xyz".index(up)] / 2
    return ObjectPose(kind, (xy[0], xy[1], COUNTER + half), lying_orientation(kind.extents, up, direction))


# -- options: what fits the gripper, where ---------------------------------------------------------------


@pytest.mark.parametrize("yaw_deg", [0, 35, 60, 90, 160, -120])
def test_a_box_at_any_yaw_is_grasped_across_the_face_pair_that_fits_the_gripper(yaw_deg):
    yaw = math.radians(yaw_deg)
    box = _standing("cereal", yaw)  # 7 x 19 x 28 cm: only its 7 cm fit a 9 cm gripper
    options = grasp_options(box, GRIPPER.max_opening)
    assert options and all(o.width == pytest.approx(0.07) for o in options)
    top = [o for o in options if o.approach == "top"]
    sides = [o for o in options if o.approach == "side"]
    assert len(top) == 1 and _axis_angle(top[0].closing, yaw) < 1e-9  # across its own x axis
    assert top[0].point[2] == pytest.approx(box.top - TOP_DEPTH)
    # horizontally from either end of its long (y) axis, GRASP_DEPTH in past the near face
    assert sorted(round(math.degrees(_angle(o.heading, yaw))) for o in sides) == [90, 90]
    for o in sides:
        near_face = np.asarray(box.centre[:2]) - 0.095 * np.array([math.cos(o.heading), math.sin(o.heading)])
        inside = np.dot(np.asarray(o.point[:2]) - near_face, [math.cos(o.heading), math.sin(o.heading)])
        assert inside == pytest.approx(GRASP_DEPTH)
        assert o.point[2] == pytest.approx(box.centre[2])
        assert o.grasp.radius == pytest.approx(0.095 - GRASP_DEPTH) and o.grasp.opening == pytest.approx(0.07)


def test_faces_wider_than_the_gripper_opens_are_not_grasped():
    assert grasp_options(_standing("cereal"), max_opening=0.075) == []  # 7 cm + 1 cm margin > 7.5 cm
    narrow = grasp_options(_standing("milk"), max_opening=0.09)
    assert {round(o.width, 3) for o in narrow} == {0.07}
    # a 7 x 7 cm carton: across x and across y, each from the top and from both sides
    assert len(narrow) == 6


def test_a_lying_milk_carton_is_grasped_across_its_body_not_along_it():
    direction = math.radians(30)  # its long (z) axis lies along 30 deg
    carton = _lying("milk", "x", direction)
    assert not carton.is_upright and carton.half_height == pytest.approx(0.035)
    options = grasp_options(carton, GRIPPER.max_opening)
    assert options and all(o.width == pytest.approx(0.07) for o in options)  # never along its 20 cm
    top = [o for o in options if o.approach == "top"]
    assert len(top) == 1 and _axis_angle(top[0].closing, direction + math.pi / 2) < 1e-9
    assert top[0].point[2] == pytest.approx(max(carton.centre[2], carton.top - TOP_DEPTH))
    assert top[0].grasp.height == pytest.approx(top[0].point[2] - COUNTER)  # above its bottom as it lies
    sides = [o for o in options if o.approach == "side"]
    assert sides and all(_axis_angle(o.heading, direction) < 1e-9 for o in sides)  # from its ends


def test_a_cereal_box_lying_flat_is_too_wide_to_grasp_and_on_its_narrow_side_is_grasped_from_above():
    assert grasp_options(_lying("cereal", "x", 0.0), GRIPPER.max_opening) == []  # 19 x 28 cm from above
    on_edge = grasp_options(_lying("cereal", "y", 0.0), GRIPPER.max_opening)  # 7 x 28 cm from above
    assert {o.approach for o in on_edge} == {"top", "side"} and all(o.width == pytest.approx(0.07) for o in on_edge)


def test_round_bodies_standing_and_lying():
    cup = object_type("cup")
    standing = grasp_options(_standing("cup"), GRIPPER.max_opening)
    assert {(o.approach, o.heading) for o in standing} == {("side", None), ("top", None)}
    lying = ObjectPose(cup, (1.0, 4.55, COUNTER + 0.035), lying_orientation(cup.extents, "x", 0.0))
    options = grasp_options(lying, GRIPPER.max_opening)
    top = [o for o in options if o.approach == "top"]
    assert len(top) == 1 and _axis_angle(top[0].closing, math.pi / 2) < 1e-9  # across its axis
    assert all(_axis_angle(o.heading, 0.0) < 1e-9 for o in options if o.approach == "side")  # along it


def test_rims_of_bowls_and_plates_and_nothing_for_an_upturned_bowl():
    for name in ("bowl", "plate"):
        options = grasp_options(_standing(name), GRIPPER.max_opening)
        kind = object_type(name)
        assert len(options) == 1 and options[0].kind == "rim"
        assert options[0].radius == pytest.approx(kind.size[0] - kind.size[2] / 2)
        assert options[0].width == pytest.approx(kind.size[2])
        assert options[0].point[2] < COUNTER + kind.height
    bowl = object_type("bowl")
    upside_down = ObjectPose(bowl, (1.0, 4.55, COUNTER + bowl.half_height), (0.0, 1.0, 0.0, 0.0))
    assert grasp_options(upside_down, GRIPPER.max_opening) == []


# -- candidates: for where the robot stands ---------------------------------------------------------------


def test_candidates_face_the_robot_and_leave_out_the_far_side_and_overturned_wrists():
    box = _standing("cereal", math.radians(60))  # its ends face 150 and -30 deg
    base = (1.0, 3.9, math.pi / 2)  # in front of it, facing +y
    candidates = grasp_candidates(box, GRIPPER, base)
    sides = [c for c in candidates if c.approach == "side"]
    assert [round(math.degrees(c.heading)) for c in sides] == [150]  # not from behind (-30 deg)
    assert len([c for c in candidates if c.approach == "top"]) == 2  # the gripper either way round
    # turned 90 deg from the heading the wrist would turn too far: no horizontal candidate
    assert not [c for c in grasp_candidates(box, GRIPPER, base, max_turn=math.radians(55)) if c.approach == "side"]
    lying = _lying("milk", "x", 0.0)  # along the counter's edge: its ends face +-x
    assert {c.approach for c in grasp_candidates(lying, GRIPPER, base)} == {"top"}
    assert MAX_TURN < math.pi / 2


def test_candidates_are_ranked_by_how_well_they_face_the_robot_and_by_the_margin():
    box = _standing("milk", math.radians(10))
    base = (1.0, 3.9, math.pi / 2)
    candidates = grasp_candidates(box, GRIPPER, base)
    assert candidates == sorted(candidates, key=lambda c: c.score)
    best = candidates[0]
    assert best.approach == "side" and _angle(best.heading, math.radians(100)) < 1e-9  # 10 deg off facing
    # turned 30 deg, the box is taken from the top first (as the tables' top grasps rank)
    assert grasp_candidates(_standing("milk", math.radians(30)), GRIPPER, base)[0].approach == "top"
    wide = GripperGeometry(max_opening=0.2)  # more margin, better score
    assert grasp_candidates(box, wide, base)[0].score < best.score
    assert best.margin == pytest.approx(0.02)


def test_an_arm_coming_from_the_side_it_grasps_ranks_before_one_reaching_across():
    box = _standing("cereal", math.radians(60))  # grasped from its end facing 150 deg: the right side
    base = (1.0, 3.9, math.pi / 2)
    right_shoulder, left_shoulder = (1.19, 3.9), (0.81, 3.9)
    right = [c for c in grasp_candidates(box, GRIPPER, base, arm_root=right_shoulder) if c.approach == "side"]
    left = [c for c in grasp_candidates(box, GRIPPER, base, arm_root=left_shoulder) if c.approach == "side"]
    assert right[0].score < left[0].score


def test_candidate_tool_poses_point_along_the_approach_with_the_fingers_across_the_faces():
    box = _standing("cereal", math.radians(60))
    for c in grasp_candidates(box, GRIPPER, (1.0, 3.9, math.pi / 2)):
        r = _rotation(c.orientation)
        assert np.allclose(r[:, 0], c.direction, atol=1e-9)  # tool x: the approach
        if c.approach == "top":
            fingers = math.atan2(r[1, 1], r[0, 1])
            assert abs(r[2, 1]) < 1e-9 and _axis_angle(fingers, math.radians(60)) < 1e-9  # across x
            assert c.pre_grasp == pytest.approx((c.point[0], c.point[1], c.point[2] + GRIPPER.pre_grasp))
        else:
            assert abs(r[2, 1]) < 1e-9  # the fingers open horizontally, across the box's x axis
            back = np.asarray(c.point) - GRIPPER.pre_grasp * np.asarray(c.direction)
            assert np.allclose(c.pre_grasp, back)
        assert c.opening == GRIPPER.max_opening and c.centre == box.centre


def test_top_grasps_keep_the_finger_tips_off_the_surface():
    spoon = _standing("spoon")  # 1 cm thick
    long_fingers = GripperGeometry(max_opening=0.09, fingertip_reach=0.04, top_clearance=0.003)
    for c in grasp_candidates(spoon, long_fingers, (1.0, 3.9, math.pi / 2)):
        if c.approach == "top":
            assert c.point[2] == pytest.approx(COUNTER + 0.043)


def test_rim_candidates_take_the_rim_nearest_the_robot():
    bowl = _standing("bowl", xy=(1.0, 4.55))
    (c,) = grasp_candidates(bowl, GRIPPER, (1.6, 4.55, math.pi))
    assert c.point[:2] == pytest.approx((1.0 + 0.066, 4.55))
    r = _rotation(c.orientation)
    assert _axis_angle(math.atan2(r[1, 1], r[0, 1]), 0.0) < 1e-9  # the fingers close across the wall


def test_tool_orientation_conventions():
    r = _rotation(tool_orientation(math.radians(40), "side"))
    assert np.allclose(r[:, 0], [math.cos(math.radians(40)), math.sin(math.radians(40)), 0.0])
    r = _rotation(tool_orientation(0.0, "top"))
    assert np.allclose(r[:, 0], [0.0, 0.0, -1.0]) and np.allclose(r[:, 1], [0.0, 1.0, 0.0])


def test_gripper_geometry_rejects_a_gripper_that_does_not_open():
    with pytest.raises(ValueError, match="max_opening"):
        GripperGeometry(max_opening=0.0)


# -- the belief's reading of a lying object -----------------------------------------------------------------


def _perceived(type_name: str, size: tuple[float, float, float], axis: float | None) -> PerceivedObject:
    return PerceivedObject(
        f"{type_name}-1", type_name, (1.0, 4.55, COUNTER + size[2] / 2), {"size": size, "axis": axis}
    )


def test_the_belief_tells_a_lying_carton_by_its_shadow_and_a_short_looking_standing_one_is_not_lying():
    lying = _perceived("milk", (0.19, 0.09, 0.07), axis=0.4)
    assert lying.lying_axis == "x"
    r = _rotation(lying.orientation)
    assert r[2, 0] == pytest.approx(1.0)  # its x axis up
    assert _axis_angle(math.atan2(r[1, 2], r[0, 2]), 0.4) < 1e-9  # its long axis as measured
    hidden_top = _perceived("milk", (0.07, 0.07, 0.12), axis=None)  # the arm hides its top
    assert hidden_top.lying_axis is None
    assert hidden_top.orientation == pytest.approx((1.0, 0.0, 0.0, 0.0))
    unseen_axis = _perceived("milk", (0.19, 0.09, 0.07), axis=None)
    assert unseen_axis.lying_axis == "x" and unseen_axis.orientation is None


def test_a_cereal_box_lying_on_its_narrow_side_has_its_y_axis_up():
    box = _perceived("cereal", (0.29, 0.08, 0.19), axis=0.0)
    assert box.lying_axis == "y"
    pose = ObjectPose(object_type("cereal"), box.pose, box.orientation)
    assert pose.half_height == pytest.approx(0.095)


def test_a_location_target_carries_the_measured_orientation():
    lying = _perceived("milk", (0.19, 0.09, 0.07), axis=0.4)
    target = as_target(lying)
    assert target.orientation == pytest.approx(lying.orientation)
    standing = as_target(_perceived("milk", (0.07, 0.07, 0.2), axis=None))
    assert ObjectPose(object_type("milk"), standing.position, standing.orientation).is_upright


# -- the object turns with the hand ------------------------------------------------------------------------


def test_an_object_put_down_is_believed_turned_as_the_hand_turned_it():
    from pycram.actions.held import Held, fingers_yaw
    from pycram.reasoning.locations import BaseLocation
    from pycram.world.belief import BeliefState
    from pycram.world.objects import Grasp

    box = _perceived("cereal", (0.10, 0.19, 0.28), axis=math.radians(120))  # turned by 30 deg
    assert math.degrees(box.yaw) == pytest.approx(30.0)
    picked = BaseLocation(1.0, 3.9, math.radians(120), "right", "side")  # reached along 120 deg
    held = Held(box, "right", "right", Grasp("side", 0.07, 0.14), fingers_yaw(picked))
    assert math.degrees(held.hand_yaw) == pytest.approx(210.0 - 360.0)
    turned = (math.cos(math.radians(45)), 0.0, 0.0, math.sin(math.radians(45)))  # tool along 90 deg
    placed = BaseLocation(4.0, 1.6, math.radians(90), "right", "side", tool_poses=(((0, 0, 1), turned),) * 2)
    assert math.degrees(held.hand_turn(fingers_yaw(placed))) == pytest.approx(-30.0)
    belief = BeliefState()
    belief.add(box)
    belief.put_down(box, (4.0, 2.3, 0.89), held.hand_turn(fingers_yaw(placed)))
    assert _axis_angle(box.yaw, 0.0) < 1e-9 and box.pose == (4.0, 2.3, 0.89)  # turned 30 deg back
    assert Held(box, "right", "right", Grasp("side", 0.07, 0.14)).hand_turn(1.0) == 0.0  # not known
