"""Collision groups (MuJoCo contype/conaffinity bits) shared by all scene parts.

Two geoms collide iff (contype1 & conaffinity2) or (contype2 & conaffinity1).
- ENVIRONMENT (counters, walls, obstacles) collides with the robot and items.
- FLOOR collides with items only (the base rides on joints, not on wheels).
- ROBOT collides with the environment and items, never with itself (overlapping link meshes).
- ITEM collides with everything.
"""

ENVIRONMENT = 1
ROBOT = 2
ITEM = 4
FLOOR = 8

CONAFFINITY = {
    ENVIRONMENT: ROBOT | ITEM,
    FLOOR: ITEM,
    ROBOT: ENVIRONMENT | ITEM,
    ITEM: ENVIRONMENT | ROBOT | ITEM | FLOOR,
}


def set_group(geom: object, group: int) -> None:
    """Put an `MjsGeom` into a collision group."""
    geom.contype = group  # type: ignore[attr-defined]
    geom.conaffinity = CONAFFINITY[group]  # type: ignore[attr-defined]
