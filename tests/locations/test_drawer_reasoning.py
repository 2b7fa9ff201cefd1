"""Location reasoning for objects in drawers, without a simulator (a scripted prospection):
grasps over the walls only, approach and lift above them, the base off the open drawer, other
torso heights, and the error that names the walls."""

from __future__ import annotations

import math

import pytest
from test_location_reasoning import APARTMENT, CUP_ON_TABLE, ScriptedProspection

from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.locations import KnownObject, LocationReasoner, RobotGeometry
from pycram.reasoning.locations.reach import RIM_CLEARANCE
from pycram.reasoning.locations.standing import DOOR_CLEARANCE, DRAWER_CLEARANCE
from pycram.robot import ResolverSet
from pycram.world.robot_registry import robot_description

pr2 = robot_description("pr2")

DRAWER_2 = APARTMENT.container("drawer 2")
OPENING = 0.38
#: A cup 20 cm behind the front of drawer 2, which is pulled out by `OPENING`.
CUP_IN_DRAWER = KnownObject("cup", "cup", (0.4 + OPENING, 2.9, 0.365 + 0.045))


class TorsoProspection(ScriptedProspection):
    """Reaches only with the torso at `reach_at` [m]; the torso stands at `now` [m]."""

    def __init__(self, reach_at: float | None = None, now: float = 0.28):
        super().__init__()
        self.reach_at, self.now, self.asked_poses, self.torsos_asked = reach_at, now, [], []

    def joint_position(self, name):
        assert name == pr2.TORSO["joint"]
        return self.now

    def reachable(self, arm, poses, pose, configuration=None):
        self.asked_poses.append(list(poses))
        torso = (configuration or {}).get(pr2.TORSO["joint"], self.now)
        self.torsos_asked.append(torso)
        return super().reachable(arm, poses, pose, configuration) if self._ok(torso) else _No()

    def _ok(self, torso):
        return self.reach_at is None or abs(torso - self.reach_at) < 1e-6


class _No:
    reason, solutions = "out_of_reach", ()

    def __bool__(self):
        return False


def resolver_set(prospection, states=None):
    reasoner = LocationReasoner(
        RobotGeometry.from_description(pr2),
        lambda: APARTMENT,
        lambda: prospection,
        lambda: [],
        container_states=lambda: dict(states or {}),
    )
    rs = ResolverSet("test locations")
    rs.location_generators.append(reasoner.generator)
    return rs


def first(designator, n=3):
    return [s for s, _ in zip(designator.solutions(), range(n))]


def test_in_a_drawer_a_cup_is_taken_from_the_top_coming_in_and_leaving_above_the_walls():
    prospection = TorsoProspection()
    with resolver_set(prospection, {"drawer 2": OPENING}):
        found = first(LocationDesignator([("to_reach", CUP_IN_DRAWER)]))
    assert found and all(s.grasp == "top" for s in found)
    rim = DRAWER_2.rim_height
    for s in found:
        pre, grasp, lift = (p for p, _ in s.tool_poses)
        assert pre[2] >= rim + RIM_CLEARANCE - 1e-9  # the empty hand clears the walls
        assert lift[2] - 0.06 >= rim + RIM_CLEARANCE - 1e-9  # so does the cup's bottom (grasped 6 cm up)
        assert math.isclose(grasp[0], CUP_IN_DRAWER.position[0]) and grasp[2] < rim
        # the base stands off the drawer pulled out, handle included
        front = DRAWER_2.front + OPENING + (DRAWER_2.handle[0] - DRAWER_2.front)
        assert s.x - front >= pr2.BASE["inscribed_radius"] + DRAWER_CLEARANCE - 0.05
        assert s.torso is None  # reachable with the torso as it is


def test_out_in_the_open_a_cup_is_taken_by_its_side_unless_the_top_is_asked_for():
    with resolver_set(TorsoProspection()):
        assert {s.grasp for s in first(LocationDesignator([("to_reach", CUP_ON_TABLE)]), 4)} == {"side"}
        asked = first(LocationDesignator([("to_reach", CUP_ON_TABLE), ("grasp", "top")]), 2)
    assert asked and {s.grasp for s in asked} == {"top"}


def test_a_drawer_too_low_for_the_torso_as_it_is_gives_a_solution_with_the_torso_down():
    prospection = TorsoProspection(reach_at=pr2.TORSO_POSITIONS["down"], now=pr2.TORSO_POSITIONS["up"])
    with resolver_set(prospection, {"drawer 2": OPENING}):
        found = first(LocationDesignator([("to_reach", CUP_IN_DRAWER)]), 1)
    assert found[0].torso == "down"


def test_out_in_the_open_a_low_torso_is_raised_only_when_nothing_works_as_it_is():
    up, down = pr2.TORSO_POSITIONS["up"], pr2.TORSO_POSITIONS["down"]
    with resolver_set(TorsoProspection(reach_at=up, now=down)):
        found = first(LocationDesignator([("to_reach", CUP_ON_TABLE)]), 1)
    assert found[0].torso == "up" and found[0].grasp == "side"
    with resolver_set(TorsoProspection(now=down)):  # reaches at any height: the torso stays
        assert first(LocationDesignator([("to_reach", CUP_ON_TABLE)]), 1)[0].torso is None
    prospection = TorsoProspection(reach_at=down, now=up)  # never lowered out in the open
    with resolver_set(prospection), pytest.raises(NoSolutionError, match="no base pose"):
        LocationDesignator([("to_reach", CUP_ON_TABLE)]).reference()
    assert {round(a, 2) for a in prospection.torsos_asked} == {up}


def test_an_object_without_a_grasp_over_the_walls_is_refused_naming_them():
    milk = KnownObject("milk", "milk", (0.4 + 0.4, 2.9, 0.625 + 0.1))
    with resolver_set(TorsoProspection(), {"drawer 3": 0.4}), pytest.raises(NoSolutionError) as caught:
        LocationDesignator([("to_reach", milk)]).reference()
    assert "lies in 'drawer 3', whose walls rise to 0.86 m" in str(caught.value)


def test_a_drawer_knows_where_its_contents_are():
    assert DRAWER_2.front == pytest.approx(0.6) and DRAWER_2.rim_height == pytest.approx(0.6)
    assert DRAWER_2.surface_holding(CUP_IN_DRAWER.position, OPENING).name == "drawer 2 inside"
    assert DRAWER_2.surface_holding(CUP_IN_DRAWER.position, 0.0) is None  # closed, it is not there
    assert APARTMENT.container("drawer 3").surface_holding(CUP_IN_DRAWER.position, OPENING) is None
    assert APARTMENT.container("fridge").surface_holding((3.0, 4.6, 0.67), 0.0) is None  # a door's shelves


def test_the_base_stands_clear_of_an_open_door_not_only_of_the_furniture():
    """The cupboard opened 69 deg: its door stands out into the room in front of the compartment's
    west half. With every pose reachable (a scripted prospection that sees no door), the
    standing poses chosen to reach a cup inside keep the base `DOOR_CLEARANCE` off the panel."""
    cupboard = APARTMENT.container("cupboard")
    opening = 1.2
    cup = KnownObject("cup", "cup", (4.2, 4.63, 0.8 + 0.045))
    with resolver_set(TorsoProspection(), {"cupboard": opening}):
        found = first(LocationDesignator([("to_reach", cup)]), 5)
    assert found
    (ax, ay), _, _ = cupboard.door_face(opening, 0.0, "outside")
    (bx, by), _, _ = cupboard.door_face(opening, cupboard.door_width, "outside")
    for s in found:
        t = max(0.0, min(1.0, ((s.x - ax) * (bx - ax) + (s.y - ay) * (by - ay)) / ((bx - ax) ** 2 + (by - ay) ** 2)))
        distance = math.dist((s.x, s.y), (ax + t * (bx - ax), ay + t * (by - ay)))
        assert distance >= pr2.BASE["inscribed_radius"] + DOOR_CLEARANCE - 0.05, (s, distance)


def test_in_a_drawer_means_inside_it_as_it_is_believed_open():
    drawer = APARTMENT.container("drawer 2")
    assert drawer.opened_interior(0.0) == ()  # closed: its inside lies under the cabinet top
    (inside,) = drawer.opened_interior(0.3)
    x0, y0, x1, y1 = inside.bounds
    closed = drawer.interior[0].bounds
    assert x0 == pytest.approx(drawer.front) and x1 == pytest.approx(closed[2] + 0.3)
    assert (y0, y1) == pytest.approx((closed[1], closed[3]))
    with resolver_set(ScriptedProspection(), {"drawer 2": 0.3}):
        spots = first(LocationDesignator([("in", "drawer 2"), ("for", "cup")]), 10)
    assert spots and all(s.container == "drawer 2" and s.surface == "drawer 2 inside" for s in spots)
    for s in spots:  # out from under the cabinet, inside the moved drawer, clear of its walls
        assert inside.contains(s[0], s[1], 0.035 + 0.03 - 1e-9)
        assert drawer.along_slide(s[0], s[1]) - 0.035 >= drawer.front
    with (
        resolver_set(ScriptedProspection(), {}),
        pytest.raises(NoSolutionError, match="closed as far as the robot knows"),
    ):
        LocationDesignator([("in", "drawer 2"), ("for", "cup")]).reference()
