"""`procedural:SEED`: generated apartments, one per seed (the same seed gives the same apartment).

    from pycram.environments import load
    env = load("procedural:17")  # or pycram.environments.procedural.generate(17)

Every generated apartment has the parts of the hand-made `apartment`, under the same names, so
plans and scenarios written for it find their way: a kitchen ``counter`` along one wall with a
``sink`` and a stove (``cooker #1``, ``cooker #2``), a ``cabinet top`` over a drawer cabinet
(``drawer 1`` at the bottom up to ``drawer 2`` .. ``drawer 4``: two to four drawers), a
``fridge`` (three shelves behind a hinged door), a ``cupboard`` (one shelf behind a hinged door)
and a dining ``table``, and the places ``start``, ``kitchen``, ``drawers``, ``fridge``,
``cupboard``, ``table south`` and ``table north``. What the seed draws (all from one
`random.Random(seed)`, never the global generator):

- the room: 6.2-7.5 m wide, 5.0-6.0 m deep, walls on its north side and on its west side or
  (mirrored) its east side;
- the counter run: 2.2-3.0 m along the north wall, straight or L-shaped (then a ``side counter``
  runs down the side wall, with a place ``side counter`` in front of it), with the sink and the
  stove at drawn spots (the stove on the side counter in some L-shaped kitchens); counter tops
  0.86-0.94 m high;
- the drawer cabinet on the side wall: 0.8-1.1 m wide, 2-4 drawers stacked at different heights;
- the order of fridge and cupboard along the north wall, the gaps between them, and the side
  each door is hinged on (left or right);
- the table: its size (1.2-1.6 x 0.8-1.0 m), height (0.72-0.78 m) and where it stands; chairs
  at none, one or both of its ends, and sometimes one more chair by the open side of the room.

Guarantees (tested over many seeds in ``tests/world/test_procedural_environment.py``): part
names are unique; every place is on free floor and reachable from ``start`` by a base of the
PR2's size (`pycram.environments.checks.drivability_problems`); furniture does not overlap;
surfaces are between 0.1 and 1.5 m high; containers move freely (a door's hinge side keeps
0.25 m from its neighbour).

Lengths in [m], angles in [rad], map frame: x east, y north, z up.
"""

from __future__ import annotations

import functools
import math
import random
from dataclasses import dataclass, field, replace

from pycram.world.environment import Box, Camera, Container, Environment, Place, Surface, rect_around

__all__ = ["generate", "PREFIX", "parse_seed", "MAX_SEED"]

#: Environment names of generated apartments read ``PREFIX + seed``.
PREFIX = "procedural:"
#: The largest seed `generate` accepts (seeds are non-negative integers up to this).
MAX_SEED = 2**63 - 1

_WALL = (0.93, 0.92, 0.88, 1.0)
_COUNTER = (0.82, 0.80, 0.76, 1.0)
_WOOD = (0.72, 0.56, 0.38, 1.0)
_DRAWER = (0.80, 0.66, 0.48, 1.0)
_TABLE = (0.55, 0.38, 0.24, 1.0)
_CHAIR = (0.42, 0.30, 0.22, 1.0)
_FRIDGE = (0.90, 0.92, 0.95, 1.0)
_FRIDGE_DOOR = (0.84, 0.87, 0.91, 1.0)
_STEEL = (0.62, 0.64, 0.67, 1.0)
_STOVE = (0.12, 0.12, 0.13, 1.0)

_COUNTER_DEPTH = 0.6
_FRIDGE_WIDTH, _FRIDGE_DEPTH = 0.7, 0.63
_CUPBOARD_WIDTH, _CUPBOARD_DEPTH = 0.6, 0.45
_CABINET_DEPTH = 0.6
_DRAWER_WALL = 0.015
_CHAIR_HALF = 0.22  # [m] half the side of a chair's seat
_CHAIR_SEAT = 0.46  # [m] seat height
#: A door's hinge side keeps this far [m] from a neighbour: opened past 90 degrees, its panel
#: swings behind the hinge line.
_HINGE_GAP = 0.25
#: A base standing at a place keeps this far [m] from the furniture (the PR2's circumscribed
#: radius, 0.47 m, and some room).
_STAND_OFF = 0.65


def parse_seed(text: str) -> int:
    """The seed of an environment name ``procedural:SEED`` (or of ``SEED`` alone): a
    non-negative integer written in decimal digits. Raises `ValueError` saying what is wrong."""
    raw = text[len(PREFIX) :] if text.startswith(PREFIX) else text
    if not raw.isascii() or not raw.isdigit():
        raise ValueError(f"the seed must be a non-negative integer (e.g. {PREFIX}17), not {raw!r}")
    seed = int(raw)
    if seed > MAX_SEED:
        raise ValueError(f"the seed must be at most {MAX_SEED}, not {seed}")
    return seed


@functools.lru_cache(maxsize=64)
def generate(seed: int) -> Environment:
    """The generated apartment of `seed` (a non-negative integer), named ``procedural:SEED``.

    The same seed gives an equal `Environment` (and, within a process, the same object: results
    are cached). Raises `ValueError` for a seed that is not a non-negative integer.
    """
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise ValueError(
            f"the seed of a generated apartment is a non-negative integer (at most {MAX_SEED}), not {seed!r}"
        )
    rng = random.Random(seed)
    plan = _Plan(rng)
    env = plan.build(f"{PREFIX}{seed}")
    return _mirrored(env, plan.width) if plan.mirrored else env


def _r(value: float) -> float:
    """`value` rounded to the millimetre (tidy numbers, the same on every machine)."""
    return round(value, 3)


@dataclass
class _Plan:
    """The draws of one apartment and the parts built from them (west-wall layout: a mirrored
    apartment is built like this and then mirrored in x)."""

    rng: random.Random
    static: list[Box] = field(default_factory=list)
    surfaces: list[Surface] = field(default_factory=list)
    containers: list[Container] = field(default_factory=list)
    places: list[Place] = field(default_factory=list)
    summary: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        rng = self.rng
        self.width = round(rng.uniform(6.2, 7.5), 2)
        self.depth = round(rng.uniform(5.0, 6.0), 2)
        self.mirrored = rng.random() < 0.5
        self.counter_height = round(rng.uniform(0.86, 0.94), 2)
        self.table_height = round(rng.uniform(0.72, 0.78), 2)
        self.l_shaped = rng.random() < 0.5
        self.counter_length = round(rng.uniform(2.2, 3.0), 2)
        self.side_length = round(rng.uniform(1.0, 1.5), 2) if self.l_shaped else 0.0

    # ---------------------------------------------------------------- the whole apartment
    def build(self, name: str) -> Environment:
        w, d = self.width, self.depth
        self.summary.append(f"room {w:.2f} x {d:.2f} m")
        self._walls()
        self._kitchen()
        north_end = self._tall_units()
        cabinet_y = self._drawer_cabinet()
        self._dining(cabinet_y, north_end)
        self.places.insert(0, Place("start", (1.7, 1.2, math.pi / 2)))
        cam_x = w + 0.4
        env = Environment(
            name=name,
            title=f"A generated apartment ({name}): " + ", ".join(self.summary),
            static=tuple(self.static),
            surfaces=tuple(self.surfaces),
            containers=tuple(self.containers),
            floor=((0.0, 0.0, w, d),),
            places=tuple(self.places),
            camera=Camera("overview", (cam_x, -1.6, 3.9), (_r(0.4 * w), _r(0.58 * d), 0.3), 55.0),
            extent=(-1.0, -1.0, _r(w + 1.0), _r(d + 1.0)),
            notes="generated by pycram.environments.procedural; " + "; ".join(self.summary),
        )
        return env

    def _walls(self) -> None:
        w, d = self.width, self.depth
        self.static += [
            Box("wall north", (_r(w / 2 - 0.05), _r(d + 0.05), 1.1), (_r(w / 2 + 0.05), 0.05, 1.1), _WALL),
            Box("wall west", (-0.05, _r(d / 2), 1.1), (0.05, _r(d / 2 + 0.1), 1.1), _WALL),
        ]

    # ---------------------------------------------------------------- counter, sink, stove
    def _kitchen(self) -> None:
        rng, d, h = self.rng, self.depth, self.counter_height
        length, front = self.counter_length, _r(d - _COUNTER_DEPTH)
        self.static.append(
            Box("counter", (_r(length / 2), _r(d - 0.3), _r(h / 2)), (_r(length / 2), 0.3, _r(h / 2)), _COUNTER)
        )
        self.surfaces.append(Surface.rectangle("counter", (0.0, front, length, d), h, "counter"))
        stove_on_side = self.l_shaped and rng.random() < 0.5
        if self.l_shaped:
            y0 = _r(front - self.side_length)
            half = _r(self.side_length / 2)
            self.static.append(Box("side counter", (0.3, _r(y0 + half), _r(h / 2)), (0.3, half, _r(h / 2)), _COUNTER))
            self.surfaces.append(Surface.rectangle("side counter", (0.0, y0, _COUNTER_DEPTH, front), h, "counter"))
            # in front of the side counter, clear of the counter along the north wall
            stand_y = _r(front - max(half, _STAND_OFF + 0.05))
            self.places.append(Place("side counter", (_r(_COUNTER_DEPTH + _STAND_OFF + 0.15), stand_y, math.pi)))
        # sink and stove along the north run, clear of the corner of an L
        x_lo = _COUNTER_DEPTH + 0.05 if self.l_shaped else 0.05
        parts = [("sink", 0.25)] + ([] if stove_on_side else [("stove", 0.35)])
        rng.shuffle(parts)
        slack = length - 0.05 - x_lo - sum(2 * half for _, half in parts) - 0.05 * (len(parts) - 1)
        x, centres = x_lo, {}
        for i, (part, half) in enumerate(parts):
            gap = rng.uniform(0.0, slack)  # of the slack left
            slack -= gap
            x += gap + (0.05 if i else 0.0)
            centres[part] = _r(x + half)
            x += 2 * half
        self.static.append(
            Box("sink", (centres["sink"], _r(d - 0.28), _r(h + 0.002)), (0.25, 0.2, 0.002), _STEEL, collides=False)
        )
        if stove_on_side:
            cx, cy = 0.3, _r(front - self.side_length / 2)
            self.static.append(Box("stove", (cx, cy, _r(h + 0.002)), (0.25, 0.35, 0.002), _STOVE, collides=False))
            cookers = [(cx, _r(cy + 0.17)), (cx, _r(cy - 0.17))]
            self.summary.append("L-shaped counter with the stove on its side")
        else:
            cx, cy = centres["stove"], _r(d - 0.3)
            self.static.append(Box("stove", (cx, cy, _r(h + 0.002)), (0.35, 0.25, 0.002), _STOVE, collides=False))
            cookers = [(_r(cx - 0.17), cy), (_r(cx + 0.17), cy)]
            self.summary.append("L-shaped counter" if self.l_shaped else "straight counter")
        for i, xy in enumerate(cookers, start=1):
            self.surfaces.append(Surface.rectangle(f"cooker #{i}", rect_around(xy, (0.1, 0.1)), h, "cooker"))
        # in front of the middle of the counter's reachable part, clear of the side wall's furniture
        stand_x = max((x_lo + length) / 2, _CABINET_DEPTH + _STAND_OFF + 0.05)
        self.places.append(Place("kitchen", (_r(stand_x), _r(front - 0.8), math.pi / 2)))

    # ---------------------------------------------------------------- fridge and cupboard
    def _tall_units(self) -> float:
        """Fridge and cupboard along the north wall east of the counter; returns where the
        last one ends [m, x]."""
        rng = self.rng
        units = ["fridge", "cupboard"]
        rng.shuffle(units)
        hinges = {u: rng.choice(("left", "right")) for u in units}  # seen from the room: left = west
        x, previous_hinge_east = self.counter_length, False
        for unit in units:
            width = _FRIDGE_WIDTH if unit == "fridge" else _CUPBOARD_WIDTH
            west_hinged = hinges[unit] == "left"
            least = _HINGE_GAP if (unit == "cupboard" and west_hinged) or previous_hinge_east else 0.05
            x = _r(x + rng.uniform(least, least + 0.3))
            if unit == "fridge":
                self._fridge(x, west_hinged)
            else:
                self._cupboard(x, west_hinged)
            previous_hinge_east = unit == "cupboard" and not west_hinged
            x = _r(x + width)
        self.summary.append(
            f"{units[0]} then {units[1]}, fridge hinged {hinges['fridge']}, cupboard hinged {hinges['cupboard']}"
        )
        return x

    def _fridge(self, x0: float, west_hinged: bool) -> None:
        d = self.depth
        yc = _r(d - 0.315)
        xm = _r(x0 + 0.35)
        self.static += [
            Box("fridge side west", (_r(x0 + 0.015), yc, 0.85), (0.015, 0.315, 0.85), _FRIDGE),
            Box("fridge side east", (_r(x0 + 0.685), yc, 0.85), (0.015, 0.315, 0.85), _FRIDGE),
            Box("fridge back", (xm, _r(d - 0.015), 0.85), (0.32, 0.015, 0.85), _FRIDGE),
            Box("fridge top", (xm, yc, 1.685), (0.35, 0.315, 0.015), _FRIDGE),
            Box("fridge plinth", (xm, yc, 0.06), (0.35, 0.315, 0.06), _FRIDGE),
            Box("fridge shelf board 1", (xm, yc, 0.61), (0.32, 0.285, 0.01), _FRIDGE),
            Box("fridge shelf board 2", (xm, yc, 1.11), (0.32, 0.285, 0.01), _FRIDGE),
        ]
        shelf = (_r(x0 + 0.04), _r(d - 0.59), _r(x0 + 0.66), _r(d - 0.04))
        hinge_x, handle_x = (x0, x0 + 0.6) if west_hinged else (x0 + _FRIDGE_WIDTH, x0 + 0.1)
        self.containers.append(
            Container(
                name="fridge",
                kind="door",
                body=Box("fridge door", (xm, _r(d - 0.65), 0.85), (0.35, 0.02, 0.84), _FRIDGE_DOOR),
                handle=(_r(handle_x), _r(d - 0.71), 1.0),
                opening_direction=(0.0, -1.0),
                limits=(0.0, 1.9),
                hinge=(_r(hinge_x), _r(d - 0.67)),
                damping=8.0,
                friction=2.0,
                interior=(
                    Surface.rectangle("fridge bottom shelf", shelf, 0.12, "shelf", clearance=0.47),
                    Surface.rectangle("fridge middle shelf", shelf, 0.62, "shelf", clearance=0.47),
                    Surface.rectangle("fridge top shelf", shelf, 1.12, "shelf", clearance=0.53),
                ),
            )
        )
        # in front of the handle's side, as the apartment's
        self.places.append(Place("fridge", (_r(handle_x), _r(d - 1.8), math.pi / 2)))

    def _cupboard(self, x0: float, west_hinged: bool) -> None:
        d = self.depth
        yc = _r(d - 0.225)
        xm = _r(x0 + 0.3)
        self.static += [
            Box("cupboard base", (xm, yc, 0.4), (0.3, 0.225, 0.4), _WOOD),
            Box("cupboard side west", (_r(x0 + 0.015), yc, 1.1), (0.015, 0.225, 0.3), _WOOD),
            Box("cupboard side east", (_r(x0 + 0.585), yc, 1.1), (0.015, 0.225, 0.3), _WOOD),
            Box("cupboard back", (xm, _r(d - 0.015), 1.1), (0.27, 0.015, 0.3), _WOOD),
            Box("cupboard top", (xm, yc, 1.415), (0.3, 0.225, 0.015), _WOOD),
        ]
        hinge_x, handle_x = (x0, x0 + 0.55) if west_hinged else (x0 + _CUPBOARD_WIDTH, x0 + 0.05)
        self.containers.append(
            Container(
                name="cupboard",
                kind="door",
                body=Box("cupboard door", (xm, _r(d - 0.46), 1.1), (0.3, 0.015, 0.3), _DRAWER),
                handle=(_r(handle_x), _r(d - 0.515), 1.1),
                opening_direction=(0.0, -1.0),
                limits=(0.0, 1.9),
                hinge=(_r(hinge_x), _r(d - 0.475)),
                damping=4.0,
                friction=1.0,
                interior=(
                    Surface.rectangle(
                        "cupboard shelf",
                        (_r(x0 + 0.03), _r(d - 0.43), _r(x0 + 0.57), _r(d - 0.03)),
                        0.8,
                        "cupboard",
                        clearance=0.58,
                    ),
                ),
            )
        )
        self.places.append(Place("cupboard", (xm, _r(d - 1.4), math.pi / 2)))

    # ---------------------------------------------------------------- the drawer cabinet
    def _drawer_cabinet(self) -> tuple[float, float]:
        """The drawer cabinet on the west wall, south of the counter; returns its (y0, y1)."""
        rng, h = self.rng, self.counter_height
        width = round(rng.uniform(0.8, 1.1), 2)
        top = self.depth - _COUNTER_DEPTH - self.side_length - 0.3  # the highest north edge
        y0 = _r(rng.uniform(0.8, top - width))
        y1, yc = _r(y0 + width), _r(y0 + width / 2)
        zc = _r(h / 2)
        self.static += [
            Box("cabinet side south", (0.3, _r(y0 + 0.01), zc), (0.3, 0.01, zc), _WOOD),
            Box("cabinet side north", (0.3, _r(y1 - 0.01), zc), (0.3, 0.01, zc), _WOOD),
            Box("cabinet back", (0.01, yc, zc), (0.01, _r(width / 2 - 0.02), zc), _WOOD),
            Box("cabinet top", (0.3, yc, _r(h - 0.015)), (0.3, _r(width / 2), 0.015), _WOOD),
            Box("cabinet plinth", (0.3, yc, 0.04), (0.3, _r(width / 2 - 0.02), 0.04), _WOOD),
        ]
        self.surfaces.append(Surface.rectangle("cabinet top", (0.0, y0, _CABINET_DEPTH, y1), h, "counter"))
        count = rng.randint(2, 4)
        height = _r((h - 0.04 - 0.09 - 0.01 * (count - 1)) / count)
        for i in range(count):
            self.containers.append(self._drawer(i + 1, _r(0.09 + i * (height + 0.01)), height, y0, y1))
        self.places.append(Place("drawers", (1.6, yc, math.pi)))
        self.summary.append(f"a drawer cabinet of {count} drawers {height:.2f} m high")
        return (y0, y1)

    def _drawer(self, number: int, bottom: float, height: float, y0: float, y1: float) -> Container:
        """Drawer `number` of the cabinet from `y0` to `y1`, its box from `bottom` [m] up by `height`."""
        zc, yc = _r(bottom + height / 2), _r((y0 + y1) / 2)
        return Container(
            name=f"drawer {number}",
            kind="drawer",
            body=Box(f"drawer {number}", (0.315, yc, zc), (0.285, _r((y1 - y0) / 2 - 0.025), _r(height / 2)), _DRAWER),
            handle=(0.64, yc, _r(zc + min(0.06, height / 2 - 0.05))),
            opening_direction=(1.0, 0.0),
            limits=(0.0, 0.42),
            interior=(
                Surface.rectangle(
                    f"drawer {number} inside",
                    (0.045, _r(y0 + 0.04), 0.585, _r(y1 - 0.04)),
                    _r(bottom + _DRAWER_WALL),
                    "drawer",
                    clearance=_r(height - _DRAWER_WALL - 0.01),
                ),
            ),
            damping=30.0,
            friction=4.0,
            wall=_DRAWER_WALL,
        )

    # ---------------------------------------------------------------- table and chairs
    def _dining(self, cabinet_y: tuple[float, float], north_end: float) -> None:
        rng, w, d = self.rng, self.width, self.depth
        hx, hy = round(rng.uniform(0.6, 0.8), 2), round(rng.uniform(0.4, 0.5), 2)
        chair_reach = 2 * _CHAIR_HALF + 0.05  # a chair at an end stands this far out
        tx = _r(rng.uniform(2.8 + hx, w - 1.2 - hx - chair_reach))
        # the seats' places on the free floor south and north of it, the north one clear of the
        # fridge and cupboard doors swinging open
        ty_lo = _STAND_OFF + 0.55 + hy
        ty_hi = d - _FRIDGE_DEPTH - 0.04 - _FRIDGE_WIDTH - 0.5 - _STAND_OFF - hy
        ty = _r(rng.uniform(ty_lo, ty_hi))
        h = self.table_height
        self.static.append(Box("table", (tx, ty, _r(h - 0.02)), (hx, hy, 0.02), _TABLE))
        for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
            self.static.append(
                Box(
                    f"table leg {i + 1}",
                    (_r(tx + sx * (hx - 0.06)), _r(ty + sy * (hy - 0.06)), _r((h - 0.04) / 2)),
                    (0.025, 0.025, _r((h - 0.04) / 2)),
                    _TABLE,
                )
            )
        self.surfaces.append(Surface.rectangle("table", rect_around((tx, ty), (hx, hy)), h, "table"))
        self.places.append(Place("table south", (tx, _r(ty - hy - _STAND_OFF), math.pi / 2)))
        self.places.append(Place("table north", (tx, _r(ty + hy + _STAND_OFF), -math.pi / 2)))
        chairs = 0
        for side in (-1, 1):  # the chairs at the table's ends, their backs outwards
            if rng.random() < 0.6:
                chairs += 1
                cx = _r(tx + side * (hx + 0.05 + _CHAIR_HALF))
                self._chair(chairs, (cx, ty), side)
        if rng.random() < 0.5:  # one more by the open side of the room, south of the table's seat
            chairs += 1
            cx = _r(w - 0.3)
            cy = _r(rng.uniform(0.35, max(0.35, ty - hy - 0.3)))
            self._chair(chairs, (cx, cy), 1)
        self.summary.append(f"a {2 * hx:.2f} x {2 * hy:.2f} m table, {chairs} chair{'s' if chairs != 1 else ''}")

    def _chair(self, number: int, xy: tuple[float, float], back: int) -> None:
        """Chair `number` at `xy`: a solid seat block and a backrest on its `back` side (+1 east)."""
        x, y = xy
        half = _CHAIR_HALF
        self.static += [
            Box(f"chair {number}", (x, y, _CHAIR_SEAT / 2), (half, half, _CHAIR_SEAT / 2), _CHAIR),
            Box(f"chair {number} back", (_r(x + back * (half - 0.02)), y, 0.68), (0.02, half, 0.22), _CHAIR),
        ]


# -------------------------------------------------------------------- mirroring
def _swap_sides(name: str) -> str:
    return name.replace("west", "\0").replace("east", "west").replace("\0", "east")


def _mirror_xy(width: float, x: float, y: float) -> tuple[float, float]:
    return (_r(width - x), y)


def _mirror_box(box: Box, width: float) -> Box:
    x, y, z = box.center
    return replace(box, name=_swap_sides(box.name), center=(_r(width - x), y, z))


def _mirror_surface(surface: Surface, width: float) -> Surface:
    x0, y0, x1, y1 = surface.bounds
    return Surface.rectangle(
        surface.name, (_r(width - x1), y0, _r(width - x0), y1), surface.height, surface.kind, surface.clearance
    )


def _mirrored(env: Environment, width: float) -> Environment:
    """`env` mirrored in x about the middle of a room `width` [m] wide (walls north and east)."""
    containers = tuple(
        replace(
            c,
            body=_mirror_box(c.body, width),
            handle=(_r(width - c.handle[0]), c.handle[1], c.handle[2]),
            opening_direction=(-c.opening_direction[0] + 0.0, c.opening_direction[1]),
            hinge=None if c.hinge is None else _mirror_xy(width, *c.hinge),
            interior=tuple(_mirror_surface(s, width) for s in c.interior),
        )
        for c in env.containers
    )
    places = tuple(
        Place(
            p.name,
            (
                _r(width - p.pose[0]),
                p.pose[1],
                round(math.atan2(math.sin(math.pi - p.pose[2]), math.cos(math.pi - p.pose[2])), 6),
            ),
        )
        for p in env.places
    )
    cam = env.camera
    camera = Camera(
        cam.name,
        (_r(width - cam.position[0]), cam.position[1], cam.position[2]),
        (_r(width - cam.target[0]), cam.target[1], cam.target[2]),
        cam.fovy,
    )
    x0, y0, x1, y1 = env.extent
    title = env.title.replace("left", "\0").replace("right", "left").replace("\0", "right")
    return replace(
        env,
        title=title + " (walls north and east)",
        static=tuple(_mirror_box(b, width) for b in env.static),
        surfaces=tuple(_mirror_surface(s, width) for s in env.surfaces),
        containers=containers,
        floor=tuple((_r(width - f[2]), f[1], _r(width - f[0]), f[3]) for f in env.floor),
        places=places,
        camera=camera,
        extent=(_r(width - x1), y0, _r(width - x0), y1),
        notes=env.notes + "; mirrored: walls north and east",
    )
