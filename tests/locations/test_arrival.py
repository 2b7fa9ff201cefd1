"""How a base pose is checked for the robot as it arrives (location reasoning without a
simulator): free arms tucked, a holding arm as it is -- with the object it carries -- or, where
the carried object would touch the furniture, lifted clear of it (`LIFT_STEP` steps)."""

from __future__ import annotations

import math

import pytest

from pycram.environments import load
from pycram.locations import LocationReasoner, RobotGeometry
from pycram.reasoning.locations.search import LIFT_STEP
from pycram.world.prospection import ToolPose
from pycram.world.robot_registry import robot_description

pr2 = robot_description("pr2")
APARTMENT = load("apartment")
ARM = "left"
#: The one joint of the test's arm the double reads: the tool's height [m] is its value.
HEIGHT_JOINT = pr2.ARMS[ARM]["joints"][0]


class IK:
    def __init__(self, positions=()):
        self.positions = positions

    def __bool__(self):
        return bool(self.positions)


class LiftingProspection:
    """Test double: the tool of the left arm stands at the height its first joint says; the
    carried object touches the furniture while the tool is below `clear` [m]; the arm reaches
    up to `reach` [m]; the robot itself collides where `robot_collides` says."""

    def __init__(self, clear=1.2, reach=1.6, robot_collides=lambda base: False):
        self.clear, self.reach, self.robot_collides = clear, reach, robot_collides
        self.asked: list[tuple] = []

    def joint_position(self, joint):
        return 1.0 if joint == HEIGHT_JOINT else 0.0

    def in_collision(self, base, configuration=None, carried=(), objects=False):
        self.asked.append((tuple(base), dict(configuration or {}), tuple(carried), objects))
        if self.robot_collides(base):
            return True
        return bool(carried) and (configuration or {}).get(HEIGHT_JOINT, 1.0) < self.clear - 1e-9

    def tool_pose(self, arm, base, configuration=None):
        return ToolPose((base[0] + 0.6, base[1], (configuration or {}).get(HEIGHT_JOINT, 1.0)), (1.0, 0.0, 0.0, 0.0))

    def solve_ik(self, arm, pose, base, configuration=None, **_):
        z = pose[0][2]
        if z > self.reach:
            return IK()
        return IK((z,) + (0.0,) * (len(pr2.ARMS[arm]["joints"]) - 1))


def _reasoner(prospection, holding):
    return LocationReasoner(
        RobotGeometry.from_description(pr2), lambda: APARTMENT, lambda: prospection, holding=lambda: holding
    )


def test_a_holding_arm_arrives_as_it_is_and_free_arms_tucked():
    prosp = LiftingProspection()
    arrival = _reasoner(prosp, {ARM: "cereal-1"}).arrival_configuration(prosp)
    tucked = RobotGeometry.from_description(pr2).tucked
    assert arrival[HEIGHT_JOINT] == 1.0  # as it is
    right = pr2.ARMS["right"]["joints"]
    assert all(arrival[j] == tucked[j] for j in right)  # the free arm tucked


def test_the_carried_object_is_lifted_in_steps_until_it_clears_the_furniture():
    prosp = LiftingProspection(clear=1.2)
    reasoner = _reasoner(prosp, {ARM: "cereal-1"})
    base = (2.0, 3.9, math.pi / 2)
    lifted = reasoner._lifted_arrival(prosp, ARM, base, reasoner.arrival_configuration(prosp))
    steps = math.ceil(round((1.2 - 1.0) / LIFT_STEP, 6))
    assert lifted and lifted[0] == pytest.approx(1.0 + steps * LIFT_STEP)
    # every check carried the held object and counted the objects around as obstacles
    assert all(carried == ("cereal-1",) and objects for _, _, carried, objects in prosp.asked[1:])


def test_no_lift_when_the_arm_reaches_no_higher_or_the_robot_itself_is_in_the_way():
    base = (2.0, 3.9, math.pi / 2)
    prosp = LiftingProspection(clear=1.8, reach=1.6)  # clear only beyond the arm's reach
    reasoner = _reasoner(prosp, {ARM: "cereal-1"})
    assert reasoner._lifted_arrival(prosp, ARM, base, reasoner.arrival_configuration(prosp)) == ()
    prosp = LiftingProspection(robot_collides=lambda b: True)
    reasoner = _reasoner(prosp, {ARM: "cereal-1"})
    assert reasoner._lifted_arrival(prosp, ARM, base, reasoner.arrival_configuration(prosp)) == ()
    assert len(prosp.asked) == 1  # one look showed the robot itself in the way: no IK tried


def test_an_arm_holding_nothing_is_not_lifted():
    prosp = LiftingProspection()
    reasoner = _reasoner(prosp, {})
    base = (2.0, 3.9, math.pi / 2)
    assert reasoner._lifted_arrival(prosp, ARM, base, reasoner.arrival_configuration(prosp)) == ()
    assert reasoner.carried() == []


def _differential(geometry: RobotGeometry) -> RobotGeometry:
    import dataclasses

    from pycram.world.base_kinematics import BaseKinematics

    return dataclasses.replace(geometry, base_kinematics=BaseKinematics("differential", approach=0.3))


def test_a_differential_drive_needs_a_way_in_an_omnidirectional_base_does_not():
    """A pose the robot fits at, but neither straight behind it (where it would come from) nor
    turned on the spot: no way in for a differential drive; an omnidirectional base slides in."""
    base = (2.0, 3.0, 0.0)

    def boxed_in(pose):  # free only at the pose's own (x, y) facing +x
        return not (abs(pose[0] - 2.0) < 1e-9 and abs(pose[1] - 3.0) < 1e-9 and abs(pose[2]) < 1e-9)

    prosp = LiftingProspection(robot_collides=boxed_in)
    geometry = RobotGeometry.from_description(pr2)
    omni = LocationReasoner(geometry, lambda: APARTMENT, lambda: prosp, holding=lambda: {})
    diff = LocationReasoner(_differential(geometry), lambda: APARTMENT, lambda: prosp, holding=lambda: {})
    tucked = geometry.tucked
    assert not omni.no_way_in(prosp, base, tucked)
    prosp.asked.clear()
    assert diff.no_way_in(prosp, base, tucked)
    # it asked about the poses behind it, then about turning on the spot
    asked = [b for b, *_ in prosp.asked]
    assert (1.85, 3.0, 0.0) in [tuple(round(v, 6) for v in b) for b in asked]
    assert any(abs(b[2] - math.pi / 4) < 1e-9 for b in asked)
    # free behind it: it comes in straight; free all round: it turns there
    behind_free = LiftingProspection(robot_collides=lambda pose: abs(pose[1] - 3.0) > 1e-9 or abs(pose[2]) > 1e-9)
    assert not diff.no_way_in(behind_free, base, tucked)
    assert not diff.no_way_in(LiftingProspection(), base, tucked)
