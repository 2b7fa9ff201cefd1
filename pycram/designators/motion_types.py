"""Motion types: the vocabulary of motion designators, declared once as data.

A robot (or a world) lists the motion types it understands in ``motion_types`` (see
:class:`pycram.robot.ResolverSet`): for each type its keys -- required or optional, what they
mean, their unit, the form of their value and the valid values. The same declaration is used to
validate a designator before anything moves and to document the vocabulary
(:func:`vocabulary_table`)::

    MotionType("moving", "drive the base to a pose", (
        MotionKey("pose", "base pose: Pose2D or (x [m], y [m], yaw [rad])", form="pose2d"),
        MotionKey("frame", "frame of the pose", form="name", required=False,
                  choices=("map", "base_footprint")),
    ))

Guarantees
----------
- :func:`check_motion` raises :class:`MotionPropertyError` naming the designator's type, the
  offending key and the valid keys of the type, for a missing required key, a key the type does
  not have (with the closest valid key as a suggestion), and a value of the wrong form, out of
  range, not among the valid values, or not finite (NaN, inf).
- Checks run in the caller's thread before a designator is queued on a process module
  (:meth:`pycram.process_module.ProcessModule.perform`) and again when it is resolved.
- A type no active resolver set declares is not refused here: a process module of an extension
  may serve it. When none does, :class:`pycram.process_module.UnknownMotionTypeError` lists the
  known types of the active robot. Without any declared vocabulary nothing is checked (the
  thesis' global resolver lists).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from numbers import Real
from typing import Any

from pycram.designators.core import PropertyError, _short

__all__ = [
    "MotionKey",
    "MotionType",
    "MotionPropertyError",
    "GoalOutsideEnvironment",
    "COMMON_KEYS",
    "FORMS",
    "active_motion_types",
    "check_motion",
    "describe_known_types",
    "vocabulary_table",
]

#: The forms a key's value may have, and how each is described in messages and docs.
FORMS: Mapping[str, str] = {
    "any": "any value",
    "bool": "True or False",
    "text": "a string",
    "name": "one of the valid values",
    "number": "a finite number",
    "numbers": "a list of finite numbers",
    "point": "a point [x, y, z] of finite numbers",
    "pose2d": "a base pose: Pose2D or (x, y, yaw) of finite numbers",
    "fluent": "a Fluent",
}


class MotionPropertyError(PropertyError):
    """A motion designator does not fit its motion type: a key is missing, unknown or has an
    invalid value (or the type is missing).

    Attributes: ``designator``, ``motion_type`` (the type's name or ``None``), ``key`` (the
    offending key or ``None``), ``valid_keys`` (of the type; empty if the type is unknown).
    """

    def __init__(
        self,
        message: str,
        designator: Any = None,
        motion_type: Any = None,
        key: Any = None,
        valid_keys: Iterable[str] = (),
    ) -> None:
        super().__init__(message)
        self.designator = designator
        self.motion_type = motion_type
        self.key = key
        self.valid_keys = list(valid_keys)


class GoalOutsideEnvironment(MotionPropertyError):
    """A motion's goal lies outside the environment (e.g. a base pose off the free floor)."""


@dataclass(frozen=True)
class MotionKey:
    """One key of a motion type.

    ``meaning`` says what the value is, with its unit in brackets (``"[m]"``); ``form`` is one of
    :data:`FORMS`. ``choices`` are the valid values of a ``'name'`` (none: any value) and the
    symbolic values a ``'number'`` may take besides a number (e.g. ``'up'`` for a torso height);
    ``range`` bounds a ``'number'`` (inclusive). Other forms ignore both.
    """

    name: str
    meaning: str
    form: str = "any"
    required: bool = True
    choices: tuple[Any, ...] = ()
    range: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.form not in FORMS:
            raise ValueError(f"motion key {self.name!r}: unknown form {self.form!r}; available: {sorted(FORMS)}")

    def valid_values(self) -> str:
        """The valid values in words, for messages and docs."""
        if self.form not in ("name", "number"):
            return FORMS[self.form]
        parts = []
        if self.choices:
            parts.append(", ".join(repr(c) for c in sorted(self.choices, key=str)))
        if self.form == "number":
            parts.append(
                FORMS["number"] if self.range is None else f"a number in [{self.range[0]:g}, {self.range[1]:g}]"
            )
        return " or ".join(parts) or FORMS["any"]

    def problem(self, value: Any) -> str | None:
        """Why ``value`` is not valid for this key, or ``None`` when it is."""
        if self.form == "name":
            ok = not self.choices or _among(value, self.choices)
        elif self.form == "number":
            ok = _among(value, self.choices) or (
                _finite_number(value) and (self.range is None or self.range[0] <= float(value) <= self.range[1])
            )
        else:
            ok = _FORM_CHECKS[self.form](value)
        return None if ok else f"must be {self.valid_values()}"


#: Keys every motion type has: its type, and ``wait`` (``False``: return an execution handle at
#: once instead of waiting; see ``ProcessModule.perform``).
COMMON_KEYS: tuple[MotionKey, ...] = (
    MotionKey("type", "the motion type", form="text"),
    MotionKey(
        "wait", "False: return an execution handle at once; default: wait until done", form="bool", required=False
    ),
)


@dataclass(frozen=True)
class MotionType:
    """A motion type: its name, what it does, its keys, and optional checks that need more than
    one value or knowledge of the world (``check(designator, motion_type)``, raising
    :class:`MotionPropertyError`, e.g. a goal inside the environment)."""

    name: str
    meaning: str
    keys: tuple[MotionKey, ...] = ()
    checks: tuple[Callable[[Any, MotionType], None], ...] = field(default=(), compare=False)

    def all_keys(self) -> tuple[MotionKey, ...]:
        """The type's own keys followed by :data:`COMMON_KEYS`."""
        own = {k.name for k in self.keys}
        return self.keys + tuple(k for k in COMMON_KEYS if k.name not in own)

    def key(self, name: Any) -> MotionKey | None:
        for key in self.all_keys():
            if key.name == name:
                return key
        return None

    def describe_keys(self) -> str:
        """The valid keys in one line: ``pose (required), frame, wait``."""
        return ", ".join(f"{k.name} (required)" if k.required else k.name for k in self.all_keys() if k.name != "type")

    def check(self, designator: Any) -> None:
        """Raise :class:`MotionPropertyError` unless ``designator`` fits this type."""
        valid = [k.name for k in self.all_keys()]

        def error(message: str, key: Any, cls: type[MotionPropertyError] = MotionPropertyError) -> Exception:
            return cls(
                f"motion designator of type {self.name!r}: {message}; valid keys of "
                f"{self.name!r}: {self.describe_keys()} (in {designator!r})",
                designator=designator,
                motion_type=self.name,
                key=key,
                valid_keys=valid,
            )

        for name, value in designator.properties:
            key = self.key(name)
            if key is None:
                close = difflib.get_close_matches(str(name), valid, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise error(f"unknown key {name!r}{hint}", name)
            if value is None:
                continue
            problem = key.problem(value)
            if problem is not None:
                raise error(f"key {name!r} ({key.meaning}) {problem}, got {_short(value)}", name)
        for key in self.all_keys():
            if key.required and designator.prop_value(key.name) is None:
                raise error(f"missing the required key {key.name!r} ({key.meaning})", key.name)
        for extra_check in self.checks:
            extra_check(designator, self)


def active_motion_types() -> dict[Any, MotionType]:
    """The motion types declared by the active world and robot (the robot's win)."""
    from pycram.designators.resolvers import active_resolver_sets

    merged: dict[Any, MotionType] = {}
    for resolver_set in reversed(active_resolver_sets()):
        merged.update(getattr(resolver_set, "motion_types", None) or {})
    return merged


def describe_known_types(types: Mapping[Any, MotionType], wanted: Any = None) -> str:
    """``known motion types of active robot 'pr2': [...]`` (with a suggestion close to
    ``wanted``)."""
    from pycram.designators.resolvers import describe_active_robot

    names = sorted(str(t) for t in types)
    close = difflib.get_close_matches(str(wanted), names, n=1) if wanted is not None else []
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"{hint}known motion types of {describe_active_robot()}: {', '.join(names)}"


def check_motion(designator: Any) -> None:
    """Check ``designator`` against the active vocabulary (see the module docstring).

    Raises :class:`MotionPropertyError` (a :class:`PropertyError`). Does nothing when no active
    resolver set declares motion types, or when the designator's type is declared by none.
    """
    types = active_motion_types()
    if not types:
        return
    type_name = designator.prop_value("type")
    if type_name is None:
        raise MotionPropertyError(
            f"{designator!r} has no 'type'; {describe_known_types(types)}", designator=designator, key="type"
        )
    try:
        motion_type = types.get(type_name)
    except TypeError:  # an unhashable type value
        motion_type = None
    if motion_type is not None:
        motion_type.check(designator)


def vocabulary_table(types: Mapping[Any, MotionType]) -> str:
    """The vocabulary as a Markdown table (docs): per type a row saying what it does, then one row
    per key; the keys every type has (:data:`COMMON_KEYS` but ``type``) at the end."""
    rows = ["| type | key | required | meaning [unit] | valid values |", "|---|---|---|---|---|"]

    def key_row(type_cell: str, key: MotionKey) -> str:
        return (
            f"| {type_cell} | `{key.name}` | {'yes' if key.required else 'no'} | {key.meaning} | {key.valid_values()} |"
        )

    for name in sorted(types, key=str):
        rows.append(f"| `{name}` | | | {types[name].meaning} | |")
        rows.extend(key_row("", key) for key in types[name].keys)
    rows.extend(key_row("every type", key) for key in COMMON_KEYS if key.name != "type")
    return "\n".join(rows)


# --------------------------------------------------------------------------- value forms


def _among(value: Any, choices: tuple[Any, ...]) -> bool:
    if isinstance(value, bool):  # True == 1: never a name, never an alias
        return any(c is value for c in choices)
    try:
        return any(value == c for c in choices)
    except (TypeError, ValueError):  # e.g. numpy arrays
        return False


def _finite_number(value: Any) -> bool:
    return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)


def _finite_numbers(value: Any) -> list[float] | None:
    if isinstance(value, (str, bytes)):
        return None
    try:
        items = list(value)
    except TypeError:
        return None
    return [float(v) for v in items] if all(_finite_number(v) for v in items) else None


def _is_pose2d(value: Any) -> bool:
    if all(hasattr(value, a) for a in ("x", "y", "yaw")):
        return all(_finite_number(getattr(value, a)) for a in ("x", "y", "yaw"))
    numbers = _finite_numbers(value)
    return numbers is not None and len(numbers) == 3


def _is_fluent(value: Any) -> bool:
    from pycram.core.fluent import Fluent

    return isinstance(value, Fluent)


_FORM_CHECKS: Mapping[str, Callable[[Any], bool]] = {
    "any": lambda v: True,
    "bool": lambda v: isinstance(v, bool),
    "text": lambda v: isinstance(v, str),
    "numbers": lambda v: bool(_finite_numbers(v)),
    "point": lambda v: len(_finite_numbers(v) or ()) == 3,
    "pose2d": _is_pose2d,
    "fluent": _is_fluent,
}
