"""Random scenes built for real: objects settle where they were placed (none falls or tips),
objects inside a drawer ride out with it, the head camera sees multi-part objects, and the same
seed builds the same world."""

from __future__ import annotations

import math

import pytest
from sim_helpers import ok, settle, tilt

from pycram.sim import ItemSpec, World
from pycram.world.objects import object_type
from pycram.world.scenes import random_scene

BREAKFAST = ["cup", "bowl", "spoon", "cereal", "milk", "plate"]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_objects_of_a_random_scene_settle_where_they_were_placed(seed):
    with World("tiago", environment="apartment", seed=seed, objects=BREAKFAST + ["cup", "bowl"]) as world:
        assert [p.name for p in world.placements] == BREAKFAST + ["cup 2", "bowl 2"]
        assert {it.name for it in world.scene.items} == {p.name for p in world.placements}
        settle(world, 2.0)
        poses = world.item_poses.get_value()
        for p in world.placements:
            pose = poses[p.name]
            assert math.dist(pose.position, p.position) < 0.01, (seed, p, pose)
            assert tilt(pose.orientation) < math.radians(3), (seed, p)


def test_the_same_seed_builds_the_same_world():
    a = World("pr2", environment="apartment", seed=11, objects=BREAKFAST, activate_clock=False)
    b = World("pr2", environment="apartment", seed=11, objects=BREAKFAST, activate_clock=False)
    c = World("pr2", environment="apartment", seed=12, objects=BREAKFAST, activate_clock=False)
    try:
        assert a.placements == b.placements
        assert (a.scene.model.qpos0 == b.scene.model.qpos0).all()  # the compiled initial state
        assert a.scene.model.nbody == b.scene.model.nbody
        assert (a.scene.model.qpos0 != c.scene.model.qpos0).any()
    finally:
        for w in (a, b, c):
            w.close()


def test_objects_in_a_drawer_ride_out_with_it():
    from pycram import environments

    apartment = environments.load("apartment")
    scene = random_scene(apartment, ["cup", "spoon", "bowl"], seed=4, supports=["drawer 2 inside"])
    items = [ItemSpec.of(object_type(p.type), p.name, p.position, p.yaw) for p in scene]
    with World("pr2", items, environment="apartment") as world:
        settle(world, 1.0)
        before = world.item_poses.get_value()
        ok(world.push_container("drawer 2", (40.0, 0.0, 0.0), 0.4))
        settle(world, 1.0)
        opened = world.container_states.get_value()["drawer 2"]
        assert opened > 0.08
        after = world.item_poses.get_value()
        for p in scene:  # carried along by friction, still upright in the drawer
            dx = after[p.name].position[0] - before[p.name].position[0]
            assert dx == pytest.approx(opened, abs=0.02), p.name
            assert tilt(after[p.name].orientation) < math.radians(5), p.name


def test_the_head_camera_sees_a_bowl_made_of_several_parts():
    items = [
        ItemSpec.of(object_type("bowl"), "bowl", (4.3, 1.8, None)),
        ItemSpec.of(object_type("plate"), "plate", (4.0, 1.8, None)),
    ]
    with World("pr2", items, environment="apartment", base_pose=(4.3, 0.9, math.pi / 2)) as world:
        ok(world.point_head((4.15, 1.8, 0.75)))
        seen = {v.name: v for v in ok(world.perceive())}
        assert {"bowl", "plate"} <= set(seen)
        assert seen["bowl"].type == "bowl" and seen["bowl"].pixels > 100
