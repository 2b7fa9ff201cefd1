"""The compiled scene (no simulation thread): kitchen geometry, repeatable loading, model sources,
the headless GL switch, and inverse kinematics within joint limits."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest
from sim_helpers import facing_quat, to_map

from pycram.backends.sim.errors import UnknownNameError
from pycram.environments import load as load_environment
from pycram.sim import DEFAULT_ITEMS, Pose, build_scene

ROBOTS = ("pr2", "tiago")
REPO = Path(__file__).resolve().parents[2]
log = logging.getLogger(__name__)


@pytest.mark.parametrize("robot", ROBOTS)
def test_scene_loads_in_one_call_repeatably(robot):
    """Three builds in one process give equal, independent models (load time is logged, not asserted)."""
    scenes = []
    for _ in range(3):
        t0 = time.perf_counter()
        scenes.append(build_scene(robot))
        log.info("build_scene(%r): %.3f s", robot, time.perf_counter() - t0)
    a, b, _ = scenes
    assert a.model is not b.model
    assert (a.model.nq, a.model.ngeom, a.model.nbody) == (b.model.nq, b.model.ngeom, b.model.nbody)
    assert a.robot == robot and {it.name for it in a.items} == {it.name for it in DEFAULT_ITEMS}
    with pytest.raises(UnknownNameError, match="Available: pr2, tiago"):
        build_scene("r2d2")


def _box_top(model: mujoco.MjModel, geom: str) -> float:
    g = model.geom(geom)
    return float(g.pos[2] + g.size[2]) + float(model.body(int(g.bodyid[0])).pos[2])


def test_counters_are_0_9_m_high_with_two_cooker_areas():
    model = build_scene("pr2").model
    for counter in ("counter_back", "counter_left"):
        assert abs(_box_top(model, counter) - 0.9) < 0.01, counter
    kitchen = load_environment("thesis-kitchen")
    cookers = kitchen.surfaces_of_kind("cooker")
    assert [c.name for c in cookers] == ["cooker #1", "cooker #2"]
    tops = {"counter_back": None, "counter_left": None}
    for cooker in cookers:
        assert abs(cooker.height - 0.9) < 0.01
        site = model.site(cooker.name)
        x, y, z = model.site_pos[site.id] + model.body(int(site.bodyid[0])).pos
        assert abs(z - 0.9) < 0.01
        # each cooker area lies on the top of one counter, a different one for each cooker
        on = [
            n
            for n in tops
            if all(abs(v - c) <= h for v, c, h in zip((x, y), model.geom(n).pos[:2], model.geom(n).size[:2]))
        ]
        assert len(on) == 1
        assert tops[on[0]] is None
        tops[on[0]] = cooker.name
    mug = next(it for it in DEFAULT_ITEMS if it.name == "mug")
    assert 0.05 <= 2 * mug.size[0] <= 0.15 and 0.05 <= 2 * mug.size[1] <= 0.2 and 0.1 <= mug.mass <= 1.0


def test_models_come_from_installed_packages_not_the_repository():
    from pycram.backends.sim.assets import robot_data_dir

    data = robot_data_dir().resolve()
    assert Path(sys.prefix).resolve() in data.parents  # the installed example-robot-data package
    suffixes = (".stl", ".dae", ".obj", ".urdf", ".srdf", ".xml", ".png")
    tracked = subprocess.run(
        ["git", "ls-files", "pycram"], cwd=REPO, capture_output=True, text=True, check=True
    ).stdout.split()
    assert tracked and [f for f in tracked if f.lower().endswith(suffixes)] == []


def test_headless_gl_is_chosen_only_when_nothing_else_is(monkeypatch):
    from pycram.backends.sim._gl import configure_gl

    for name in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(name, raising=False)
    configure_gl()
    assert os.environ["MUJOCO_GL"] == "egl"
    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.setenv("DISPLAY", ":0")
    configure_gl()
    assert "MUJOCO_GL" not in os.environ
    monkeypatch.delenv("DISPLAY")
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    configure_gl()
    assert os.environ["MUJOCO_GL"] == "osmesa"


def test_importing_the_simulation_without_display_renders_headless(tmp_path):
    """A fresh process with neither MUJOCO_GL nor DISPLAY set can render after `import pycram.sim`."""
    env = {
        k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY", "WAYLAND_DISPLAY")
    }
    code = (
        "import os, pycram.sim, mujoco\n"
        "m = pycram.sim.build_scene('pr2').model\n"
        "r = mujoco.Renderer(m, 48, 64); d = mujoco.MjData(m); mujoco.mj_forward(m, d)\n"
        "r.update_scene(d, camera='overview'); img = r.render(); r.close()\n"
        "print(os.environ['MUJOCO_GL'], img.std() > 1)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=REPO, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[-2:] == ["egl", "True"]


@pytest.mark.parametrize("robot", ROBOTS)
def test_ik_solutions_respect_joint_limits(robot):
    from pycram.backends.sim.engine import Engine
    from pycram.backends.sim.ik import solve_ik
    from pycram.backends.sim.world import DEFAULT_BASE_POSE

    eng = Engine(build_scene(robot), DEFAULT_BASE_POSE)  # a private engine, used by this thread only
    model, arm = eng.model, eng.desc.DEFAULT_ARM
    joints = eng.desc.ARMS[arm]["joints"]
    base = eng.base_pose()
    goal = Pose(to_map(base, 0.6, -0.2, 1.0), facing_quat(base.yaw))
    solution = solve_ik(eng, arm, goal)
    assert solution is not None and solution.position_error < 0.01
    for joint, q in zip(joints, solution.positions):
        jid = eng.scene.joint_id(joint)
        if model.jnt_limited[jid]:
            lo, hi = model.jnt_range[jid]
            assert lo - 1e-9 <= q <= hi + 1e-9, (joint, q, lo, hi)
    # the same goal with every arm joint confined to +-0.05 rad of where it is: no solution
    for joint in joints:
        jid = eng.scene.joint_id(joint)
        q0 = eng.q(joint)
        model.jnt_limited[jid] = 1
        model.jnt_range[jid] = (q0 - 0.05, q0 + 0.05)
    assert solve_ik(eng, arm, goal) is None
    here = eng.site_pose(eng.tool_sites[arm])
    near = Pose(tuple(np.add(here.position, (0.0, 0.0, 0.01))), here.orientation)
    assert solve_ik(eng, arm, near, use_orientation=False) is not None  # a 1 cm step still is fine
