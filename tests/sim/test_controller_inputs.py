"""Every command ends whatever its input (issue 12, point 6): non-finite goals, durations,
tolerances and time-outs are refused with outcome "invalid" at start -- nothing moves, the world
keeps running. Today a NaN drive goal made the drive's duration NaN and the command never ended.
"""

from __future__ import annotations

import math

import pytest
from sim_helpers import T, ok

NAN, INF = math.nan, math.inf


def _refused(handle, what):
    outcome = handle.wait(T)  # bounded: a command that never ends fails here
    assert outcome is not None, f"{what}: the command did not end within {T} s of simulated time"
    assert not outcome.succeeded and outcome.reason == "invalid", (what, outcome)
    assert what in outcome.message, outcome.message
    return outcome


def test_non_finite_inputs_are_refused_and_nothing_moves(world):
    d = world.description
    arm = next(iter(d.ARMS))
    gripper = next(iter(d.GRIPPERS))
    joints = d.ARMS[arm]["joints"]
    before_base = world.base_pose.get_value()
    before_joints = dict(world.joint_states.get_value().position)
    park = list(d.ARM_CONFIGURATIONS[arm]["park"])
    cases = [
        (lambda: world.drive_to(NAN, 0.0, 0.0), "goal"),
        (lambda: world.drive_to(0.5, INF, 0.0), "goal"),
        (lambda: world.drive_to(0.5, 0.5, NAN), "goal"),
        (lambda: world.set_torso(NAN), "goal"),
        (lambda: world.set_torso(0.1, duration=NAN), "duration"),
        (lambda: world.set_torso(0.1, duration=INF), "duration"),
        (lambda: world.set_torso(0.1, duration=0.0), "duration must be positive"),
        (lambda: world.move_arm(arm, [NAN] * len(joints)), "goal"),
        (lambda: world.move_arm(arm, park, duration=-1.0), "duration must be positive"),
        (lambda: world.reach(arm, (NAN, 0.0, 1.0)), "position"),
        (lambda: world.reach(arm, (0.5, 0.0, 1.0), (NAN, 0.0, 0.0, 1.0)), "orientation"),
        (lambda: world.reach(arm, (0.5, 0.0, 1.0), tolerance=INF), "tolerance"),
        (lambda: world.point_head((1.0, NAN, 1.0)), "point"),
        (lambda: world.track_point((INF, 0.0, 1.0)), "point"),
        (lambda: world.set_gripper(gripper, NAN), "opening"),
        (lambda: world.set_gripper(gripper, 0.05, effort=INF), "effort"),
        (lambda: world.give_item("mug", gripper, timeout=NAN), "timeout"),
        (lambda: world.give_item("mug", gripper, timeout=INF), "timeout"),
    ]
    for command, what in cases:
        _refused(command(), what)
    after_base = world.base_pose.get_value()
    assert math.hypot(after_base.x - before_base.x, after_base.y - before_base.y) < 1e-3
    after_joints = world.joint_states.get_value().position
    assert max(abs(after_joints[j] - before_joints[j]) for j in joints) < 0.01
    assert world.running
    ok(world.set_torso(d.TORSO["default"]))  # the world still works


def test_the_process_modules_refuse_a_time_out_that_never_expires(world):
    from pycram.robots.common.sim_modules import NavigationModule

    module = NavigationModule(world)
    sent = []
    for timeout in (NAN, INF, 0.0, -1.0):
        with pytest.raises(ValueError, match="time-out must be a positive number"):
            module._run_command(lambda: sent.append(1), "drive", timeout=timeout)
    assert sent == []
