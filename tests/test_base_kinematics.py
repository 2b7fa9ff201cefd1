"""Base kinematics (pycram.world.base_kinematics) and the path planner for a differential drive:
every step of a plan is a turn on the spot or a straight drive along the heading."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pycram.world.base_kinematics import BaseKinematics, is_primitive, move_options
from pycram.world.navigation import Footprint, OccupancyGrid, PathPlanner
from pycram.world.prospection import BasePose
from pycram.world.robot_description import RobotDescription, RobotDescriptionError
from pycram.world.robot_registry import robot_description

RES = 0.05
DIFF = BaseKinematics("differential", max_reverse=0.5, approach=0.3)


def room(walls: list[tuple[float, float, float, float]], size: float = 6.0) -> OccupancyGrid:
    n = int(size / RES)
    centres = (np.arange(n) + 0.5) * RES
    X, Y = np.meshgrid(centres, centres)
    occ = np.zeros((n, n), bool)
    for x0, y0, x1, y1 in walls:
        occ |= (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
    return OccupancyGrid((0.0, 0.0), RES, occ)


def _all_primitive(start: BasePose, path: list[BasePose]) -> bool:
    prev = start
    for p in path:
        if not is_primitive(prev, p):
            return False
        prev = p
    return True


def test_an_omnidirectional_base_moves_in_one_straight_line():
    a, b = BasePose(0, 0, 0), BasePose(0, 1, 0.3)
    assert move_options(a, b, BaseKinematics()) == [[b]]
    assert not is_primitive(a, b)  # sideways: no move for a differential drive


def test_a_differential_drive_turns_drives_and_turns():
    a, b = BasePose(0, 0, 0), BasePose(0, 1, 0)
    options = move_options(a, b, DIFF)
    first = options[0]
    assert [round(p.yaw, 6) for p in first] == [round(math.pi / 2, 6), round(math.pi / 2, 6), 0.0]
    assert first[-1] == b
    for option in options:
        assert option[-1] == b and _all_primitive(a, option)


def test_backwards_only_within_max_reverse():
    a = BasePose(0, 0, 0)
    near, far = BasePose(-0.4, 0, 0), BasePose(-0.8, 0, 0)
    # straight back 0.4 m: the backwards option, no turn at all
    assert [BasePose(-0.4, 0, 0)] in move_options(a, near, DIFF)
    assert all(len(o) > 1 for o in move_options(a, far, DIFF))  # too far to back up: it turns


def test_a_bad_base_kind_names_the_key_and_the_choices():
    data = {k: getattr(robot_description("tiago"), k) for k in RobotDescription.keys()}
    data["BASE"] = {**data["BASE"], "kind": "tracked"}
    with pytest.raises(RobotDescriptionError, match="BASE.*'tracked'.*omnidirectional, differential"):
        RobotDescription.from_mapping(data)


def test_every_registered_robot_names_a_base_kind():
    from pycram.world.base_kinematics import KINDS
    from pycram.world.robot_registry import robot_names

    for name in robot_names():
        assert robot_description(name).base_kinematics.kind in KINDS
    assert robot_description("pr2").base_kinematics.holonomic


def test_a_differential_plan_has_only_turns_and_straight_drives():
    grid = room([(2.9, 0.0, 3.1, 4.5), (2.9, 5.5, 3.1, 6.0)])  # a wall with a gap at y 4.5-5.5
    planner = PathPlanner(grid, Footprint.circle(0.25), kinematics=DIFF)
    start, goal = BasePose(1.0, 1.0, 0.0), BasePose(5.0, 1.0, -math.pi / 2)
    path = planner.plan(start, goal)
    assert path[-1] == goal
    assert _all_primitive(start, path)
    assert planner.path_free(start, path)
    # the same question gives the same answer
    assert planner.plan(start, goal) == path


def test_a_narrow_bay_is_entered_straight():
    """A long footprint fits a 0.5 m wide bay only facing along it: the robot cannot turn inside,
    so it turns in front of the bay and drives straight in (the `approach` option)."""
    bay = [(2.0, 0.0, 4.0, 2.7), (2.0, 3.3, 4.0, 6.0), (4.0, 0.0, 4.2, 6.0)]
    long_robot = Footprint.rectangle(-0.35, -0.15, 0.35, 0.15)
    planner = PathPlanner(room(bay), long_robot, clearance=0.02, kinematics=DIFF)
    start, goal = BasePose(1.0, 1.5, math.pi / 2), BasePose(3.4, 3.0, 0.0)
    path = planner.plan(start, goal)
    assert _all_primitive(start, path)
    # no turn on the spot inside the bay: every pose there faces along it
    assert all(abs(math.remainder(p.yaw, math.pi)) < 0.02 for p in path if p.x > 2.0)
    # from the room, off the bay's axis: driving straight at a pose in the bay enters it at an
    # angle; arriving straight along the goal's heading (from 0.9 m before it) fits
    a, inside = BasePose(1.0, 2.0, 0.0), BasePose(2.5, 3.0, 0.0)
    approach = BaseKinematics("differential", max_reverse=0.5, approach=0.9)
    assert PathPlanner(room(bay), long_robot, clearance=0.02, kinematics=approach).segment_free(a, inside)
    no_approach = BaseKinematics("differential", max_reverse=0.5, approach=0.0)
    assert not PathPlanner(room(bay), long_robot, clearance=0.02, kinematics=no_approach).segment_free(a, inside)


def test_a_differential_drive_backs_out_of_a_dead_end_before_it_turns():
    """In a dead end too narrow to turn in, facing its closed end, the robot must back out
    before it can turn: the cell search (which knows no headings) finds no such path, the
    search over headings does; every step is a turn on the spot or a straight drive."""
    dead_end = [(2.0, 0.0, 4.0, 2.7), (2.0, 3.3, 4.0, 6.0), (4.0, 0.0, 4.2, 6.0)]
    long_robot = Footprint.rectangle(-0.35, -0.15, 0.35, 0.15)
    planner = PathPlanner(room(dead_end), long_robot, clearance=0.02, kinematics=DIFF)
    start, goal = BasePose(3.4, 3.0, 0.0), BasePose(1.0, 1.0, -math.pi / 2)
    path = planner.plan(start, goal)
    assert path[-1] == goal
    assert _all_primitive(start, path)
    assert planner.path_free(start, path)
    # it left the dead end backwards, facing its end, and turned only outside it
    prev = start
    for p in path:
        if abs(math.remainder(p.yaw - prev.yaw, 2 * math.pi)) > 0.1:
            assert p.x < 2.0 - 0.3, (prev, p)
        prev = p


def test_turning_round_in_a_dead_end_takes_backing_out_and_coming_back():
    """Facing the closed end of a dead end too narrow to turn in, and asked to face the other
    way at the same spot: only backing out, turning outside and driving back in does it. The
    cell search knows no headings; the search over headings (`_lattice`) finds it."""
    dead_end = [(2.0, 0.0, 4.0, 2.7), (2.0, 3.3, 4.0, 6.0), (4.0, 0.0, 4.2, 6.0)]
    long_robot = Footprint.rectangle(-0.35, -0.15, 0.35, 0.15)
    planner = PathPlanner(room(dead_end), long_robot, clearance=0.02, kinematics=DIFF)
    start, goal = BasePose(3.4, 3.0, 0.0), BasePose(3.4, 3.0, math.pi)
    path = planner.plan(start, goal)
    assert path[-1] == goal
    assert _all_primitive(start, path)
    assert planner.path_free(start, path)
    assert min(p.x for p in path) < 2.0  # out of the dead end and back


def test_a_differential_drive_moves_on_arcs_or_turns_then_drives():
    """From where a drive ended a little off its line the next move is an arc through the goal
    (then a small turn); a goal far to the side is turn, drive, turn."""
    from pycram.world.base_kinematics import arc_pose, arc_radius, drive_moves

    here = BasePose(0.0, 0.0, 0.0)
    slightly_off = BasePose(1.0, 0.1, 0.0)
    moves = drive_moves(here, slightly_off, DIFF)
    assert len(moves) == 2 and arc_radius(here, moves[0]) is not None and moves[-1] == slightly_off
    mid = arc_pose(here, moves[0], 0.5)  # on the arc, the robot faces along it
    assert math.hypot(mid.x, mid.y - arc_radius(here, moves[0])) == pytest.approx(abs(arc_radius(here, moves[0])))
    aside = BasePose(0.0, 1.0, 0.0)
    assert len(drive_moves(here, aside, DIFF)) == 3  # turn, drive, turn
    assert drive_moves(here, aside, BaseKinematics()) == [aside]


def test_a_goal_within_reach_is_reached_by_turning_on_the_spot():
    """Measured on the TIAGo: a drive stopped 1.3 mm beside its goal, whose heading was 76 deg
    away; the next move turned 110 deg towards that offset (the direction of 1.3 mm), drove it
    and turned back, swinging a held cup into the fridge. A goal within `reach` is one turn."""
    from pycram.world.base_kinematics import drive_moves

    here = BasePose(2.27414, 3.87399, 2.7952)
    goal = BasePose(2.275, 3.875, 1.5282)
    assert len(drive_moves(here, goal, DIFF)) == 3  # without a reach: towards the offset and back
    (turn,) = drive_moves(here, goal, DIFF, reach=0.005)
    assert (turn.x, turn.y, turn.yaw) == (here.x, here.y, goal.yaw)
    assert len(drive_moves(here, BasePose(2.4, 3.875, 1.5282), DIFF, reach=0.005)) > 1  # farther: driven
