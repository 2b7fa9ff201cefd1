"""A base pose is offered only where navigation would drive the robot: with `DRIVE_ROOM` around
it (location reasoning without a simulator: a prospection double whose furniture is a wall).

Measured before: the TIAGo Pro's long base (0.72 x 0.50 m) was offered poses 0.38-0.40 m in
front of the furniture behind it -- the occupancy layer keeps only the base's inscribed circle
off the furniture -- and navigation refused every one of them (goal_in_collision)."""

from __future__ import annotations

import math

import pytest

from pycram.environments import load
from pycram.locations import LocationReasoner, RobotGeometry
from pycram.reasoning.locations.search import DRIVE_ROOM
from pycram.world.robot_registry import robot_description

APARTMENT = load("apartment")


class WallBehind:
    """Test double: the robot (a base reaching `rear` [m] behind its centre, along its heading)
    touches a wall along x = `wall` [m] when its rear reaches past it; records what was asked."""

    def __init__(self, wall: float, rear: float = 0.36) -> None:
        self.wall, self.rear = wall, rear
        self.asked: list[tuple[float, float, float]] = []

    def in_collision(self, base, configuration=None, carried=(), objects=False):
        x, y, yaw = base
        self.asked.append((x, y, yaw))
        return x - self.rear * math.cos(yaw) < self.wall


def _reasoner(prospection):
    geometry = RobotGeometry.from_description(robot_description("tiago-pro"))
    return LocationReasoner(geometry, lambda: APARTMENT, lambda: prospection, holding=lambda: {})


@pytest.mark.parametrize(
    ("gap", "cramped"),
    [(DRIVE_ROOM + 0.01, False), (DRIVE_ROOM - 0.01, True), (0.0, True)],
)
def test_a_pose_needs_room_to_drive_in_around_the_robot(gap, cramped):
    """The robot faces +x, its rear `gap` [m] short of a wall behind it: the pose itself fits
    (the caller checks that), but with less than `DRIVE_ROOM` behind it navigation would not
    drive there."""
    prospection = WallBehind(wall=0.0)
    base = (0.36 + gap, 2.0, 0.0)
    reasoner = _reasoner(prospection)
    assert reasoner.has_no_room(prospection, base, {}) is cramped
    assert reasoner.cannot_drive_in(prospection, base, {}) is cramped  # an omnidirectional base


def test_the_room_is_checked_ahead_behind_and_to_both_sides_along_the_heading():
    prospection = WallBehind(wall=-10.0)
    yaw = math.pi / 2
    assert not _reasoner(prospection).has_no_room(prospection, (1.0, 2.0, yaw), {})
    moved = {(round(x - 1.0, 6), round(y - 2.0, 6)) for x, y, _ in prospection.asked}
    # ahead is +y for a robot facing +y, its left is -x
    assert moved == {(0.0, DRIVE_ROOM), (0.0, -DRIVE_ROOM), (-DRIVE_ROOM, 0.0), (DRIVE_ROOM, 0.0)}
    assert all(asked_yaw == yaw for *_, asked_yaw in prospection.asked)
