"""Planned arm motions over ROS (issue 32, point 4): the ROS robot plans its arm's path in the
world it believes in and sends it as one multi-point ``FollowJointTrajectory`` goal; the bridge's
controller follows it point by point and stops the arm on an unexpected contact; the robot then
backs off, looks, and plans again around what it now perceives (real roscore, real bridge
process).

The PR2 stands at the apartment's dining table with a cereal box on it that the robot has never
perceived. Its right arm moves the tool from the right of the box to its left: the path planned
in the believed world (without the box) runs through it.
"""

from __future__ import annotations

import math

import pytest
from ros_helpers import robot_in_environment

pytest.importorskip("mujoco")
pytest.importorskip("ompl")
pytest.importorskip("ruckig")
pytest.importorskip("mink")

BASE = (4.3, 1.15, math.pi / 2)  # facing the table's south edge (y = 1.55), 0.4 m from it
FORWARD = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # tool pointing north (+y)
BOX = (4.13, 1.85)  # the cereal box, standing on the table
START, GOAL = (4.27, 1.78, 0.83), (3.99, 1.78, 0.83)  # tool positions either side of the box
ARM = "right"


@pytest.fixture(scope="module")
def pr2_at_the_table(ros_master, transport):
    yield from robot_in_environment(ros_master, transport, "pr2", "apartment", (f"cereal@{BOX[0]},{BOX[1]}",), BASE)


def test_a_trajectory_stopped_on_an_unperceived_box_is_planned_again_around_it(pr2_at_the_table):
    from pycram.designator import MotionDesignator, perform

    robot, truth = pr2_at_the_table
    base = robot.state.base_pose.get_value()
    start = robot.prospection.solve_ik(ARM, (START, FORWARD), base)
    assert start, start
    assert robot.belief.objects() == []  # nobody looked: the box is not in the believed world
    perform(MotionDesignator(type="setting_arm_joints", arm=ARM, positions=list(start.positions)))
    before = truth.fresh()["cereal"]
    reached = perform(MotionDesignator(type="reaching", arm=ARM, target=list(GOAL), orientation=list(FORWARD)))
    assert math.dist(reached.position, GOAL) < 0.01
    planner = robot.process_module(f"arm_{ARM}")._motions
    (stop,) = planner.last_stops  # the bridge's controller stopped the arm on the box
    assert stop.reason == "collision" and "cereal" in stop.message, stop
    assert stop.outcome.value is not None and len(stop.outcome.value.positions) == len(planner.joints)
    assert [o.type for o in robot.belief.objects()] == ["cereal"]  # it looked where it stopped
    assert planner.last_plans[-1] and planner.last_plans[-1].planner == "RRTConnect"  # around the box
    after = truth.fresh()["cereal"]
    assert math.dist(after[:2], before[:2]) < 0.03 and truth.tilts["cereal"] < math.radians(10)  # a soft hit


def test_a_timed_path_becomes_one_trajectory_goal_and_bad_samples_are_refused(transport):
    from pycram.backends.ros.modules import path_goal

    joints = ("a", "b")
    goal = path_goal(transport, joints, [(0.0, (0.0, 0.1)), (0.5, (0.2, 0.3)), (1.0, (0.4, 0.5))])
    points = goal.trajectory.points
    assert list(goal.trajectory.joint_names) == list(joints) and len(points) == 3
    assert [p.time_from_start.to_sec() for p in points] == [0.0, 0.5, 1.0]
    assert list(points[1].positions) == [0.2, 0.3] and list(points[-1].velocities) == [0.0, 0.0]  # ends at rest
    with pytest.raises(ValueError, match="at least one sample"):
        path_goal(transport, joints, [])
    with pytest.raises(ValueError, match="2 joints"):
        path_goal(transport, joints, [(0.0, (0.0,))])
    with pytest.raises(ValueError, match="times must increase"):
        path_goal(transport, joints, [(0.5, (0.0, 0.0)), (0.5, (0.1, 0.1))])
    with pytest.raises(ValueError, match="finite"):
        path_goal(transport, joints, [(0.0, (0.0, math.inf))])
