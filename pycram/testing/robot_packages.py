"""Robot packages written at run time, for tests: a robot registered the way a package outside
PyCRAM registers one (`pycram.world.robot_registry`).

- :func:`write_robot_package` writes, into a folder, a robot package -- a copy of a registered
  robot's description under another name, with changes -- and the distribution metadata
  ``pip install`` writes for it: a ``*.dist-info`` folder whose ``entry_points.txt`` declares
  the robot in the ``pycram.robots`` group.
- :func:`on_import_path` puts a folder first on ``sys.path`` for a ``with`` block (the registry
  finds the robots in it at its next lookup), then takes it off again and forgets the modules
  imported from it, so that a later package of the same name, elsewhere, is imported afresh.
- :func:`installed_robot_package` does both::

    with installed_robot_package(tmp_path, "tiago_omni", overrides={"BASE": {"kind": "omnidirectional"}}):
        world = World("tiago_omni")  # the TIAGo's description on an omnidirectional base

A written package has no ``robot.py``; the simulator then makes the robot from the description
alone (`pycram.robots.common.sim_robot.make_sim_robot`).
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import os
import sys
import textwrap
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from pycram.world.robot_registry import ENTRY_POINT_GROUP, robot_package

__all__ = ["write_robot_package", "on_import_path", "installed_robot_package"]

#: The version written into a package's distribution metadata (``<package>-0.1.dist-info``).
_VERSION = "0.1"


def _literal(key: str, value: Any) -> str:
    """``repr(value)``, checked to read back as the same plain data; `ValueError` otherwise."""
    text = repr(value)
    try:
        same = ast.literal_eval(text) == value
    except (ValueError, SyntaxError):
        same = False
    if not same:
        raise ValueError(f"override {key!r}: {text} is not plain data (numbers, strings, tuples, lists, dicts)")
    return text


def _override_lines(like: str, source: dict[str, Any], overrides: Mapping[str, Any]) -> list[str]:
    """The description lines that set `overrides` after the copied keys (`source`: the values of
    the description of `like`)."""
    lines = []
    for key, value in overrides.items():
        if not (key.isidentifier() and key.isupper()):
            raise ValueError(f"override {key!r}: description keys are UPPERCASE names, e.g. 'BASE'")
        if key == "NAME":
            raise ValueError("override 'NAME': the robot's name is the `name` argument")
        if isinstance(value, Mapping):
            if not isinstance(source.get(key), Mapping):
                has = f"its {key} is a {type(source[key]).__name__}" if key in source else f"it has no {key}"
                raise ValueError(
                    f"override {key!r}: a mapping updates a dict of the description of {like!r}, but {has}; "
                    "give the whole value in `changes` instead"
                )
            items = ", ".join(f"{_literal(key, k)}: {_literal(key, v)}" for k, v in value.items())
            lines.append(f"{key} = {{**{key}, {items}}}")
        else:
            lines.append(f"{key} = {_literal(key, value)}")
    return lines


def write_robot_package(
    folder: str | os.PathLike[str],
    name: str,
    like: str = "tiago",
    *,
    package: str | None = None,
    overrides: Mapping[str, Any] | None = None,
    changes: str = "",
) -> Path:
    """Write the package of the robot `name` into `folder` (made if missing) and return the
    package's folder:

    - ``<package>/__init__.py``;
    - ``<package>/description.py``: the description of the registered robot `like`, then
      ``NAME = name``, then `overrides`, then `changes`;
    - ``<package>-0.1.dist-info/``: ``METADATA`` and ``entry_points.txt`` declaring
      ``name = package`` in the ``pycram.robots`` group.

    `package` is the importable package's name (default: `name` with ``-`` as ``_``).
    `overrides` sets description keys after the copied ones: a mapping given for a key whose
    copied value is a dict updates that dict (``{"BASE": {"kind": "differential"}}`` changes
    only the base's kind), any other value replaces the key's value; values are plain data.
    `changes` is Python code appended to the description, which may use the copied keys (e.g.
    ``del TORSO``).

    The robot is registered once `folder` is on ``sys.path`` (`on_import_path`). Raises
    `ValueError` for a package name that is not an identifier, a package already in `folder`,
    or an override that is not plain data or updates a key that is not a dict;
    `UnknownRobotError` when `like` is not registered.
    """
    package = package if package is not None else name.replace("-", "_")
    if not package.isidentifier():
        raise ValueError(f"package {package!r} is not a Python identifier; name one with package=...")
    root = Path(folder)
    target = root / package
    if target.exists():
        raise ValueError(f"{target} exists already: write each robot package once (or into another folder)")
    module_name = f"{robot_package(like)}.description"
    spec = importlib.util.find_spec(module_name)
    if spec is None or spec.origin is None:
        raise ValueError(f"robot {like!r} has no description file ({module_name})")
    source = importlib.import_module(module_name)
    lines = [
        Path(spec.origin).read_text(encoding="utf-8").rstrip("\n"),
        "",
        f"# The robot {name!r}: {like!r}'s description with these changes (pycram.testing.robot_packages).",
        f"NAME = {name!r}",
        *_override_lines(like, vars(source), overrides or {}),
        textwrap.dedent(changes).strip("\n"),
    ]
    target.mkdir(parents=True)
    (target / "__init__.py").write_text(f'"""The robot {name!r}: a package outside PyCRAM."""\n', encoding="utf-8")
    (target / "description.py").write_text("\n".join(lines).rstrip("\n") + "\n", encoding="utf-8")
    dist = root / f"{package}-{_VERSION}.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(
        f"Metadata-Version: 2.1\nName: {package.replace('_', '-')}\nVersion: {_VERSION}\n", encoding="utf-8"
    )
    (dist / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n{name} = {package}\n", encoding="utf-8")
    return target


def _inside(file: str | None, folder: Path) -> bool:
    if not file:
        return False
    try:
        return Path(file).resolve().is_relative_to(folder)
    except (OSError, ValueError):
        return False


@contextmanager
def on_import_path(folder: str | os.PathLike[str]) -> Iterator[Path]:
    """Put `folder` first on ``sys.path`` while the block runs (the robot registry reads the entry
    points again at its next lookup, so the robots written there are registered); afterwards
    take it off and drop the modules imported from it from ``sys.modules``. Yields the folder."""
    path = str(folder)
    sys.path.insert(0, path)
    importlib.invalidate_caches()
    try:
        yield Path(folder)
    finally:
        if path in sys.path:
            sys.path.remove(path)
        resolved = Path(folder).resolve()
        for module_name, module in list(sys.modules.items()):
            if _inside(getattr(module, "__file__", None), resolved):
                del sys.modules[module_name]


@contextmanager
def installed_robot_package(
    folder: str | os.PathLike[str],
    name: str,
    like: str = "tiago",
    *,
    package: str | None = None,
    overrides: Mapping[str, Any] | None = None,
    changes: str = "",
) -> Iterator[Path]:
    """The robot `name` registered while the block runs: `write_robot_package` into `folder`
    (same arguments), with `folder` on the import path (`on_import_path`). Yields the package's
    folder."""
    target = write_robot_package(folder, name, like, package=package, overrides=overrides, changes=changes)
    with on_import_path(folder):
        yield target
