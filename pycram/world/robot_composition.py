"""A robot composed from an arm's model file and a mobile base built from primitives: the schema of
a description's ``COMPOSITION`` key.

A description with ``COMPOSITION`` names an arm's URDF as its ``URDF`` (e.g. the Panda of
`example-robot-data`); the simulator (`pycram.backends.sim.composition`) builds the rest of the
robot around it from boxes and cylinders:

- ``base_link``: a box (``"shape": "box"``, ``"size"``: length x, width y [m]) or a cylinder
  (``"shape": "cylinder"``, ``"radius"`` [m]), ``"height"`` [m] tall, on the floor. Its
  footprint must fit the description's ``BASE``: within ``BASE["radius"]`` of the base centre,
  covering the ``BASE["inscribed_radius"]`` circle;
- ``torso_lift_link``: a lift column on the base at ``torso["position"]`` (x, y [m] in the base
  frame), ``torso["size"]`` (x, y, height above the base's top with the torso down [m]), raised
  by the prismatic ``torso_lift_joint`` over ``TORSO["range"]``. Its frame is the column's top
  centre;
- the arm: the URDF's root link, fixed to the column's top at ``arm["xyz"]`` [m] turned by
  ``arm["rpy"]`` [rad] (roll, pitch, yaw; optional), so it rises with the torso;
- ``mast_link``: a camera mast on the base at ``mast["position"]`` (x, y [m]) carrying a pan/tilt
  head whose axes cross ``mast["height"]`` [m] above the floor: ``head_pan_joint`` (about z),
  ``head_tilt_joint`` (about y: positive looks down) and the camera link ``head_camera_link``
  (x: viewing direction, z: up).

The description names what the composition builds (`COMPOSED_NAMES`): ``ROOT_LINK`` is
``base_footprint``, ``TORSO["joint"]`` ``torso_lift_joint``, ``HEAD`` its pan and tilt joints and
camera link. Lengths in [m], angles in [rad]. Pure Python: no simulator.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = [
    "COMPOSITION_KEYS",
    "COMPOSED_NAMES",
    "BASE_SHAPES",
    "HEAD_PAN_RANGE",
    "HEAD_TILT_RANGE",
    "CompositionError",
    "validate_composition",
]

#: The keys of ``COMPOSITION`` and, per part, its required and optional keys.
COMPOSITION_KEYS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "base": (("shape", "height"), ("size", "radius")),
    "torso": (("position", "size"), ()),
    "arm": (("xyz",), ("rpy",)),
    "mast": (("position", "height"), ()),
}
#: Names of the links and joints the composition builds that the description names elsewhere:
#: (description key, entry) -> name.
COMPOSED_NAMES: dict[tuple[str, str], str] = {
    ("ROOT_LINK", ""): "base_footprint",
    ("TORSO", "joint"): "torso_lift_joint",
    ("HEAD", "pan_joint"): "head_pan_joint",
    ("HEAD", "tilt_joint"): "head_tilt_joint",
    ("HEAD", "camera_link"): "head_camera_link",
}
#: Shapes of the base.
BASE_SHAPES = ("box", "cylinder")
#: Joint range [rad] of the composed head's pan (about z).
HEAD_PAN_RANGE = (-2.6, 2.6)
#: Joint range [rad] of the composed head's tilt (about y, positive looks down).
HEAD_TILT_RANGE = (-0.8, 1.3)


class CompositionError(ValueError):
    """A ``COMPOSITION`` that does not fit the schema; the message names the part and the key
    (the description wraps it into a `RobotDescriptionError` naming the robot)."""


def _numbers(value: Any, n: int, where: str, positive: bool = False) -> tuple[float, ...]:
    ok = not isinstance(value, (str, bytes)) and hasattr(value, "__len__") and len(value) == n
    if ok:
        ok = all(isinstance(v, (int, float)) and math.isfinite(v) and (v > 0 or not positive) for v in value)
    if not ok:
        kind = "positive numbers" if positive else "numbers"
        raise CompositionError(f"{where} must be {n} {kind}, not {value!r}")
    return tuple(float(v) for v in value)


def _positive(value: Any, where: str) -> float:
    return _numbers((value,), 1, where, positive=True)[0]


def _footprint(base: Mapping[str, Any]) -> tuple[float, float]:
    """(circumscribed, inscribed) radius [m] of the base's footprint about the base centre."""
    if base["shape"] == "cylinder":
        r = _positive(base.get("radius"), "COMPOSITION['base']['radius']")
        return r, r
    length, width = _numbers(base.get("size"), 2, "COMPOSITION['base']['size'] (length, width)", positive=True)
    return math.hypot(length, width) / 2, min(length, width) / 2


def validate_composition(composition: Any, description: Mapping[str, Any]) -> None:
    """Check `composition` (a description's ``COMPOSITION``) against the schema of the module
    docstring and the description's other keys (`description`: ``{key: value}``, at least
    ``ROOT_LINK``, ``TORSO``, ``HEAD`` and ``BASE``). Raises `CompositionError` naming the
    part, the key and the valid keys or choices."""
    if not isinstance(composition, Mapping):
        raise CompositionError(f"COMPOSITION must be a mapping with the keys {', '.join(COMPOSITION_KEYS)}")
    for part, (required, optional) in COMPOSITION_KEYS.items():
        spec = composition.get(part)
        if not isinstance(spec, Mapping):
            raise CompositionError(
                f"COMPOSITION lacks the mapping {part!r}; parts of a composition: {', '.join(COMPOSITION_KEYS)}"
            )
        missing = [k for k in required if k not in spec]
        if missing:
            raise CompositionError(
                f"COMPOSITION[{part!r}] lacks {missing[0]!r}; keys of {part!r}: {', '.join(required + optional)}"
            )
        unknown = sorted(set(spec) - set(required) - set(optional))
        if unknown:
            raise CompositionError(
                f"COMPOSITION[{part!r}] has the unknown key {unknown[0]!r}; valid: {', '.join(required + optional)}"
            )
    unknown_parts = sorted(set(composition) - set(COMPOSITION_KEYS))
    if unknown_parts:
        raise CompositionError(
            f"COMPOSITION has the unknown part {unknown_parts[0]!r}; parts: {', '.join(COMPOSITION_KEYS)}"
        )
    base, torso, arm, mast = (composition[p] for p in COMPOSITION_KEYS)
    if base["shape"] not in BASE_SHAPES:
        raise CompositionError(f"COMPOSITION['base']['shape'] is {base['shape']!r}; shapes: {', '.join(BASE_SHAPES)}")
    base_height = _positive(base["height"], "COMPOSITION['base']['height']")
    outer, inner = _footprint(base)
    footprint = description.get("BASE") or {}
    radius, inscribed = footprint.get("radius"), footprint.get("inscribed_radius")
    if isinstance(radius, (int, float)) and outer > radius + 1e-6:
        raise CompositionError(
            f"COMPOSITION['base'] reaches {outer:.3f} m from the base centre, beyond BASE['radius'] "
            f"({radius} m): make the base smaller or BASE['radius'] larger"
        )
    if isinstance(inscribed, (int, float)) and inner < inscribed - 1e-6:
        raise CompositionError(
            f"COMPOSITION['base'] covers only {inner:.3f} m around the base centre, less than "
            f"BASE['inscribed_radius'] ({inscribed} m)"
        )
    _numbers(torso["position"], 2, "COMPOSITION['torso']['position'] (x, y)")
    _numbers(torso["size"], 3, "COMPOSITION['torso']['size'] (x, y, height)", positive=True)
    _numbers(arm["xyz"], 3, "COMPOSITION['arm']['xyz']")
    _numbers(arm.get("rpy", (0.0, 0.0, 0.0)), 3, "COMPOSITION['arm']['rpy'] (roll, pitch, yaw)")
    _numbers(mast["position"], 2, "COMPOSITION['mast']['position'] (x, y)")
    if _positive(mast["height"], "COMPOSITION['mast']['height']") <= base_height:
        raise CompositionError(
            f"COMPOSITION['mast']['height'] ({mast['height']} m) must be above the base's top ({base_height} m)"
        )
    for (key, entry), name in COMPOSED_NAMES.items():
        value = description.get(key)
        stated = value.get(entry) if entry and isinstance(value, Mapping) else value
        if stated != name:
            where = f"{key}[{entry!r}]" if entry else key
            raise CompositionError(f"{where} is {stated!r}, but the composition builds {name!r}: name that")
    torso_range = (description.get("TORSO") or {}).get("range")
    low, high = _numbers(torso_range, 2, "TORSO['range'] of a composed torso")
    if not 0.0 <= low < high:
        raise CompositionError(f"TORSO['range'] of a composed torso must be 0 <= low < high [m], not {torso_range!r}")
