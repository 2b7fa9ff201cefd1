"""A robot from a package outside this repository: its folder and one entry-point line are all it
takes. The registry lists it, its description is validated, and the simulator builds a world with
it -- no module of PyCRAM names it."""

from __future__ import annotations

import os
import sys

import pytest

from pycram.testing.robot_packages import installed_robot_package
from pycram.world import robot_registry

os.environ.setdefault("MUJOCO_GL", "egl")

ROBOT = "tiago_twin"


@pytest.fixture
def installed_robot(tmp_path):
    """A package ``twin_robot`` with a description (the TIAGo's data under another name), and the
    distribution metadata that registers it (what `pip install` writes for a package whose
    pyproject.toml says ``[project.entry-points."pycram.robots"] tiago_twin = "twin_robot"``),
    on the import path while the test runs."""
    with installed_robot_package(tmp_path, ROBOT, like="tiago", package="twin_robot") as package:
        yield package


def test_a_robot_package_outside_pycram_is_registered_by_its_entry_point(installed_robot):
    assert ROBOT in robot_registry.robot_names()
    assert {"pr2", "tiago"} <= set(robot_registry.robot_names())
    description = robot_registry.robot_description(ROBOT)
    assert description.NAME == ROBOT
    assert description.ARMS == robot_registry.robot_description("tiago").ARMS


def test_the_simulator_builds_a_world_with_the_registered_robot(installed_robot):
    from pycram.backends.sim.scene import build_scene

    scene = build_scene(robot=ROBOT)
    assert scene.description.NAME == ROBOT
    assert scene.robot == ROBOT


def test_without_its_entry_point_the_robot_is_unknown_and_the_error_lists_the_registered_ones():
    with pytest.raises(robot_registry.UnknownRobotError, match="Available: pr2, tiago"):
        robot_registry.robot_description(ROBOT)


def test_leaving_the_block_unregisters_the_robot_and_forgets_its_modules(tmp_path):
    with installed_robot_package(tmp_path, ROBOT, like="tiago", package="twin_robot"):
        assert robot_registry.robot_description(ROBOT).NAME == ROBOT  # imports twin_robot.description
        assert "twin_robot.description" in sys.modules
    assert ROBOT not in robot_registry.robot_names()
    assert str(tmp_path) not in sys.path
    assert not [m for m in sys.modules if m.split(".")[0] == "twin_robot"]


def test_overrides_update_a_dict_key_or_replace_a_value(tmp_path):
    tiago = robot_registry.robot_description("tiago")
    overrides = {"BASE": {"kind": "omnidirectional"}, "ROS": None}
    with installed_robot_package(tmp_path, "tiago-omni", like="tiago", overrides=overrides):
        twin = robot_registry.robot_description("tiago-omni")
    assert twin.base_kinematics.kind == "omnidirectional" and tiago.base_kinematics.kind == "differential"
    assert {k: v for k, v in twin.BASE.items() if k != "kind"} == {k: v for k, v in tiago.BASE.items() if k != "kind"}
    assert twin.ROS is None and tiago.ROS is not None
    assert twin.ARMS == tiago.ARMS


def test_a_wrong_override_is_a_clear_error_and_writes_nothing(tmp_path):
    from pycram.testing.robot_packages import write_robot_package

    with pytest.raises(ValueError, match="override 'URDF': a mapping updates a dict of the description of 'tiago'"):
        write_robot_package(tmp_path, "bad", overrides={"URDF": {"x": 1}})
    with pytest.raises(ValueError, match="override 'NAME': the robot's name is the `name` argument"):
        write_robot_package(tmp_path, "bad", overrides={"NAME": "other"})
    with pytest.raises(ValueError, match="override 'BASE': .* is not plain data"):
        write_robot_package(tmp_path, "bad", overrides={"BASE": {"kind": object()}})
    with pytest.raises(ValueError, match="override 'base': description keys are UPPERCASE names"):
        write_robot_package(tmp_path, "bad", overrides={"base": {}})
    with pytest.raises(robot_registry.UnknownRobotError):
        write_robot_package(tmp_path, "bad", like="nao")
    assert list(tmp_path.iterdir()) == []


def test_a_package_with_a_description_alone_loads_as_a_simulated_robot(installed_robot, tmp_path):
    """`pycram.robots.load` makes the robot every simulated robot is (`make_sim_robot`) when the
    package has no ``robot.py``; a ``robot.py`` that fails to import says why."""
    from pycram import robots
    from pycram.sim import World

    with World(ROBOT) as world:
        robot = robots.load(ROBOT, world)
        try:
            assert robot.description.NAME == ROBOT
            assert {"navigation", "perception"} <= set(robot.process_modules)
        finally:
            robot.shutdown()
        (installed_robot / "robot.py").write_text("import no_such_module_for_pycram\n")
        with pytest.raises(ModuleNotFoundError, match="no_such_module_for_pycram"):
            robots.load(ROBOT, world)
