"""An action of the action library over ROS: ``Search`` finds the demo's mug with the ROS
robot's perception and belief alone (real roscore, real bridge process)."""

from __future__ import annotations

import math

import pytest

from pycram.designator import ObjectDesignator, perform


@pytest.fixture(scope="module")
def robot(pr2_with_mug):
    """The PR2 behind a bridge with the demo's mug on slot 1, active for the module."""
    return pr2_with_mug


def test_search_finds_the_mug_over_ros(robot):
    from pycram.actions import Search
    from pycram.apps.demos.kitchen_world import SLOTS

    assert robot.belief.present() == []
    found = perform(Search(ObjectDesignator(type="mug")))
    x, y = SLOTS[1]
    assert found.type == "mug" and found in robot.belief.present()
    assert math.hypot(found.pose[0] - x, found.pose[1] - y) < 0.05, found
    assert ObjectDesignator(type="mug").reference() is found
