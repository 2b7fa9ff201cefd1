"""Location reasoning without a simulator: costmaps, best-first order, spots, error messages.

The prospection here is a test double (`ScriptedProspection`): it answers from a rule given by
the test, so that each constraint can be made to rule candidates out on purpose.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.environments import load
from pycram.locations import BaseLocation, Costmap, FloorGrid, KnownObject, LocationReasoner, RobotGeometry, Spot
from pycram.reasoning.locations.costmap import occupancy_layer
from pycram.reasoning.locations.search import MAX_CANDIDATES, SPACING
from pycram.robot import ResolverSet
from pycram.world.robot_registry import robot_description

pr2 = robot_description("pr2")
tiago = robot_description("tiago")

APARTMENT = load("apartment")
CUP_ON_TABLE = KnownObject("cup", "cup", (4.3, 1.7, 0.795))


class Answer:
    def __init__(self, reason=None):
        self.reason, self.solutions, self.ok = reason, ((0.0,),), reason is None

    def __bool__(self):
        return self.ok


class ScriptedProspection:
    """Test double of `Prospection`: collision and reachability by rules of the test."""

    def __init__(self, collides=lambda pose: False, unreachable=lambda arm, pose: None):
        self.collides, self.unreachable = collides, unreachable
        self.asked = 0

    def in_collision(self, pose, configuration=None, carried=(), objects=False):
        self.asked += 1
        return self.collides(pose)

    def reachable(self, arm, poses, pose, configuration=None):
        self.asked += 1
        return Answer(self.unreachable(arm, pose))

    def visible(self, target, pose, threshold=0.5, configuration=None):
        raise AssertionError("not used here")


def resolver_set(description=pr2, prospection=None, known=(), states=None):
    reasoner = LocationReasoner(
        RobotGeometry.from_description(description),
        lambda: APARTMENT,
        lambda: prospection or ScriptedProspection(),
        lambda: list(known),
        container_states=lambda: dict(states or {}),
    )
    rs = ResolverSet("test locations")
    rs.location_generators.append(reasoner.generator)
    return rs, reasoner


def test_costmap_cells_come_cheapest_first_each_once():
    grid = FloorGrid.of(APARTMENT)
    rng = np.random.default_rng(0)
    layer = rng.uniform(0, 1, grid.shape)
    layer[rng.uniform(0, 1, grid.shape) < 0.3] = np.inf
    cells = list(Costmap(grid, {"random": layer}).cells(chunk=100))
    costs = [c for _, _, c in cells]
    assert costs == sorted(costs)
    assert len(cells) == len({(r, c) for r, c, _ in cells}) == int(np.isfinite(layer).sum())


def test_occupancy_keeps_the_base_off_furniture_and_walls():
    grid = FloorGrid.of(APARTMENT)
    occupancy = occupancy_layer(APARTMENT, grid, 0.3)

    def at(x, y):
        return occupancy[int((y - grid.bounds[1]) / grid.resolution), int((x - grid.bounds[0]) / grid.resolution)]

    assert np.isinf(at(4.3, 2.0))  # under the table top (the torso would hit it)
    assert np.isinf(at(1.3, 4.3))  # 0.1 m from the counter
    assert np.isinf(at(0.2, 1.0))  # against the west wall
    assert at(2.0, 1.5) == 0.0  # the start place


def test_to_reach_solutions_are_ranked_spaced_and_say_arm_and_grasp():
    rs, _ = resolver_set()
    with rs:
        designator = LocationDesignator([("to_reach", CUP_ON_TABLE)])
        found = [s for s, _ in zip(designator.solutions(), range(6))]
    assert all(isinstance(s, BaseLocation) and s.arm in ("left", "right") and s.grasp == "side" for s in found)
    assert [s.cost for s in found] == sorted(s.cost for s in found)
    for i, a in enumerate(found):
        assert APARTMENT.is_free_floor(a.x, a.y)
        assert 0.3 < math.hypot(a.x - 4.3, a.y - 1.7) < 1.1
        for b in found[:i]:
            assert math.hypot(a.x - b.x, a.y - b.y) >= SPACING - 1e-9  # no repeats
    # the first one faces the table's south edge squarely
    assert abs(found[0].yaw - math.pi / 2) < 0.35 and found[0].y < 1.55


def test_to_reach_one_armed_robot_and_arm_requests():
    rs, _ = resolver_set(tiago)
    with rs:
        first = LocationDesignator([("to_reach", CUP_ON_TABLE), ("arm", "left")]).reference()
    assert first.arm == "right"  # TIAGo serves the left arm with its only arm
    rs, _ = resolver_set(pr2)
    with rs:
        assert LocationDesignator([("to_reach", CUP_ON_TABLE), ("arm", "left")]).reference().arm == "left"
        with pytest.raises(Exception, match=r"pr2 has no arm 'middle'"):
            LocationDesignator([("to_reach", CUP_ON_TABLE), ("arm", "middle")]).reference()


def test_directional_grasps_fix_the_heading():
    milk = KnownObject("milk", "milk", (4.3, 1.7, 0.85), yaw=0.3)
    rs, _ = resolver_set()
    with rs:
        found = [s for s, _ in zip(LocationDesignator([("to_reach", milk)]).solutions(), range(4))]
    for s in found:
        side = {"+x": 0.0, "-x": math.pi, "+y": math.pi / 2, "-y": -math.pi / 2}[s.grasp]
        heading = 0.3 + side + math.pi
        assert abs((s.yaw - heading + math.pi) % (2 * math.pi) - math.pi) < 1e-9


def test_no_solution_names_collisions():
    prospection = ScriptedProspection(collides=lambda pose: True)
    rs, _ = resolver_set(prospection=prospection)
    with rs, pytest.raises(NoSolutionError) as info:
        LocationDesignator([("to_reach", CUP_ON_TABLE)]).reference()
    message = str(info.value)
    assert "no base pose for to_reach cup with the pr2" in message
    n = int(re.search(r"(\d+) candidates: ", message).group(1))
    assert 0 < n <= MAX_CANDIDATES and f"{n} candidates: {n} in collision" in message
    assert prospection.asked == n  # bounded: one check per candidate


def test_no_solution_names_the_arm_and_reason():
    prospection = ScriptedProspection(unreachable=lambda arm, pose: "out_of_reach" if arm == "left" else "collision")
    rs, _ = resolver_set(prospection=prospection)
    with rs, pytest.raises(NoSolutionError) as info:
        LocationDesignator([("to_reach", CUP_ON_TABLE)]).reference()
    message = str(info.value)
    assert "unreachable for arm 'left' (out_of_reach" in message
    assert "unreachable for arm 'right' (collision" in message


def test_a_target_outside_the_floor_names_the_reach_layer():
    rs, _ = resolver_set()
    with (
        rs,
        pytest.raises(
            NoSolutionError,
            match=r"is outside the environment: no cell of the floor of "
            r"apartment lies within the layer 'reach'",
        ),
    ):
        LocationDesignator([("to_reach", (20.0, 20.0, 0.9))]).reference()


def test_other_vocabulary_is_left_to_other_generators():
    _, reasoner = resolver_set()
    assert reasoner.generator(LocationDesignator([("named", "start")])) is None
    assert reasoner.generator(LocationDesignator([("on", "cooker #2"), ("slot", 1)])) is None


def test_bad_targets_say_what_a_target_is():
    rs, _ = resolver_set()
    with rs, pytest.raises(Exception, match=r"unknown target 'teapot'.*known: \["):
        LocationDesignator([("to_reach", "teapot")]).reference()


def test_on_spots_fit_the_type_and_keep_off_other_objects():
    milk = KnownObject("milk", "milk", (4.3, 2.0, 0.85))
    bowl = KnownObject("bowl", "bowl", (4.0, 1.8, 0.785))
    rs, _ = resolver_set(known=[milk, bowl])
    with rs:
        spots = [
            s
            for s, _ in zip(
                LocationDesignator([("on", "table"), ("for", "cup"), ("near", "milk")]).solutions(), range(20)
            )
        ]
    table = APARTMENT.surface("table")
    assert all(isinstance(s, Spot) and s.surface == "table" for s in spots)
    for s in spots:
        assert abs(s[2] - (0.75 + 0.045)) < 1e-9  # the cup's centre when it stands there
        assert table.contains(s[0], s[1], 0.035 + 0.03 - 1e-9)
        for other in (milk, bowl):
            assert math.hypot(s[0] - other.position[0], s[1] - other.position[1]) >= 0.035 + other.radius + 0.02 - 1e-9
    near = [math.hypot(s[0] - 4.3, s[1] - 2.0) for s in spots]
    assert near == sorted(near)  # the nearest to the milk first
    assert len({(round(s[0], 3), round(s[1], 3)) for s in spots}) == len(spots)


def test_in_a_container_checks_its_clearance():
    rs, _ = resolver_set(states={"drawer 2": 0.3})
    with rs:
        spot = LocationDesignator([("in", "drawer 2"), ("for", "spoon")]).reference()
        assert spot.container == "drawer 2" and spot.surface == "drawer 2 inside"
        with pytest.raises(NoSolutionError, match=r"a cereal \(0.28 m tall\) fits on none of \['drawer 2 inside'\]"):
            LocationDesignator([("in", "drawer 2"), ("for", "cereal")]).reference()


def test_a_full_surface_says_it_is_occupied():
    cups = [
        KnownObject(f"cup {i}", "cup", (x, y, 0.945))
        for i, (x, y) in enumerate([(1.73, 4.65), (1.83, 4.65), (1.73, 4.75), (1.83, 4.75)])
    ]
    rs, _ = resolver_set(known=cups)
    with (
        rs,
        pytest.raises(
            NoSolutionError,
            match=r"no free spot for a cup .* on cooker #1: \d+ candidates: "
            r"\d+ too close to the edge, \d+ occupied \(cup 0 \d+",
        ),
    ):
        LocationDesignator([("on", "cooker #1"), ("for", "cup")]).reference()
    with (
        rs,
        pytest.raises(
            NoSolutionError,
            match=r"no free spot for a plate .* on cooker #1: \d+ candidates: "
            r"\d+ too close to the edge$",
        ),
    ):
        LocationDesignator([("on", "cooker #1"), ("for", "plate")]).reference()


def test_to_open_stands_clear_of_the_opening_and_follows_the_handle():
    asked = []

    class Recording(ScriptedProspection):
        def reachable(self, arm, poses, pose, configuration=None):
            asked.append([p[0] for p in poses])
            return Answer()

    rs, _ = resolver_set(prospection=Recording())
    fridge = APARTMENT.container("fridge")
    with rs:
        door = LocationDesignator([("to_open", "fridge")]).reference()
        drawer = LocationDesignator([("to_open", "drawer 3"), ("opening", 0.2)]).reference()
    hx, hy = fridge.hinge
    assert math.hypot(door.x - hx, door.y - hy) > 0.7 + 0.335  # outside the door's swing
    assert door.grasp == "front" and drawer.grasp == "front_vertical"  # how the fingers meet the handle
    handle_path = asked[0][1:]
    assert handle_path[0] == pytest.approx(fridge.handle) and handle_path[-1] == pytest.approx(
        fridge.handle_position(1.2)
    )
    assert drawer.x > 0.6 + 0.2 + 0.335  # in front of the drawer pulled out 0.2 m
    assert asked[-1][-1] == pytest.approx(APARTMENT.container("drawer 3").handle_position(0.2))


def test_believed_objects_and_object_designators_are_targets():
    from pycram.designators.object import BelievedObject
    from pycram.locations import as_target

    cup = BelievedObject("cup-1", "cup", (4.3, 1.7, 0.795))
    target = as_target(cup, APARTMENT)
    assert target.kind == "object" and target.position == (4.3, 1.7, 0.795) and target.type.name == "cup"

    class Designator:  # anything with reference(): an object designator
        def reference(self):
            return cup

    assert as_target(Designator(), APARTMENT).name == "cup-1"
    rs, _ = resolver_set()
    with rs:
        assert LocationDesignator([("to_reach", cup)]).reference().grasp == "side"


def test_pushing_a_door_checks_each_tool_pose_with_the_door_where_it_will_be_and_stands_clear_of_its_swing():
    import dataclasses

    from pycram.designators.core import NoSolutionError
    from pycram.reasoning.locations import doors

    asked = []

    class Recording(ScriptedProspection):
        def reachable(self, arm, poses, pose, configuration=None):
            asked.append((pose, [p.angle for p in poses], dict(configuration or {})))
            return Answer()

    geometry = RobotGeometry.from_description(tiago)
    reasoner = LocationReasoner(geometry, lambda: APARTMENT, Recording, container_states=lambda: {"fridge": 0.3})
    rs = ResolverSet("test locations")
    rs.location_generators.append(reasoner.generator)
    fridge = APARTMENT.container("fridge")
    with rs:
        found = LocationDesignator([("to_open", "fridge"), ("opening", 1.2), ("pushing", "inside")]).reference()
    assert found.push == "inside" and found.grasp == "push" and found.arm == "right"
    assert list(found.tool_poses) == doors.push_sequence(fridge, tiago.DOOR_PUSH, 0.3, 1.2, "inside")
    # one pose at a time, the door's joint where that pose expects it, seeded with the previous solution
    for _, angles, configuration in asked:
        assert len(angles) == 1 and configuration[fridge.joint_name] == angles[0]
    angles = [a[0] for _, a, _ in asked]
    assert angles[0] == pytest.approx(0.3) and angles[-1] == pytest.approx(1.2)
    for q in np.linspace(0.3, 1.2, 10):  # clear of the panel anywhere on its way
        for d in np.linspace(0.0, fridge.door_width, 8):
            (px, py), _, _ = fridge.door_face(q, d, "outside")
            assert math.hypot(found.x - px, found.y - py) >= geometry.inscribed_radius
    # a robot that does not push doors, a drawer
    no_push = LocationReasoner(
        dataclasses.replace(geometry, door_push=None), lambda: APARTMENT, Recording, container_states=dict
    )
    with pytest.raises(NoSolutionError, match="does not push doors.*DOOR_PUSH"):
        next(no_push.generator(LocationDesignator([("to_open", "fridge"), ("pushing", "outside")])))
    with pytest.raises(NoSolutionError, match="only doors are pushed"):
        next(reasoner.generator(LocationDesignator([("to_open", "drawer 1"), ("pushing", "outside")])))


def test_a_grasp_that_turns_the_base_is_checked_facing_where_it_turns():
    """A directional grasp (the milk's) sets the base's heading; the pose is checked at that
    heading, not only facing the object: where the robot collides at every heading a milk grasp
    would turn it to, no pose is offered (measured: the TIAGo Pro's rectangular base was checked
    at 1.79 rad and offered at 1.57 rad, which navigation refused)."""
    milk = KnownObject("milk", "milk", (4.3, 1.7, 0.85), yaw=0.3)
    headings = [0.3 + side + math.pi for side in (0.0, math.pi, math.pi / 2, -math.pi / 2)]

    def turned(pose):
        return any(abs((pose[2] - h + math.pi) % (2 * math.pi) - math.pi) < 1e-6 for h in headings)

    rs, _ = resolver_set(prospection=ScriptedProspection(collides=turned))
    with rs, pytest.raises(NoSolutionError, match="in collision"):
        LocationDesignator([("to_reach", milk)]).reference()
    rs, _ = resolver_set()  # free everywhere: the same designator has its solutions
    with rs:
        assert LocationDesignator([("to_reach", milk)]).reference().grasp in ("+x", "-x", "+y", "-y")
