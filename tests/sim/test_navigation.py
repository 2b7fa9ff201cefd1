"""Driving around things: planned base paths in the simulator, re-planning when an obstacle
appears during a drive, and a named failure when there is no way."""

from __future__ import annotations

import math

from sim_helpers import Recorder, T, ok, wait_wall

OBSTACLE_HALF = 0.15  # [m] half width of `place_obstacle`'s box


def _footprint_radius(world) -> float:
    from pycram.backends.sim.path_drive import navigation_of

    nav = ok(world._call("navigation", navigation_of))
    return nav.footprint.inscribed_radius


def test_a_free_straight_drive_stays_straight(world):
    start = world.base_pose.get_value()
    poses = Recorder(world.base_pose)
    ok(world.drive_to(start.x + 1.5, start.y + 0.5, start.yaw))
    line = (1.5, 0.5)
    n = math.hypot(*line)
    off = [abs((p.x - start.x) * line[1] - (p.y - start.y) * line[0]) / n for p in poses.samples]
    assert max(off) < 0.01
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_an_obstacle_appearing_mid_drive_is_driven_around(world):
    start = world.base_pose.get_value()
    goal = (start.x + 2.2, start.y, start.yaw)
    poses = Recorder(world.base_pose)
    handle = world.drive_to(*goal)
    # when the base crosses 0.4 m from its start, a box appears 1.0 m ahead on its way
    assert wait_wall(lambda: world.base_pose.get_value().x > start.x + 0.4, [world.base_pose], timeout=T)
    obstacle_x = start.x + 1.4
    obstacle = ok(world.place_obstacle(obstacle_x, start.y))
    try:
        out = handle.wait(T)
        assert out is not None and out.succeeded, out
        final = world.base_pose.get_value()
        assert math.hypot(final.x - goal[0], final.y - goal[1]) < 0.02
        # it went around: off the straight line, and never closer to the box than fits
        assert max(abs(p.y - start.y) for p in poses.samples) > OBSTACLE_HALF + 0.2
        # (a drive that touches anything ends with "collision"); the base's centre kept at least
        # its inscribed radius from the box
        closest = min(
            math.hypot(max(abs(p.x - obstacle_x) - OBSTACLE_HALF, 0.0), max(abs(p.y - start.y) - OBSTACLE_HALF, 0.0))
            for p in poses.samples
        )
        assert closest > _footprint_radius(world)
    finally:
        ok(world.remove_obstacle(obstacle))
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_an_obstacle_on_the_goal_fails_with_no_path_and_the_base_stays(world):
    start = world.base_pose.get_value()
    obstacle = ok(world.place_obstacle(start.x + 1.5, start.y))
    try:
        out = world.drive_to(start.x + 1.5, start.y, start.yaw).wait(T)
        assert out is not None and not out.succeeded
        assert out.reason == "no_path" and "goal_in_collision" in out.message
        assert world.base_pose.get_value().distance_to(start) < 0.01
    finally:
        ok(world.remove_obstacle(obstacle))


def _distance_to_segment(p, a, b) -> float:
    (px, py), (ax, ay), (bx, by) = p, a, b
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(px - ax - t * dx, py - ay - t * dy)


def test_a_door_left_open_across_the_route_is_driven_around():
    from sim_helpers import settle

    from pycram.sim import World

    world = World("pr2", environment="apartment", base_pose=(1.5, 3.5, 0.0))
    try:
        fridge = world.environment.container("fridge")
        ok(world.push_container("fridge", (0.0, -40.0, 0.0), 1.0))  # a person leaves it open
        settle(world, 2.0)
        q = world.container_states.get_value()["fridge"]
        door = (fridge.hinge, fridge.handle_position(q)[:2])
        assert _distance_to_segment((2.6, 3.5), *door) < 0.3, f"the door (q={q:.2f}) is not across the route"
        poses = Recorder(world.base_pose)
        out = world.drive_to(4.5, 3.5, 0.0).wait(T)
        assert out is not None and out.succeeded, out
        # around the door, never touching it: it is where it was left
        assert abs(world.container_states.get_value()["fridge"] - q) < 0.02
        closest = min(_distance_to_segment((p.x, p.y), *door) for p in poses.samples)
        assert closest > _footprint_radius(world)
    finally:
        world.close()


def _moves_left(world) -> tuple[float, float]:
    """Drive 0.4 m to the robot's left (same heading) and back; (metres travelled along the base's
    own y axis, largest heading change [rad]) on the way there."""
    start = world.base_pose.get_value()
    left = (-math.sin(start.yaw), math.cos(start.yaw))
    poses = Recorder(world.base_pose)
    ok(world.drive_to(start.x + 0.4 * left[0], start.y + 0.4 * left[1], start.yaw))
    samples = [start, *poses.samples]
    sideways = 0.0
    for a, b in zip(samples, samples[1:]):
        dx, dy = b.x - a.x, b.y - a.y
        sideways += abs(-math.sin(a.yaw) * dx + math.cos(a.yaw) * dy)
    turned = max(abs(math.remainder(p.yaw - start.yaw, 2 * math.pi)) for p in samples)
    final = world.base_pose.get_value()
    assert math.hypot(final.x - start.x - 0.4 * left[0], final.y - start.y - 0.4 * left[1]) < 0.01
    ok(world.drive_to(start.x, start.y, start.yaw))
    return sideways, turned


def test_a_base_moves_sideways_as_its_kinematics_allow(world):
    """Asked to move 0.4 m to its left, the omnidirectional PR2 steps sideways without turning;
    the TIAGo, a differential drive as its real base is, turns, drives along its heading and
    turns back: it faces the way it goes (about 90 deg) and travels less than 2 cm sideways."""
    kind = world.description.base_kinematics.kind
    assert kind == {"pr2": "omnidirectional", "tiago": "differential"}[world.robot]
    sideways, turned = _moves_left(world)
    if kind == "omnidirectional":
        assert sideways > 0.35, sideways
        assert turned < 0.05
    else:
        assert sideways < 0.02, sideways
        assert turned > 1.2


def test_a_base_drives_around_an_obstacle_on_its_way(world):
    start = world.base_pose.get_value()
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    obstacle = ok(world.place_obstacle(start.x + 0.9 * c, start.y + 0.9 * s))
    try:
        ok(world.drive_to(start.x + 1.8 * c, start.y + 1.8 * s, start.yaw))
        final = world.base_pose.get_value()
        assert math.hypot(final.x - start.x - 1.8 * c, final.y - start.y - 1.8 * s) < 0.02
    finally:
        ok(world.remove_obstacle(obstacle))
    ok(world.drive_to(start.x, start.y, start.yaw))
