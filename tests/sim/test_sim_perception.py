"""Head camera and perception, for both robots: pointing (target near the image centre), tracking
while the base drives, and items that are occluded or out of view not being reported."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import ViewMonitor, ok

from pycram.environments import load as load_environment
from pycram.sim import ItemSpec, World

COUNTER_HEIGHT = load_environment("thesis-kitchen").surface("counter_back").height

ROBOTS = ("pr2", "tiago")
MUG_SPOT = (0.1, -1.15)  # on the back counter at cooker #2 [m]
CENTRE = (160.0, 120.0)  # of the 320 x 240 [px] images perceive() renders


def put_mug(world, xy=MUG_SPOT):
    half = world.scene.item("mug").half_height
    ok(world.move_item("mug", (xy[0], xy[1], COUNTER_HEIGHT + half)))
    return world.item_poses.get_value()["mug"].position


def test_head_camera_looks_at_target(world):
    mug = put_mug(world)
    pose = world.kitchen_base_pose("cooker #2")
    ok(world.drive_to(pose.x, pose.y, pose.yaw))
    angle = ok(world.point_head(mug))
    assert angle < math.radians(1.5)
    seen = {v.name: v for v in ok(world.perceive())}
    assert set(seen) == {"mug"}  # the box on the other counter is out of view
    u, v = seen["mug"].centroid
    cu, cv = CENTRE
    assert abs(u - cu) < 12 and abs(v - cv) < 12, (u, v)
    assert seen["mug"].type == "mug"
    assert np.linalg.norm(np.subtract(seen["mug"].pose.position, mug)) < 0.005


def test_head_tracks_target_continuously_while_driving(world):
    mug = put_mug(world)
    pose = world.kitchen_base_pose("cooker #2")
    ok(world.drive_to(pose.x, pose.y, pose.yaw))
    ok(world.point_head(mug))
    probe = ViewMonitor(mug)
    monitor = world.submit(probe, "view monitor")
    track = world.track_point(mug)
    if world.description.BASE.get("kind", "omnidirectional") == "omnidirectional":
        # sideways, and turning away from the mug by 0.5 rad: the head must counter-rotate
        ok(world.drive_to(pose.x + 0.6, pose.y + 0.1, pose.yaw - 0.5))
    else:  # a differential drive cannot step sideways: backwards on an arc, turning away 0.5 rad
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        ok(world.drive_to(pose.x - 0.4 * c - 0.1 * s, pose.y - 0.4 * s + 0.1 * c, pose.yaw - 0.5))
    monitor.cancel()
    assert monitor.wait(5.0).reason == "cancelled"
    moving = [angle for _, speed, angle in probe.samples if speed > 0.1]
    assert len(moving) > 50  # 0.5 s of driving at 100 Hz
    assert max(moving) < 2.0, max(moving)  # [deg] ~9 px from the centre of a 240 px high image
    seen = {v.name: v for v in ok(world.perceive())}
    cu, cv = CENTRE
    assert abs(seen["mug"].centroid[0] - cu) < 12 and abs(seen["mug"].centroid[1] - cv) < 12
    assert not track.done
    track.cancel()
    assert track.wait(5.0).reason == "cancelled"


@pytest.mark.parametrize("robot", ROBOTS)
def test_occluded_and_out_of_view_items_are_not_reported(robot):
    """A 40 cm crate stands between the head camera and a mug: only the crate is reported; with
    the crate gone the mug is; with the head turned away nothing is."""
    crate = ItemSpec("crate", "crate", "box", (0.12, 0.06, 0.2), 1.0, (0.1, -1.2, None), (0.6, 0.5, 0.3, 1))
    mug = ItemSpec("mug", "mug", "cylinder", (0.03, 0.05), 0.25, (0.1, -1.45, None), (0.85, 0.2, 0.15, 1))
    from pycram.backends.sim.robot_model import load_description

    base = load_description(robot).KITCHEN_BASE_POSES["cooker #2"]
    with World(robot, [crate, mug], base_pose=base) as world:
        target = world.item_poses.get_value()["mug"].position
        ok(world.point_head(target))
        seen = [v.name for v in ok(world.perceive())]
        assert seen == ["crate"]  # the mug is in the view frustum, but hidden
        ok(world.move_item("crate", (4.0, 4.0, 0.21)))
        seen = {v.name: v for v in ok(world.perceive())}
        assert set(seen) == {"mug"}
        b = world.base_pose.get_value()
        away = (b.x + 2.0 * math.cos(b.yaw + 1.2), b.y + 2.0 * math.sin(b.yaw + 1.2), 1.0)
        ok(world.point_head(away))
        assert ok(world.perceive()) == []
