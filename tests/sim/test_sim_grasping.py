"""Grippers and grasping, for both robots: effort limits, contact-triggered grasps (never a
teleport), carrying an item through a 2 m drive, losing it (fault injection) and getting it back.

One world per robot is shared by the tests of this module; each test sets up the mug itself.
"""

from __future__ import annotations

import math

import numpy as np
from sim_helpers import T, facing_quat, ok

from pycram.environments import load as load_environment

KITCHEN = load_environment("thesis-kitchen")
COUNTER_HEIGHT = KITCHEN.surface("counter_back").height

MUG_SPOT = (0.1, -1.15)  # on the back counter at cooker #2 [m]


def approach_mug(world):
    """Put the mug on its spot, stand in front of it, open the gripper and hold it 12 cm behind
    the mug (on the approach line). Returns (arm, gripper, mug centre, tool orientation)."""
    d = world.description
    arm = d.DEFAULT_ARM
    gripper = d.ARMS[arm]["gripper"]
    half = world.scene.item("mug").half_height
    mug = (MUG_SPOT[0], MUG_SPOT[1], COUNTER_HEIGHT + half)
    ok(world.move_item("mug", mug))  # releases any grasp
    base = world.kitchen_base_pose("cooker #2")
    ok(world.set_torso(d.TORSO["range"][1] * 0.9))
    ok(world.set_gripper(gripper, 0.09))
    ok(world.move_arm_to(arm, "carry"))
    ok(world.drive_to(base.x, base.y, base.yaw))
    q = facing_quat(base.yaw)
    ok(world.reach(arm, (mug[0], mug[1] + 0.12, mug[2]), q))
    return arm, gripper, world.item_poses.get_value()["mug"].position, q


def test_closing_on_nothing_grasps_nothing_and_leaves_a_near_item_alone(world):
    arm, gripper, mug, _ = approach_mug(world)
    tool = world.tool_poses.get_value()[arm].position
    assert 0.08 < np.linalg.norm(np.subtract(tool, mug)) < 0.2  # close by, but not between the fingers
    closed = ok(world.set_gripper(gripper, 0.0))
    state = world.gripper_states[gripper].get_value()
    assert closed < 0.01 and state.opening < 0.01
    assert state.holding is None
    # the arm moves away: the mug stays where it was (no weld, no teleport)
    ok(world.reach(arm, (mug[0], mug[1] + 0.25, mug[2] + 0.1), None))
    assert np.linalg.norm(np.subtract(world.item_poses.get_value()["mug"].position, mug)) < 0.003
    assert world.gripper_states[gripper].get_value().holding is None


def test_gripper_effort_is_limited_and_grasp_needs_contact(world):
    arm, gripper, mug, q = approach_mug(world)
    world.reach(arm, mug, q, tolerance=0.02).wait(T)  # the tool may push the mug a little
    opening = ok(world.set_gripper(gripper, 0.0, effort=8.0))
    state = world.gripper_states[gripper].get_value()
    assert 0.03 < opening < 0.08  # stalled on the mug (diameter 6 cm)
    assert state.holding == "mug"  # both fingers touch it: grasped
    assert 7.0 < state.effort <= 8.0 + 1e-6  # squeezing with exactly the allowed effort [N]
    ok(world.set_gripper(gripper, 0.0, effort=40.0))
    assert 38.0 < world.gripper_states[gripper].get_value().effort <= 40.0 + 1e-6
    out = world.set_gripper(gripper, 0.0, effort=0.0).wait(T)
    assert out is not None and out.reason == "invalid"
    # opening releases it: the arm leaves and the mug stays
    ok(world.set_gripper(gripper, 0.09))
    assert world.gripper_states[gripper].get_value().holding is None
    ok(world.reach(arm, (mug[0], mug[1] + 0.25, mug[2] + 0.1), None))
    assert world.item_poses.get_value()["mug"].position[2] < COUNTER_HEIGHT + 0.1


def test_grasp_lift_drive_keeps_item_and_taking_it_closes_the_gripper(world):
    arm, gripper, mug, q = approach_mug(world)
    world.reach(arm, mug, q, tolerance=0.02).wait(T)
    ok(world.set_gripper(gripper, 0.0))
    assert world.gripper_states[gripper].get_value().holding == "mug"
    ok(world.reach(arm, (mug[0], mug[1] + 0.1, mug[2] + 0.1), q))
    assert world.item_poses.get_value()["mug"].position[2] > mug[2] + 0.05  # lifted
    ok(world.move_arm_to(arm, "carry"))
    start = world.base_pose.get_value()
    target = world.kitchen_base_pose("cooker #1")
    assert math.hypot(target.x - start.x, target.y - start.y) > 2.0
    ok(world.drive_to(target.x, target.y, target.yaw))
    held = world.item_poses.get_value()["mug"].position
    tool = world.tool_poses.get_value()[arm].position
    assert np.linalg.norm(np.subtract(held, tool)) < 0.05
    assert world.gripper_openings[gripper].get_value() > 0.03
    # fault: somebody takes the mug; the fingers close below 1 cm within 0.5 s of simulated time
    t0 = world.clock.now()
    assert ok(world.take_item(gripper)) == "mug"
    assert (world.gripper_openings[gripper] < 0.01).wait_for(0.5)
    assert world.clock.now() - t0 <= 0.5 + 0.02
    assert world.gripper_states[gripper].get_value().holding is None
    # ... and gives it back
    ok(world.give_item("mug", gripper))
    assert world.gripper_states[gripper].get_value().holding == "mug"
    assert world.gripper_openings[gripper].get_value() > 0.03
    # fault: the item is moved elsewhere (out of the gripper, onto cooker #1)
    cooker = KITCHEN.surface("cooker #1").centroid
    spot = (cooker[0], cooker[1], cooker[2] + world.scene.item("mug").half_height + 0.001)
    ok(world.move_item("mug", spot))
    assert world.gripper_states[gripper].get_value().holding is None
    assert np.linalg.norm(np.subtract(world.item_poses.get_value()["mug"].position, spot)) < 0.01
    ok(world.set_gripper(gripper, 0.09))
    ok(world.move_arm_to(arm, "park"))


def test_an_item_handed_into_the_open_gripper_is_grasped_when_the_robot_closes_it(world):
    d = world.description
    arm = d.DEFAULT_ARM
    gripper = d.ARMS[arm]["gripper"]
    ok(world.move_item("mug", (MUG_SPOT[0], MUG_SPOT[1], COUNTER_HEIGHT + world.scene.item("mug").half_height)))
    ok(world.set_gripper(gripper, 0.09))
    ok(world.move_arm_to(arm, "carry"))
    # a person holds the mug between the open fingers, waiting for the robot to close them
    handover = world.give_item("mug", gripper, close=False, timeout=3.0)
    assert handover.wait(0.5) is None  # not grasped yet: the gripper is still open
    assert world.gripper_states[gripper].get_value().holding is None
    closed = ok(world.set_gripper(gripper, 0.0))  # the robot's own command, not preempted by the person
    assert ok(handover) > 0.03 and closed > 0.03  # the fingers stalled on the mug
    assert world.gripper_states[gripper].get_value().holding == "mug"
    # nobody closes the gripper: the person gives up after the time-out and the mug drops
    ok(world.set_gripper(gripper, 0.09))
    assert world.gripper_states[gripper].get_value().holding is None
    unattended = world.give_item("mug", gripper, close=False, timeout=1.0).wait(T)
    assert unattended is not None and not unattended.succeeded and unattended.reason == "timeout"
    assert world.gripper_states[gripper].get_value().holding is None


def test_opening_lets_go_also_when_the_fingers_already_stand_fully_open(world):
    """A box grasped across its diagonal (found as 9.9 cm in put-away: a 7-cm carton turned 45
    deg) stalls the fingers at their widest; "open" is then no wider than they stand, and must
    let go all the same (it did not: the carton was carried back out of the fridge)."""
    d = world.description
    arm = d.DEFAULT_ARM
    gripper = d.ARMS[arm]["gripper"]
    widest = d.GRIPPERS[gripper]["max_opening"]
    ok(world.move_item("mug", (MUG_SPOT[0], MUG_SPOT[1], COUNTER_HEIGHT + world.scene.item("mug").half_height)))
    ok(world.set_gripper(gripper, widest))
    ok(world.move_arm_to(arm, "carry"))
    # held with the fingers as wide as they go (as the contact weld does for a diagonal grasp)
    ok(world._call("weld at full opening", lambda eng: eng.weld(eng.grippers[gripper], "mug")))
    assert world.gripper_states[gripper].get_value().holding == "mug"
    assert world.gripper_openings[gripper].get_value() >= widest - 0.002
    ok(world.set_gripper(gripper, widest))
    assert world.gripper_states[gripper].get_value().holding is None
