"""The simulated world, for both robots: loading, base, head, arms, grasping, faults, pictures, shutdown.

Every wait is on a command handle or a fluent with a time-out in simulated seconds; nothing
sleeps and hopes. One world per robot is shared by the tests (they leave it in a usable state).
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

from pycram.sim import COOKERS, World, build_scene, cooker_positions
from pycram.sim.errors import UnknownNameError

T = 60.0  # generous simulated-time limit for a single command [s]


def ok(handle, timeout=T):
    out = handle.wait(timeout)
    assert out is not None, f"{handle} did not end within {timeout} s"
    assert out.succeeded, out
    return out.value


def to_map(base, dx, dy, dz):
    """A point given in the robot's base frame (x ahead, y left) in the map frame."""
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    return (base.x + c * dx - s * dy, base.y + s * dx + c * dy, dz)


def facing_quat(yaw):
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


@pytest.mark.parametrize("robot", ["pr2", "tiago"])
def test_scene_builds_quickly_and_repeatably(robot):
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        scene = build_scene(robot)
        times.append(time.perf_counter() - t0)
    assert max(times) < 3.0
    assert {c.name for c in COOKERS} == {"cooker #1", "cooker #2"}
    assert "mug" in [it.name for it in scene.items]
    with pytest.raises(UnknownNameError, match="Available: pr2, tiago"):
        build_scene("r2d2")


def test_world_publishes_sensors(world):
    assert world.sim_time.get_value() is not None
    t0 = world.sim_time.get_value()
    assert (world.sim_time > t0 + 0.2).wait_for(T) if hasattr(world.sim_time, "__gt__") else True
    js = world.joint_states.get_value()
    assert world.description.TORSO["joint"] in js.position
    for g, fl in world.gripper_openings.items():
        assert 0.0 <= fl.get_value() <= 0.1
    assert set(world.item_poses.get_value()) >= {"mug"}
    from pycram.runtime import current_clock

    assert current_clock() is world.clock
    assert abs(world.clock.now() - world.sim_time.get_value()) < 0.1


def test_base_reaches_goal(world):
    start = world.base_pose.get_value()
    goal = (start.x + 0.8, start.y + 0.5, start.yaw + 0.7)
    pose = ok(world.drive_to(*goal))
    measured = world.base_pose.get_value()
    for p in (pose, measured):
        assert math.hypot(p.x - goal[0], p.y - goal[1]) < 0.02
        assert abs((p.yaw - goal[2] + math.pi) % (2 * math.pi) - math.pi) < math.radians(2)
    ok(world.drive_to(*start.__dict__.values()))


def test_blocked_drive_fails_and_stops(world):
    start = world.base_pose.get_value()
    obstacle = ok(world.place_obstacle(start.x + 1.2, start.y))
    try:
        out = world.drive_to(start.x + 2.0, start.y, start.yaw).wait(T)
        assert out is not None and not out.succeeded
        assert out.reason in ("collision", "blocked")
        p = world.base_pose.get_value()
        assert p.x < start.x + 1.2 - 0.15  # stopped before the obstacle's centre
    finally:
        ok(world.remove_obstacle(obstacle))
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_drive_can_be_cancelled(world):
    start = world.base_pose.get_value()
    handle = world.drive_to(start.x + 2.0, start.y + 1.0, start.yaw)
    moved = world.base_pose.get_value()
    assert (world.sim_time > world.sim_time.get_value() + 0.8).wait_for(T)
    handle.cancel()
    out = handle.wait(T)
    assert out.reason == "cancelled"
    moved = world.base_pose.get_value()
    assert moved.distance_to(start) > 0.1
    assert (world.sim_time > world.sim_time.get_value() + 1.0).wait_for(T)
    still = world.base_pose.get_value()
    assert still.distance_to(moved) < 0.25  # came to rest instead of driving on
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_head_camera_looks_at_target(world):
    pose = world.kitchen_base_pose("cooker #2")
    ok(world.drive_to(pose.x, pose.y, pose.yaw))
    mug = world.item_poses.get_value()["mug"]
    ok(world.point_head(mug.position))
    seen = {v.name: v for v in ok(world.perceive())}
    assert "mug" in seen
    u, v = seen["mug"].centroid
    assert abs(u - 160) < 24 and abs(v - 120) < 24, (u, v)
    # tracking keeps it centred while the base moves sideways
    track = world.track_point(mug.position)
    ok(world.drive_to(pose.x + 0.3, pose.y + 0.1, pose.yaw + 0.3))
    seen = {v.name: v for v in ok(world.perceive())}
    assert "mug" in seen and abs(seen["mug"].centroid[0] - 160) < 30
    track.cancel()
    assert track.wait(T).reason == "cancelled"


def test_arm_reaches_cartesian_goal_and_reports_unreachable(world):
    ok(world.set_torso(world.description.TORSO["default"]))
    base = world.base_pose.get_value()
    for arm in world.description.ARMS:
        side = -0.2 if arm == "right" else 0.2
        goal = to_map(base, 0.6, side, 1.0)
        pose = ok(world.reach(arm, goal, facing_quat(base.yaw)))
        measured = world.tool_poses.get_value()[arm]
        for p in (pose, measured):
            assert np.linalg.norm(np.subtract(p.position, goal)) < 0.01
        out = world.reach(arm, to_map(base, 2.5, side, 1.0)).wait(T)
        assert out is not None and out.reason == "unreachable"
        ok(world.move_arm_to(arm, "park"))


def test_grasp_lift_drive_and_lose_item(world):
    d = world.description
    arm = d.DEFAULT_ARM
    gripper = d.ARMS[arm]["gripper"]
    base = world.kitchen_base_pose("cooker #2")
    ok(world.set_torso(d.TORSO["range"][1] * 0.9))
    ok(world.move_arm_to(arm, "carry"))
    ok(world.drive_to(base.x, base.y, base.yaw))
    mug = world.item_poses.get_value()["mug"].position
    q = facing_quat(base.yaw)
    ok(world.set_gripper(gripper, 0.09))
    ok(world.reach(arm, (mug[0], mug[1] + 0.12, mug[2]), q))
    world.reach(arm, mug, q, tolerance=0.02).wait(T)
    opening = ok(world.set_gripper(gripper, 0.0))
    assert 0.03 < opening < 0.08  # stalled on the mug (diameter 6 cm)
    assert world.gripper_states[gripper].get_value().holding == "mug"
    ok(world.reach(arm, (mug[0], mug[1] + 0.1, mug[2] + 0.1), q))
    ok(world.move_arm_to(arm, "carry"))
    start = world.base_pose.get_value()
    target = world.kitchen_base_pose("cooker #1")
    assert math.hypot(target.x - start.x, target.y - start.y) > 2.0
    ok(world.drive_to(target.x, target.y, target.yaw))
    held = world.item_poses.get_value()["mug"].position
    tool = world.tool_poses.get_value()[arm].position
    assert np.linalg.norm(np.subtract(held, tool)) < 0.05
    assert world.gripper_openings[gripper].get_value() > 0.03
    # fault: somebody takes the mug out of the gripper
    t0 = world.sim_time.get_value()
    assert ok(world.take_item(gripper)) == "mug"
    assert (world.gripper_openings[gripper] < 0.01).wait_for(0.5)
    assert world.sim_time.get_value() - t0 <= 0.5 + 0.05
    # ... and gives it back
    ok(world.give_item("mug", gripper))
    assert world.gripper_states[gripper].get_value().holding == "mug"
    assert world.gripper_openings[gripper].get_value() > 0.03
    # put it on cooker #1 and let go
    cooker = cooker_positions()["cooker #1"]
    ok(world.move_item("mug", (cooker[0], cooker[1], cooker[2] + 0.051)))
    assert world.gripper_states[gripper].get_value().holding is None
    ok(world.set_gripper(gripper, 0.09))
    ok(world.move_arm_to(arm, "park"))


def test_images_are_not_blank_and_show_the_robot(world, tmp_path):
    path = world.snapshot(tmp_path / "overview.png")
    import imageio.v3 as iio

    img = iio.imread(path)
    assert img.shape == (480, 640, 3) and img.std() > 10
    seg = ok(world.request_segmentation("overview", 320, 240))
    model = world.scene.model
    mount = model.body(world.description.ROOT_LINK).id
    robot_bodies = {b for b in range(model.nbody) if model.body_rootid[b] == mount or b == mount}
    robot_pixels = sum(int(np.count_nonzero(seg == g)) for g in range(model.ngeom)
                       if model.geom_bodyid[g] in robot_bodies)
    assert robot_pixels > 300
    head = ok(world.request_image("head_camera"))
    assert head.shape == (240, 320, 3) and head.std() > 5


def test_animation_is_recorded(world, tmp_path):
    ok(world.start_recording(fps=20))
    base = world.base_pose.get_value()
    ok(world.drive_to(base.x + 0.3, base.y, base.yaw))
    frames = world.stop_recording(tmp_path / "run.gif")
    assert len(frames) >= 5
    assert (tmp_path / "run.gif").stat().st_size > 1000


def test_clean_shutdown_leaves_no_thread():
    before = set(threading.enumerate())
    with World("pr2") as w:
        handle = w.drive_to(3.0, 3.0, 0.0)
        assert w.running
    assert not w.running
    assert handle.wait(1.0).reason == "closed"
    assert set(threading.enumerate()) <= before
    from pycram.runtime import current_clock

    assert current_clock() is not w.clock
    with pytest.raises(Exception):
        w.drive_to(0, 0, 0)


def test_realtime_mode_follows_the_wall_clock():
    w = World("pr2", realtime=True, activate_clock=False)
    try:
        t0 = time.monotonic()
        s0 = w.sim_time.get_value()
        time.sleep(0.6)  # measuring pacing against the wall clock is the point here
        elapsed_sim = w.sim_time.get_value() - s0
        assert 0.3 < elapsed_sim < 0.6 * 1.3 + 0.05, elapsed_sim
        assert time.monotonic() - t0 < 5
    finally:
        w.close()
