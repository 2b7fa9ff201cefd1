"""Prospection in the simulator: collision, reachability and visibility questions answered on
scratch copies of the current state, from any thread, without disturbing the running world."""

from __future__ import annotations

import math
import random
import threading

import numpy as np
import pytest
from sim_helpers import T, ok, to_map

from pycram.world.prospection import Prospection, Reachability, Visibility

MUG = (0.1, -1.15, 0.95)  # the default mug's centre on the back counter [m]
MUG_FRONT = (0.1, -1.118, 0.95)  # a point on the mug's side facing the room (radius 0.03 m)
LOOK_AT_MUG = (0.1, 0.5, -math.pi / 2)  # 1.6 m in front of the back counter, facing it
BEHIND_MUG = (0.1, -1.04, 0.961)  # a spot on the counter's front edge, between LOOK_AT_MUG and the mug


def _yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def _grasp_sequence(base) -> list:
    """Pre-grasp, grasp and lift of the mug from `base` (tool pointing along the base's heading)."""
    q = _yaw_quat(base.yaw)
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    x, y, z = MUG
    return [((x - 0.1 * c, y - 0.1 * s, z), q), (MUG, q), ((x, y, z + 0.1), q)]


def _state(world) -> dict:
    """The simulation thread's own state arrays, copied in that thread."""
    return ok(
        world._call(
            "copy state",
            lambda eng: {
                "qpos": eng.data.qpos.copy(),
                "qvel": eng.data.qvel.copy(),
                "ctrl": eng.data.ctrl.copy(),
                "mocap": eng.data.mocap_pos.copy(),
                "time": eng.time,
            },
        )
    )


def test_is_a_prospection_and_the_same_object_every_time(world):
    p = world.prospection()
    assert isinstance(p, Prospection)
    assert world.prospection() is p
    assert p.arms == tuple(world.description.ARMS)


def test_collision_true_and_false(world):
    p = world.prospection()
    here = world.base_pose.get_value()
    assert not p.in_collision(here)
    assert p.in_collision((0.2, -1.2, 0.0))  # inside the back counter
    pairs = p.collisions((0.2, -1.2, 0.0))
    assert "counter_back" in {env for _, env in pairs} and len(set(pairs)) == len(pairs)
    # 0.55 m in front of the left wall: free with the arms parked, not with an arm held out
    arm = world.description.DEFAULT_ARM
    joints = world.description.ARMS[arm]["joints"]
    facing_wall = (-0.6, 0.0, math.pi)
    assert not p.in_collision(facing_wall)
    stretched = dict(zip(joints, world.description.ARM_CONFIGURATIONS[arm]["carry"]))  # 0.6 m ahead
    assert p.in_collision(facing_wall, stretched)
    with pytest.raises(ValueError, match="unknown joint 'elbow'.*valid joints"):
        p.in_collision(here, {"elbow": 0.3})
    with pytest.raises(ValueError, match="base pose"):
        p.in_collision("kitchen")


def test_reflects_obstacles_placed_and_removed(world):
    p = world.prospection()
    spot = (2.5, 2.5, 0.0)
    assert not p.in_collision(spot)
    obstacle = ok(world.place_obstacle(2.5, 2.5))
    try:
        assert p.in_collision(spot)  # the outcome arrives after the state was published
        assert any(env == obstacle for _, env in p.collisions(spot))
    finally:
        ok(world.remove_obstacle(obstacle))
    assert not p.in_collision(spot)


def test_reachable_success_gives_solutions_that_really_reach(world):
    p = world.prospection()
    arm = world.description.DEFAULT_ARM
    cooker = world.kitchen_base_pose("cooker #2")
    at_counter = p.reachable(arm, _grasp_sequence(cooker), cooker)
    assert isinstance(at_counter, Reachability) and at_counter, at_counter
    assert len(at_counter.solutions) == 3 and at_counter.reason is None
    # executed in the simulator (in free space, where moving between the joint solutions
    # cannot be blocked by furniture), each solution puts the tool where it was asked to
    base = world.base_pose.get_value()
    q = _yaw_quat(base.yaw)
    x, y = world.description.REACH_POINT_IN_BASE[arm]  # in line with the shoulder
    ahead = [(to_map(base, x - 0.1, y, 1.0), q), (to_map(base, x, y, 1.0), q), (to_map(base, x, y, 1.1), q)]
    answer = p.reachable(arm, ahead, base)
    assert answer, answer
    try:
        for (position, _), solution in zip(ahead, answer.solutions):
            ok(world.move_arm(arm, solution))
            reached = world.tool_poses.get_value()[arm].position
            assert np.linalg.norm(np.subtract(reached, position)) < 0.01
    finally:
        ok(world.move_arm_to(arm, "park"))


def test_reachable_failure_reasons(world):
    p = world.prospection()
    arm = world.description.DEFAULT_ARM
    base = (0.8, 0.6, 0.0)
    far = p.reachable(arm, [((2.8, 0.6, 0.8), None)], base)
    assert not far and far.reason == "out_of_reach" and far.failed_index == 0
    assert "reach" in far.message
    behind = p.reachable(arm, [((0.2, 0.4, 0.8), None)], base)  # straight behind the robot
    assert behind.reason == "joint_limit" and "outside [" in behind.message
    cooker = world.kitchen_base_pose("cooker #2")
    q = _yaw_quat(cooker.yaw)
    into_counter = p.reachable(arm, [(MUG, q), ((MUG[0], MUG[1], 0.8), q)], cooker)
    assert into_counter.reason == "collision" and into_counter.failed_index == 1
    assert len(into_counter.solutions) == 1 and "counter_back" in into_counter.message
    base_in_counter = p.reachable(arm, [(MUG, q)], (0.2, -1.2, 0.0))
    assert base_in_counter.reason == "collision" and base_in_counter.failed_index == -1
    with pytest.raises(ValueError, match="unknown arm 'middle'.*valid arms"):
        p.reachable("middle", [(MUG, q)], cooker)
    with pytest.raises(ValueError, match="at least one"):
        p.reachable(arm, [], cooker)


def test_visible_with_and_without_an_occluder(world):
    p = world.prospection()
    clear = p.visible("mug", LOOK_AT_MUG)
    assert isinstance(clear, Visibility) and clear.visible and clear.fraction > 0.9, clear
    assert p.visible(MUG_FRONT, LOOK_AT_MUG).visible  # a point
    box_home = world.item_poses.get_value()["box"]
    ok(world.move_item("box", BEHIND_MUG))
    assert (world.sim_time > world.sim_time.get_value() + 0.3).wait_for(T)  # let it settle
    try:
        hidden = p.visible("mug", LOOK_AT_MUG)
        assert not hidden.visible and hidden.fraction < 0.4 and hidden.occluders[0] == "box", hidden
        assert not p.visible(MUG_FRONT, LOOK_AT_MUG).visible
        # from beside the counter the mug is in plain view again
        assert p.visible("mug", (1.0, -0.4, math.pi)).fraction > 0.9
    finally:
        ok(world.move_item("box", box_home.position, box_home.orientation))
    with pytest.raises(ValueError, match="unknown object 'teapot'.*mug"):
        p.visible("teapot", LOOK_AT_MUG)


def test_visible_agrees_with_the_head_camera(world):
    """Prospection's answer matches what the segmentation render of the real camera shows."""
    p = world.prospection()
    start = world.base_pose.get_value()
    box_home = world.item_poses.get_value()["box"]
    ok(world.drive_to(*LOOK_AT_MUG))
    try:
        ok(world.point_head(MUG))
        here = world.base_pose.get_value()
        seen = {v.name: v.pixels for v in ok(world.perceive())}
        assert p.visible("mug", here).visible and seen.get("mug", 0) > 50
        ok(world.move_item("box", BEHIND_MUG))
        assert (world.sim_time > world.sim_time.get_value() + 0.3).wait_for(T)
        hidden = p.visible("mug", here)
        seen_hidden = {v.name: v.pixels for v in ok(world.perceive())}
        assert not hidden.visible and seen_hidden.get("mug", 0) < 0.5 * seen["mug"]
    finally:
        ok(world.move_item("box", box_home.position, box_home.orientation))
        ok(world.drive_to(start.x, start.y, start.yaw))


def test_prospection_does_not_change_the_running_world(world):
    p = world.prospection()
    arm = world.description.DEFAULT_ARM
    cooker = world.kitchen_base_pose("cooker #2")
    assert (world.sim_time > world.sim_time.get_value() + 1.5).wait_for(T)  # earlier motions settle
    before = _state(world)
    for _ in range(3):
        p.in_collision((0.2, -1.2, 0.0))  # the robot "inside" the counter
        p.reachable(arm, _grasp_sequence(cooker), cooker)
        p.reachable(arm, [((2.8, 0.6, 0.8), None)], (0.8, 0.6, 0.0))
        p.visible("mug", LOOK_AT_MUG)
    after = _state(world)
    assert after["time"] > before["time"]  # the simulation ran on meanwhile
    assert np.array_equal(after["ctrl"], before["ctrl"])  # no command
    assert np.array_equal(after["mocap"], before["mocap"])
    # the robot rests where it was (the questions put it into the counter and moved its arm)
    assert np.allclose(after["qpos"], before["qpos"], atol=5e-4)
    assert np.abs(after["qvel"]).max() < 1e-2


def test_eight_threads_give_the_same_answers_as_one(world):
    from pycram.backends.sim.prospection import SimProspection

    frozen = world._state  # one published state, so that every answer is about the same world
    p = SimProspection(world.scene, lambda: frozen)
    arm = world.description.DEFAULT_ARM
    cooker = world.kitchen_base_pose("cooker #2")
    rng = random.Random(4)
    questions = []
    for _ in range(6):
        base = (rng.uniform(-0.3, 2.5), rng.uniform(-0.9, 3.0), rng.uniform(-math.pi, math.pi))
        questions.append(("collision", base))
    questions += [
        ("collision", (0.2, -1.2, 0.0)),
        ("reach", cooker),
        ("reach", (0.29, -0.3, -1.5708)),
        ("reach", (0.8, 0.6, 0.0)),
        ("see", LOOK_AT_MUG),
        ("see", (1.0, -0.4, math.pi)),
        ("see", (2.0, 2.0, 0.5)),
    ]

    def ask(kind, base):
        if kind == "collision":
            return p.in_collision(base)
        if kind == "reach":
            return p.reachable(
                arm, _grasp_sequence(type("B", (), {"yaw": base[2] if isinstance(base, tuple) else base.yaw})), base
            )
        return p.visible("mug", base)

    alone = [ask(*q) for q in questions]
    assert any(a is True for a in alone) and any(a is False for a in alone)
    results: list = [None] * 8
    errors: list = []
    barrier = threading.Barrier(8)

    def worker(i: int) -> None:
        try:
            order = list(range(len(questions)))
            random.Random(i).shuffle(order)
            barrier.wait()
            answers = {}
            for _ in range(2):
                for k in order:
                    answers[k] = ask(*questions[k])
            results[i] = [answers[k] for k in range(len(questions))]
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=worker, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert not errors, errors
    for r in results:
        assert r == alone


def test_drivable_counts_an_arms_touch_as_the_drive_does(world):
    """Approaching the back counter with the right arm held out at counter height: the first
    pose where the fingers touch the counter by less than prospection's `COLLISION_TOLERANCE` (a
    touch arm motions may make) is one the drive refuses -- it fails on any contact -- and
    `drivable` refuses it too, with the drive's tolerance (measured: reasoning offered standing
    poses where a carried box touched the counter by 0.1 mm, every one refused by the drive as
    "goal_in_collision")."""
    p = world.prospection()
    start = world.base_pose.get_value()
    ok(world.move_arm_to("right", "pre_grasp"))
    try:
        poses = [(0.2, -0.3 - 0.01 * k, -math.pi / 2) for k in range(80)]
        brushing = next(i for i, pose in enumerate(poses) if p.in_collision(pose, objects=True, tolerance=0.0))
        assert not p.in_collision(poses[brushing], objects=True)  # within prospection's tolerance
        assert not p.drivable(poses[brushing])
        out = world.drive_to(*poses[brushing]).wait(T)
        assert out is not None and not out.succeeded and "goal_in_collision" in out.message
        outside = poses[brushing - 1]
        assert p.drivable(outside)
        ok(world.drive_to(*outside))
        ok(world.drive_to(start.x, start.y, start.yaw))
    finally:
        ok(world.move_arm_to("right", "park"))


def test_drivable_is_the_drives_own_verdict_on_a_goal(world):
    """Approaching the back counter head-on: where the robot still touches nothing, the drive
    keeps its clearance and refuses a goal; `drivable` says so before the drive does (location
    reasoning asks it, so it never offers such a goal), and agrees with it just outside."""
    p = world.prospection()
    start = world.base_pose.get_value()
    poses = [(0.2, -0.3 - 0.01 * k, -math.pi / 2) for k in range(80)]  # towards the counter
    touching = next(i for i, pose in enumerate(poses) if p.in_collision(pose))
    refused = next(i for i, pose in enumerate(poses) if not p.drivable(pose))
    assert all(p.drivable(pose) for pose in poses[:refused])
    assert refused < touching  # a gap: free in 3D, but too close for the drive
    gap, outside = poses[refused], poses[refused - 1]
    assert not p.in_collision(gap)
    out = world.drive_to(*gap).wait(T)
    assert out is not None and not out.succeeded and out.reason == "no_path" and "goal_in_collision" in out.message
    ok(world.drive_to(*outside))
    ok(world.drive_to(start.x, start.y, start.yaw))
