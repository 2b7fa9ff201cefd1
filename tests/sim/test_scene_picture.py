"""`pycram scene`: a labelled picture of a random scene, and clear errors for bad input."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")
from typer.testing import CliRunner  # noqa: E402

from pycram.apps.cli import app  # noqa: E402

runner = CliRunner()


def test_scene_command_writes_a_labelled_picture(tmp_path):
    import imageio.v3 as iio

    out = tmp_path / "scene.png"
    result = runner.invoke(app, ["scene", "--env", "apartment", "--seed", "3", "-o", str(out)])
    assert result.exit_code == 0, result.output
    for name in ("cup", "bowl", "spoon", "cereal", "milk", "plate"):
        assert name in result.output  # where each object starts is listed
    image = iio.imread(out)
    assert image.shape[1] > 1200 and image.shape[0] > 500  # plan and overview side by side
    assert np.asarray(image).std() > 20  # a picture, not a blank canvas


def test_scene_command_on_the_thesis_kitchen_without_objects(tmp_path):
    out = tmp_path / "kitchen.png"
    result = runner.invoke(
        app, ["scene", "--env", "thesis-kitchen", "--objects", "", "--robot", "tiago", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert out.stat().st_size > 10_000


@pytest.mark.parametrize(
    "args, message",
    [
        (["--env", "garage"], "environment 'garage' does not exist. Available: apartment, thesis-kitchen"),
        (["--objects", "cup,fork"], "object type 'fork' does not exist. Available: bowl, cereal, cup"),
        (["--env", "thesis-kitchen", "--objects", ",".join(["cereal"] * 40)], "no free spot for 'cereal"),
    ],
)
def test_scene_command_names_bad_input(tmp_path, args, message):
    result = runner.invoke(app, ["scene", *args, "-o", str(tmp_path / "x.png")])
    assert result.exit_code == 1
    assert message in " ".join(result.output.split())
    assert not (tmp_path / "x.png").exists()


def test_costmap_command_draws_layers_and_chosen_poses(tmp_path):
    import imageio.v3 as iio

    out = tmp_path / "costmap.png"
    result = runner.invoke(app, ["costmap", "to_reach cup", "--seed", "3", "--objects", "cup,bowl", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "BaseLocation(" in result.output and "arm=" in result.output  # the poses chosen
    assert np.asarray(iio.imread(out)).std() > 20


def test_costmap_of_an_impossible_location_says_why(tmp_path):
    out = tmp_path / "none.png"
    result = runner.invoke(
        app, ["scene", "--seed", "3", "--objects", "cup", "-o", str(out), "--costmap", "in drawer 1, for cereal"]
    )
    assert result.exit_code == 0, result.output
    assert "cereal (0.28 m tall) fits on none of" in " ".join(result.output.split())
    assert out.exists()
    bad = runner.invoke(app, ["costmap", "to_reach", "-o", str(out)])
    assert bad.exit_code != 0 and "a location property is 'key value'" in bad.output


def test_scene_command_draws_the_belief_beside_the_ground_truth(tmp_path):
    import imageio.v3 as iio

    out = tmp_path / "belief.png"
    result = runner.invoke(app, ["scene", "--env", "apartment", "--seed", "3", "--belief", "-o", str(out)])
    assert result.exit_code == 0, result.output
    # seed 3: the plate and the milk stand on the table in front of the robot, in view
    assert "believed: <plate-1: white plate" in result.output and "believed: <milk-1:" in result.output
    assert "cereal-" not in result.output  # in the closed fridge: never perceived
    image = iio.imread(out)
    assert image.shape[1] > 1200 and np.asarray(image).std() > 20
