"""One plan, two robots: the thesis' ch. 4.2.2 process-module pattern on test robots.

A two-armed robot has one process module per arm (Pr2ArmL / Pr2ArmR style); a one-armed robot
has a single arm module that decides how to serve a request for either arm. The plan is the
same for both and never names a robot.
"""

from __future__ import annotations

import threading

import pytest

from pycram.designator import MotionDesignator, perform
from pycram.fluent import Fluent
from pycram.language import State, par
from pycram.process_module import NoProcessModuleError, ProcessModule, ProcessModuleStatus
from pycram.robot import Robot, current_robot, use_robot, use_world


@pytest.fixture(autouse=True)
def _clean_globals():
    saved = list(ProcessModule.resolvers), list(MotionDesignator.resolvers)
    ProcessModule.resolvers.clear()
    MotionDesignator.resolvers.clear()
    previous_robot, previous_world = use_robot(None), use_world(None)
    yield
    ProcessModule.resolvers[:] = saved[0]
    MotionDesignator.resolvers[:] = saved[1]
    use_robot(previous_robot)
    use_world(previous_world)


# --------------------------------------------------------------------------- test robots


class Journal:
    """What a test robot did, in order (thread-safe)."""

    def __init__(self):
        self.entries = []
        self._lock = threading.Lock()

    def add(self, *entry):
        with self._lock:
            self.entries.append(entry)


def motion_resolver(joint_count):
    """Thesis-style motion resolver (ch. 4.2.1); the robot's joint count shapes the solution."""

    def resolver(desig):
        solutions = []
        if desig.check_constraints([("type", "moving"), "pose"]):
            solutions.append(
                desig.make_dictionary(
                    [("cmd", "move"), "pose", ("wait", True), ("frame", desig.prop_value("frame") or "base_footprint")]
                )
            )
        if desig.check_constraints([("type", "setting_arm_joints"), "arm", "positions"]):
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "set_arm_joints"),
                        "arm",
                        ("positions", list(desig.prop_value("positions"))[:joint_count]),
                        ("wait", True),
                    ]
                )
            )
        if desig.check_constraints([("type", "pointing_head"), "coordinates"]):
            solutions.append(
                desig.make_dictionary([("cmd", "point_head"), "coordinates", ("wait", True), ("frame", "map")])
            )
        return solutions

    return resolver


class FakeNavigation(ProcessModule):
    def __init__(self, journal):
        super().__init__("navigation")
        self.journal = journal

    def _execute(self, designator):
        solution = designator.reference()
        if solution["cmd"] == "move":
            self.journal.add("navigation", "move_to", solution["pose"], solution["frame"])


class FakeHead(ProcessModule):
    def __init__(self, journal):
        super().__init__("head")
        self.journal = journal

    def _execute(self, designator):
        solution = designator.reference()
        if solution["cmd"] == "point_head":
            self.journal.add("head", "point_head_to", solution["coordinates"])


class Control:
    """Stand-in for the thesis' ``control.py`` (``c``): records every command in a journal.

    ``set_arm_joints`` waits (at most 5 s) until both arms are moving at the same time and
    records whether they were -- two arm process modules must run concurrently.
    """

    def __init__(self, journal):
        self.journal = journal
        self._lock = threading.Lock()
        self._moving = 0
        self.most_arms_moving = Fluent(0)  # never decreases: a waiter cannot miss the peak

    def move_to(self, pose, wait, frame):
        self.journal.add("navigation", "move_to", pose, frame)

    def point_head_to(self, x, y, z, wait, frame):
        self.journal.add("head", "point_head_to", (x, y, z))

    def set_arm_joints(self, arm, positions, wait):
        with self._lock:
            self._moving += 1
            if self._moving > self.most_arms_moving.get_value():
                self.most_arms_moving.set_value(self._moving)
        together = (self.most_arms_moving >= 2).wait_for(5.0)
        self.journal.add(f"arm_{arm}", "set_arm_joints", positions, f"together={together}")
        with self._lock:
            self._moving -= 1


class OnlyArm(ProcessModule):
    """The one-armed robot's arm: it serves a request for either arm with its only arm."""

    def __init__(self, journal):
        super().__init__("arm")
        self.journal = journal
        self.inside = 0
        self.max_inside = 0

    def _execute(self, designator):
        self.inside += 1
        self.max_inside = max(self.max_inside, self.inside)
        try:
            self._serve(designator)
        finally:
            self.inside -= 1

    def _serve(self, designator):
        solution = designator.reference()
        if solution["cmd"] == "set_arm_joints":
            requested = {"0": "left", "1": "right"}[solution["arm"]]
            self.journal.add("arm", "set_arm_joints", solution["positions"], f"requested {requested}")


def make_two_armed_robot():
    """The thesis' ch. 4.2.2 process modules, as written there, bundled into a test robot."""
    journal = Journal()
    c = Control(journal)

    class Pr2Navigation(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            if solution["cmd"] == "move":
                c.move_to(solution["pose"], solution["wait"], solution["frame"])

    class Pr2Head(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            if solution["cmd"] == "point_head":
                coordinates = solution["coordinates"]
                c.point_head_to(coordinates[0], coordinates[1], coordinates[2], solution["wait"], solution["frame"])

    class Pr2ArmL(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            if solution["cmd"] == "set_arm_joints":
                c.set_arm_joints("l", solution["positions"], solution["wait"])

    class Pr2ArmR(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            if solution["cmd"] == "set_arm_joints":
                c.set_arm_joints("r", solution["positions"], solution["wait"])

    pr2_navigation = Pr2Navigation()
    pr2_head = Pr2Head()
    pr2_arm_l = Pr2ArmL()
    pr2_arm_r = Pr2ArmR()

    def available_pr2_process_modules(design):  # thesis ch. 4.2.2: dispatch on type and arm
        if design.check_constraints([("type", "moving")]):
            return pr2_navigation
        if design.check_constraints([("type", "pointing_head")]):
            return pr2_head
        if design.check_constraints([("type", "setting_arm_joints")]):
            if design.check_constraints([("arm", "0")]):
                return pr2_arm_l
            if design.check_constraints([("arm", "1")]):
                return pr2_arm_r
        return None

    robot = Robot(
        "two-armed-test-robot",
        {"navigation": pr2_navigation, "head": pr2_head, "arm_left": pr2_arm_l, "arm_right": pr2_arm_r},
    )
    robot.motion_resolvers.append(motion_resolver(joint_count=7))
    robot.process_module_resolvers.append(available_pr2_process_modules)
    return robot, journal


def make_one_armed_robot():
    journal = Journal()
    robot = Robot("one-armed-test-robot")
    navigation = robot.add_process_module("navigation", FakeNavigation(journal))
    head = robot.add_process_module("head", FakeHead(journal))
    arm = robot.add_process_module("arm", OnlyArm(journal))
    robot.motion_resolvers.append(motion_resolver(joint_count=6))

    def available_process_modules(design):
        if design.check_constraints([("type", "moving")]):
            return navigation
        if design.check_constraints([("type", "pointing_head")]):
            return head
        if design.check_constraints([("type", "setting_arm_joints")]):
            return arm  # either arm: the module decides how to serve it
        return None

    robot.process_module_resolvers.append(available_process_modules)
    return robot, journal


JOINTS = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]


def plan():
    """The same plan for every robot (thesis' reset_robot shape)."""
    perform(MotionDesignator([("type", "moving"), ("pose", "p0"), ("frame", "map")]))
    errors = []
    state = par(
        lambda: perform(MotionDesignator([("type", "setting_arm_joints"), ("arm", "0"), ("positions", JOINTS)])),
        lambda: perform(MotionDesignator([("type", "setting_arm_joints"), ("arm", "1"), ("positions", JOINTS)])),
        lambda: ProcessModule.perform(MotionDesignator([("type", "pointing_head"), ("coordinates", (1, 2, 3))])),
        errors=errors,
    )
    assert state.get_value() is State.SUCCEEDED, errors


# --------------------------------------------------------------------------- tests


def test_same_plan_on_two_armed_robot():
    robot, journal = make_two_armed_robot()
    with robot:
        plan()
    entries = journal.entries
    assert entries[0] == ("navigation", "move_to", "p0", "map")
    by_module = {e[0]: e for e in entries[1:]}
    # one module per arm: both arms moved at the same time
    assert by_module["arm_l"] == ("arm_l", "set_arm_joints", JOINTS, "together=True")
    assert by_module["arm_r"] == ("arm_r", "set_arm_joints", JOINTS, "together=True")
    assert by_module["head"] == ("head", "point_head_to", (1, 2, 3))
    assert len(entries) == 4
    assert robot.process_module("arm_left").status.get_value() is ProcessModuleStatus.SUCCEEDED


def test_same_plan_on_one_armed_robot():
    robot, journal = make_one_armed_robot()
    with robot:
        plan()
    entries = journal.entries
    assert entries[0] == ("navigation", "move_to", "p0", "map")
    arm_entries = sorted(e for e in entries if e[0] == "arm")
    assert arm_entries == [
        ("arm", "set_arm_joints", JOINTS[:6], "requested left"),
        ("arm", "set_arm_joints", JOINTS[:6], "requested right"),
    ]
    assert ("head", "point_head_to", (1, 2, 3)) in entries and len(entries) == 4
    assert robot.process_module("arm").max_inside == 1  # one arm: the requests took turns


def test_active_robot_is_process_global_across_plan_branches():
    robot, _ = make_two_armed_robot()
    seen = []
    with robot:
        par(lambda: seen.append(current_robot()), lambda: seen.append(current_robot()))
    assert seen == [robot, robot]


def test_switching_robots_between_runs_of_one_plan():
    two, journal2 = make_two_armed_robot()
    one, journal1 = make_one_armed_robot()
    with two:
        plan()
    with one:
        plan()
    with two:
        plan()
    assert len(journal2.entries) == 8 and len(journal1.entries) == 4


def test_thesis_global_lists_for_a_single_robot_program():
    robot, journal = make_two_armed_robot()
    # a single-robot program registers globally and never activates a robot
    MotionDesignator.resolvers.extend(robot.motion_resolvers)
    ProcessModule.resolvers.extend(robot.process_module_resolvers)
    assert current_robot() is None
    plan()
    assert len(journal.entries) == 4


def test_robot_without_matching_module():
    robot, _ = make_one_armed_robot()
    with robot, pytest.raises(NoProcessModuleError) as info:
        perform(MotionDesignator([("type", "setting_torso"), ("position", 0.3)]))
    message = str(info.value)
    assert "('type', 'setting_torso')" in message and "('position', 0.3)" in message
    assert "one-armed-test-robot" in message
    assert "['arm', 'head', 'navigation']" in message


def test_process_module_lookup_by_name():
    robot, _ = make_one_armed_robot()
    assert robot.process_module("arm").name == "arm"
    with pytest.raises(KeyError, match="available: \\['arm', 'head', 'navigation'\\]"):
        robot.process_module("arm_left")


def test_current_prospection_is_the_active_robots_else_the_worlds():
    from pycram.robot import ResolverSet, current_prospection

    with pytest.raises(LookupError, match="no prospection available: no active robot"):
        current_prospection()
    world = ResolverSet("kitchen")
    world.prospection = object()
    robot = Robot("r")
    with world:
        assert current_prospection() is world.prospection
        with robot:  # a robot without one: the world's still answers
            assert current_prospection() is world.prospection
            robot.prospection = object()
            assert current_prospection() is robot.prospection
    with pytest.raises(LookupError):
        current_prospection()
