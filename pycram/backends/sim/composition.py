"""A composed robot's model: the arm's URDF with a mobile base, a torso lift column and a camera mast
with a pan/tilt head built from primitives around it (a description's ``COMPOSITION``, schema and
names in :mod:`pycram.world.robot_composition`).

The composition is done on the URDF text (`composed_urdf_text`), so the composed robot is one
URDF like any other and the simulator loads it the same way (`pycram.backends.sim.robot_model`).
The arm file's COLLADA meshes, which MuJoCo cannot read, are replaced by the STL meshes of the
same name in its ``collision`` folder; a COLLADA visual without one is left out.
"""

from __future__ import annotations

import functools
import logging
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import mujoco

from pycram.world.robot_composition import COMPOSED_NAMES, HEAD_PAN_RANGE, HEAD_TILT_RANGE
from pycram.world.robot_description import RobotDescription, RobotDescriptionError

from .assets import urdf_text

__all__ = ["COMPOSED_LINKS", "composed_urdf_text", "paint_composed"]

_log = logging.getLogger(__name__)

#: The links the composition builds around the arm, with their colours (r, g, b, a) in the simulator.
COMPOSED_LINKS: dict[str, tuple[float, float, float, float]] = {
    "base_footprint": (0.2, 0.2, 0.22, 1.0),
    "base_link": (0.22, 0.24, 0.3, 1.0),
    "torso_lift_link": (0.75, 0.75, 0.78, 1.0),
    "mast_link": (0.3, 0.3, 0.33, 1.0),
    "head_pan_link": (0.3, 0.3, 0.33, 1.0),
    "head_tilt_link": (0.15, 0.15, 0.17, 1.0),
    "head_camera_link": (0.1, 0.1, 0.1, 1.0),
}
#: Radius [m] of the camera mast.
MAST_RADIUS = 0.025
#: Half sizes [m] of the head's box (x: viewing direction), and the camera ahead of its centre [m].
HEAD_HALF_SIZE = (0.03, 0.07, 0.025)
CAMERA_AHEAD = 0.035
#: Masses [kg] of the composed links (gravity is compensated; they matter for contacts only).
_MASS = {"base_footprint": 1.0, "base_link": 40.0, "torso_lift_link": 10.0, "mast_link": 2.0}


def _fmt(values: Any) -> str:
    return " ".join(f"{float(v):.6g}" for v in values)


def _link(name: str, mass: float, geometry: ET.Element | None = None, origin: Any = (0.0, 0.0, 0.0)) -> ET.Element:
    link = ET.Element("link", name=name)
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz=_fmt(origin), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=f"{mass:g}")
    moment = max(mass * 0.01, 1e-4)
    ET.SubElement(
        inertial, "inertia", ixx=f"{moment:g}", ixy="0", ixz="0", iyy=f"{moment:g}", iyz="0", izz=f"{moment:g}"
    )
    if geometry is not None:
        collision = ET.SubElement(link, "collision")
        ET.SubElement(collision, "origin", xyz=_fmt(origin), rpy="0 0 0")
        geom = ET.SubElement(collision, "geometry")
        geom.append(geometry)
    return link


def _box(size: Any) -> ET.Element:
    return ET.Element("box", size=_fmt(size))


def _cylinder(radius: float, length: float) -> ET.Element:
    return ET.Element("cylinder", radius=f"{radius:g}", length=f"{length:g}")


def _joint(
    name: str,
    kind: str,
    parent: str,
    child: str,
    xyz: Any,
    rpy: Any = (0.0, 0.0, 0.0),
    axis: Any = None,
    limit: tuple[float, float, float] | None = None,
) -> ET.Element:
    """A URDF joint; `limit` is (lower, upper [m or rad], velocity [m/s or rad/s])."""
    joint = ET.Element("joint", name=name, type=kind)
    ET.SubElement(joint, "origin", xyz=_fmt(xyz), rpy=_fmt(rpy))
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    if axis is not None:
        ET.SubElement(joint, "axis", xyz=_fmt(axis))
    if limit is not None:
        ET.SubElement(
            joint, "limit", lower=f"{limit[0]:g}", upper=f"{limit[1]:g}", velocity=f"{limit[2]:g}", effort="1000"
        )
    return joint


def _mesh_for_mujoco(filename: str) -> str | None:
    """`filename` if MuJoCo reads it, else the STL of the same name in the ``collision`` folder
    (None when there is none)."""
    path = Path(filename)
    if path.suffix.lower() != ".dae":
        return filename
    stl = Path(str(path.parent).replace("/visual", "/collision")) / (path.stem + ".stl")
    return str(stl) if stl.is_file() else None


def _arm_root(robot: ET.Element, desc: RobotDescription) -> str:
    children = {c.get("link") for j in robot.findall("joint") for c in j.findall("child")}
    roots = [link.get("name", "") for link in robot.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise RobotDescriptionError(
            desc.NAME, "URDF", f"URDF: {desc.URDF} must have one root link to mount the arm by, it has {roots}"
        )
    return roots[0]


@functools.cache
def _composed_text(desc: RobotDescription) -> str:
    robot = ET.fromstring(urdf_text(desc.URDF))
    for link in robot.findall("link"):
        if link.get("name") in COMPOSED_LINKS:
            raise RobotDescriptionError(
                desc.NAME,
                "COMPOSITION",
                f"COMPOSITION: {desc.URDF} has a link {link.get('name')!r}, a name the composition builds",
            )
        for visual in link.findall("visual"):
            for mesh in visual.iter("mesh"):
                usable = _mesh_for_mujoco(mesh.get("filename", ""))
                if usable is None:
                    _log.info("%s: visual mesh %s left out (MuJoCo reads no COLLADA)", desc.NAME, mesh.get("filename"))
                    link.remove(visual)
                    break
                mesh.set("filename", usable)
    arm_root = _arm_root(robot, desc)
    c = desc.COMPOSITION or {}
    base, torso, arm, mast = c["base"], c["torso"], c["arm"], c["mast"]
    height = float(base["height"])
    if base["shape"] == "cylinder":
        base_geometry = _cylinder(float(base["radius"]), height)
    else:
        base_geometry = _box((*base["size"], height))
    tx, ty = torso["position"]
    sx, sy, column = torso["size"]
    low, high = desc.TORSO["range"]
    # the column reaches down into the base, so that it stands on it at any height (never below the floor)
    length = column + min(float(high), height - 0.02)
    mx, my = mast["position"]
    head_height = float(mast["height"])
    mast_length = head_height - height - HEAD_HALF_SIZE[2] - 0.01
    torso_joint = COMPOSED_NAMES[("TORSO", "joint")]
    pan, tilt = COMPOSED_NAMES[("HEAD", "pan_joint")], COMPOSED_NAMES[("HEAD", "tilt_joint")]
    parts = [
        _link("base_footprint", _MASS["base_footprint"]),
        _link("base_link", _MASS["base_link"], base_geometry, (0.0, 0.0, height / 2)),
        _joint("base_footprint_joint", "fixed", "base_footprint", "base_link", (0.0, 0.0, 0.0)),
        _link("torso_lift_link", _MASS["torso_lift_link"], _box((sx, sy, length)), (0.0, 0.0, -length / 2)),
        _joint(
            torso_joint,
            "prismatic",
            "base_link",
            "torso_lift_link",
            (tx, ty, height + column),
            axis=(0, 0, 1),
            limit=(float(low), float(high), 0.1),
        ),
        _joint("arm_mount_joint", "fixed", "torso_lift_link", arm_root, arm["xyz"], arm.get("rpy", (0.0, 0.0, 0.0))),
        _link("mast_link", _MASS["mast_link"], _cylinder(MAST_RADIUS, mast_length), (0.0, 0.0, mast_length / 2)),
        _joint("mast_joint", "fixed", "base_link", "mast_link", (mx, my, height)),
        _link("head_pan_link", 0.3, _cylinder(MAST_RADIUS * 1.4, 0.02), (0.0, 0.0, -HEAD_HALF_SIZE[2] - 0.01)),
        _joint(
            pan,
            "revolute",
            "mast_link",
            "head_pan_link",
            (0.0, 0.0, head_height - height),
            axis=(0, 0, 1),
            limit=(*HEAD_PAN_RANGE, 2.0),
        ),
        _link("head_tilt_link", 0.5, _box([2 * h for h in HEAD_HALF_SIZE])),
        _joint(
            tilt,
            "revolute",
            "head_pan_link",
            "head_tilt_link",
            (0.0, 0.0, 0.0),
            axis=(0, 1, 0),
            limit=(*HEAD_TILT_RANGE, 2.0),
        ),
        _link("head_camera_link", 0.01),
        _joint("head_camera_joint", "fixed", "head_tilt_link", "head_camera_link", (CAMERA_AHEAD, 0.0, 0.0)),
    ]
    robot.extend(parts)
    robot.set("name", desc.NAME)
    return ET.tostring(robot, encoding="unicode")


def composed_urdf_text(desc: RobotDescription) -> str:
    """The URDF text of the composed robot of `desc` (which has a ``COMPOSITION``), ready for
    `mujoco.MjSpec.from_string`: the arm's URDF (``desc.URDF``) with the base, the torso lift
    column, the mast and the head of the module docstring. Raises `RobotDescriptionError` when
    the arm's URDF has no single root link or uses a name the composition builds."""
    if desc.COMPOSITION is None:
        raise ValueError(f"robot {desc.NAME!r} has no COMPOSITION: load its URDF {desc.URDF!r} as it is")
    return _composed_text(desc)


def paint_composed(spec: mujoco.MjSpec) -> None:
    """Colour the geoms of the composed links (`COMPOSED_LINKS`) in `spec`."""
    for name, rgba in COMPOSED_LINKS.items():
        body = spec.body(name)
        if body is None:
            continue
        for geom in body.geoms:
            geom.rgba = list(rgba)
