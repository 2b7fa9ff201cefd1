"""Check d: the robot's camera sees a test object in front of it, into its belief.

The test object (the scene's cup) is put upright on the floor `DISTANCE` ahead of the robot's
base, where the robot stands (the simulator moves it, as a test fixture would; the robot is not
told). The robot points its head at that spot and performs one ``detecting`` motion for the
object's type. The check passes when perception folds the object into the robot's belief
(``robot.belief``) within `POSITION_TOLERANCE` of where it truly stands (the simulator's truth).
Nothing else is asked of the robot -- no drive, no location reasoning -- so a failure here is
the camera's or perception's.
"""

from __future__ import annotations

import math
from typing import Any

from pycram.apps.robot_check.results import CheckFailed, CheckSkipped
from pycram.apps.robot_check.scene import SETUP_TIMEOUT, TEST_OBJECT, CheckScene

__all__ = ["DISTANCE", "POSITION_TOLERANCE", "camera_sees_test_object"]

#: How far ahead of the base [m] the test object is put on the floor.
DISTANCE = 1.0
#: The believed object's centre must lie this close [m] to the true one.
POSITION_TOLERANCE = 0.03


def camera_sees_test_object(scene: CheckScene) -> tuple[str, dict[str, Any]]:
    """Run the check (see the module docstring) with the robot active; returns (detail, data),
    raises `CheckFailed` naming what was seen instead."""
    from pycram.designator import MotionDesignator, perform
    from pycram.world.objects import object_type

    world = scene.world
    base = world.base_pose.get_value()
    x, y = base.x + DISTANCE * math.cos(base.yaw), base.y + DISTANCE * math.sin(base.yaw)
    if not world.environment.is_free_floor(x, y, margin=0.1):
        raise CheckSkipped(
            f"no free floor {DISTANCE} m ahead of the base at ({base.x:.2f}, {base.y:.2f}) for the test object"
        )
    outcome = world.move_item(TEST_OBJECT, (x, y, object_type(TEST_OBJECT).half_height + 0.002)).wait(SETUP_TIMEOUT)
    if outcome is None or not outcome.succeeded:
        raise RuntimeError(f"could not put the test {TEST_OBJECT} on the floor: {outcome}")
    truth = world.item_poses.get_value()[TEST_OBJECT].position
    perform(MotionDesignator(type="pointing_head", coordinates=tuple(truth)))
    seen = perform(MotionDesignator(type="detecting", object=TEST_OBJECT))
    believed = [o for o in scene.robot.belief.present() if o.type == TEST_OBJECT]
    if not believed:
        names = ", ".join(getattr(o, "name", str(o)) for o in seen) or "nothing"
        raise CheckFailed(f"the {TEST_OBJECT} {DISTANCE} m ahead is not in the belief after a look (saw {names})")
    best = min(believed, key=lambda o: math.dist(o.pose, truth))
    error = math.dist(best.pose, truth)
    data = {"object": best.name, "error": error, "distance": DISTANCE}
    if error > POSITION_TOLERANCE:
        raise CheckFailed(
            f"the believed {best.name} is {error * 100:.1f} cm from the true {TEST_OBJECT} "
            f"(> {POSITION_TOLERANCE * 100:.0f})",
            data,
        )
    return f"{best.name} on the floor {DISTANCE} m ahead, believed {error * 1000:.0f} mm from where it stands", data
