"""Sensor values built when first read (`engine.Deferred`) and the base planner's outlines taken
for all height bands in one pass: both must give exactly what the straightforward computation
gives, at the tick they were published -- they are there for speed only (issue 31)."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")


def test_a_deferred_value_is_made_once_from_what_it_was_given():
    from pycram.backends.sim.engine import Deferred

    calls = []
    source = np.array([1.0, 2.0])

    def make(values: np.ndarray) -> list[float]:
        calls.append(1)
        return values.tolist()

    value = Deferred(make, source.copy())
    source[:] = 9.0  # what it was given was a copy: later changes do not matter
    first = value()
    assert first == [1.0, 2.0] and value() is first and len(calls) == 1


def _eager(world):
    """The sensor values computed at once in the simulation thread, as `_publish` did before."""
    from pycram.backends.sim.handle import _wait_wall
    from pycram.world.types import JointStates

    def probe(eng):
        d = eng.data
        joints = JointStates(
            eng.time,
            {name: float(d.qpos[q]) for name, q, _ in eng.robot_joints},
            {name: float(d.qvel[v]) for name, _, v in eng.robot_joints},
        )
        tools = {arm: eng.site_pose(site) for arm, site in eng.tool_sites.items()}
        items = {name: eng.item_pose(name) for name in eng.item_bodies}
        return eng.time, joints, tools, items, eng.furniture.positions(d)

    handle = world._call("probe", probe)
    _wait_wall(handle, 30.0)
    assert handle.outcome is not None and handle.outcome.succeeded, handle.outcome
    return handle.outcome.value


@pytest.mark.parametrize("robot", ["pr2", "tiago"])
def test_published_values_are_those_of_their_tick_whenever_they_are_read(robot):
    from pycram.sim import World

    with World(robot, objects=["cup", "bowl"], environment="apartment", seed=2, stepping="free") as world:
        world.hold_at(0.5)
        assert world.held.wait(30.0)
        published = {
            name: getattr(world, name)._value
            for name in ("joint_states", "tool_poses", "item_poses", "container_states")
        }
        stamp, joints, tools, items, containers = _eager(world)
        assert world.sim_time.get_value() == stamp
        # read now, while the world stands where they were published: exactly the eager values
        assert world.joint_states.get_value() == joints and world.joint_states.get_value().stamp == stamp
        assert world.tool_poses.get_value() == tools
        assert world.item_poses.get_value() == items and set(items) == {"cup", "bowl"}
        assert world.container_states.get_value() == containers
        assert world.joint_states.get_value() is world.joint_states.get_value()  # built once
        world.release()
        assert (world.sim_time > stamp + 0.3).wait_for(30.0)
        # a value published then and read only now still shows its own tick, not the present
        late = published["joint_states"]
        assert callable(late) and late().stamp == stamp and late() == joints
        assert world.joint_states.get_value().stamp > stamp
        assert published["tool_poses"]() == tools and published["item_poses"]() == items


@pytest.mark.parametrize("robot", ["pr2", "tiago"])
def test_outlines_of_all_bands_in_one_pass_are_those_of_each_band_alone(robot):
    """`body_outlines` shares work between heights (each geom placed once, a part's outline
    taken once for heights that keep the same points): the footprints must be exactly those of
    each height computed alone, over many arm configurations."""
    import mujoco

    from pycram.backends.sim.engine import Engine
    from pycram.backends.sim.occupancy import body_outlines, build_floor_map, robot_parts
    from pycram.backends.sim.scene import build_scene
    from pycram.environments import load

    scene = build_scene(robot, [], (64, 48), load("apartment"))
    eng = Engine(scene, (1.0, 1.0, 0.0))
    model, data = eng.model, eng.data
    parts = robot_parts(scene)
    heights = [top + 0.02 for top in build_floor_map(scene, data).bands(model, data)]
    assert len(heights) > 5
    rng = np.random.default_rng(7)
    for _ in range(12):
        for name, address, _ in eng.robot_joints:
            jid = scene.joint_id(name)
            if model.jnt_limited[jid] and not name.startswith("base"):
                lo, hi = model.jnt_range[jid]
                data.qpos[address] = rng.uniform(lo, hi)
        mujoco.mj_kinematics(model, data)
        together = body_outlines(scene, data, heights, parts)
        for height in heights:
            alone = body_outlines(scene, data, [height], parts)[height]
            assert together[height] == alone
        # taller bands see more of the robot: the outlines grow (or stay) with the height
        areas = [sum(_area(f.vertices) for f in together[h]) for h in heights]
        assert areas[-1] >= areas[0] - 1e-9


def _area(vertices) -> float:
    return 0.5 * abs(math.fsum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(vertices, vertices[1:] + vertices[:1])))
