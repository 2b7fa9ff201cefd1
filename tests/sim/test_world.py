"""The simulated robot's hardware, for both robots: sensors, base, torso, arms, pictures.

Every wait is on a command handle or a fluent with a time-out in simulated seconds; nothing
sleeps and hopes. One world per robot is shared by the tests (they leave it in a usable state).
Grasping, perception and the world's life cycle have their own modules (test_sim_*.py).
"""

from __future__ import annotations

import math

import numpy as np
from sim_helpers import Recorder, T, facing_quat, ok, to_map

from pycram.environments import load as load_environment

COUNTER_HEIGHT = load_environment("thesis-kitchen").surface("counter_back").height


def test_world_publishes_sensors(world):
    from pycram.runtime import current_clock

    t0 = world.sim_time.get_value()
    assert (world.sim_time > t0 + 0.2).wait_for(T)
    js = world.joint_states.get_value()
    assert world.description.TORSO["joint"] in js.position and "base_x" in js.velocity
    assert abs(js.stamp - world.sim_time.get_value()) < 0.05
    for arm in world.description.ARMS:
        assert all(j in js.position for j in world.description.ARMS[arm]["joints"])
    assert set(world.gripper_openings) == set(world.description.GRIPPERS)
    for g, fl in world.gripper_openings.items():
        assert 0.0 <= fl.get_value() <= 0.1
        assert world.gripper_states[g].get_value().opening == fl.get_value()
    base = world.base_pose.get_value()
    assert abs(base.x - js.position["base_x"]) < 1e-9
    items = world.item_poses.get_value()
    assert set(items) >= {"mug", "box"}
    # the items rest on the 0.9 m counter
    assert abs(items["mug"].position[2] - (COUNTER_HEIGHT + world.scene.item("mug").half_height)) < 0.01
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
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_base_respects_velocity_and_acceleration_limits(world):
    limits = world.description.BASE
    start = world.base_pose.get_value()
    samples = Recorder(world.joint_states)
    ok(world.drive_to(start.x + 2.0, start.y + 0.5, start.yaw))  # long enough to cruise
    ok(world.drive_to(start.x + 2.0, start.y + 0.5, start.yaw + 2.5))  # a turn on the spot
    js = samples.samples
    speed = [(s.stamp, math.hypot(s.velocity["base_x"], s.velocity["base_y"]), s.velocity["base_yaw"]) for s in js]
    vmax, wmax = limits["max_linear_velocity"], limits["max_angular_velocity"]
    assert 0.9 * vmax < max(v for _, v, _ in speed) <= 1.05 * vmax
    assert 0.9 * wmax < max(abs(w) for _, _, w in speed) <= 1.05 * wmax
    # accelerations over 0.1 s windows (5 samples at 50 Hz)
    acc = [abs(b[1] - a[1]) / (b[0] - a[0]) for a, b in zip(speed, speed[5:]) if b[0] > a[0]]
    ang = [abs(b[2] - a[2]) / (b[0] - a[0]) for a, b in zip(speed, speed[5:]) if b[0] > a[0]]
    assert max(acc) <= 1.15 * limits["linear_acceleration"], max(acc)
    assert max(ang) <= 1.15 * limits["angular_acceleration"], max(ang)
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_blocked_straight_drive_fails_and_stops(world):
    start = world.base_pose.get_value()
    obstacle = ok(world.place_obstacle(start.x + 1.2, start.y))
    try:
        out = world.drive_to(start.x + 2.0, start.y, start.yaw, plan_path=False).wait(T)
        assert out is not None and not out.succeeded
        assert out.reason in ("collision", "blocked")
        p = world.base_pose.get_value()
        assert p.x < start.x + 1.2 - 0.15  # stopped before the obstacle's centre
        assert (world.sim_time > world.sim_time.get_value() + 0.5).wait_for(T)
        assert world.base_pose.get_value().distance_to(p) < 0.02  # and stays there
    finally:
        ok(world.remove_obstacle(obstacle))
    ok(world.drive_to(start.x, start.y, start.yaw))


def test_a_base_that_stopped_touching_something_drives_off_but_not_into_it(world):
    """A drive stopped by a contact leaves the base touching the obstacle: a drive away from it
    succeeds (every drive failed at once before: the TIAGo Pro stood against a drawer handle for
    the rest of a set-table run), a drive on into it still fails and does not get past it."""
    start = world.base_pose.get_value()
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    obstacle = ok(world.place_obstacle(start.x + 1.2 * c, start.y + 1.2 * s))
    try:
        out = world.drive_to(start.x + 2.0 * c, start.y + 2.0 * s, start.yaw, plan_path=False).wait(T)
        assert out is not None and out.reason == "collision", out
        stopped = world.base_pose.get_value()
        out = world.drive_to(start.x + 2.0 * c, start.y + 2.0 * s, start.yaw, plan_path=False).wait(T)
        assert out is not None and out.reason in ("collision", "blocked"), out
        assert world.base_pose.get_value().distance_to(stopped) < 0.05
        ok(world.drive_to(start.x, start.y, start.yaw, plan_path=False))
    finally:
        ok(world.remove_obstacle(obstacle))
    assert world.base_pose.get_value().distance_to(start) < 0.02


def test_drive_can_be_cancelled(world):
    start = world.base_pose.get_value()
    # 2 m ahead along its heading: every base (a differential drive too) sets off at once
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    handle = world.drive_to(start.x + 2.0 * c, start.y + 2.0 * s, start.yaw)
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


def test_torso_moves_within_its_range(world):
    d = world.description
    joint, (lo, hi) = d.TORSO["joint"], d.TORSO["range"]
    for height in (lo + 0.02, hi - 0.02, d.TORSO["default"]):
        ok(world.set_torso(height))
        assert abs(world.joint_states.get_value().position[joint] - height) < 0.01
    out = world.set_torso(hi + 0.2).wait(T)
    assert out is not None and out.reason == "invalid"


def test_arm_joint_trajectories_and_named_configurations(world):
    d = world.description
    for arm, spec in d.ARMS.items():
        configurations = d.ARM_CONFIGURATIONS[arm]
        assert {"park", "carry"} <= set(configurations)
        for name in ("carry", "park"):
            ok(world.move_arm_to(arm, name))
            measured = [world.joint_states.get_value().position[j] for j in spec["joints"]]
            assert max(abs(a - b) for a, b in zip(measured, configurations[name])) < 0.02, (arm, name)
        # a trajectory to an arbitrary joint goal (midway: inside the joint limits)
        goal = [(a + b) / 2 for a, b in zip(configurations["park"], configurations["carry"])]
        ok(world.move_arm(arm, goal, duration=1.5))
        measured = [world.joint_states.get_value().position[j] for j in spec["joints"]]
        assert max(abs(a - b) for a, b in zip(measured, goal)) < 0.02
        ok(world.move_arm_to(arm, "park"))


def test_arm_reaches_cartesian_goal_and_reports_unreachable(world):
    ok(world.set_torso(world.description.TORSO["default"]))
    base = world.base_pose.get_value()
    model = world.scene.model
    for arm in world.description.ARMS:
        side = -0.2 if arm == "right" else 0.2
        goal = to_map(base, 0.6, side, 1.0)
        pose = ok(world.reach(arm, goal, facing_quat(base.yaw)))
        measured = world.tool_poses.get_value()[arm]
        for p in (pose, measured):
            assert np.linalg.norm(np.subtract(p.position, goal)) < 0.01
        js = world.joint_states.get_value().position
        for joint in world.description.ARMS[arm]["joints"]:
            jid = world.scene.joint_id(joint)
            if model.jnt_limited[jid]:
                lo, hi = model.jnt_range[jid]
                assert lo - 0.01 <= js[joint] <= hi + 0.01, joint
        out = world.reach(arm, to_map(base, 2.5, side, 1.0)).wait(T)
        assert out is not None and out.reason == "unreachable" and not out.succeeded
        ok(world.move_arm_to(arm, "park"))


def test_images_are_not_blank_and_show_the_robot(world, tmp_path):
    import imageio.v3 as iio

    path = world.snapshot(tmp_path / "overview.png")
    img = iio.imread(path)
    assert img.shape == (480, 640, 3) and img.std() > 10
    seg = ok(world.request_segmentation("overview", 640, 480))
    model = world.scene.model
    mount = model.body(world.description.ROOT_LINK).id
    robot_geoms = [g for g in range(model.ngeom) if model.body_rootid[model.geom_bodyid[g]] == mount]
    robot = np.isin(seg, robot_geoms)
    assert robot.sum() > 1000
    # in the PNG, the robot's pixels are shaded (not a flat fill) and unlike the rest of the picture
    assert img[robot].std() > 20
    assert np.abs(img[robot].mean(axis=0) - img[~robot].mean(axis=0)).max() > 20
    head = ok(world.request_image("head_camera"))
    assert head.shape == (240, 320, 3) and head.std() > 5
    assert world.camera_image.get_value() is head  # the camera fluent holds the image on request
    path = world.snapshot(tmp_path / "head.png", camera="head_camera", width=320, height=240)
    assert iio.imread(path).std() > 5


def test_a_snapshot_costs_the_run_no_simulated_time(world, tmp_path):
    """Pictures for people draw the published state in the caller's thread: in a lock-step world
    the simulation takes no step for them, so a run with pictures is the run without (a start
    picture had moved a TIAGo Pro set-table run by one tick and changed its outcome)."""
    import imageio.v3 as iio

    assert world.stepping == "lockstep"
    before, trajectory = world.sim_time.get_value(), len(world.trajectory())
    first = iio.imread(world.snapshot(tmp_path / "a.png"))
    second = iio.imread(world.snapshot(tmp_path / "b.png"))
    assert world.sim_time.get_value() == before and len(world.trajectory()) == trajectory
    assert (first == second).all()  # the same state drawn twice: the same picture


def test_animation_is_recorded(world, tmp_path):
    ok(world.start_recording(fps=20))
    base = world.base_pose.get_value()
    ok(world.drive_to(base.x + 0.3, base.y, base.yaw))
    frames = world.stop_recording(tmp_path / "run.gif")
    assert len(frames) >= 5
    assert any(np.abs(frames[0].astype(int) - f.astype(int)).max() > 30 for f in frames[1:])  # it moves
    assert (tmp_path / "run.gif").stat().st_size > 1000
    ok(world.drive_to(base.x, base.y, base.yaw))
