"""Tool poses of pushing a door (`pycram.reasoning.locations.doors`): pure geometry on the apartment's
fridge with the robots' own `DOOR_PUSH` data."""

from __future__ import annotations

import math

import pytest

from pycram.environments.apartment import ENVIRONMENT as APARTMENT
from pycram.reasoning.locations import doors
from pycram.world.robot_registry import robot_description

pr2 = robot_description("pr2")
tiago = robot_description("tiago")

FRIDGE = APARTMENT.container("fridge")


def _heading(pose) -> tuple[float, float]:
    w, _, _, z = pose.orientation
    yaw = 2 * math.atan2(z, w)
    return math.cos(yaw), math.sin(yaw)


def _off_face(pose, side: str) -> float:
    """Signed distance [m] of the tool frame from the door's `side` face at the pose's angle."""
    (px, py), _, normal = FRIDGE.door_face(pose.angle, 0.0, side)
    x, y, _ = pose.position
    return (x - px) * normal[0] + (y - py) * normal[1]


def test_pushing_from_inside_goes_round_the_free_edge_and_follows_the_arc_with_the_hand_on_the_face():
    start, goal = math.radians(16), math.radians(69)
    poses = doors.push_sequence(FRIDGE, tiago.DOOR_PUSH, start, goal, "inside")
    hinge = FRIDGE.hinge
    first = poses[0]
    assert first.phase == "approach" and math.dist(first.position[:2], hinge) > FRIDGE.door_width + 0.1
    assert [p.phase for p in poses[:3]] == ["approach", "approach", "contact"]
    pushes = [p for p in poses if p.phase == "push"]
    assert len(pushes) == doors.PUSH_STEPS and pushes[-1].angle == pytest.approx(goal)
    assert all(b.angle > a.angle for a, b in zip(pushes, pushes[1:]))
    palm_off = tiago.DOOR_PUSH["inside"]["offset"][1]
    for pose in poses:
        off = _off_face(pose, "inside")
        if pose.phase == "push":  # the palm's side pressed a little into the face
            assert off == pytest.approx(palm_off - doors.PUSH_DEPTH, abs=1e-9)
        else:
            assert off >= palm_off - 1e-9
        _, along, _ = FRIDGE.door_face(pose.angle, 0.0, "inside")
        hx, hy = _heading(pose)
        assert hx * along[0] + hy * along[1] == pytest.approx(-1.0, abs=1e-4)  # pointing at the hinge
        assert pose.position[2] == FRIDGE.handle[2]


def test_pushing_shut_from_outside_ends_beyond_closed_with_the_finger_tips_into_the_face():
    poses = doors.push_sequence(FRIDGE, pr2.DOOR_PUSH, math.radians(30), 0.0, "outside")
    assert [p.phase for p in poses[:2]] == ["approach", "contact"]
    assert _off_face(poses[0], "outside") == pytest.approx(doors.APPROACH_CLEARANCE["outside"] + 0.01)
    angles = [p.angle for p in poses]
    assert all(b <= a for a, b in zip(angles, angles[1:])) and angles[-1] == -doors.PUSH_BEYOND
    for pose in poses[2:]:
        _, _, normal = FRIDGE.door_face(pose.angle, 0.0, "outside")
        hx, hy = _heading(pose)
        assert hx * normal[0] + hy * normal[1] == pytest.approx(-1.0, abs=1e-4)  # into the face
        (cx, cy), _, _ = FRIDGE.door_face(pose.angle, doors.push_distance(FRIDGE, "outside"), "outside")
        assert math.dist(pose.position[:2], (cx, cy)) == pytest.approx(0.01 - doors.PUSH_DEPTH, abs=1e-9)
    # partly shut: no pose beyond the goal
    part = doors.push_sequence(FRIDGE, tiago.DOOR_PUSH, 1.2, 0.4, "outside")
    assert part[-1].angle == pytest.approx(0.4)
    # clear of the handle's bar
    handle_distance = math.dist(FRIDGE.handle[:2], FRIDGE.hinge)
    assert doors.push_distance(FRIDGE, "outside") < handle_distance - 0.1
