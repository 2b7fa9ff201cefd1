"""A robot's description as a typed, validated object: the schema of `pycram.robots.<name>.description`.

Each robot package keeps its description as a pure-data module (UPPERCASE constants, no imports;
see :mod:`pycram.world.robot_registry`). :class:`RobotDescription` mirrors that module: one field
per key, with the key's UPPERCASE name, so that ``description.ARMS`` reads the same on the
validated object as on the module. :meth:`RobotDescription.from_module` checks the module once
(every required key present, no unknown UPPERCASE key, the arms and grippers well formed) and
raises :class:`RobotDescriptionError` naming the robot, the key and the valid keys or choices.

Units are those of the data modules: angles in [rad], lengths in [m], velocities in [m/s] /
[rad/s], forces in [N]. The values are the module's own objects (not copies; except ``ARMS``,
``GRIPPERS`` and ``HEAD`` when something in them is read from the URDF, see
:mod:`pycram.world.robot_model_file`): the object is frozen (no field can be rebound), its
mappings are the module's.

Optional keys and their defaults (the defaults the readers used before this schema existed):
``DEFAULT_ARM`` (the first arm of ``ARMS``), ``ARM_ALIASES`` (each arm names itself),
``GRIPPER_MODEL`` (None: the URDF has its own gripper), ``GRASP_CONTACT_MARGIN`` (0.0),
``DOOR_PUSH``, ``DOOR_PULL_LIMIT``, ``DOOR_GRIP_OPENING`` (None: the robot does not push doors,
pulls them all the way, opens its gripper fully), ``FINGERTIP_REACH`` and
``TOP_GRASP_CLEARANCE`` (0.0), ``ROS`` (None: no ROS interface), ``COMPOSITION`` (None: the
URDF is the whole robot; see :mod:`pycram.world.robot_composition`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from .base_kinematics import BaseKinematics
from .robot_composition import CompositionError, validate_composition
from .robot_model_file import ModelFileError, infer_from_model

__all__ = ["RobotDescription", "RobotDescriptionError", "ARM_KEYS", "ARM_OPTIONAL_KEYS", "GRIPPER_KEYS"]

#: The keys of one entry of ``ARMS``: its joints (in the order of `set_arm_joints`), its tool
#: frame's link (x: approach direction, y: finger opening direction) and its gripper.
ARM_KEYS = ("joints", "tool_link", "gripper")
#: Keys an entry of ``ARMS`` may have besides `ARM_KEYS`: ``root_link``, the link its chain
#: starts at -- then ``joints`` may be left out and is read from the URDF
#: (`pycram.world.robot_model_file.infer_from_model`).
ARM_OPTIONAL_KEYS = ("root_link",)

#: The keys of one entry of ``GRIPPERS``.
GRIPPER_KEYS = (
    "joint",
    "coupled_joints",
    "joint_range",
    "pad_links",
    "pad_offset",
    "palm_link",
    "finger_links",
    "max_opening",
    "effort_lever",
    "default_effort",
)


class RobotDescriptionError(ValueError):
    """A robot description that does not fit the schema: a missing or unknown key, or a
    malformed value. The message names the robot, the key and the valid keys or choices;
    `robot` and `key` say the same as data."""

    def __init__(self, robot: str, key: str, problem: str) -> None:
        self.robot, self.key = robot, key
        super().__init__(f"robot description of {robot!r}: {problem}")


@dataclass(frozen=True, eq=False)
class RobotDescription:
    """One robot's names and numbers (see the module docstring); the fields mirror the UPPERCASE
    constants of the robot's data module ``pycram.robots.<name>.description``.

    Compared by identity, like the module it mirrors (the registry keeps one per robot).
    """

    #: The robot's name (its registry name).
    NAME: str
    #: URDF path relative to the `example-robot-data` share directory.
    URDF: str
    #: Root link of the URDF, mounted on an omnidirectional base (slide x, slide y, hinge yaw).
    ROOT_LINK: str
    #: Base limits (velocities, accelerations), footprint radii [m] and the links that count as
    #: the base when checking for collisions while driving; ``kind``: how it moves,
    #: ``"omnidirectional"`` (the default) or ``"differential"`` (then optionally
    #: ``max_reverse`` and ``approach`` [m]: `pycram.world.base_kinematics.BaseKinematics`).
    BASE: dict[str, Any]
    #: The torso's ``joint``, its ``range`` [m] and ``default`` height [m].
    TORSO: dict[str, Any]
    #: Head pan / tilt joints, camera link, vertical field of view [deg] and resolution [px].
    HEAD: dict[str, Any]
    #: Arms by name; each entry has the keys `ARM_KEYS`.
    ARMS: dict[str, dict[str, Any]]
    #: Grippers by name; each entry has the keys `GRIPPER_KEYS`.
    GRIPPERS: dict[str, dict[str, Any]]
    #: Named arm configurations per arm [rad] (joint order as in ``ARMS[arm]["joints"]``).
    ARM_CONFIGURATIONS: dict[str, dict[str, tuple[float, ...]]]
    #: Joint positions when a world is created.
    INITIAL_CONFIGURATION: dict[str, float]
    #: Base poses (x [m], y [m], yaw [rad]) in the simulated thesis kitchen by place name.
    KITCHEN_BASE_POSES: dict[str, tuple[float, float, float]]
    #: Torso heights [m] of the symbolic positions of `setting_torso`.
    TORSO_POSITIONS: dict[str, float]
    #: Gripper names accepted in designators -> the physical gripper.
    GRIPPER_ALIASES: dict[Any, str]
    #: Where a point to reach lies in the base frame (x ahead [m], y left [m]), per arm.
    REACH_POINT_IN_BASE: dict[str, tuple[float, float]]
    #: Tool offsets of each `reaching` phase: (back along the approach [m], up [m]).
    APPROACH_OFFSETS: dict[str, tuple[float, float]]
    #: Position tolerance [m] of the tool per `reaching` phase (``'default'`` for the others).
    REACH_TOLERANCE: dict[str, float]
    #: The arm used when a request names none ("": the first arm of ``ARMS``).
    DEFAULT_ARM: str = ""
    #: Arm names accepted in designators -> the physical arm (None: each arm names itself).
    ARM_ALIASES: dict[Any, str] = None  # type: ignore[assignment]
    #: A parallel gripper of our own built onto the URDF (None: the URDF has its gripper).
    GRIPPER_MODEL: dict[str, Any] | None = None
    #: A grasp pose counts as reachable only if the tool also reaches this much [m] lower.
    GRASP_CONTACT_MARGIN: float = 0.0
    #: How the hand meets a door's faces when it pushes them (None: it does not push doors).
    DOOR_PUSH: dict[str, dict[str, Any]] | None = None
    #: How far [rad] the grip carries a door by its handle (None: all the way).
    DOOR_PULL_LIMIT: float | None = None
    #: How far (a fraction of the full opening) the gripper opens before closing on a door's
    #: handle (None: fully).
    DOOR_GRIP_OPENING: float | None = None
    #: How far [m] the finger tips reach beyond the tool frame along the approach.
    FINGERTIP_REACH: float = 0.0
    #: Clearance [m] of the finger tips above the supporting surface in a top grasp.
    TOP_GRASP_CLEARANCE: float = 0.0
    #: The robot's ROS interface as plain data: keyword arguments of
    #: `pycram.backends.ros.config.RosRobotConfig` without ``robot``, arms and grippers as
    #: mappings of their fields (None: no ROS interface).
    ROS: dict[str, Any] | None = None
    #: A robot composed from an arm's model file (``URDF``) and a base, torso lift column and
    #: camera mast built from primitives (`pycram.world.robot_composition`; None: the URDF is
    #: the whole robot).
    COMPOSITION: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        if not self.DEFAULT_ARM and isinstance(self.ARMS, Mapping) and self.ARMS:
            object.__setattr__(self, "DEFAULT_ARM", next(iter(self.ARMS)))
        if self.ARM_ALIASES is None and isinstance(self.ARMS, Mapping):
            object.__setattr__(self, "ARM_ALIASES", {a: a for a in self.ARMS})
        self._validate()

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        """All keys of a description, in the order of the fields."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def required_keys(cls) -> tuple[str, ...]:
        """The keys a description must have."""
        return tuple(f.name for f in dataclasses.fields(cls) if f.default is dataclasses.MISSING)

    @classmethod
    def from_module(cls, module: ModuleType) -> RobotDescription:
        """The validated description of a data module: its public UPPERCASE names are the keys
        (names starting with ``_`` are the module's helpers). Raises `RobotDescriptionError`."""
        data = {k: v for k, v in vars(module).items() if not k.startswith("_") and k.isupper()}
        return cls.from_mapping(data, source=module.__name__)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], source: str | None = None) -> RobotDescription:
        """The validated description from ``{key: value}``; `source` (e.g. the module's name)
        names where it came from in errors. Raises `RobotDescriptionError` for a missing or
        unknown key, or a malformed value."""
        robot = str(data.get("NAME") or source or "?")
        where = f" (in {source})" if source else ""
        keys = cls.keys()
        unknown = sorted(set(data) - set(keys))
        if unknown:
            raise RobotDescriptionError(
                robot, unknown[0], f"unknown key {unknown[0]!r}{where}; valid keys: {', '.join(keys)}"
            )
        missing = [k for k in cls.required_keys() if k not in data]
        if missing:
            raise RobotDescriptionError(
                robot,
                missing[0],
                f"missing key {missing[0]!r}{where}; required keys: {', '.join(cls.required_keys())}",
            )
        try:
            data = infer_from_model(data, robot)
        except ModelFileError as exc:
            key = next((k for k in ("ARMS", "GRIPPERS", "HEAD") if f": {k}:" in str(exc)), "URDF")
            problem = str(exc).removeprefix(f"robot description of {robot!r}: ")
            raise RobotDescriptionError(robot, key, problem) from None
        return cls(**data)

    def _fail(self, key: str, problem: str) -> RobotDescriptionError:
        return RobotDescriptionError(str(self.NAME), key, f"{key}: {problem}")

    def _validate(self) -> None:
        for key in ("NAME", "URDF", "ROOT_LINK"):
            if not isinstance(getattr(self, key), str) or not getattr(self, key):
                raise self._fail(key, f"must be a non-empty string, not {getattr(self, key)!r}")
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if str(f.type).startswith("dict") and not isinstance(value, Mapping):
                if value is None and f.default is None:
                    continue
                raise self._fail(f.name, f"must be a mapping, not {type(value).__name__}")
        self._validate_grippers()
        self._validate_arms()
        self._validate_base()
        if self.COMPOSITION is not None:
            try:
                validate_composition(self.COMPOSITION, {k: getattr(self, k) for k in self.keys()})
            except CompositionError as exc:
                raise RobotDescriptionError(str(self.NAME), "COMPOSITION", str(exc)) from None
        if self.DEFAULT_ARM not in self.ARMS:
            raise self._fail("DEFAULT_ARM", f"{self.DEFAULT_ARM!r} is no arm; arms: {', '.join(self.ARMS)}")
        for key, valid in (("ARM_ALIASES", self.ARMS), ("GRIPPER_ALIASES", self.GRIPPERS)):
            for alias, target in getattr(self, key).items():
                if target not in valid:
                    raise self._fail(key, f"{alias!r} -> {target!r}, which is none of: {', '.join(valid)}")
        for arm, configurations in self.ARM_CONFIGURATIONS.items():
            if arm not in self.ARMS:
                raise self._fail("ARM_CONFIGURATIONS", f"{arm!r} is no arm; arms: {', '.join(self.ARMS)}")
            n = len(self.ARMS[arm]["joints"])
            for name, q in configurations.items():
                if len(q) != n:
                    raise self._fail(
                        "ARM_CONFIGURATIONS", f"{arm!r} {name!r} has {len(q)} joint positions, the arm {n} joints"
                    )
        for arm in self.ARMS:
            if arm not in self.ARM_CONFIGURATIONS:
                raise self._fail("ARM_CONFIGURATIONS", f"no configurations of arm {arm!r}")

    @property
    def base_kinematics(self) -> BaseKinematics:
        """How the base moves (``BASE["kind"]``, ``"max_reverse"``, ``"approach"``)."""
        return BaseKinematics.of(self.BASE)

    def _validate_base(self) -> None:
        try:
            BaseKinematics.of(self.BASE)
        except ValueError as exc:
            raise self._fail("BASE", str(exc)) from None

    def _validate_arms(self) -> None:
        if not self.ARMS:
            raise self._fail("ARMS", "a robot needs at least one arm")
        for arm, spec in self.ARMS.items():
            self._check_entry("ARMS", arm, spec, ARM_KEYS, ARM_OPTIONAL_KEYS)
            joints = spec["joints"]
            if isinstance(joints, str) or not joints or not all(isinstance(j, str) for j in joints):
                raise self._fail("ARMS", f"arm {arm!r}: 'joints' must be a non-empty sequence of joint names")
            if spec["gripper"] not in self.GRIPPERS:
                raise self._fail(
                    "ARMS",
                    f"arm {arm!r}: gripper {spec['gripper']!r} is none of the grippers: {', '.join(self.GRIPPERS)}",
                )

    def _validate_grippers(self) -> None:
        if not self.GRIPPERS:
            raise self._fail("GRIPPERS", "a robot needs at least one gripper")
        for gripper, spec in self.GRIPPERS.items():
            self._check_entry("GRIPPERS", gripper, spec, GRIPPER_KEYS)
            joint_range = spec["joint_range"]
            if len(joint_range) != 2 or not joint_range[0] < joint_range[1]:
                raise self._fail(
                    "GRIPPERS", f"gripper {gripper!r}: 'joint_range' must be (closed, open), not {joint_range!r}"
                )

    def _check_entry(
        self, key: str, name: str, spec: Any, valid: tuple[str, ...], optional: tuple[str, ...] = ()
    ) -> None:
        what, article = ("arm", "an") if key == "ARMS" else ("gripper", "a")
        if not isinstance(spec, Mapping):
            raise self._fail(key, f"{what} {name!r} must be a mapping with the keys {', '.join(valid)}")
        missing = [k for k in valid if k not in spec]
        if missing:
            hint = " (or 'root_link', to read them from the URDF)" if missing[0] == "joints" else ""
            raise self._fail(
                key, f"{what} {name!r} lacks {missing[0]!r}{hint}; keys of {article} {what}: {', '.join(valid)}"
            )
        unknown = sorted(set(spec) - set(valid) - set(optional))
        if unknown:
            raise self._fail(
                key, f"{what} {name!r} has the unknown key {unknown[0]!r}; valid: {', '.join(valid + optional)}"
            )
