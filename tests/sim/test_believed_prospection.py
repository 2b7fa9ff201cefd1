"""The robot's prospection knows only what the robot knows: the environment's description, its
own joints, the containers as last seen, the objects it perceived (`World.prospection(belief)`,
`pycram.backends.sim.believed_world`). The simulator's own prospection (`World.prospection()`)
answers from the true state; the tests contrast the two."""

from __future__ import annotations

import math

import pytest
from sim_helpers import ok

from pycram.world.belief import BeliefState, PerceivedObject, PerceptionReport

ARM = "right"
FORWARD = (1.0, 0.0, 0.0, 0.0)


@pytest.fixture(scope="module", params=["pr2", "tiago"])
def apartment(request):
    from pycram.sim import World

    w = World(request.param, environment="apartment", objects=["cup"], seed=3)
    yield w
    w.close()


def _believing(world) -> tuple[BeliefState, object]:
    belief = BeliefState(world.environment)
    return belief, world.prospection(belief)


def test_one_prospection_per_belief_and_it_is_not_the_simulators(apartment):
    belief, p = _believing(apartment)
    assert apartment.prospection(belief) is p
    assert p is not apartment.prospection()
    assert apartment.prospection(BeliefState(apartment.environment)) is not p
    assert p.believed.names() == []


def test_an_obstacle_nobody_perceived_is_unknown_to_the_robot(apartment):
    _, believed = _believing(apartment)
    truth = apartment.prospection()
    spot = (2.5, 2.5, 0.0)
    obstacle = ok(apartment.place_obstacle(2.5, 2.5))
    try:
        assert truth.in_collision(spot)  # the simulator knows it is there
        assert not believed.in_collision(spot)  # the robot does not: it would find out by touch
    finally:
        ok(apartment.remove_obstacle(obstacle))


def test_a_drawer_pulled_out_unseen_stays_closed_until_perceived(apartment):
    belief, believed = _believing(apartment)
    truth = apartment.prospection()
    drawer = apartment.environment.container("drawer 2")
    ok(apartment.push_container("drawer 2", (30.0, 0.0, 0.0), 0.5))  # a person pulls it out
    try:
        opened = truth.joint_position(drawer.joint_name)
        assert opened > 0.05
        assert believed.joint_position(drawer.joint_name) == 0.0  # nobody saw it
        belief.update(PerceptionReport(1.0, (), None, {"drawer 2": opened}))  # a look measures it
        assert believed.joint_position(drawer.joint_name) == pytest.approx(opened)
    finally:
        ok(apartment.push_container("drawer 2", (-40.0, 0.0, 0.0), 0.8))


def test_objects_stand_where_they_are_believed_by_their_belief_names(apartment):
    belief, believed = _believing(apartment)
    true_cup = apartment.item_poses.get_value()["cup"].position
    with pytest.raises(ValueError, match="unknown object 'cup-1'; believed objects: \\[\\]"):
        believed.visible("cup-1", apartment.base_pose.get_value())
    with pytest.raises(ValueError, match="unknown object 'cup'"):  # simulator names mean nothing here
        believed.visible("cup", apartment.base_pose.get_value())
    # believed 1 m from where it really is, on the table
    table = apartment.environment.surface("table")
    x, y, z = table.centroid
    belief.add(PerceivedObject("cup-1", "cup", (x, y, z + 0.05)))
    assert believed.believed.names() == ["cup-1"]
    assert math.dist((x, y), true_cup[:2]) > 0.5
    view = (x - 1.3, y, 0.0)  # looking at the table from 1.3 m
    seen = believed.visible("cup-1", view, 0.3)
    assert seen.in_view > 0.9 and seen.visible, seen


def test_a_believed_object_is_an_obstacle_to_the_arm_except_to_grasp_it(apartment):
    belief, believed = _believing(apartment)
    table = apartment.environment.surface("table")
    x0, y0, _, y1 = table.bounds
    z = table.centroid[2]
    cup = (x0 + 0.15, (y0 + y1) / 2, z + 0.05)  # near the table's west edge
    belief.add(PerceivedObject("cup-1", "cup", cup))
    base = (x0 - 0.5, cup[1] + 0.2, 0.0)  # facing east, the right arm in front of the cup
    solution = believed.solve_ik(ARM, (cup, None), base, exempt_object="cup-1")
    assert solution, solution
    with believed.configuration_checker(ARM, base) as checker:
        assert not checker.is_free(solution.positions)  # the tool inside the believed cup
    with believed.configuration_checker(ARM, base, exempt_object="cup-1") as checker:
        hits = checker.contacts(solution.positions)
        assert not any("believed:cup" in env for _, env in hits), hits
    belief.lost(belief.objects()[0])  # believed gone: no obstacle any more
    with believed.configuration_checker(ARM, base) as checker:
        assert not any("believed:cup" in env for _, env in checker.contacts(solution.positions))


def test_untyped_objects_are_boxes_of_their_measured_size_in_each_worlds_own_model(apartment):
    first, p = _believing(apartment)
    second, q = _believing(apartment)
    first.add(PerceivedObject("box-1", "box", (2.0, 2.0, 1.0), {"size": (0.1, 0.2, 0.3)}))
    second.add(PerceivedObject("box-1", "box", (2.0, 2.0, 1.0), {"size": (0.04, 0.04, 0.04)}))
    sizes = []
    for prospection in (p, q):
        model = prospection.model
        body = prospection.scene.body(prospection.believed.body_of("box-1"))
        (geom,) = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body]
        sizes.append(tuple(float(v) for v in model.geom_size[geom]))
    assert sizes == [pytest.approx((0.05, 0.1, 0.15)), pytest.approx((0.02, 0.02, 0.02))]


def test_proxies_nobody_stands_for_are_parked_far_below_the_floor(apartment):
    belief, p = _believing(apartment)
    belief.add(PerceivedObject("cup-1", "cup", (2.0, 2.0, 1.0)))
    qpos = p.believed.snapshot().qpos
    model, scene = p.model, p.scene
    used = p.believed.body_of("cup-1")
    for spec in scene.items:
        adr = int(model.jnt_qposadr[model.body_jntadr[scene.body(spec.name)]])
        if spec.name == used:
            assert tuple(qpos[adr : adr + 3]) == pytest.approx((2.0, 2.0, 1.0))
        else:
            assert qpos[adr + 2] < -10.0 and tuple(qpos[adr + 3 : adr + 7]) == (1.0, 0.0, 0.0, 0.0)


def test_a_believed_world_needs_no_simulator_only_the_robots_sensed_joints(apartment):
    """Built from the robot's name, the environment's description, the belief and the joints by
    name and base pose (what a robot over ROS has), it is the believed world of the simulation's
    own robot: the same state, the same answers."""
    from pycram.backends.sim.believed_world import BelievedWorld, SensedRobot
    from pycram.backends.sim.prospection import SimProspection

    belief, p = _believing(apartment)
    belief.add(PerceivedObject("cup-1", "cup", (2.0, 2.0, 1.0)))
    belief.update(PerceptionReport(1.0, (), None, {"drawer 2": 0.2}))

    def sensed() -> SensedRobot:
        joints = apartment.joint_states.get_value()
        base = apartment.base_pose.get_value()
        return SensedRobot(joints.stamp, {**joints.position, "a joint it does not have": 1.0}, base)

    believed = BelievedWorld(apartment.robot, apartment.environment, belief, sensed)
    q = SimProspection(believed.scene, believed.snapshot, believed=believed)
    ours, theirs = believed.snapshot().qpos, p.believed.snapshot().qpos
    assert ours == pytest.approx(theirs, abs=1e-9)
    tool = believed.tool_poses()[ARM].position
    assert tool == pytest.approx(apartment.tool_poses.get_value()[ARM].position, abs=1e-6)
    base = apartment.base_pose.get_value()
    assert q.in_collision(base) == p.in_collision(base)
    robot, environment = apartment.robot, apartment.environment
    broken = BelievedWorld(robot, environment, belief, lambda: SensedRobot(0.0, {"x": math.nan}))
    broken.snapshot()  # a joint it does not have: ignored
    broken = BelievedWorld(robot, environment, belief, lambda: SensedRobot(0.0, {"base_x": math.nan}))
    with pytest.raises(ValueError, match="'base_x' at nan: not a finite position"):
        broken.snapshot()
