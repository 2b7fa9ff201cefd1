"""The worked example of docs/byo-robot.md: a robot from outside the repository
(`examples/byo_robot`, a Panda arm on a base composed from primitives) registered through its entry
point passes the short `pycram robot check`; its description is the one the page shows; a broken
composition fails naming the robot and the key."""

from __future__ import annotations

import contextlib
import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from pycram.world import robot_registry
from pycram.world.robot_description import RobotDescription, RobotDescriptionError

os.environ.setdefault("MUJOCO_GL", "egl")

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "byo_robot"
DESCRIPTION = EXAMPLE / "mobile_panda" / "description.py"
ROBOT = "mobile-panda"


@contextlib.contextmanager
def registered_example(folder: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The example package on the path with the distribution metadata `pip install
    examples/byo_robot` writes (its pyproject's entry point, into `folder`), registered after
    `pycram` was imported: nothing but the import path is touched; undone on exit."""
    entry = re.search(r'\[project\.entry-points\."pycram\.robots"\]\n(.+?)\n', (EXAMPLE / "pyproject.toml").read_text())
    assert entry is not None and entry.group(1).replace(" ", "") == f'{ROBOT}="mobile_panda"'
    dist = folder / "mobile_panda-0.1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: mobile-panda\nVersion: 0.1.0\n")
    (dist / "entry_points.txt").write_text(f"[pycram.robots]\n{ROBOT} = mobile_panda\n")
    monkeypatch.syspath_prepend(str(EXAMPLE))
    monkeypatch.syspath_prepend(str(folder))
    try:
        yield
    finally:
        monkeypatch.undo()
        for module in [m for m in sys.modules if m.split(".")[0] == "mobile_panda"]:
            del sys.modules[module]


@pytest.fixture
def mobile_panda(tmp_path, monkeypatch):
    """The example registered (`registered_example`) for the test."""
    with registered_example(tmp_path, monkeypatch):
        yield


def test_the_description_is_at_most_80_lines_of_data():
    lines = DESCRIPTION.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 80, f"{DESCRIPTION} has {len(lines)} lines"
    assert not any(line.startswith(("import ", "from ")) for line in lines)


def test_the_docs_page_shows_the_description_as_it_is():
    page = (REPO / "docs" / "byo-robot.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```python\n(.*?)^```", page, re.S | re.M)
    assert DESCRIPTION.read_text(encoding="utf-8") in blocks, "docs/byo-robot.md: copy the description again"


def test_a_robot_registered_after_import_is_known_everywhere_and_gone_with_its_package(tmp_path, monkeypatch):
    import pycram.backends.sim.robot_model as robot_model
    import pycram.robots as robots
    from pycram.apps.experiments.scenarios import ROBOTS as SCENARIO_ROBOTS

    lists = (robots.ROBOT_NAMES, robot_model.ROBOTS, SCENARIO_ROBOTS)
    assert all(ROBOT not in names for names in lists)
    with registered_example(tmp_path, monkeypatch):
        for names in lists:
            assert ROBOT in names and tuple(names) == robot_registry.robot_names() and names[len(names) - 1]
        assert robot_registry.robot_package(ROBOT) == "mobile_panda"
        assert robot_registry.robot_description(ROBOT).NAME == ROBOT
    assert all(ROBOT not in names for names in lists)
    with pytest.raises(robot_registry.UnknownRobotError, match="'mobile-panda' does not exist"):
        robot_registry.robot_description(ROBOT)


def test_the_short_robot_check_passes(mobile_panda):
    from pycram.apps.robot_check import PASS, run_robot_check

    assert ROBOT in robot_registry.robot_names()
    description = robot_registry.robot_description(ROBOT)
    # the arm's joints come from the Panda's URDF, the torso and head from the composition
    assert description.ARMS["arm"]["joints"] == tuple(f"panda_joint{i}" for i in range(1, 8))
    report = run_robot_check(ROBOT, short=True)
    failures = "\n".join(f"{r.check}: {r.detail}" for r in report.failures())
    assert report.passed, f"{ROBOT} failed the short check:\n{failures}"
    checks = {r.check: r for r in report.results}
    assert checks["camera sees a test object"].result == PASS
    assert checks["action: transporting"].result == PASS
    assert checks["reach: arm arm"].data["at_counter_height"][0] > 0


def test_set_gripper_takes_the_grippers_name_which_is_no_arm_name(mobile_panda):
    from pycram.actions import ActionParameterError, SetGripper
    from pycram.apps.robot_check.scene import CheckScene
    from pycram.designator import perform

    description = robot_registry.robot_description(ROBOT)
    gripper = description.ARMS["arm"]["gripper"]
    assert gripper == "hand" and "hand" not in description.ARM_ALIASES
    scene = CheckScene.open(ROBOT)
    try:
        with scene.robot:
            perform(SetGripper(gripper, 0.0))
            closed = scene.world.gripper_states[gripper].get_value().opening
            perform(SetGripper(gripper, 1.0))
            opened = scene.world.gripper_states[gripper].get_value().opening
            with pytest.raises(ActionParameterError, match="no gripper 'claw'"):
                perform(SetGripper("claw", 1.0))
    finally:
        scene.close()
    assert closed < 0.005 and opened > 0.8 * description.GRIPPERS[gripper]["max_opening"]


def test_the_composed_model_has_the_base_torso_and_head(mobile_panda):
    import mujoco

    from pycram.backends.sim.robot_model import build_robot_spec

    description = robot_registry.robot_description(ROBOT)
    model = build_robot_spec(description).compile()
    torso = model.joint("torso_lift_joint")
    assert torso.type[0] == mujoco.mjtJoint.mjJNT_SLIDE
    assert tuple(model.jnt_range[torso.id]) == pytest.approx(description.TORSO["range"])
    for joint in ("head_pan_joint", "head_tilt_joint", "panda_joint1", "panda_joint7"):
        assert model.joint(joint).type[0] == mujoco.mjtJoint.mjJNT_HINGE
    # the Panda's own hand is replaced by the parallel gripper of GRIPPER_MODEL
    names = {model.body(b).name for b in range(model.nbody)}
    assert "panda_hand" not in names and {"palm", "finger_left", "tool_link"} <= names
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    base_top = description.COMPOSITION["base"]["height"]
    assert data.body("panda_link0").xpos[2] == pytest.approx(base_top + description.COMPOSITION["torso"]["size"][2])


def _description_with(**changes):
    namespace: dict = {}
    exec(compile(DESCRIPTION.read_text(encoding="utf-8"), str(DESCRIPTION), "exec"), namespace)
    data = {k: v for k, v in namespace.items() if k.isupper()}
    composition = {part: dict(spec) for part, spec in data["COMPOSITION"].items()}
    for key, value in changes.items():
        part, entry = key.split("__")
        composition[part][entry] = value
    return RobotDescription.from_mapping({**data, "COMPOSITION": composition}, source="test")


@pytest.mark.parametrize(
    "change, message",
    [
        ({"base__shape": "sphere"}, "shapes: box, cylinder"),
        ({"base__size": (1.2, 0.48)}, r"beyond BASE\['radius'\]"),
        (
            {"torso__size": (0.16, 0.16)},
            r"COMPOSITION\['torso'\]\['size'\] \(x, y, height\) must be 3 positive numbers",
        ),
        ({"mast__height": 0.1}, "must be above the base's top"),
        ({"arm__pose": (0, 0, 0)}, "unknown key 'pose'; valid: xyz, rpy"),
    ],
)
def test_a_broken_composition_names_the_robot_and_the_key(change, message):
    with pytest.raises(RobotDescriptionError, match=message) as error:
        _description_with(**change)
    assert error.value.robot == ROBOT and error.value.key == "COMPOSITION"


def test_the_description_must_name_what_the_composition_builds():
    namespace: dict = {}
    exec(compile(DESCRIPTION.read_text(encoding="utf-8"), str(DESCRIPTION), "exec"), namespace)
    data = {k: v for k, v in namespace.items() if k.isupper()}
    data["HEAD"] = {**data["HEAD"], "pan_joint": "neck"}
    with pytest.raises(RobotDescriptionError, match=r"HEAD\[.pan_joint.\] is .neck.*head_pan_joint"):
        RobotDescription.from_mapping(data, source="test")
