"""`pycram sim-ros-bridge --environment ENV` (issue 33): the bridge's world can be a generated
apartment or a kitchen from files; a bad value is one line and exit code 2 (no ROS needed for
that); the world served is the one named, and the plan's robot is configured for it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pycram.apps.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


@pytest.mark.parametrize(
    "value, message",
    [
        ("garage", "--environment: environment 'garage' does not exist"),
        ("procedural:x", "--environment: environment 'procedural:x': the seed must be a non-negative integer"),
        ("file:/no/such/kitchen.toml", "no sidecar file '/no/such/kitchen.toml'"),
    ],
)
def test_a_bad_environment_is_one_line_and_exit_code_2(value, message):
    result = runner.invoke(app, ["sim-ros-bridge", "--environment", value])
    assert result.exit_code == 2, result.output
    assert message in result.output and len(result.output.strip().split("\n")) == 1, result.output


def test_the_demos_mug_is_refused_outside_the_thesis_kitchen():
    result = runner.invoke(app, ["sim-ros-bridge", "--env", "procedural:3", "--item-at", "1"])
    assert result.exit_code == 2 and "use --object in the procedural:3" in result.output, result.output


def test_a_kitchen_file_is_named_by_its_absolute_path(monkeypatch):
    from pycram.apps.demos.ros_kitchen_world import bridge_environment

    monkeypatch.chdir(REPO)
    sidecar = REPO / "examples" / "kitchens" / "small_kitchen.toml"
    assert bridge_environment("file:examples/kitchens/small_kitchen.toml") == f"file:{sidecar}"
    assert bridge_environment(" procedural:7 ") == "procedural:7"


def test_the_bridge_serves_the_generated_apartment_it_was_given(ros_master):
    """A bridge of procedural:1: the robot over ROS (configured by `open_ros_world` for the same
    apartment) stands at that apartment's start and believes in its furniture."""
    pytest.importorskip("mujoco")
    from pycram.apps.demos.ros_kitchen_world import open_ros_world
    from pycram.backends.ros.launch import BridgeProcess
    from pycram.environments import load

    apartment = load("procedural:1")
    assert apartment.start_pose != load("thesis-kitchen").start_pose
    bridge = BridgeProcess("pr2", ros_master.uri, item_at=None, environment="procedural:1")
    try:
        world, robot = open_ros_world("pr2", master_uri=ros_master.uri, environment="procedural:1")
        try:
            assert robot.config.environment == "procedural:1"
            assert robot.state.environment.name == "procedural:1"
            pose = robot.state.base_pose.get_value()
            x, y, yaw = apartment.start_pose
            assert math.dist((pose.x, pose.y), (x, y)) < 0.05, (pose, apartment.start_pose)
            assert abs(math.remainder(pose.yaw - yaw, math.tau)) < 0.05
        finally:
            world.close()
    finally:
        bridge.stop()
