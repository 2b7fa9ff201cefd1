"""The action library over ROS (issue 32, point 4): ``PickUp``, ``Place``, ``Open``, ``Close`` and
``Transport`` run on the PR2 over ROS against ``pycram sim-ros-bridge`` in the apartment (real
roscore, real bridge process), with the ROS robot's own reasoning: its prospection is built from
its belief, the environment's description and its joint states (never from the simulator behind
the bridge), its location designators are resolved by the same reasoning as the simulated
robot's, and its arm motions are planned in that prospection and sent as joint trajectories.

The plan's process runs on the bridge's ``/clock`` (as a ROS node with ``use_sim_time``). Results
are judged with the simulator's truth from the bridge's simulator-only ``/pycram_sim/items``
topic (never given to the plan) and with what perception measured of the drawer.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
from ros_helpers import on_surface, robot_in_environment

from pycram.designator import ObjectDesignator, perform

pytest.importorskip("mujoco")

#: Whether arm motions are planned (the planning libraries are installed).
PLANNING = all(importlib.util.find_spec(m) is not None for m in ("ompl", "ruckig", "mink"))
#: Where the cup starts: on the apartment's counter (x, y [m, map]).
CUP_AT = (1.0, 4.55)


@pytest.fixture(scope="module")
def pr2_in_the_apartment(ros_master, transport):
    """The PR2 over ROS behind a bridge of the apartment with a cup on the counter; the plan's
    clock follows the bridge's ``/clock``."""
    yield from robot_in_environment(ros_master, transport, "pr2", "apartment", (f"cup@{CUP_AT[0]},{CUP_AT[1]}",))


def test_the_ros_robot_reasons_in_the_world_it_believes_in(pr2_in_the_apartment):
    robot, _ = pr2_in_the_apartment
    from pycram.robots.common.ros_arm_motion import RosPlannedArmModule

    prospection = robot.prospection
    assert prospection is not None and prospection.believed.names() == []  # it perceived nothing yet
    here = robot.state.base_pose.get_value()
    assert not prospection.in_collision(here)  # standing on the free floor, as it believes
    assert isinstance(robot.process_module("arm_right"), RosPlannedArmModule)


def test_open_and_close_a_drawer_over_ros(pr2_in_the_apartment):
    from pycram.actions import Close, MoveTorso, Open, ParkArms

    robot, _ = pr2_in_the_apartment
    perform(ParkArms())
    perform(MoveTorso("up"))
    measured = perform(Open("drawer 3"))
    assert measured >= 0.15 and robot.belief.container_states["drawer 3"] == pytest.approx(measured)
    measured = perform(Close("drawer 3"))
    assert measured < 0.03


def test_pick_up_place_and_transport_over_ros(pr2_in_the_apartment):
    from pycram.actions import PickUp, Place, Transport

    robot, truth = pr2_in_the_apartment
    held = perform(PickUp(ObjectDesignator(type="cup")))
    assert truth.fresh() and truth.held == {"cup": held.arm}
    obj = perform(Place(held, "table"))
    assert truth.fresh() and truth.held == {}
    assert on_surface(robot, truth, "cup", "table")
    assert math.dist(truth.fresh()["cup"][:2], obj.pose[:2]) < 0.05  # where the robot believes it
    if PLANNING:  # the arm's motions were planned in the believed world (and sent as trajectories)
        planner = robot.process_module(f"arm_{held.arm}")._motions
        assert planner is not None and planner.plans > 0 and planner.last_plans and planner.last_plans[-1]
    obj = perform(Transport(ObjectDesignator(type="cup"), "counter"))
    assert on_surface(robot, truth, "cup", "counter")
    assert math.dist(truth.fresh()["cup"][:2], obj.pose[:2]) < 0.05
