"""The command line's ``--robot`` options name the robots registered when a command runs, not
those registered when `pycram.apps.cli` was imported: a robot package installed later (here
written at run time, as a package outside PyCRAM registers one) is in their help and accepted;
an unknown robot is refused in one line, with exit code 2, naming the registered robots."""

from __future__ import annotations

import os
import sys
import types

import pytest
from typer.testing import CliRunner

from pycram.apps.cli import app
from pycram.testing.robot_packages import installed_robot_package
from pycram.world import robot_registry

os.environ.setdefault("MUJOCO_GL", "egl")

runner = CliRunner()

#: The robot registered at run time: the TIAGo's description under another name.
TWIN = "tiago-cli-twin"
#: The commands whose ``--robot`` option lists the registered robots (`costmap` needs a location).
COMMANDS = [["demo"], ["scene"], ["costmap", "to_reach cup"], ["experiment"]]


@pytest.fixture
def twin(tmp_path):
    """The twin, registered while the test runs (after `pycram.apps.cli` was imported)."""
    assert TWIN not in robot_registry.robot_names()
    with installed_robot_package(tmp_path, TWIN, like="tiago"):
        yield TWIN
    assert TWIN not in robot_registry.robot_names()


@pytest.fixture
def fake_demo(monkeypatch):
    """A stand-in for the thesis demo that records the options it was started with."""
    started: list[dict] = []
    fake = types.ModuleType("pycram.apps.demos.kitchen")
    fake.main = lambda **kwargs: started.append(kwargs) or 0
    monkeypatch.setitem(sys.modules, "pycram.apps.demos.kitchen", fake)
    return started


def _help(command: list[str]) -> str:
    result = runner.invoke(app, [command[0], "--help"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c[0])
def test_the_robot_option_lists_a_robot_registered_after_the_cli_was_imported(tmp_path, command):
    assert "tiago-pro" in _help(command) and TWIN not in _help(command)
    with installed_robot_package(tmp_path, TWIN, like="tiago"):
        assert TWIN in _help(command)
    assert TWIN not in _help(command)  # gone again with its package


def test_the_ros_bridge_lists_the_registered_robots_with_a_ros_interface(tmp_path):
    with (
        installed_robot_package(tmp_path / "a", TWIN, like="tiago"),
        installed_robot_package(tmp_path / "b", "tiago-without-ros", like="tiago", overrides={"ROS": None}),
    ):
        help_text = _help(["sim-ros-bridge"])
        assert TWIN in help_text  # the TIAGo's ROS interface came with its description
        assert "tiago-without-ros" not in help_text
        for name in robot_registry.robot_names():
            has_ros = robot_registry.robot_description(name).ROS is not None
            assert (f"'{name}'" in help_text) == has_ros, (name, help_text)


@pytest.mark.parametrize("command", COMMANDS[:3], ids=lambda c: c[0])
def test_an_unknown_robot_is_one_line_exit_2_naming_the_registered_robots(twin, fake_demo, command):
    result = runner.invoke(app, [*command, "--robot", "nao"], catch_exceptions=False)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    assert lines[0].startswith("error: --robot must be ") and lines[0].endswith("not 'nao'; see `pycram robot list`")
    for name in robot_registry.robot_names():
        assert f"'{name}'" in lines[0]
    assert f"'{twin}'" in lines[0]
    assert fake_demo == []


def test_the_demo_accepts_the_registered_robot(twin, fake_demo):
    result = runner.invoke(app, ["demo", "--robot", twin, "--no-record", "--quiet"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert [started["robot"] for started in fake_demo] == [twin]
