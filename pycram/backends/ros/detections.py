"""Perception reports as ``pycram_msgs/DetectedItems`` messages, and back (no middleware here).

The simulator bridge publishes each look of the simulated head camera
(:meth:`pycram.sim.World.detect`: what the camera measured, perception faults included -- never
simulator names or true poses) with :func:`detections_message`; the ROS perception module turns
each message back into a :class:`~pycram.world.belief.PerceptionReport` with :func:`report_of`
and folds it into the robot's belief with :meth:`~pycram.world.belief.BeliefState.update`, as
the in-process perception module does. A real robot's perception publishes the same message.

Conventions: every pose is in the message's ``header.frame_id`` (the map); the camera pose is
OpenGL's (x right, y up, looking along -z); the depth image is ``32FC1`` [m along the optical
axis]; ``''`` stands for "none" in ``support`` / ``container``, NaN for a top's ``axis`` not
measured; ``slack`` [m] how far off a centre seen in part may be. A message without a depth image
carries no view: then no believed object is marked gone.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from pycram.world.belief import CameraView, Detection, PerceptionReport
from pycram.world.types import matrix_to_quat

__all__ = ["detections_message", "report_of", "quaternion_of", "rotation_of"]


def quaternion_of(rotation: Any) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of a 3x3 rotation matrix (Shepperd's method)."""
    return matrix_to_quat(np.asarray(rotation, float).reshape(3, 3))


def rotation_of(w: float, x: float, y: float, z: float) -> np.ndarray:
    """The 3x3 rotation matrix of the quaternion (w, x, y, z) (normalised first)."""
    norm = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def detections_message(report: PerceptionReport, message: Callable[..., Any], frame_id: str) -> Any:
    """A ``pycram_msgs/DetectedItems`` of ``report`` (poses in ``frame_id``); ``message(type,
    **fields)`` makes a message (:meth:`pycram.backends.ros.transport.Transport.message`). The caller
    sets ``header.stamp`` (a middleware time: ``report.stamp`` [s])."""
    out = message("pycram_msgs/DetectedItems")
    out.header.frame_id = frame_id
    view = report.view
    items = []
    for d in report.detections:
        projected = view.project(d.position) if view is not None else None
        items.append(
            message(
                "pycram_msgs/DetectedItem",
                name="",
                type=d.type,
                pose=_pose(message, d.position, (1.0, 0.0, 0.0, 0.0)),
                size=message("geometry_msgs/Vector3", x=float(d.size[0]), y=float(d.size[1]), z=float(d.size[2])),
                color=d.color,
                rgb=message("std_msgs/ColorRGBA", r=float(d.rgb[0]), g=float(d.rgb[1]), b=float(d.rgb[2]), a=1.0),
                support=d.support or "",
                container=d.container or "",
                pixels=int(d.pixels),
                u=float(projected[0]) if projected else 0.0,
                v=float(projected[1]) if projected else 0.0,
                axis=math.nan if d.axis is None else float(d.axis),
                slack=float(d.slack),
            )
        )
    out.items = items
    if view is not None:
        out.camera_pose = _pose(message, view.position, quaternion_of(view.rotation))
        out.fovy, out.max_range = float(view.fovy), float(view.max_range)
        depth = np.ascontiguousarray(view.depth, dtype="<f4")
        height, width = depth.shape
        out.depth = message(
            "sensor_msgs/Image",
            height=int(height),
            width=int(width),
            encoding="32FC1",
            is_bigendian=0,
            step=int(width) * 4,
            data=depth.tobytes(),
        )
        out.depth.header.frame_id = frame_id
    out.container_names = list(report.container_states)
    out.container_positions = [float(q) for q in report.container_states.values()]
    return out


def report_of(msg: Any, stamp: float) -> PerceptionReport:
    """The :class:`~pycram.world.belief.PerceptionReport` of a ``pycram_msgs/DetectedItems``
    message taken at ``stamp`` [s of the plan's clock]. ``ValueError`` for a depth image that is
    not ``32FC1`` or whose size does not match its data."""
    detections = tuple(
        Detection(
            type=i.type,
            position=(float(i.pose.position.x), float(i.pose.position.y), float(i.pose.position.z)),
            size=(float(i.size.x), float(i.size.y), float(i.size.z)),
            color=i.color,
            rgb=(float(i.rgb.r), float(i.rgb.g), float(i.rgb.b)),
            support=i.support or None,
            container=i.container or None,
            pixels=int(i.pixels),
            axis=None if math.isnan(i.axis) else float(i.axis),
            slack=float(i.slack),
        )
        for i in msg.items
    )
    view = None
    image = msg.depth
    if image.width and image.height:
        if image.encoding != "32FC1":
            raise ValueError(f"detections: depth image encoding {image.encoding!r}, expected '32FC1'")
        dtype = ">f4" if image.is_bigendian else "<f4"
        data = np.frombuffer(bytes(image.data), dtype=dtype)
        if data.size != image.width * image.height:
            raise ValueError(f"detections: depth image of {image.width} x {image.height} px carries {data.size} values")
        p, q = msg.camera_pose.position, msg.camera_pose.orientation
        view = CameraView(
            (float(p.x), float(p.y), float(p.z)),
            rotation_of(q.w, q.x, q.y, q.z),
            float(msg.fovy),
            data.astype(float).reshape(image.height, image.width),
            float(msg.max_range),
        )
    states = {name: float(q) for name, q in zip(msg.container_names, msg.container_positions)}
    return PerceptionReport(stamp, detections, view, states)


def _pose(message: Callable[..., Any], position: Any, quaternion: tuple[float, float, float, float]) -> Any:
    x, y, z = (float(v) for v in position)
    w, qx, qy, qz = quaternion
    return message(
        "geometry_msgs/Pose",
        position=message("geometry_msgs/Point", x=x, y=y, z=z),
        orientation=message("geometry_msgs/Quaternion", x=qx, y=qy, z=qz, w=w),
    )
