"""Arm motion planning on prospection (`pycram.reasoning.motion`): paths that are collision-free
when checked densely, detours around an object in the way, typed failures, the same path for the
same seed, timing within the joints' limits, and IK with mink to 1 mm.

The world is a `SimProspection` on a frozen state of the apartment (no simulation runs): the PR2
standing at the dining table's south edge, a tall thin box on the table in front of it."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("ompl")
pytest.importorskip("ruckig")
pytest.importorskip("mink")

import mujoco  # noqa: E402

from pycram.reasoning.motion import PLAN_FAILURES, OMPLPlanner, time_parameterize  # noqa: E402
from pycram.world.prospection import JointLimits, Prospection  # noqa: E402

BASE = (4.3, 1.15, math.pi / 2)  # facing the table's south edge (y = 1.55), 0.4 m from it
FORWARD = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # tool pointing north (+y)
#: a box on the table in front of the robot, 6 cm thin, 30 cm deep, 30 cm tall
WALL = ("wall", (0.03, 0.15, 0.15), (4.12, 1.85))
CUP = ("cup-1", (4.55, 1.75))
ARM = "right"


@pytest.fixture(scope="module")
def world():
    from pycram.backends.sim.items import ItemSpec
    from pycram.backends.sim.prospection import SimProspection
    from pycram.backends.sim.recording import StateSnapshot
    from pycram.backends.sim.scene import build_scene, initial_state
    from pycram.world.objects import object_type

    name, half, (x, y) = WALL
    items = [
        ItemSpec(name, "box", "box", half, 1.0, (x, y, None)),
        ItemSpec.of(object_type("cup"), CUP[0], (*CUP[1], None)),
    ]
    scene = build_scene("pr2", items=items, environment="apartment")
    snapshot = StateSnapshot.of(initial_state(scene, BASE))
    return scene, SimProspection(scene, lambda: snapshot)


def _ik(prospection, position, **options):
    result = prospection.solve_ik(ARM, (position, FORWARD), BASE, **options)
    assert result, result.message
    return list(result.positions)


@pytest.fixture(scope="module")
def around_the_wall(world):
    """Start and goal with the tool low on either side of the wall: the straight line hits it."""
    _, prospection = world
    start = _ik(prospection, (4.02, 1.78, 0.83))
    goal = _ik(prospection, (4.24, 1.78, 0.83))
    return start, goal


def _tool(scene, prospection, q):
    """Tool position [m] and rotation matrix with the right arm at q, the robot at BASE."""
    from pycram.backends.sim.robot_model import BASE_JOINTS, tool_site

    d = mujoco.MjData(scene.model)
    d.qpos[:] = prospection._snapshot().qpos
    for joint, v in zip(BASE_JOINTS, BASE):
        d.qpos[scene.joint_qpos(joint)] = v
    for joint, v in zip(scene.description.ARMS[ARM]["joints"], q):
        d.qpos[scene.joint_qpos(joint)] = v
    mujoco.mj_kinematics(scene.model, d)
    site = scene.site(tool_site(ARM))
    return d.site_xpos[site].copy(), d.site_xmat[site].reshape(3, 3).copy()


def _densely_free(checker, path, step=0.004) -> bool:
    for a, b in zip(path, path[1:]):
        a, b = np.asarray(a), np.asarray(b)
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / step))
        if not all(checker.is_free(a + (i / n) * (b - a)) for i in range(n + 1)):
            return False
    return True


def test_a_goal_behind_the_wall_gets_a_detour_that_is_free_when_checked_densely(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    with prospection.configuration_checker(ARM, BASE) as checker:
        assert checker.is_free(start) and checker.is_free(goal)
        assert not checker.motion_free(start, goal, 0.02)  # the straight line goes through the wall
        plan = OMPLPlanner().plan_with(checker, prospection.arm_joint_limits(ARM), start, goal, seed=1)
        assert plan, plan.message
        assert plan.planner == "RRTConnect" and len(plan.path) >= 3
        assert np.allclose(plan.path[0], start) and np.allclose(plan.path[-1], goal)
        assert plan.checks > 0 and plan.planning_time > 0
        assert _densely_free(checker, plan.path)
    # the wall is what is in the way: without it (an exempt object only spares the gripper, so
    # take the straight line's contacts instead) the arm touches it on the straight line
    with prospection.configuration_checker(ARM, BASE) as checker:
        middle = [(a + b) / 2 for a, b in zip(start, goal)]
        touched = {other for _, other in checker.contacts(middle)} | set()
        line = [np.asarray(start) + s * (np.asarray(goal) - np.asarray(start)) for s in np.linspace(0, 1, 60)]
        touched |= {other for q in line for _, other in checker.contacts(q)}
    assert WALL[0] in touched


@pytest.mark.parametrize("seed", [0, 2])
def test_a_search_too_coarse_to_see_the_wall_is_repaired_to_a_path_free_when_checked_densely(
    world, around_the_wall, seed
):
    """At 0.5 rad between checks the search's edges can jump the 6 cm wall (these seeds' do); the
    planner repairs them at its resolution, so the path is free all the same."""
    _, prospection = world
    start, goal = around_the_wall
    limits = prospection.arm_joint_limits(ARM)
    with prospection.configuration_checker(ARM, BASE) as checker:
        for simplify in (True, False):
            planner = OMPLPlanner(search_resolution=0.5, simplify=simplify)
            plan = planner.plan_with(checker, limits, start, goal, seed=seed)
            assert plan and plan.planner == "RRTConnect", plan.message
            assert np.allclose(plan.path[0], start) and np.allclose(plan.path[-1], goal)
            assert _densely_free(checker, plan.path)


def test_shortcuts_leave_a_shorter_path_of_fewer_vertices(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    for seed in range(3):
        raw = OMPLPlanner(simplify=False).plan(prospection, ARM, start, goal, BASE, seed=seed)
        short = OMPLPlanner().plan(prospection, ARM, start, goal, BASE, seed=seed)
        assert raw and short
        assert len(short.path) <= len(raw.path) and short.length < raw.length
        with prospection.configuration_checker(ARM, BASE) as checker:
            assert _densely_free(checker, short.path)


def test_clearances_count_near_contacts_and_only_as_asked(world, around_the_wall):
    """A configuration a step before the straight line's first contact with the wall (an object)
    is free without clearance, not with 2 cm of clearance or of object clearance; tolerating 2 cm
    of penetration does not free the touching one."""
    _, prospection = world
    start, goal = around_the_wall
    line = [np.asarray(start) + s * (np.asarray(goal) - np.asarray(start)) for s in np.linspace(0, 1, 200)]
    with prospection.configuration_checker(ARM, BASE) as checker:
        first = next(i for i, q in enumerate(line) if not checker.is_free(q))
        near, touching = line[first - 1], line[first]
        assert checker.contacts(near) == [] and WALL[0] in {other for _, other in checker.contacts(touching)}
    for options, free in (
        ({"clearance": 0.02}, False),
        ({"object_clearance": 0.02}, False),
        ({"clearance": -0.02}, True),
    ):
        with prospection.configuration_checker(ARM, BASE, **options) as checker:
            assert checker.is_free(near) is free, options
            assert not checker.is_free(touching)
            assert bool(checker.contacts(near)) is not free


def test_the_threshold_table_takes_the_larger_clearance_and_never_counts_an_ignored_pair():
    from pycram.backends.sim.arm_checker import threshold_table

    ignore = np.zeros((3, 3), bool)
    ignore[0, 1] = ignore[1, 0] = True
    clearance = np.array([0.0, 0.02, 0.05])
    table = threshold_table(ignore, clearance)
    assert table[0, 1] == table[1, 0] == -math.inf
    assert table[0, 2] == table[2, 1] == 0.05 and table[1, 1] == 0.02 and table[0, 0] == 0.0
    assert threshold_table(ignore, clearance) is table  # cached: made once per checker setting
    assert threshold_table(ignore, 2 * clearance)[0, 2] == 0.1
    other = ignore.copy()
    other[0, 1] = other[1, 0] = False
    assert threshold_table(other, clearance)[0, 1] == 0.02  # another exclusion matrix: its own table
    # geoms 0 and 1 the robot's: their contacts (self-collisions) count only deeper than 15 mm
    robot = np.array([True, True, False])
    own = threshold_table(ignore, clearance, robot, -0.015)
    assert own[0, 0] == own[1, 1] == -0.015 and own[0, 1] == -math.inf  # still never if ignored
    assert own[0, 2] == own[2, 1] == 0.05 and own[2, 2] == 0.05  # with anything else: as before
    assert threshold_table(ignore, clearance) is table and threshold_table(ignore, clearance, robot, -0.015) is own
    assert threshold_table(ignore, -0.02 + 0 * clearance, robot, -0.015)[0, 0] == -0.02  # a deeper clearance


#: A TIAGo right-arm configuration (measured: the arm leaving drawer 2's handle) in which, with the
#: torso down, the convex hulls of the shoulder (``arm_1_link``) and the torso column overlap 11 mm.
TIAGO_BASE = (2.0, 1.5, math.pi / 2)
SHOULDER_OVER_COLUMN = (2.170, -1.376, 1.271, 2.222, -0.324, -1.412, -0.977)


def test_the_robots_own_link_hulls_may_overlap_by_the_tolerance():
    """Counted, the TIAGo's shoulder-over-column hull overlap (torso down) put the start of every
    plan from such a configuration "in collision", and the plan was made again tolerating 15 mm
    with everything -- a carried spoon grazed a drawer's handle that deep and was knocked out of
    the hand (tests/sim/test_actions_containers.py). Self-contacts count deeper than the
    prospection's tolerance; contacts with anything else as before (the test above)."""
    from pycram.backends.sim.prospection import SimProspection
    from pycram.backends.sim.recording import StateSnapshot
    from pycram.backends.sim.scene import build_scene, initial_state

    scene = build_scene("tiago", environment="apartment")
    snapshot = StateSnapshot.of(initial_state(scene, TIAGO_BASE))
    for torso, tolerance, counted in ((0.0, 0.015, False), (0.0, 0.0, True), (0.25, 0.0, False)):
        prospection = SimProspection(scene, lambda: snapshot, tolerance=tolerance)
        with prospection.configuration_checker("right", TIAGO_BASE, {"torso_lift_joint": torso}) as checker:
            contacts = checker.contacts(SHOULDER_OVER_COLUMN)
            assert checker.is_free(SHOULDER_OVER_COLUMN) is not counted
            assert (("arm_1_link", "torso_fixed_column_link") in contacts) is counted, contacts
            if not counted:
                assert contacts == []


def test_an_open_motion_is_the_straight_line(world):
    _, prospection = world
    start = _ik(prospection, (4.55, 1.75, 1.05))
    goal = _ik(prospection, (4.45, 1.8, 1.15))
    plan = OMPLPlanner().plan(prospection, ARM, start, goal, BASE)
    assert plan and plan.planner == "straight_line" and len(plan.path) == 2


def test_the_same_seed_gives_the_same_path(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    planner = OMPLPlanner()
    first = planner.plan(prospection, ARM, start, goal, BASE, seed=5)
    again = planner.plan(prospection, ARM, start, goal, BASE, seed=5)
    assert first and first.planner == "RRTConnect"
    assert first.path == again.path


def test_start_or_goal_in_collision_gives_the_typed_reason(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    inside = _ik(prospection, (4.12, 1.8, 0.92), avoid_collisions=False)  # the gripper inside the wall
    planner = OMPLPlanner()
    plan = planner.plan(prospection, ARM, inside, goal, BASE)
    assert not plan and plan.reason == "start_in_collision" and plan.path == ()
    assert WALL[0] in plan.message
    plan = planner.plan(prospection, ARM, start, inside, BASE)
    assert plan.reason == "goal_in_collision"
    limits = prospection.arm_joint_limits(ARM)
    beyond = list(start)
    beyond[0] = limits.upper[0] + 0.5
    assert planner.plan(prospection, ARM, beyond, goal, BASE).reason == "outside_limits"
    assert {"start_in_collision", "goal_in_collision", "no_path", "outside_limits"} == set(PLAN_FAILURES)


def test_no_path_within_the_check_budget_says_so_and_is_the_same_every_time(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    planner = OMPLPlanner(max_checks=40, search_resolution=0.02)
    plans = [planner.plan(prospection, ARM, start, goal, BASE, seed=3) for _ in range(2)]
    for plan in plans:
        assert plan.reason == "no_path" and "found no path in" in plan.message
    assert plans[0].checks == plans[1].checks  # the budget is counted in checks, not in wall time
    assert 40 <= plans[0].checks < 40 + 200  # the last extension finishes its checks


def test_no_path_within_the_wall_time_safety_net_says_so(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    plan = OMPLPlanner(time_limit=1e-4, search_resolution=0.02).plan(prospection, ARM, start, goal, BASE)
    assert plan.reason == "no_path" and "found no path in" in plan.message


def test_the_object_being_grasped_may_touch_the_gripper(world):
    _, prospection = world
    x, y = CUP[1]
    grasp = _ik(prospection, (x, y, 0.83), avoid_collisions=False)  # fingers around the cup
    with prospection.configuration_checker(ARM, BASE) as checker:
        assert {other for _, other in checker.contacts(grasp)} == {CUP[0]}
    assert prospection.arm_configuration_free(ARM, grasp, BASE, exempt_object=CUP[0])
    # IK for the grasp itself finds it free only with the cup exempt
    exempt = prospection.solve_ik(ARM, ((x, y, 0.83), FORWARD), BASE, seeds=[grasp], exempt_object=CUP[0])
    assert exempt and prospection.arm_configuration_free(ARM, exempt.positions, BASE, exempt_object=CUP[0])
    with pytest.raises(ValueError, match="unknown object 'mug'.*known objects"):
        prospection.configuration_checker(ARM, BASE, exempt_object="mug")


def test_the_timed_trajectory_keeps_to_the_path_and_the_limits(world, around_the_wall):
    _, prospection = world
    start, goal = around_the_wall
    plan = OMPLPlanner().plan(prospection, ARM, start, goal, BASE, seed=1)
    limits = prospection.arm_joint_limits(ARM)
    period = 0.01
    timed = time_parameterize(plan.path, limits, period=period, velocity_scale=0.5, acceleration_scale=0.8)
    t = np.asarray(timed.times)
    q = np.asarray(timed.positions)
    v = np.asarray(timed.velocities)
    assert t[0] == 0.0 and np.all(np.diff(t) > 0) and np.all(np.diff(t)[:-1] == pytest.approx(period))
    assert np.allclose(q[0], plan.path[0]) and np.allclose(q[-1], plan.path[-1], atol=1e-6)
    assert np.allclose(v[0], 0) and np.allclose(v[-1], 0, atol=1e-6)
    vmax = 0.5 * np.asarray(limits.velocity)
    amax = 0.8 * np.asarray(limits.acceleration)
    assert np.all(np.abs(v) <= vmax * (1 + 1e-6))
    assert np.all(np.abs(np.diff(q, axis=0)) <= vmax * np.diff(t)[:, None] * (1 + 1e-6))
    assert np.all(np.abs(np.diff(v, axis=0)) <= amax * np.diff(t)[:, None] * (1 + 1e-6))
    assert np.abs(v).max(axis=0).max() > 0.5 * vmax.min()  # it does move at speed
    # every sample lies on one of the path's straight segments
    path = np.asarray(plan.path)
    for sample in q:
        gaps = []
        for a, b in zip(path, path[1:]):
            s = np.clip(np.dot(sample - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
            gaps.append(np.linalg.norm(sample - (a + s * (b - a))))
        assert min(gaps) < 1e-6
    # ... and the timed samples are free too
    with prospection.configuration_checker(ARM, BASE) as checker:
        assert all(checker.is_free(sample) for sample in q)


def test_timing_rejects_malformed_input():
    limits = JointLimits(("a", "b"), (-1.0, -1.0), (1.0, 1.0), (1.0, 2.0), (1.0, 1.0))
    with pytest.raises(ValueError, match="at least one"):
        time_parameterize([], limits)
    with pytest.raises(ValueError, match="2 positions"):
        time_parameterize([(0.0,)], limits)
    still = time_parameterize([(0.1, 0.2)], limits)
    assert still.duration == 0.0 and still.positions == ((0.1, 0.2),)
    with pytest.raises(ValueError, match="positive"):
        JointLimits(("a",), (0.0,), (1.0,), (0.0,), (1.0,))


def test_mink_reaches_a_reachable_pose_within_a_millimetre(world):
    scene, prospection = world
    target_q = list(scene.description.ARM_CONFIGURATIONS[ARM]["pre_grasp"])
    position, rotation = _tool(scene, prospection, target_q)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rotation.ravel())
    park = scene.description.ARM_CONFIGURATIONS[ARM]["park"]
    result = prospection.solve_ik(ARM, (tuple(position), tuple(quat)), BASE, seeds=[park])
    assert result, result.message
    reached, reached_rotation = _tool(scene, prospection, result.positions)
    assert np.linalg.norm(reached - position) <= 1e-3
    assert result.position_error <= 1e-3 and result.orientation_error <= 0.01
    angle = math.acos(np.clip((np.trace(rotation.T @ reached_rotation) - 1) / 2, -1, 1))
    assert angle <= 0.01
    assert prospection.arm_joint_limits(ARM).within(result.positions)
    far = prospection.solve_ik(ARM, ((4.3, 3.0, 0.9), FORWARD), BASE)
    assert not far and far.reason == "no_solution" and far.positions == ()


def _off_the_line(scene, prospection, path, a, b):
    """The farthest [m] the tool leaves the line a-b along the path's joint segments, sampled 20
    times each."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    worst = 0.0
    for q0, q1 in zip(path, path[1:]):
        for s in np.linspace(0.0, 1.0, 21):
            p, _ = _tool(scene, prospection, [x + s * (y - x) for x, y in zip(q0, q1)])
            along = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
            worst = max(worst, float(np.linalg.norm(p - (a + along * (b - a)))))
    return worst


def test_the_tools_straight_line_keeps_the_tool_on_it_where_the_joints_line_bows(world):
    from pycram.reasoning.motion.cartesian import LINE_TOLERANCE, plan_cartesian_line

    scene, prospection = world
    a, b = (4.32, 1.62, 1.0), (4.32, 1.78, 1.0)  # 16 cm forward over the table
    start = _ik(prospection, a)
    plan = plan_cartesian_line(prospection, ARM, start, (b, FORWARD), BASE)
    assert plan and plan.planner == "cartesian_line", plan.message
    assert plan.path[0] == tuple(start) and 2 <= len(plan.path) < 17  # simplified: fewer than its 16 steps
    assert _off_the_line(scene, prospection, plan.path, a, b) <= LINE_TOLERANCE + 1e-3
    end, _ = _tool(scene, prospection, plan.path[-1])
    assert np.linalg.norm(end - np.asarray(b)) <= 1e-3
    assert prospection.arm_configuration_free(ARM, plan.path[-1], BASE)
    # the same goal solved from another seed: the joints' straight line to it leaves the line
    other = _ik(prospection, b, seeds=[[0.0] * len(start)])
    assert _off_the_line(scene, prospection, [start, other], a, b) > 0.05


def test_the_tools_straight_line_says_what_it_touches_or_where_ik_fails(world):
    from pycram.reasoning.motion.cartesian import plan_cartesian_line

    _, prospection = world
    through = plan_cartesian_line(
        prospection, ARM, _ik(prospection, (4.02, 1.78, 0.83)), ((4.24, 1.78, 0.83), FORWARD), BASE
    )
    assert not through and through.reason == "no_path" and "touches wall" in through.message
    start = _ik(prospection, (4.32, 1.62, 1.0))
    too_far = plan_cartesian_line(prospection, ARM, start, ((4.32, 3.0, 1.0), FORWARD), BASE)
    assert not too_far and too_far.reason == "no_path" and "no IK solution on the line" in too_far.message
    with pytest.raises(ValueError, match="start needs 7 positions"):
        plan_cartesian_line(prospection, ARM, start[:3], ((4.32, 1.7, 1.0), FORWARD), BASE)


def test_a_held_objects_lean_is_measured_from_how_it_stands_now_and_limits_free_configurations(world):
    scene, prospection = world
    joints = scene.description.ARMS[ARM]["joints"]
    now = [float(prospection._snapshot().qpos[scene.joint_qpos(j)]) for j in joints]
    rng = np.random.default_rng(3)
    limits = prospection.arm_joint_limits(ARM)
    with prospection.configuration_checker(ARM, BASE, held_object=CUP[0], clearance=-1.0) as checker:
        assert checker.held_lean(now) == pytest.approx(0.0, abs=1e-6)
        _, rotation_now = _tool(scene, prospection, now)
        leans = []
        for _ in range(20):
            q = [float(rng.uniform(max(lo, -math.pi), min(hi, math.pi))) for lo, hi in zip(limits.lower, limits.upper)]
            _, rotation = _tool(scene, prospection, q)
            up = rotation @ rotation_now.T @ np.array([0.0, 0.0, 1.0])  # the direction up now, turned with the hand
            expected = math.acos(np.clip(up[2], -1.0, 1.0))
            assert checker.held_lean(q) == pytest.approx(expected, abs=1e-6)
            leans.append((expected, q))
        leans.append((0.0, now))
        assert max(leans)[0] > math.radians(30.0)
        assert checker.is_free(max(leans)[1])  # any lean, by default (contacts tolerated up to 1 m here)
        checker.max_held_lean = math.radians(30.0)
        for lean, q in leans:
            assert checker.is_free(q) == (lean <= math.radians(30.0))
            if lean > math.radians(30.0):
                assert ("the held object", "its tilt limit (30 deg)") in checker.contacts(q)
    with prospection.configuration_checker(ARM, BASE) as empty:  # no held object: no lean
        assert empty.held_lean(now) == 0.0


def test_joint_limits_come_from_the_model_and_the_urdf(world):
    _, prospection = world
    limits = prospection.arm_joint_limits(ARM)
    assert limits.joints[0] == "r_shoulder_pan_joint" and len(limits.joints) == 7
    assert limits.velocity[0] == pytest.approx(2.088)  # the PR2 URDF's shoulder pan
    assert limits.continuous[4] and not limits.continuous[0]  # forearm roll turns freely
    torso = prospection.arm_joint_limits(ARM, include_torso=True)
    assert torso.joints[0] == "torso_lift_joint" and torso.upper[0] == pytest.approx(0.31)
    with pytest.raises(ValueError, match="unknown arm 'middle'.*valid arms"):
        prospection.arm_joint_limits("middle")


def test_a_prospection_without_planning_says_so():
    class Minimal(Prospection):
        arms = ("right",)

        def in_collision(self, base_pose, joint_configuration=None, carried=(), objects=False):
            return False

        def collisions(self, base_pose, joint_configuration=None):
            return []

        def reachable(self, arm, poses, base_pose, joint_configuration=None):
            raise AssertionError

        def visible(self, target, base_pose, threshold=0.5, joint_configuration=None):
            raise AssertionError

    with pytest.raises(NotImplementedError, match="Minimal does not provide arm_joint_limits"):
        OMPLPlanner().plan(Minimal(), "right", [0.0], [1.0], (0, 0, 0))
    with pytest.raises(NotImplementedError, match="solve_ik"):
        Minimal().solve_ik("right", ((0, 0, 1), None), (0, 0, 0))
