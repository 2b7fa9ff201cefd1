"""The backend-neutral base path planner (pycram.world.navigation) on hand-made grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pycram.world.navigation import Footprint, NoPathError, OccupancyGrid, PathPlanner, dilate
from pycram.world.prospection import BasePose

RES = 0.05


def room(walls: list[tuple[float, float, float, float]], size: float = 6.0) -> OccupancyGrid:
    """A size x size m grid from (0, 0) with the axis-aligned boxes (x0, y0, x1, y1) occupied."""
    n = int(size / RES)
    occ = np.zeros((n, n), bool)
    centres = (np.arange(n) + 0.5) * RES
    X, Y = np.meshgrid(centres, centres)
    for x0, y0, x1, y1 in walls:
        occ |= (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
    return OccupancyGrid((0.0, 0.0), RES, occ)


SQUARE = Footprint.rectangle(-0.3, -0.3, 0.3, 0.3)
#: a wall across the room at x = 3 with a 1 m gap at y in [4.5, 5.5]
WALL_WITH_GAP = [(2.9, 0.0, 3.1, 4.5), (2.9, 5.5, 3.1, 6.0)]


def _check_path(planner: PathPlanner, start: BasePose, path: list[BasePose]) -> None:
    prev = start
    for p in path:
        assert planner.segment_free(prev, p)
        prev = p


def test_dilate_matches_brute_force():
    rng = np.random.default_rng(0)
    mask = rng.random((40, 50)) > 0.97
    out = dilate(mask, 3.5)
    rr, cc = np.nonzero(mask)
    R, C = np.mgrid[0:40, 0:50]
    expected = np.zeros_like(mask)
    for r, c in zip(rr, cc):
        expected |= (R - r) ** 2 + (C - c) ** 2 <= 3.5**2
    assert np.array_equal(out, expected)


def test_footprint_radii():
    assert SQUARE.inscribed_radius == pytest.approx(0.3)
    assert SQUARE.circumscribed_radius == pytest.approx(0.3 * math.sqrt(2))
    circle = Footprint.circle(0.25)
    assert circle.inscribed_radius == pytest.approx(0.25)


def test_the_straight_line_when_it_is_free():
    planner = PathPlanner(room([]), SQUARE)
    goal = BasePose(5.0, 4.0, 1.0)
    assert planner.plan((1.0, 1.0, 0.0), goal) == [goal]


def test_around_a_wall_through_its_gap():
    planner = PathPlanner(room(WALL_WITH_GAP), SQUARE)
    start, goal = BasePose(1.0, 1.0, 0.0), BasePose(5.0, 1.0, math.pi / 2)
    path = planner.plan(start, goal)
    assert path[-1] == goal and len(path) >= 2
    crossings = [
        p.y + (q.y - p.y) * (3.0 - p.x) / (q.x - p.x)
        for p, q in zip([start] + path, path)
        if (p.x - 3.0) * (q.x - 3.0) < 0
    ]
    assert len(crossings) == 1 and 4.5 < crossings[0] < 5.5  # through the gap
    _check_path(planner, start, path)
    assert planner.plan(start, goal) == path  # deterministic


def test_a_gap_too_narrow_for_the_footprint_is_no_path():
    narrow = [(2.9, 0.0, 3.1, 2.7), (2.9, 3.2, 3.1, 6.0)]  # 0.5 m gap, robot 0.6 m wide
    planner = PathPlanner(room(narrow), SQUARE)
    with pytest.raises(NoPathError) as info:
        planner.plan((1.0, 3.0, 0.0), (5.0, 3.0, 0.0))
    assert info.value.reason == "no_path" and "no collision-free path" in str(info.value)
    # the round robot of 0.2 m radius fits through
    small = PathPlanner(room(narrow), Footprint.circle(0.2), clearance=0.0)
    _check_path(small, BasePose(1.0, 3.0, 0.0), small.plan((1.0, 3.0, 0.0), (5.0, 3.0, 0.0)))


def test_goal_in_collision_and_off_the_map():
    planner = PathPlanner(room(WALL_WITH_GAP), SQUARE)
    with pytest.raises(NoPathError) as info:
        planner.plan((1.0, 1.0, 0.0), (3.0, 1.0, 0.0))
    assert info.value.reason == "goal_in_collision"
    with pytest.raises(NoPathError) as info:
        planner.plan((1.0, 1.0, 0.0), (9.0, 1.0, 0.0))  # straight line crosses the wall
    assert info.value.reason == "outside_map"


def test_heading_matters_for_a_long_footprint():
    """A 1.2 m x 0.4 m robot passes a 0.7 m gap lengthwise only."""
    long = Footprint.rectangle(-0.6, -0.2, 0.6, 0.2)
    gap = [(2.9, 0.0, 3.1, 2.65), (2.9, 3.35, 3.1, 6.0)]
    planner = PathPlanner(room(gap), long, clearance=0.0)
    assert planner.pose_free(3.0, 3.0, 0.0) and not planner.pose_free(3.0, 3.0, math.pi / 2)
    start = BasePose(1.0, 3.0, 0.0)
    path = planner.plan(start, (5.0, 3.0, 0.0))
    _check_path(planner, start, path)


def test_a_robot_touching_a_wall_can_still_leave():
    planner = PathPlanner(room([(0.0, 0.0, 0.1, 6.0)]), SQUARE)
    start = BasePose(0.38, 3.0, 0.0)  # its back edge 2 cm into the wall's clearance
    assert not planner.pose_free(start.x, start.y, start.yaw)
    assert planner.plan(start, (3.0, 3.0, 0.0))[-1] == BasePose(3.0, 3.0, 0.0)


def test_squared_distances_are_exact_within_reach_and_follow_the_mask_content():
    from pycram.world.navigation import squared_distances

    rng = np.random.default_rng(1)
    mask = rng.random((30, 45)) > 0.98
    rr, cc = np.nonzero(mask)
    R, C = np.mgrid[0:30, 0:45]
    brute = np.min([(R - r) ** 2 + (C - c) ** 2 for r, c in zip(rr, cc)], axis=0)
    for reach in (2.0, 6.5, 4.0, 13.0):  # asking farther than before computes again
        d2 = squared_distances(mask, reach)
        near = brute <= reach * reach
        assert np.array_equal(d2[near], brute[near])
        assert (d2[~near] > reach * reach).all()
        assert np.array_equal(dilate(mask, reach), near)
    far_cell = tuple(np.argwhere(brute > 9)[0])
    assert squared_distances(mask, 3.0)[far_cell] > 9
    mask[far_cell] = True  # changed in place: another content, not the cached answer
    assert squared_distances(mask, 3.0)[far_cell] == 0
