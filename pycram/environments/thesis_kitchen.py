"""`thesis-kitchen`: the kitchen of the thesis' demo (ch. 4), built from primitives.

Two counters with cooker areas: cooker #2 is on the counter along the back wall (y < -1 m),
cooker #1 on the counter along the left wall (x < -0.55 m); the floor between them is free to
drive on. A fridge block stands next to the back counter. Counter tops are 0.9 m high.
"""

from __future__ import annotations

from pycram.world.environment import Box, Camera, Environment, Place, Surface, rect_around

COUNTER_HEIGHT = 0.9  # [m]
_H = COUNTER_HEIGHT / 2.0
_COUNTER = (0.82, 0.80, 0.76, 1.0)
_WALL = (0.93, 0.92, 0.88, 1.0)
_STOVE = (0.12, 0.12, 0.13, 1.0)
_COOKER_RADIUS = 0.11

_COUNTERS = (
    Box("counter_back", (0.2, -1.3, _H), (1.2, 0.3, _H), _COUNTER),
    Box("counter_left", (-0.85, 2.1, _H), (0.3, 1.1, _H), _COUNTER),
)
_STATIC = _COUNTERS + (
    Box("wall_back", (0.9, -1.65, 1.1), (2.1, 0.05, 1.1), _WALL),
    Box("wall_left", (-1.2, 1.0, 1.1), (0.05, 2.7, 1.1), _WALL),
    Box("fridge", (1.75, -1.25, 0.9), (0.35, 0.35, 0.9), (0.75, 0.78, 0.8, 1.0)),
    # the stove plates around the cookers (dark, flat)
    Box("stove_1", (-0.8, 1.9, COUNTER_HEIGHT + 0.002), (0.25, 0.3, 0.002), _STOVE, collides=False),
    Box("stove_2", (0.1, -1.3, COUNTER_HEIGHT + 0.002), (0.3, 0.25, 0.002), _STOVE, collides=False),
)
_COOKERS = {"cooker #1": (-0.72, 1.9), "cooker #2": (0.1, -1.2)}

ENVIRONMENT = Environment(
    name="thesis-kitchen",
    title="The thesis kitchen: two counters with a cooker each",
    static=_STATIC,
    surfaces=tuple(Surface.rectangle(b.name, b.footprint, COUNTER_HEIGHT, "counter") for b in _COUNTERS)
    + tuple(
        Surface.rectangle(name, rect_around(xy, (_COOKER_RADIUS, _COOKER_RADIUS)), COUNTER_HEIGHT, "cooker")
        for name, xy in _COOKERS.items()
    ),
    containers=(),
    floor=((-0.45, -0.9, 3.0, 3.5),),
    places=(Place("start", (0.8, 0.6, 0.0)),),
    camera=Camera("overview", (3.4, 3.6, 3.2), (-0.1, 0.2, 0.5), 60.0),
    extent=(-5.0, -5.0, 7.0, 7.0),
)
