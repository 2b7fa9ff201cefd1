"""Reading the geometry of an MJCF or URDF model file without a simulator: every geom's bounding
box in the world frame, its colour, whether it collides, and the bodies (links) it belongs to.

Used by `pycram.environments.from_file` (kitchens from files). Pure Python and numpy: the world
model knows no simulator. What is read -- the parts of the formats a kitchen model uses:

- **MJCF** (``.xml``): ``<worldbody>`` with nested ``<body>`` and ``<frame>`` elements (``pos``,
  ``quat``, ``euler``, ``axisangle``; ``<compiler angle="radian">`` and the default degrees),
  ``<geom>`` of type box, sphere, cylinder, capsule, ellipsoid and mesh (``size``, ``pos``,
  orientation, ``fromto``, ``rgba``, ``material``, ``contype``, ``conaffinity``), ``<default>``
  classes (``class``, ``childclass``) for geoms, ``<asset>`` materials and meshes (STL or OBJ,
  with ``<compiler meshdir>``), ``<include file>``. Planes are left out.
- **URDF** (``.urdf``): links with their ``<collision>`` geometry (box, cylinder, sphere, mesh)
  placed through the joints' ``<origin>`` (every joint at zero); a link that has only
  ``<visual>`` geometry becomes decoration. Mesh files are found relative to the URDF file
  (``package://`` URIs are refused: they need a ROS package path).

A geom's box is exact for boxes standing upright at right angles (`Geom.exact`); for other shapes
and orientations it is the bounding box of the shape's corners (of its mesh's vertices).
Lengths in [m], the model's world frame.
"""

from __future__ import annotations

import math
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

import numpy as np

__all__ = ["Geom", "ModelFileError", "read_model"]

_GREY = (0.5, 0.5, 0.5, 1.0)
_UNIT_BOX = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
_MAX_INCLUDES = 50


class ModelFileError(ValueError):
    """A model file that cannot be read: the message names the file and what is wrong."""


@dataclass(frozen=True)
class Geom:
    """One geom of a model: `lo` and `hi` are the corners of its axis-aligned bounding box in the
    world frame [m]; `bodies` its own body (link) first, then its ancestors; `exact` whether the
    box is the geom itself (an upright box at right angles)."""

    index: int
    name: str
    bodies: tuple[str, ...]
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    rgba: tuple[float, float, float, float]
    collides: bool
    exact: bool


def read_model(path: Path) -> list[Geom]:
    """The geoms of the MJCF (``.xml``) or URDF (``.urdf``) model at `path`. Raises
    `ModelFileError`."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        raise ModelFileError(f"{path}: not an XML file: {e}") from None
    if root.tag == "robot":
        return _Urdf(path, root).geoms()
    if root.tag == "mujoco":
        return _Mjcf(path, root).geoms()
    raise ModelFileError(f"{path}: neither MJCF (<mujoco>) nor URDF (<robot>), but <{root.tag}>")


# ------------------------------------------------------------------------ rotations
def _quat(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _axis(axis: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    m = np.eye(3)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    axis = axis / np.linalg.norm(axis)
    half = angle / 2
    return _quat(np.array([math.cos(half), *(axis * math.sin(half))]))


def _box_of(points: np.ndarray) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    lo, hi = points.min(axis=0), points.max(axis=0)
    return (float(lo[0]), float(lo[1]), float(lo[2])), (float(hi[0]), float(hi[1]), float(hi[2]))


def _exact(rot: np.ndarray) -> bool:
    """Whether `rot` keeps a box an upright box at right angles (a permutation of the axes about z)."""
    return bool(np.allclose(np.abs(rot[2]), [0, 0, 1], atol=1e-6)) and bool(
        np.allclose(np.abs(rot[:2, :2]).max(axis=1), 1.0, atol=1e-6)
    )


# ------------------------------------------------------------------------ meshes
def _mesh_vertices(path: Path) -> np.ndarray:
    """The vertices (n x 3) of an STL (binary or ASCII) or OBJ file."""
    try:
        data = path.read_bytes()
    except OSError as e:
        raise ModelFileError(f"cannot read the mesh {path}: {e}") from None
    suffix = path.suffix.lower()
    if suffix == ".obj":
        rows = [line.split()[1:4] for line in data.decode(errors="replace").splitlines() if line.startswith("v ")]
        vertices = np.array(rows, float)
    elif suffix == ".stl":
        count = struct.unpack_from("<I", data, 80)[0] if len(data) >= 84 else -1
        if count >= 0 and len(data) == 84 + 50 * count:  # binary: 50 bytes per triangle
            records = np.frombuffer(data, dtype=np.uint8, offset=84).reshape(count, 50)
            vertices = records[:, 12:48].copy().view("<f4").reshape(-1, 3).astype(float)
        else:
            rows = [line.split()[1:4] for line in data.decode(errors="replace").splitlines() if "vertex" in line]
            vertices = np.array(rows, float)
    else:
        raise ModelFileError(f"mesh {path.name}: only STL and OBJ files are read, not {suffix or 'no suffix'}")
    if vertices.size == 0:
        raise ModelFileError(f"mesh {path}: no vertices")
    return vertices.reshape(-1, 3)


def _shape_points(kind: str, size: list[float], where: str) -> np.ndarray:
    """Points in the geom frame whose bounding box is the geom's: of a box, sphere, cylinder,
    capsule or ellipsoid of MJCF `size`."""
    need = {"box": 3, "sphere": 1, "cylinder": 2, "capsule": 2, "ellipsoid": 3}[kind]
    if len(size) < need:
        raise ModelFileError(f"{where}: a {kind} needs {need} size values, not {size}")
    if kind in ("box", "ellipsoid"):
        half = size[:3]
    elif kind == "sphere":
        half = [size[0]] * 3
    elif kind == "cylinder":
        half = [size[0], size[0], size[1]]
    else:
        half = [size[0], size[0], size[1] + size[0]]
    return _UNIT_BOX * np.asarray(half, float)


# ------------------------------------------------------------------------ MJCF
class _Mjcf:
    def __init__(self, path: Path, root: ET.Element) -> None:
        self.path = path
        self.root = root
        self._inline(root, 0)
        compiler = root.find("compiler")
        self.radians = compiler is not None and compiler.get("angle", "degree") == "radian"
        if compiler is not None and compiler.get("eulerseq", "xyz") != "xyz":
            self.fail("only <compiler eulerseq='xyz'> (the default) is read")
        meshdir = compiler.get("meshdir") if compiler is not None else None
        self.meshdir = (path.parent / meshdir) if meshdir else path.parent
        self.materials = {
            m.get("name", ""): self._floats(m.get("rgba", "1 1 1 1"), "material rgba") for m in root.iter("material")
        }
        self.meshes = {m.get("name") or Path(m.get("file", "")).stem: m for m in root.iter("mesh") if m.get("file")}
        self.defaults: dict[str, dict[str, str]] = {}
        for default in root.findall("default"):
            self._read_defaults(default, {})
        self.out: list[Geom] = []

    def fail(self, message: str) -> NoReturn:
        raise ModelFileError(f"{self.path}: {message}")

    def _inline(self, element: ET.Element, depth: int) -> None:
        """Replace every <include file=...> below `element` with the children of that file."""
        for i, child in enumerate(list(element)):
            if child.tag == "include":
                if depth > _MAX_INCLUDES:
                    self.fail("too many nested <include>s")
                file = self.path.parent / child.get("file", "")
                try:
                    included = ET.parse(file).getroot()
                except (ET.ParseError, OSError) as e:
                    self.fail(f"<include file={child.get('file')!r}>: {e}")
                self._inline(included, depth + 1)
                element.remove(child)
                for k, grandchild in enumerate(list(included)):
                    element.insert(i + k, grandchild)
                self._inline(element, depth + 1)
                return
            self._inline(child, depth)

    def _read_defaults(self, default: ET.Element, inherited: dict[str, str]) -> None:
        name = default.get("class", "main")
        own = dict(inherited)
        geom = default.find("geom")
        if geom is not None:
            own.update(geom.attrib)
        self.defaults[name] = own
        for child in default.findall("default"):
            self._read_defaults(child, own)

    def _floats(self, text: str, where: str) -> list[float]:
        try:
            return [float(v) for v in text.split()]
        except ValueError:
            self.fail(f"{where}: expected numbers, not {text!r}")

    def _pose(self, element: ET.Element, where: str) -> tuple[np.ndarray, np.ndarray]:
        """(position, rotation) of `element` relative to its parent."""
        pos = np.asarray(self._floats(element.get("pos", "0 0 0"), f"{where} pos"), float)
        rot = np.eye(3)
        if element.get("quat") is not None:
            rot = _quat(np.asarray(self._floats(element.get("quat", ""), f"{where} quat"), float))
        elif element.get("euler") is not None:
            a, b, c = self._floats(element.get("euler", ""), f"{where} euler")
            scale = 1.0 if self.radians else math.pi / 180.0
            rot = _axis(0, a * scale) @ _axis(1, b * scale) @ _axis(2, c * scale)
        elif element.get("axisangle") is not None:
            x, y, z, angle = self._floats(element.get("axisangle", ""), f"{where} axisangle")
            rot = _axis_angle(np.array([x, y, z]), angle if self.radians else math.radians(angle))
        elif element.get("xyaxes") is not None or element.get("zaxis") is not None:
            self.fail(f"{where}: orientations by xyaxes or zaxis are not read; use quat, euler or axisangle")
        return pos, rot

    def geoms(self) -> list[Geom]:
        world = self.root.find("worldbody")
        if world is None:
            self.fail("no <worldbody>")
        assert world is not None
        self._walk(world, np.zeros(3), np.eye(3), (), "main")
        return self.out

    def _walk(self, element: ET.Element, pos: np.ndarray, rot: np.ndarray, bodies: tuple[str, ...], cls: str) -> None:
        for child in element:
            if child.tag in ("body", "frame"):
                name = child.get("name") or f"{child.tag} {len(self.out)}"
                p, r = self._pose(child, f"<{child.tag} {name!r}>")
                inner = ((name,) + bodies) if child.tag == "body" else bodies
                self._walk(child, pos + rot @ p, rot @ r, inner, child.get("childclass", cls))
            elif child.tag == "geom":
                self._geom(child, pos, rot, bodies, cls)

    def _geom(self, geom: ET.Element, pos: np.ndarray, rot: np.ndarray, bodies: tuple[str, ...], cls: str) -> None:
        attrs = dict(self.defaults.get("main", {}))
        attrs.update(self.defaults.get(geom.get("class", cls), {}))
        attrs.update(geom.attrib)
        kind = attrs.get("type", "sphere")
        index = len(self.out)
        name = attrs.get("name", "")
        where = f"<geom {name or index!r}>"
        if kind == "plane":
            return
        local: np.ndarray | None = None
        if "fromto" in attrs and kind in ("capsule", "cylinder", "box", "ellipsoid"):
            ends = pos + (rot @ np.asarray(self._floats(attrs["fromto"], f"{where} fromto"), float).reshape(2, 3).T).T
            radius = self._floats(attrs.get("size", "0"), f"{where} size")[0]
            if kind == "cylinder":  # a disc of the radius around each end, across the axis
                axis = (ends[1] - ends[0]) / max(float(np.linalg.norm(ends[1] - ends[0])), 1e-12)
                reach = radius * np.sqrt(np.clip(1.0 - axis**2, 0.0, 1.0))
            else:  # a sphere of the radius around each end (a box's square section: of its diagonal)
                reach = np.full(3, radius * (1.0 if kind == "capsule" else math.sqrt(2.0)))
            points, exact = (ends[:, None, :] + _UNIT_BOX[None, :, :] * reach).reshape(-1, 3), False
        elif kind == "mesh":
            mesh = self.meshes.get(attrs.get("mesh", ""))
            if mesh is None:
                self.fail(f"{where}: no <mesh> named {attrs.get('mesh')!r} with a file")
            assert mesh is not None
            scale = np.asarray(self._floats(mesh.get("scale", "1 1 1"), "mesh scale"), float)
            local = _mesh_vertices(self.meshdir / mesh.get("file", "")) * scale
        elif kind in ("box", "sphere", "cylinder", "capsule", "ellipsoid"):
            local = _shape_points(kind, self._floats(attrs.get("size", "0 0 0"), f"{where} size"), where)
        else:
            self.fail(f"{where}: geoms of type {kind!r} are not read (box, sphere, cylinder, capsule, ellipsoid, mesh)")
        if local is not None:
            p, r = self._pose(geom, where)
            g_rot = rot @ r
            points = (pos + rot @ p) + local @ g_rot.T
            exact = kind == "box" and _exact(g_rot)
        # the geom's own colour, else its material's, else its default class's
        if "rgba" in geom.attrib:
            rgba = self._floats(geom.attrib["rgba"], f"{where} rgba")
        elif attrs.get("material") in self.materials:
            rgba = self.materials[attrs["material"]]
        elif "rgba" in attrs:
            rgba = self._floats(attrs["rgba"], f"{where} rgba")
        else:
            rgba = list(_GREY)
        collides = attrs.get("contype", "1") != "0" or attrs.get("conaffinity", "1") != "0"
        lo, hi = _box_of(points)
        r4 = (rgba + [1.0] * 4)[:4]
        self.out.append(Geom(index, name, bodies or ("world",), lo, hi, (r4[0], r4[1], r4[2], r4[3]), collides, exact))


# ------------------------------------------------------------------------ URDF
def _origin(element: ET.Element | None, where: str, path: Path) -> tuple[np.ndarray, np.ndarray]:
    if element is None:
        return np.zeros(3), np.eye(3)
    try:
        xyz = np.array([float(v) for v in element.get("xyz", "0 0 0").split()])
        roll, pitch, yaw = (float(v) for v in element.get("rpy", "0 0 0").split())
    except ValueError:
        raise ModelFileError(f"{path}: {where}: <origin> needs numbers") from None
    return xyz, _axis(2, yaw) @ _axis(1, pitch) @ _axis(0, roll)


class _Urdf:
    def __init__(self, path: Path, root: ET.Element) -> None:
        self.path, self.root = path, root

    def fail(self, message: str) -> NoReturn:
        raise ModelFileError(f"{self.path}: {message}")

    def geoms(self) -> list[Geom]:
        links = {link.get("name", ""): link for link in self.root.findall("link")}
        parent: dict[str, tuple[str, np.ndarray, np.ndarray]] = {}
        for joint in self.root.findall("joint"):
            p, c = joint.find("parent"), joint.find("child")
            if p is None or c is None:
                self.fail(f"joint {joint.get('name')!r} needs a <parent> and a <child>")
            assert p is not None and c is not None
            xyz, rot = _origin(joint.find("origin"), f"joint {joint.get('name')!r}", self.path)
            parent[c.get("link", "")] = (p.get("link", ""), xyz, rot)
        poses: dict[str, tuple[np.ndarray, np.ndarray]] = {}

        def pose(link: str, depth: int = 0) -> tuple[np.ndarray, np.ndarray]:
            if link in poses:
                return poses[link]
            if depth > len(links) + 1:
                self.fail(f"the joints form a loop at link {link!r}")
            if link not in parent:
                poses[link] = (np.zeros(3), np.eye(3))
            else:
                up, xyz, rot = parent[link]
                p, r = pose(up, depth + 1)
                poses[link] = (p + r @ xyz, r @ rot)
            return poses[link]

        def chain(link: str) -> tuple[str, ...]:
            names = [link]
            while names[-1] in parent and len(names) <= len(links):
                names.append(parent[names[-1]][0])
            return tuple(names)

        out: list[Geom] = []
        for name, link in links.items():
            collisions = link.findall("collision")
            parts = [(c, True) for c in collisions] or [(v, False) for v in link.findall("visual")]
            for k, (part, collides) in enumerate(parts):
                where = f"link {name!r}"
                local = self._shape(part.find("geometry"), where)
                if local is None:
                    continue
                xyz, rot = _origin(part.find("origin"), where, self.path)
                lp, lr = pose(name)
                g_rot = lr @ rot
                points = (lp + lr @ xyz) + local @ g_rot.T
                geometry = part.find("geometry")
                is_box = geometry is not None and geometry.find("box") is not None
                color = part.find("material/color")
                rgba = _GREY
                if color is not None:
                    values = [float(v) for v in color.get("rgba", "0.5 0.5 0.5 1").split()] + [1.0] * 4
                    rgba = (values[0], values[1], values[2], values[3])
                lo, hi = _box_of(points)
                label = part.get("name") or (name if len(parts) == 1 else f"{name} {k + 1}")
                out.append(Geom(len(out), label, chain(name), lo, hi, rgba, collides, is_box and _exact(g_rot)))
        return out

    def _shape(self, geometry: ET.Element | None, where: str) -> np.ndarray | None:
        if geometry is None or len(geometry) == 0:
            return None
        shape = geometry[0]
        try:
            if shape.tag == "box":
                return _UNIT_BOX * np.array([float(v) for v in shape.get("size", "").split()]) / 2.0
            if shape.tag == "cylinder":
                r, length = float(shape.get("radius", "")), float(shape.get("length", ""))
                return _UNIT_BOX * np.array([r, r, length / 2.0])
            if shape.tag == "sphere":
                return _UNIT_BOX * float(shape.get("radius", ""))
        except ValueError:
            self.fail(f"{where}: <{shape.tag}> needs its sizes as numbers")
        if shape.tag == "mesh":
            filename = shape.get("filename", "")
            if filename.startswith("package://"):
                self.fail(
                    f"{where}: mesh {filename!r}: package:// URIs are not resolved; give a path relative to the URDF"
                )
            file = Path(filename.removeprefix("file://"))
            scale = np.array([float(v) for v in shape.get("scale", "1 1 1").split()])
            return _mesh_vertices(file if file.is_absolute() else self.path.parent / file) * scale
        self.fail(f"{where}: <{shape.tag}> geometry is not read (box, cylinder, sphere, mesh)")
