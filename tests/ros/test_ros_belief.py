"""Perception over ROS fills the robot's belief (real roscore, real bridge process): the
``detecting`` motion folds each detections message into ``robot.belief`` as the in-process one
does, object designators resolve against it, and an object taken away is marked gone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pycram.designator import MotionDesignator, NoSolutionError, ObjectDesignator, perform
from pycram.world.belief import CameraView, Detection, PerceivedObject, PerceptionReport


def motion(**properties):
    return perform(MotionDesignator(**properties))


# -- the message conversion, without a master --------------------------------------------------


def _message_factory():
    pytest.importorskip("pycram_msgs.msg", reason="pycram_msgs not generated (run scripts/install_ros.sh)")
    from pycram.backends.ros.ros1 import message_class

    return lambda msg_type, **fields: message_class(msg_type)(**fields)


def test_a_report_survives_the_message_round_trip():
    from pycram.backends.ros.detections import detections_message, quaternion_of, report_of, rotation_of

    message = _message_factory()
    angle = 0.7
    rotation = np.array(  # a camera looking along +x of the map, tilted: columns are its axes
        [[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    ) @ np.array([[1, 0, 0], [0, math.cos(angle), -math.sin(angle)], [0, math.sin(angle), math.cos(angle)]])
    depth = np.linspace(0.5, 3.0, 12 * 16, dtype=float).reshape(12, 16)
    view = CameraView((0.1, 0.2, 1.3), rotation, 49.5, depth, 3.5)
    detection = Detection(
        "mug", (1.0, 0.2, 0.95), (0.06, 0.06, 0.1), "red", (0.8, 0.1, 0.1), "counter", "drawer", 57, 0.4, 0.03
    )
    plain = Detection("bowl", (1.2, -0.1, 0.93), (0.1, 0.1, 0.05), "white", (0.9, 0.9, 0.9), None, None, 30)
    report = PerceptionReport(12.5, (detection, plain), view, {"drawer": 0.21})
    msg = detections_message(report, message, "map")
    # through the wire format
    import io

    buffer = io.BytesIO()
    msg.serialize(buffer)
    received = type(msg)().deserialize(buffer.getvalue())
    back = report_of(received, 12.5)
    assert back.stamp == 12.5
    assert back.container_states == {"drawer": pytest.approx(0.21)}
    assert back.detections[0].type == "mug" and back.detections[0].color == "red"
    assert back.detections[0].position == pytest.approx(detection.position)
    assert back.detections[0].size == pytest.approx(detection.size)
    assert back.detections[0].rgb == pytest.approx(detection.rgb, abs=1e-6)  # ColorRGBA is float32
    assert (back.detections[0].support, back.detections[0].container, back.detections[0].pixels) == (
        "counter",
        "drawer",
        57,
    )
    assert (back.detections[1].support, back.detections[1].container) == (None, None)
    assert (back.detections[0].axis, back.detections[0].slack) == pytest.approx((0.4, 0.03))
    assert (back.detections[1].axis, back.detections[1].slack) == (None, 0.0)  # not measured, seen whole
    assert back.view is not None
    assert back.view.position == pytest.approx(view.position)
    assert np.asarray(back.view.rotation) == pytest.approx(rotation, abs=1e-9)
    assert back.view.depth == pytest.approx(depth, abs=1e-6)  # float32 on the wire
    assert (back.view.fovy, back.view.max_range) == (49.5, 3.5)
    assert quaternion_of(np.eye(3)) == pytest.approx((1.0, 0.0, 0.0, 0.0))
    rng = np.random.default_rng(3)
    for _ in range(50):  # every branch of the matrix -> quaternion conversion
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        q = q @ np.diag(np.sign(np.diag(r)))
        q = q if np.linalg.det(q) > 0 else -q
        assert rotation_of(*quaternion_of(q)) == pytest.approx(q, abs=1e-9)
    u, v, _ = view.project(detection.position)
    assert (received.items[0].u, received.items[0].v) == pytest.approx((u, v))
    assert received.items[0].name == ""  # the recogniser names no instances


def test_a_message_without_a_view_marks_nothing_gone():
    from pycram.backends.ros.detections import report_of
    from pycram.world.belief import BeliefState

    message = _message_factory()
    msg = message("pycram_msgs/DetectedItems")
    assert report_of(msg, 1.0).view is None
    belief = BeliefState()
    belief.update(PerceptionReport(0.0, (Detection("mug", (1.0, 0.0, 0.9), (0.1, 0.1, 0.1), "red"),)))
    update = belief.update(report_of(msg, 1.0))
    assert update.gone == () and not belief.present()[0].gone


# -- over ROS -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def robot(pr2_with_mug):
    """The PR2 behind a bridge with the demo's mug on slot 1, active for the module."""
    return pr2_with_mug


def _look_at_slot(robot) -> tuple[float, float]:
    from pycram.apps.demos.kitchen_world import SLOTS

    x, y = SLOTS[1]
    here = robot.state.base_pose.get_value()
    motion(type="moving", pose=(here.x, here.y, math.atan2(y - here.y, x - here.x)), frame="map")
    motion(type="setting_torso", position="up")
    motion(type="pointing_head", coordinates=[x, y, 0.95])
    return x, y


def test_an_object_never_perceived_cannot_be_resolved(robot):
    assert robot.belief.present() == []
    with pytest.raises(NoSolutionError):
        ObjectDesignator(type="mug").reference()


def test_detecting_fills_the_belief_and_a_designator_resolves_against_it(robot):
    x, y = _look_at_slot(robot)
    seen = motion(type="detecting")
    assert [o.type for o in seen] == ["mug"], seen
    mug = seen[0]
    assert isinstance(mug, PerceivedObject)
    assert mug.name == "mug-1"  # a belief name: nothing is taken from the simulator
    assert mug.pose[0] == pytest.approx(x, abs=0.05) and mug.pose[1] == pytest.approx(y, abs=0.05)
    props = mug.properties
    assert props["color"] == "yellow"  # the demo's mug, measured from the camera's colour image
    width, depth, height = props["size"]
    assert 0.03 < width < 0.15 and 0.05 < height < 0.15, props["size"]
    assert props["on"], props  # the surface it rests on, from the environment's description
    assert props["last_seen"] > 0.0 and mug.times_seen == 1
    assert robot.belief.looks, "the look's camera view was recorded"
    assert ObjectDesignator(type="mug").reference() is mug
    with pytest.raises(NoSolutionError):
        ObjectDesignator(type="bowl").reference()  # never seen


def test_a_second_look_refreshes_the_same_object(robot):
    (mug,) = robot.belief.present()
    first = mug.last_seen
    seen = motion(type="detecting", object="mug")
    assert seen == [mug] and mug.times_seen == 2 and mug.last_seen > first
    module = robot.process_modules["perception"]
    update = module.last_update
    assert update.refreshed == (mug,) and update.added == () and update.gone == ()


def test_the_detect_action_works_over_ros(robot):
    from pycram.actions import Detect
    from pycram.failures import ObjectNotVisible

    (mug,) = robot.belief.present()
    designator = ObjectDesignator(type="mug")
    assert perform(Detect(designator)) == [mug]
    with pytest.raises(ObjectNotVisible):
        perform(Detect("bowl"))


def test_an_object_taken_away_is_marked_gone_after_the_next_two_looks(robot, transport):
    (mug,) = robot.belief.present()
    take = transport.service(f"{robot.config.sim_namespace}/command", "pycram_msgs/SimCommand")
    response = take(command="take_item", item="mug", gripper="", wait=5.0)
    assert response.success, response
    assert motion(type="detecting") == []
    update = robot.process_modules["perception"].last_update
    assert update.missed == (mug,) and not mug.gone  # one look is no proof of absence
    assert motion(type="detecting") == []
    update = robot.process_modules["perception"].last_update
    assert update.gone == (mug,) and mug.gone
    with pytest.raises(NoSolutionError):
        ObjectDesignator(type="mug").reference()
