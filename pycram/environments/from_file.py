"""Kitchens from files: an MJCF or URDF model plus a small TOML sidecar that names its surfaces,
containers and places.

    from pycram.environments import load
    kitchen = load("file:examples/kitchens/small_kitchen.toml")
    # or: pycram.environments.from_file.load_file("examples/kitchens/small_kitchen.toml")

The model's geometry becomes the environment's static boxes: every geom is taken as its
axis-aligned bounding box in the map frame (exact for boxes that are not rotated about x or y;
other shapes and rotated boxes are approximated by their bounding box, and a log line says which).
Planes are left out (the simulator adds its own floor); geoms that collide with nothing stay
decoration (seen, never touched). The sidecar (TOML, `tomllib` of the standard library) says:

    name = "small-kitchen"           # optional: the environment's name (default: file:PATH)
    title = "A small kitchen"        # optional
    model = "small_kitchen.xml"      # the MJCF (.xml) or URDF (.urdf) file, relative to the sidecar
    floor = [[0.0, 0.0, 4.5, 4.0]]   # rectangles of floor inside the walls [m]

    [[surfaces]]                     # an open surface: the top of a body's geoms, or a rectangle
    name = "counter"
    kind = "counter"                 # counter, table, cooker, shelf, drawer, cupboard
    body = "counter"                 # or: rect = [x0, y0, x1, y1] and height = 0.9

    [[containers]]                   # a drawer or a hinged door: its moving part is a body of the
    name = "drawer 1"                # model, left out of the static geometry and rebuilt as a
    kind = "drawer"                  # drawer (bottom and four walls) on a slide, or a door panel on
    body = "drawer_1"                # a hinge, so that it opens physically
    opening_direction = [1.0, 0.0]   # where a drawer slides out / a closed door's outward normal
    limits = [0.0, 0.4]              # [m] for a drawer, [rad] for a door
    # handle = [x, y, z]             # a drawer's default: 4 cm in front of its front, near the top
    # hinge = [x, y]                 # a door's hinge axis (required for doors, as its handle)
    # [[containers.interior]]        # a drawer's default: "NAME inside", its bottom; a door's
    # name = ...; rect = [...]; height = ...; clearance = ...; kind = "shelf"  (required)

    [[places]]
    name = "start"                   # required
    pose = [2.0, 1.0, 1.5708]        # x [m], y [m], yaw [rad]

    [camera]                         # optional: the overview camera
    position = [5.0, -1.5, 3.2]
    target = [2.0, 2.0, 0.3]
    fovy = 55.0

The model is read by `pycram.environments.model_files` (no simulator needed). Lengths in [m],
angles in [rad], map frame (the model's world frame): x east, y north, z up.
"""

from __future__ import annotations

import functools
import logging
import math
import tomllib
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from pycram.world.environment import Box, Camera, Container, Environment, Place, Surface

from .errors import KitchenFileError
from .model_files import Geom, ModelFileError, read_model

__all__ = ["KitchenFileError", "load_file", "SURFACE_KINDS"]

log = logging.getLogger(__name__)

#: The kinds a sidecar's surfaces may have.
SURFACE_KINDS = ("counter", "table", "cooker", "shelf", "drawer", "cupboard")
_DRAWER_WALL = 0.015  # [m] the panels of a rebuilt drawer
_HANDLE_STANDOFF = 0.04  # [m] a default handle's distance in front of the drawer's front
_TOP_KEYS = {"name", "title", "model", "floor", "surfaces", "containers", "places", "camera", "extent", "notes"}


def load_file(path: str | Path) -> Environment:
    """The environment described by the TOML sidecar at `path` and the model it names.

    Cached per resolved path (the same file gives the same object; edit the file and start a
    new process, or call ``load_file.cache_clear()``). Raises `KitchenFileError`."""
    return _load(Path(path).expanduser().resolve())


@functools.lru_cache(maxsize=16)
def _load(path: Path) -> Environment:
    if not path.is_file():
        raise KitchenFileError(f"no sidecar file {str(path)!r}")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise KitchenFileError(f"{path}: not a TOML file: {e}") from None
    return _Sidecar(path, data).environment()


class _Sidecar:
    """One sidecar being read: its data, the model's geoms, and what is left of them."""

    def __init__(self, path: Path, data: dict[str, Any]) -> None:
        self.path, self.data = path, data
        unknown = sorted(set(data) - _TOP_KEYS)
        if unknown:
            self.fail(f"unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(_TOP_KEYS))}")
        model = data.get("model")
        if not isinstance(model, str):
            self.fail("'model' must name the MJCF (.xml) or URDF (.urdf) file, relative to the sidecar")
        self.model_path = (path.parent / model).resolve()
        if not self.model_path.is_file():
            self.fail(f"the model file {str(self.model_path)!r} does not exist")
        try:
            self.geoms = read_model(self.model_path)
        except ModelFileError as e:
            raise KitchenFileError(str(e)) from None
        self.used: set[int] = set()  # geoms that became container bodies

    def fail(self, message: str) -> NoReturn:
        raise KitchenFileError(f"{self.path}: {message}")

    # ---------------------------------------------------------------- helpers
    def _entry(self, table: dict[str, Any], key: str, where: str, kind: type | tuple[type, ...]) -> Any:
        if key not in table:
            self.fail(f"{where}: {key!r} is missing")
        value = table[key]
        if not isinstance(value, kind):
            self.fail(f"{where}: {key!r} must be a {getattr(kind, '__name__', kind)}, not {value!r}")
        return value

    def _numbers(self, value: Any, n: int, where: str) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != n or not all(isinstance(v, int | float) for v in value):
            self.fail(f"{where}: expected {n} numbers, not {value!r}")
        return tuple(float(v) for v in value)

    def _pair(self, value: Any, where: str) -> tuple[float, float]:
        a, b = self._numbers(value, 2, where)
        return (a, b)

    def _triple(self, value: Any, where: str) -> tuple[float, float, float]:
        a, b, c = self._numbers(value, 3, where)
        return (a, b, c)

    def _rect(self, value: Any, where: str) -> tuple[float, float, float, float]:
        a, b, c, d = self._numbers(value, 4, where)
        return (a, b, c, d)

    def _body_geoms(self, body: str, where: str) -> list[Geom]:
        found = [g for g in self.geoms if body in g.bodies]
        if not found:
            bodies = sorted({g.bodies[0] for g in self.geoms})
            self.fail(f"{where}: the model has no body {body!r} with geoms; bodies: {', '.join(bodies)}")
        return found

    def _body_box(self, body: str, name: str, where: str, solid: bool = False) -> Box:
        """The bounding box of the geoms of `body` (and its descendants); with `solid`, of
        those that collide when there are any (a decoration on a counter is not its top)."""
        geoms = self._body_geoms(body, where)
        if solid and any(g.collides for g in geoms):
            geoms = [g for g in geoms if g.collides]
        lo = np.min([g.lo for g in geoms], axis=0)
        hi = np.max([g.hi for g in geoms], axis=0)
        center, half = (lo + hi) / 2, (hi - lo) / 2
        return Box(name, _vec(center), _vec(half), geoms[0].rgba)

    # ---------------------------------------------------------------- parts
    def _surface(self, entry: Any, where: str, default_kind: str = "counter") -> Surface:
        if not isinstance(entry, dict):
            self.fail(f"{where}: expected a table (name = ..., ...), not {entry!r}")
        name = self._entry(entry, "name", where, str)
        where = f"{where} {name!r}"
        kind = entry.get("kind", default_kind)
        if kind not in SURFACE_KINDS:
            self.fail(f"{where}: kind must be one of {', '.join(SURFACE_KINDS)}, not {kind!r}")
        clearance = float(entry.get("clearance", math.inf))
        if "body" in entry:
            box = self._body_box(self._entry(entry, "body", where, str), name, where, solid=True)
            rect, height = box.footprint, box.z_range[1]
            inset = float(entry.get("inset", 0.0))
            rect = (rect[0] + inset, rect[1] + inset, rect[2] - inset, rect[3] - inset)
        else:
            if "rect" not in entry or "height" not in entry:
                self.fail(f"{where}: give 'body' (the top of a body of the model) or 'rect' and 'height'")
            rect, height = self._rect(entry["rect"], f"{where} rect"), float(entry["height"])
        if rect[2] - rect[0] <= 0 or rect[3] - rect[1] <= 0:
            self.fail(f"{where}: the rectangle {rect} is empty")
        x0, y0, x1, y1 = (round(v, 4) for v in rect)
        return Surface.rectangle(name, (x0, y0, x1, y1), round(height, 4), kind, clearance)

    def _container(self, entry: Any, where: str) -> Container:
        if not isinstance(entry, dict):
            self.fail(f"{where}: expected a table (name = ..., ...), not {entry!r}")
        name = self._entry(entry, "name", where, str)
        where = f"{where} {name!r}"
        kind = self._entry(entry, "kind", where, str)
        if kind not in ("drawer", "door"):
            self.fail(f"{where}: kind must be 'drawer' or 'door', not {kind!r}")
        body_name = self._entry(entry, "body", where, str)
        geoms = self._body_geoms(body_name, where)
        self.used |= {g.index for g in geoms}
        body = self._body_box(body_name, name, where)
        dx, dy = self._pair(self._entry(entry, "opening_direction", where, list), f"{where} opening_direction")
        norm = math.hypot(dx, dy)
        if norm < 1e-9:
            self.fail(f"{where}: opening_direction must not be zero")
        direction = (dx / norm, dy / norm)
        limits = self._pair(self._entry(entry, "limits", where, list), f"{where} limits")
        if not limits[0] < limits[1]:
            self.fail(f"{where}: limits must rise, not {list(limits)}")
        hinge: tuple[float, float] | None = None
        if kind == "door":
            hinge = self._pair(self._entry(entry, "hinge", where, list), f"{where} hinge")
            handle = self._triple(self._entry(entry, "handle", where, list), f"{where} handle")
        elif "handle" in entry:
            handle = self._triple(entry["handle"], f"{where} handle")
        else:  # in front of the middle of the drawer's front, near its top
            front = max(_along(direction, x, y) for x, y in _corners(body.footprint))
            cx, cy, cz = body.center
            ahead = front - _along(direction, cx, cy) + _HANDLE_STANDOFF
            handle = (cx + direction[0] * ahead, cy + direction[1] * ahead, cz + min(0.06, body.half[2] - 0.05))
        interior_entries = entry.get("interior")
        if interior_entries is None:
            if kind == "door":
                self.fail(f"{where}: a door needs its interior: [[containers.interior]] name, rect, height")
            wall = float(entry.get("wall", _DRAWER_WALL))
            x0, y0, x1, y1 = body.footprint
            bottom = body.z_range[0] + wall
            interior: tuple[Surface, ...] = (
                Surface.rectangle(
                    f"{name} inside",
                    (round(x0 + wall, 4), round(y0 + wall, 4), round(x1 - wall, 4), round(y1 - wall, 4)),
                    round(bottom, 4),
                    "drawer",
                    clearance=round(2 * body.half[2] - wall - 0.01, 4),
                ),
            )
        else:
            if not isinstance(interior_entries, list):
                self.fail(f"{where}: 'interior' must be a list of tables ([[containers.interior]])")
            default = "drawer" if kind == "drawer" else "shelf"
            interior = tuple(self._surface(s, f"{where} interior", default) for s in interior_entries)
        defaults = (30.0, 4.0) if kind == "drawer" else (6.0, 1.5)
        try:
            return Container(
                name=name,
                kind="drawer" if kind == "drawer" else "door",
                body=body,
                handle=_vec(handle),
                opening_direction=direction,
                limits=limits,
                interior=interior,
                hinge=hinge,
                damping=float(entry.get("damping", defaults[0])),
                friction=float(entry.get("friction", defaults[1])),
                wall=float(entry.get("wall", _DRAWER_WALL)),
            )
        except ValueError as e:
            self.fail(f"{where}: {e}")

    def _static(self) -> tuple[Box, ...]:
        boxes, names, approximated = [], set(), []
        for g in self.geoms:
            if g.index in self.used:
                continue
            name = g.name or f"{g.bodies[0]} geom {g.index}"
            while name in names:
                name += "'"
            names.add(name)
            lo, hi = np.asarray(g.lo), np.asarray(g.hi)
            center, half = (lo + hi) / 2, (hi - lo) / 2
            boxes.append(Box(name, _vec(center), _vec(half), g.rgba, collides=g.collides))
            if not g.exact:
                approximated.append(name)
        if approximated:
            log.info("%s: taken as their bounding boxes: %s", self.model_path.name, ", ".join(approximated))
        self.approximated = approximated
        return tuple(boxes)

    # ---------------------------------------------------------------- the whole
    def environment(self) -> Environment:
        data = self.data
        surfaces = tuple(self._surface(s, "surfaces", "counter") for s in data.get("surfaces", []))
        containers = tuple(self._container(c, "containers") for c in data.get("containers", []))
        static = self._static()
        floor_value = data.get("floor")
        if not isinstance(floor_value, list) or not floor_value:
            self.fail("'floor' must list rectangles of floor inside the walls: [[x0, y0, x1, y1], ...]")
        floor = tuple(self._rect(f, "floor") for f in floor_value)
        places = []
        for entry in data.get("places", []):
            if not isinstance(entry, dict):
                self.fail(f"places: expected a table (name = ..., pose = [x, y, yaw]), not {entry!r}")
            name = self._entry(entry, "name", "places", str)
            pose = self._triple(self._entry(entry, "pose", f"place {name!r}", list), f"place {name!r} pose")
            places.append(Place(name, pose))
        if not any(p.name == "start" for p in places):
            self.fail("a place named 'start' is needed ([[places]] name = 'start', pose = [x, y, yaw])")
        rects = list(floor) + [b.footprint for b in static] + [c.body.footprint for c in containers]
        bounds = (
            min(r[0] for r in rects),
            min(r[1] for r in rects),
            max(r[2] for r in rects),
            max(r[3] for r in rects),
        )
        extent = (
            self._rect(data["extent"], "extent")
            if "extent" in data
            else (
                bounds[0] - 1.0,
                bounds[1] - 1.0,
                bounds[2] + 1.0,
                bounds[3] + 1.0,
            )
        )
        camera_entry = data.get("camera", {})
        if not isinstance(camera_entry, dict):
            self.fail("[camera] must be a table: position, target, fovy")
        cx, cy = (bounds[0] + bounds[2]) / 2, (bounds[1] + bounds[3]) / 2
        position = camera_entry.get("position", [bounds[2] + 0.5, bounds[1] - 1.5, 3.2])
        target = camera_entry.get("target", [cx, cy, 0.3])
        camera = Camera(
            "overview",
            self._triple(position, "camera position"),
            self._triple(target, "camera target"),
            float(camera_entry.get("fovy", 55.0)),
        )
        name = data.get("name", f"file:{self.path}")
        notes = str(data.get("notes", "")) + (
            f" (from {self.model_path.name}; bounding boxes of: {', '.join(self.approximated)})"
            if self.approximated
            else f" (from {self.model_path.name})"
        )
        try:
            env = Environment(
                name=str(name),
                title=str(data.get("title", f"A kitchen from {self.path.name}")),
                static=static,
                surfaces=surfaces,
                containers=containers,
                floor=floor,
                places=tuple(places),
                camera=camera,
                extent=extent,
                notes=notes.strip(),
            )
        except ValueError as e:
            self.fail(str(e))
        _log_problems(env, self.path)
        return env


def _log_problems(env: Environment, path: Path) -> None:
    """Log what the checks of `pycram.environments.checks` find wrong (a loaded kitchen is
    used as it is: its author decides)."""
    from .checks import environment_problems

    for problem in environment_problems(env):
        log.warning("%s: %s", path.name, problem)


def _vec(values: Any) -> tuple[float, float, float]:
    x, y, z = (round(float(v), 4) for v in values)
    return (x, y, z)


def _along(direction: tuple[float, float], x: float, y: float) -> float:
    return x * direction[0] + y * direction[1]


def _corners(rect: tuple[float, float, float, float]) -> list[tuple[float, float]]:
    x0, y0, x1, y1 = rect
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
