"""What a new user trips over (issue 33, section 4): the action library's parameters are checked
like `PickUp`'s, at once where no world is needed, and the errors name the valid values.

Constructor checks need no world; the others run the apartment with the PR2 (`action_helpers`).
"""

from __future__ import annotations

import math

import pytest
from action_helpers import COUNTER, apartment_with

from pycram.actions import ActionParameterError, Detect, Navigate, PickUp, Search, Transport
from pycram.designator import LocationDesignator, ObjectDesignator, perform
from pycram.failures import GraspFailed
from pycram.world.objects import APPROACHES, OBJECT_TYPES

# -- refused at once, without a world ---------------------------------------------------------------


@pytest.mark.parametrize(
    "make", [lambda g: PickUp(ObjectDesignator(type="cup"), grasp=g), lambda g: Transport("cup", "table", grasp=g)]
)
def test_an_unknown_grasp_is_refused_at_once_naming_the_approaches(make):
    with pytest.raises(ActionParameterError, match=r"parameter 'grasp': no grasp approach 'topp'") as caught:
        make("topp")
    assert caught.value.choices == list(APPROACHES)


@pytest.mark.parametrize(
    "make",
    [
        lambda: Transport("mugg", LocationDesignator([("on", "table")])),
        lambda: Transport(ObjectDesignator(type="mugg"), "table"),
        lambda: PickUp(ObjectDesignator(type="mugg")),
        lambda: PickUp("mugg"),
        lambda: Search("mugg"),
        lambda: Search(ObjectDesignator(type="mugg")),
        lambda: Detect(ObjectDesignator(type="mugg")),
    ],
)
def test_an_unknown_object_type_is_refused_at_once_naming_the_types(make):
    with pytest.raises(
        ActionParameterError, match=r"parameter 'object': unknown object type 'mugg' \(valid: bowl, "
    ) as caught:
        make()
    assert caught.value.choices == sorted(OBJECT_TYPES)


def test_transport_takes_grasp_and_arm_like_pick_up():
    designator = Transport("cup", "table", arm="left", grasp="side")
    assert designator.prop_value("grasp") == "side" and designator.prop_value("arm") == "left"
    # a believed object's name stays possible where a look takes names (Detect)
    assert Detect("cup 2").prop_value("object") == "cup 2"


# -- checked when performed, with the robot ---------------------------------------------------------


def test_transport_passes_its_grasp_and_checks_its_arm():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        with pytest.raises(ActionParameterError, match=r"transporting: parameter 'arm'.*valid: .*left"):
            perform(Transport(ObjectDesignator(type="cup"), LocationDesignator([("on", "table")]), arm="third"))
        # the cup has no +x grasp: the pick-up inside the transport was asked for that one
        with pytest.raises(GraspFailed, match=r"cannot execute a grasp \+x of a cup") as caught:
            perform(Transport(ObjectDesignator(type="cup"), LocationDesignator([("on", "table")]), grasp="+x"))
        assert caught.value.reason == "no_executable_grasp"


def test_navigate_takes_a_named_place_like_look_at():
    with apartment_with("pr2", {"cup": COUNTER}) as (world, robot):
        x, y, yaw = world.environment.place("table north").pose
        reached = perform(Navigate("table north"))
        assert math.hypot(reached.x - x, reached.y - y) < 0.05
        with pytest.raises(ActionParameterError, match=r"'tabel north' is not a place.*valid: .*table north"):
            perform(Navigate("tabel north"))
        with pytest.raises(ActionParameterError, match=r"a place, not a surface .*\('to_see', 'table'\)"):
            perform(Navigate("table"))


# -- pycram scene --supports ------------------------------------------------------------------------


def test_scene_takes_supports(tmp_path):
    pytest.importorskip("matplotlib")
    from typer.testing import CliRunner

    from pycram.apps.cli import app

    runner = CliRunner()
    out = tmp_path / "scene.png"
    args = ["scene", "--seed", "3", "--objects", "cup,bowl,milk", "--supports", "table, counter", "-o", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    starts = [line.split()[-1] for line in result.output.splitlines() if line.startswith("  ")]
    assert len(starts) == 3 and set(starts) <= {"table", "counter"}, result.output
    assert out.exists()
    bad = runner.invoke(app, ["scene", "--objects", "cup", "--supports", "tabel", "-o", str(tmp_path / "x.png")])
    assert bad.exit_code == 1
    assert "surface 'tabel' does not exist. Available: cabinet top" in " ".join(bad.output.split())
