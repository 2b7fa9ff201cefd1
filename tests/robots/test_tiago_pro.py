"""TIAGo Pro, the third robot (issue 34, point 4): its description validates, the simulator builds
it (two arms, each with our parallel gripper in place of the URDF's PAL Pro gripper), its named
configurations put the tool where the description says, and the thesis demo runs on it unchanged
from the command line -- ``--robot tiago-pro``, a name with a dash, through the CLI, the registry
and the trace database."""

from __future__ import annotations

import os

import numpy as np
import pytest

from pycram.world.robot_registry import robot_description

pytest.importorskip("mujoco")
os.environ.setdefault("MUJOCO_GL", "egl")

ROBOT = "tiago-pro"
MIRRORED = (0, 2, 4, 6)  # joints 1, 3, 5 and 7 change sign from the right arm to the left


@pytest.fixture(scope="module")
def scene():
    from pycram.backends.sim.scene import build_scene

    return build_scene(robot=ROBOT)


def _tool_pose(scene, torso: float, configuration: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each arm's tool site (position [m], rotation matrix) in the base frame, the base at the
    origin, the torso at `torso` [m] and both arms in `configuration`."""
    import mujoco

    from pycram.backends.sim.robot_model import tool_site
    from pycram.backends.sim.scene import initial_state

    d = scene.description
    data = initial_state(scene, (0.0, 0.0, 0.0))
    data.qpos[scene.joint_qpos(d.TORSO["joint"])] = torso
    for arm, spec in d.ARMS.items():
        for joint, q in zip(spec["joints"], d.ARM_CONFIGURATIONS[arm][configuration]):
            data.qpos[scene.joint_qpos(joint)] = q
    mujoco.mj_kinematics(scene.model, data)
    out = {}
    for arm in d.ARMS:
        site = scene.model.site(tool_site(arm)).id
        out[arm] = (data.site_xpos[site].copy(), data.site_xmat[site].reshape(3, 3).copy())
    return out


def test_the_description_validates_with_two_mirrored_arms_and_an_omnidirectional_base():
    d = robot_description(ROBOT)
    assert d.NAME == ROBOT
    assert set(d.ARMS) == set(d.GRIPPERS) == {"left", "right"}
    assert d.BASE["kind"] == "omnidirectional"
    assert d.ARM_ALIASES["0"] == "left" and d.ARM_ALIASES["1"] == "right"
    assert set(d.ARM_CONFIGURATIONS["right"]) >= {"park", "carry", "pre_grasp", "carry_top", "zero"}
    for name, right in d.ARM_CONFIGURATIONS["right"].items():
        left = d.ARM_CONFIGURATIONS["left"][name]
        assert left == tuple(-q if i in MIRRORED else q for i, q in enumerate(right)), name


def test_the_simulator_mounts_a_parallel_gripper_on_each_flange_instead_of_the_pal_gripper(scene):
    import mujoco

    model = scene.model
    names = {model.body(i).name for i in range(model.nbody)}
    joints = {model.joint(i).name for i in range(model.njnt)}
    assert not {"gripper_right_base_link", "gripper_left_base_link"} & names  # the URDF's grippers
    assert not any(j.startswith("gripper_right_finger_joint") for j in joints)
    for side, g in scene.description.GRIPPERS.items():
        assert g["palm_link"] in names and g["joint"] in joints
        palm = model.body(g["palm_link"]).id
        assert model.body(model.body_parentid[palm]).name == f"arm_{side}_tool_link"
    # no coupling of a removed joint is left over; our fingers are coupled by one equality each
    joint_equalities = [e for e in range(model.neq) if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT]
    coupled = [model.joint(model.eq_obj1id[e]).name for e in joint_equalities]
    assert sorted(coupled) == sorted(j for g in scene.description.GRIPPERS.values() for j in g["coupled_joints"])


def test_the_named_configurations_put_the_tools_where_the_description_says(scene):
    d = scene.description
    up = d.TORSO_POSITIONS["up"]
    # pre_grasp: 0.75 m ahead, in line with the shoulder (0.2 m aside), 0.95 m high, pointing forward
    tools = _tool_pose(scene, up, "pre_grasp")
    for arm, sign in (("right", -1.0), ("left", 1.0)):
        position, rotation = tools[arm]
        assert np.allclose(position, (0.75, sign * 0.2, 0.95), atol=0.005), (arm, position)
        assert rotation[:, 0] @ (1.0, 0.0, 0.0) > 0.99  # the approach axis points ahead
        assert abs(rotation[2, 1]) < 0.05  # the fingers open horizontally
        assert rotation[2, 2] > 0.99  # z up: the orientation `reaching` asks of a side grasp
        assert d.REACH_POINT_IN_BASE[arm] == pytest.approx((0.75, sign * 0.2))
    # carry: 0.55 m ahead, in line with the shoulder, 1.2 m high, level with z up (an object
    # grasped from the side stays upright on its way from the grasp to carry), turned inwards
    for arm, (position, rotation) in _tool_pose(scene, up, "carry").items():
        sign = -1.0 if arm == "right" else 1.0
        assert np.allclose(position, (0.55, sign * 0.2, 1.2), atol=0.005), (arm, position)
        assert rotation[2, 2] > 0.99
        assert rotation[1, 0] * -sign > 0.8  # the approach axis turned 60 deg towards the middle
    # carry_top: the tool pointing down, the fingers opening across the heading, 0.55 m ahead,
    # 1.15 m high
    for position, rotation in _tool_pose(scene, up, "carry_top").values():
        assert rotation[:, 0] @ (0.0, 0.0, -1.0) > 0.99
        assert abs(rotation[1, 1]) > 0.99
        assert position[0] == pytest.approx(0.55, abs=0.005) and position[2] == pytest.approx(1.15, abs=0.005)
    # park: both arms tucked within the base's circumscribed radius
    for position, _ in _tool_pose(scene, d.TORSO["default"], "park").values():
        assert np.hypot(position[0], position[1]) < d.BASE["radius"]


def test_make_robot_refuses_a_world_built_for_another_robot():
    from pycram.robots.tiago_pro.robot import make_robot
    from pycram.sim import World

    with World("tiago") as world, pytest.raises(ValueError, match="needs a world with a 'tiago-pro'"):
        make_robot(world)


@pytest.mark.timeout(300)
def test_the_thesis_demo_fetches_and_places_the_mug_from_the_command_line(tmp_path):
    from typer.testing import CliRunner

    from pycram.apps.cli import app
    from pycram.trace.query import runs

    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    args = ["demo", "--robot", ROBOT, "--db", db, "-o", str(tmp_path / "out"), "--quiet", "--no-animation"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "SUCCESS: the item rests on cooker #1" in result.output
    assert "failed grasps: 0" in result.output
    (run,) = runs(db)
    assert run.robot == ROBOT and run.outcome == "succeeded"
