"""`apartment`: an open-plan kitchen and dining room, built from primitives.

Plan (x east, y north, [m]): the room is 6.5 x 5 m with walls along its north (y = 5) and west
(x = 0) sides. Along the north wall stand the kitchen counter (with a sink and a two-burner
cooker), a fridge whose hinged door opens towards the room, and a cupboard: a closed base with
one compartment from 0.8 to 1.4 m above it, behind a door hinged on its west edge. Against the
west wall stands a drawer cabinet with three drawers sliding out east; its top is a second
counter. The dining table stands in the middle of the room with at least 1.5 m of free floor on
every side.

    y=5 +--wall-----------------------------------+
        | counter [sink] [cooker]  |fridge||cupb.| |
        |                           door   door    |
        |drawer                                    |
        |cabinet          +-------table-------+    |
        |                 +-------------------+    |
        |         start                            |
    y=0 +---- x=0 ---------------------------------+ x=6.5
"""

from __future__ import annotations

from pycram.world.environment import Box, Camera, Container, Environment, Place, Surface, rect_around

_WALL = (0.93, 0.92, 0.88, 1.0)
_COUNTER = (0.82, 0.80, 0.76, 1.0)
_WOOD = (0.72, 0.56, 0.38, 1.0)
_DRAWER = (0.80, 0.66, 0.48, 1.0)
_TABLE = (0.55, 0.38, 0.24, 1.0)
_FRIDGE = (0.90, 0.92, 0.95, 1.0)
_FRIDGE_DOOR = (0.84, 0.87, 0.91, 1.0)
_STEEL = (0.62, 0.64, 0.67, 1.0)
_STOVE = (0.12, 0.12, 0.13, 1.0)

COUNTER_HEIGHT = 0.9  # [m]
TABLE_HEIGHT = 0.75  # [m]

# --- kitchen counter along the north wall, with a sink and a cooker -------------------------------
_COUNTER_RECT = (0.0, 4.4, 2.6, 5.0)
_KITCHEN = (
    Box("counter", (1.3, 4.7, COUNTER_HEIGHT / 2), (1.3, 0.3, COUNTER_HEIGHT / 2), _COUNTER),
    Box("sink", (0.7, 4.72, COUNTER_HEIGHT + 0.002), (0.25, 0.2, 0.002), _STEEL, collides=False),
    Box("stove", (1.95, 4.7, COUNTER_HEIGHT + 0.002), (0.35, 0.25, 0.002), _STOVE, collides=False),
)
_COOKERS = {"cooker #1": (1.78, 4.7), "cooker #2": (2.12, 4.7)}

# --- the drawer cabinet against the west wall: three drawers sliding out east ---------------------
_CABINET_Y = (2.4, 3.4)
_CABINET = (
    Box("cabinet side south", (0.3, 2.41, 0.45), (0.3, 0.01, 0.45), _WOOD),
    Box("cabinet side north", (0.3, 3.39, 0.45), (0.3, 0.01, 0.45), _WOOD),
    Box("cabinet back", (0.01, 2.9, 0.45), (0.01, 0.48, 0.45), _WOOD),
    Box("cabinet top", (0.3, 2.9, 0.885), (0.3, 0.5, 0.015), _WOOD),
    Box("cabinet plinth", (0.3, 2.9, 0.04), (0.3, 0.48, 0.04), _WOOD),
)
_DRAWER_WALL = 0.015


def _drawer(number: int, bottom: float) -> Container:
    """Drawer `number` of the cabinet, its box from `bottom` [m] to 0.25 m higher."""
    height = 0.25
    zc = bottom + height / 2
    inner_bottom = bottom + _DRAWER_WALL
    return Container(
        name=f"drawer {number}",
        kind="drawer",
        body=Box(f"drawer {number}", (0.315, 2.9, zc), (0.285, 0.475, height / 2), _DRAWER),
        handle=(0.64, 2.9, zc + 0.06),
        opening_direction=(1.0, 0.0),
        limits=(0.0, 0.42),
        interior=(
            Surface.rectangle(
                f"drawer {number} inside",
                (0.045, 2.44, 0.585, 3.36),
                inner_bottom,
                "drawer",
                clearance=height - _DRAWER_WALL - 0.01,
            ),
        ),
        damping=30.0,
        friction=4.0,
        wall=_DRAWER_WALL,
    )


_DRAWERS = (_drawer(1, 0.09), _drawer(2, 0.35), _drawer(3, 0.61))

# --- the fridge next to the counter, its door hinged on the west edge -----------------------------
_FRIDGE_BOXES = (
    Box("fridge side west", (2.715, 4.685, 0.85), (0.015, 0.315, 0.85), _FRIDGE),
    Box("fridge side east", (3.385, 4.685, 0.85), (0.015, 0.315, 0.85), _FRIDGE),
    Box("fridge back", (3.05, 4.985, 0.85), (0.32, 0.015, 0.85), _FRIDGE),
    Box("fridge top", (3.05, 4.685, 1.685), (0.35, 0.315, 0.015), _FRIDGE),
    Box("fridge plinth", (3.05, 4.685, 0.06), (0.35, 0.315, 0.06), _FRIDGE),
    Box("fridge shelf board 1", (3.05, 4.685, 0.61), (0.32, 0.285, 0.01), _FRIDGE),
    Box("fridge shelf board 2", (3.05, 4.685, 1.11), (0.32, 0.285, 0.01), _FRIDGE),
)
_SHELF_RECT = (2.74, 4.41, 3.36, 4.96)
_FRIDGE_DOOR_BOX = Box("fridge door", (3.05, 4.35, 0.85), (0.35, 0.02, 0.84), _FRIDGE_DOOR)
_FRIDGE_DOOR_CONTAINER = Container(
    name="fridge",
    kind="door",
    body=_FRIDGE_DOOR_BOX,
    handle=(3.3, 4.29, 1.0),
    opening_direction=(0.0, -1.0),
    limits=(0.0, 1.9),
    hinge=(2.70, 4.33),
    damping=8.0,
    friction=2.0,
    interior=(
        Surface.rectangle("fridge bottom shelf", _SHELF_RECT, 0.12, "shelf", clearance=0.47),
        Surface.rectangle("fridge middle shelf", _SHELF_RECT, 0.62, "shelf", clearance=0.47),
        Surface.rectangle("fridge top shelf", _SHELF_RECT, 1.12, "shelf", clearance=0.53),
    ),
)

# --- a cupboard against the north wall east of the fridge: a closed base, one compartment above it
# from the counter-like height 0.8 m up, its door hinged on the west edge ------------------------
_CUPBOARD_BOXES = (
    Box("cupboard base", (4.1, 4.775, 0.4), (0.3, 0.225, 0.4), _WOOD),
    Box("cupboard side west", (3.815, 4.775, 1.1), (0.015, 0.225, 0.3), _WOOD),
    Box("cupboard side east", (4.385, 4.775, 1.1), (0.015, 0.225, 0.3), _WOOD),
    Box("cupboard back", (4.1, 4.985, 1.1), (0.27, 0.015, 0.3), _WOOD),
    Box("cupboard top", (4.1, 4.775, 1.415), (0.3, 0.225, 0.015), _WOOD),
)
_CUPBOARD_CONTAINER = Container(
    name="cupboard",
    kind="door",
    body=Box("cupboard door", (4.1, 4.54, 1.1), (0.3, 0.015, 0.3), _DRAWER),
    handle=(4.35, 4.485, 1.1),
    opening_direction=(0.0, -1.0),
    limits=(0.0, 1.9),
    hinge=(3.80, 4.525),
    damping=4.0,
    friction=1.0,
    interior=(Surface.rectangle("cupboard shelf", (3.83, 4.57, 4.37, 4.97), 0.8, "cupboard", clearance=0.58),),
)

# --- the dining table in the middle of the room -------------------------------------------------
_TABLE_CENTER, _TABLE_HALF = (4.3, 2.0), (0.7, 0.45)
_TABLE_BOXES = (Box("table", (*_TABLE_CENTER, TABLE_HEIGHT - 0.02), (*_TABLE_HALF, 0.02), _TABLE),) + tuple(
    Box(
        f"table leg {i + 1}",
        (
            _TABLE_CENTER[0] + sx * (_TABLE_HALF[0] - 0.06),
            _TABLE_CENTER[1] + sy * (_TABLE_HALF[1] - 0.06),
            (TABLE_HEIGHT - 0.04) / 2,
        ),
        (0.025, 0.025, (TABLE_HEIGHT - 0.04) / 2),
        _TABLE,
    )
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1)))
)

_WALLS = (
    Box("wall north", (3.2, 5.05, 1.1), (3.3, 0.05, 1.1), _WALL),
    Box("wall west", (-0.05, 2.5, 1.1), (0.05, 2.6, 1.1), _WALL),
)

ENVIRONMENT = Environment(
    name="apartment",
    title="An apartment: kitchen counter with cooker and sink, fridge, cupboard, drawer cabinet, dining table",
    static=_WALLS + _KITCHEN + _CABINET + _FRIDGE_BOXES + _CUPBOARD_BOXES + _TABLE_BOXES,
    surfaces=(
        Surface.rectangle("counter", _COUNTER_RECT, COUNTER_HEIGHT, "counter"),
        Surface.rectangle("cabinet top", (0.0, _CABINET_Y[0], 0.6, _CABINET_Y[1]), COUNTER_HEIGHT, "counter"),
        Surface.rectangle("table", rect_around(_TABLE_CENTER, _TABLE_HALF), TABLE_HEIGHT, "table"),
    )
    + tuple(
        Surface.rectangle(name, rect_around(xy, (0.1, 0.1)), COUNTER_HEIGHT, "cooker") for name, xy in _COOKERS.items()
    ),
    containers=_DRAWERS + (_FRIDGE_DOOR_CONTAINER, _CUPBOARD_CONTAINER),
    floor=((0.0, 0.0, 6.5, 5.0),),
    places=(
        Place("start", (2.0, 1.5, 1.5708)),
        Place("kitchen", (1.3, 3.6, 1.5708)),
        Place("fridge", (3.3, 3.2, 1.5708)),
        Place("drawers", (1.6, 2.9, 3.1416)),
        Place("cupboard", (4.1, 3.6, 1.5708)),
        Place("table south", (4.3, 0.9, 1.5708)),
        Place("table north", (4.3, 3.1, -1.5708)),
    ),
    camera=Camera("overview", (6.9, -1.6, 3.9), (2.6, 2.9, 0.3), 55.0),
    extent=(-1.0, -1.0, 7.5, 6.0),
)
