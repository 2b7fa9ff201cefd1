"""One plan, two robots: the thesis' ch. 4.2.2 process-module pattern on test robots.

A two-armed robot has one process module per arm (Pr2ArmL / Pr2ArmR style); a one-armed robot
has a single arm module that decides how to serve a request for either arm. The plan is the
same for both and never names a robot.
"""

from __future__ import annotations

import threading

import pytest

from pycram.designator import MotionDesignator, perform
from pycram.language import State, par
from pycram.process_module import NoProcessModuleError, ProcessModule
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
        if desig.check_constraints([('type', 'moving'), 'pose']):
            solutions.append(desig.make_dictionary(
                [('cmd', 'move'), 'pose', ('wait', True),
                 ('frame', desig.prop_value('frame') or 'base_footprint')]))
        if desig.check_constraints([('type', 'setting_arm_joints'), 'arm', 'positions']):
            solutions.append(desig.make_dictionary(
                [('cmd', 'set_arm_joints'), 'arm',
                 ('positions', list(desig.prop_value('positions'))[:joint_count]),
                 ('wait', True)]))
        if desig.check_constraints([('type', 'pointing_head'), 'coordinates']):
            solutions.append(desig.make_dictionary(
                [('cmd', 'point_head'), 'coordinates', ('wait', True), ('frame', 'map')]))
        return solutions

    return resolver


class FakeNavigation(ProcessModule):
    def __init__(self, journal):
        super().__init__('navigation')
        self.journal = journal

    def _execute(self, designator):
        solution = designator.reference()
        if solution['cmd'] == 'move':
            self.journal.add('navigation', 'move_to', solution['pose'], solution['frame'])


class FakeHead(ProcessModule):
    def __init__(self, journal):
        super().__init__('head')
        self.journal = journal

    def _execute(self, designator):
        solution = designator.reference()
        if solution['cmd'] == 'point_head':
            self.journal.add('head', 'point_head_to', solution['coordinates'])


class FakeArm(ProcessModule):
    """One physical arm (Pr2ArmL / Pr2ArmR of the thesis)."""

    def __init__(self, journal, side):
        super().__init__(f'arm_{side}')
        self.journal = journal
        self.side = side

    def _execute(self, designator):
        solution = designator.reference()
        if solution['cmd'] == 'set_arm_joints':
            self.journal.add(self.name, 'set_arm_joints', solution['positions'])


class OnlyArm(ProcessModule):
    """The one-armed robot's arm: it serves a request for either arm with its only arm."""

    def __init__(self, journal):
        super().__init__('arm')
        self.journal = journal

    def _execute(self, designator):
        solution = designator.reference()
        if solution['cmd'] == 'set_arm_joints':
            requested = {'0': 'left', '1': 'right'}[solution['arm']]
            self.journal.add('arm', 'set_arm_joints', solution['positions'],
                             f'requested {requested}')


def make_two_armed_robot():
    journal = Journal()
    robot = Robot('two-armed-test-robot')
    navigation = robot.add_process_module('navigation', FakeNavigation(journal))
    head = robot.add_process_module('head', FakeHead(journal))
    arm_l = robot.add_process_module('arm_left', FakeArm(journal, 'left'))
    arm_r = robot.add_process_module('arm_right', FakeArm(journal, 'right'))
    robot.motion_resolvers.append(motion_resolver(joint_count=7))

    def available_process_modules(design):  # thesis ch. 4.2.2: dispatch on type and arm
        if design.check_constraints([('type', 'moving')]):
            return navigation
        if design.check_constraints([('type', 'pointing_head')]):
            return head
        if design.check_constraints([('type', 'setting_arm_joints')]):
            if design.check_constraints([('arm', '0')]):
                return arm_l
            if design.check_constraints([('arm', '1')]):
                return arm_r
        return None

    robot.process_module_resolvers.append(available_process_modules)
    return robot, journal


def make_one_armed_robot():
    journal = Journal()
    robot = Robot('one-armed-test-robot')
    navigation = robot.add_process_module('navigation', FakeNavigation(journal))
    head = robot.add_process_module('head', FakeHead(journal))
    arm = robot.add_process_module('arm', OnlyArm(journal))
    robot.motion_resolvers.append(motion_resolver(joint_count=6))

    def available_process_modules(design):
        if design.check_constraints([('type', 'moving')]):
            return navigation
        if design.check_constraints([('type', 'pointing_head')]):
            return head
        if design.check_constraints([('type', 'setting_arm_joints')]):
            return arm  # either arm: the module decides how to serve it
        return None

    robot.process_module_resolvers.append(available_process_modules)
    return robot, journal


JOINTS = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]


def plan():
    """The same plan for every robot (thesis' reset_robot shape)."""
    perform(MotionDesignator([('type', 'moving'), ('pose', 'p0'), ('frame', 'map')]))
    errors = []
    state = par(
        lambda: perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '0'),
                                          ('positions', JOINTS)])),
        lambda: perform(MotionDesignator([('type', 'setting_arm_joints'), ('arm', '1'),
                                          ('positions', JOINTS)])),
        lambda: ProcessModule.perform(MotionDesignator([('type', 'pointing_head'),
                                                        ('coordinates', (1, 2, 3))])),
        errors=errors)
    assert state.get_value() is State.SUCCEEDED, errors


# --------------------------------------------------------------------------- tests


def test_same_plan_on_two_armed_robot():
    robot, journal = make_two_armed_robot()
    with robot:
        plan()
    entries = journal.entries
    assert entries[0] == ('navigation', 'move_to', 'p0', 'map')
    by_module = {e[0]: e for e in entries[1:]}
    assert by_module['arm_left'][2] == JOINTS and by_module['arm_right'][2] == JOINTS
    assert by_module['head'] == ('head', 'point_head_to', (1, 2, 3))
    assert len(entries) == 4


def test_same_plan_on_one_armed_robot():
    robot, journal = make_one_armed_robot()
    with robot:
        plan()
    entries = journal.entries
    assert entries[0] == ('navigation', 'move_to', 'p0', 'map')
    arm_entries = sorted(e for e in entries if e[0] == 'arm')
    assert arm_entries == [('arm', 'set_arm_joints', JOINTS[:6], 'requested left'),
                           ('arm', 'set_arm_joints', JOINTS[:6], 'requested right')]
    assert ('head', 'point_head_to', (1, 2, 3)) in entries and len(entries) == 4


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
        perform(MotionDesignator([('type', 'setting_torso'), ('position', 0.3)]))
    message = str(info.value)
    assert "('type', 'setting_torso')" in message and "('position', 0.3)" in message
    assert 'one-armed-test-robot' in message
    assert "['arm', 'head', 'navigation']" in message


def test_process_module_lookup_by_name():
    robot, _ = make_one_armed_robot()
    assert robot.process_module('arm').name == 'arm'
    with pytest.raises(KeyError, match="available: \\['arm', 'head', 'navigation'\\]"):
        robot.process_module('arm_left')
