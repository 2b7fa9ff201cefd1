"""A robot from a package outside this repository: its folder and one entry-point line are all it
takes. The registry lists it, its description is validated, and the simulator builds a world with
it -- no module of PyCRAM names it."""

from __future__ import annotations

import importlib.util
import os
import textwrap

import pytest

from pycram.world import robot_registry

os.environ.setdefault("MUJOCO_GL", "egl")

ROBOT = "tiago_twin"


@pytest.fixture
def installed_robot_package(tmp_path, monkeypatch):
    """A package ``twin_robot`` with a description (the TIAGo's data under another name), and the
    distribution metadata that registers it (what `pip install` writes for a package whose
    pyproject.toml says ``[project.entry-points."pycram.robots"] tiago_twin = "twin_robot"``)."""
    package = tmp_path / "twin_robot"
    package.mkdir()
    (package / "__init__.py").write_text('"""A robot package outside PyCRAM."""\n')
    source = importlib.util.find_spec(robot_registry.robot_package("tiago") + ".description").origin
    text = open(source, encoding="utf-8").read()
    assert 'NAME = "tiago"\n' in text
    (package / "description.py").write_text(text.replace('NAME = "tiago"\n', f'NAME = "{ROBOT}"\n'))
    dist = tmp_path / "twin_robot-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: twin-robot\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(
        textwrap.dedent(
            f"""\
            [pycram.robots]
            {ROBOT} = twin_robot
            """
        )
    )
    monkeypatch.syspath_prepend(str(tmp_path))  # the registry reads the entry points again
    yield
    monkeypatch.undo()


def test_a_robot_package_outside_pycram_is_registered_by_its_entry_point(installed_robot_package):
    assert ROBOT in robot_registry.robot_names()
    assert {"pr2", "tiago"} <= set(robot_registry.robot_names())
    description = robot_registry.robot_description(ROBOT)
    assert description.NAME == ROBOT
    assert description.ARMS == robot_registry.robot_description("tiago").ARMS


def test_the_simulator_builds_a_world_with_the_registered_robot(installed_robot_package):
    from pycram.backends.sim.scene import build_scene

    scene = build_scene(robot=ROBOT)
    assert scene.description.NAME == ROBOT
    assert scene.robot == ROBOT


def test_without_its_entry_point_the_robot_is_unknown_and_the_error_lists_the_registered_ones():
    with pytest.raises(robot_registry.UnknownRobotError, match="Available: pr2, tiago"):
        robot_registry.robot_description(ROBOT)
