"""Locating robot models in installed packages and turning URDFs into MuJoCo-loadable text.

Nothing is downloaded and nothing is copied: mesh URIs are rewritten to absolute paths of the
installed `example-robot-data` package at load time.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

from pycram.world.robot_model_file import ModelFileError, model_dir

from .errors import SimulationError

#: The compiler options injected into every URDF (see SIM_NOTES: keep static bodies as links).
_COMPILER = (
    '<mujoco><compiler strippath="false" fusestatic="false" balanceinertia="true" discardvisual="false"/></mujoco>'
)


def robot_data_dir() -> Path:
    """The `share/example-robot-data` directory of the installed `example-robot-data` package
    (`pycram.world.robot_model_file.model_dir`).

    `PYCRAM_ROBOT_DATA` overrides the search. Raises `SimulationError` when it is not installed.
    """
    try:
        return model_dir()
    except ModelFileError as exc:
        raise SimulationError(str(exc)) from None


def _fix_inertia(text: str) -> str:
    """Diagonalise inertia tensors and clamp tiny moments (some TIAGo links are not positive definite)."""

    def rep(match: re.Match[str]) -> str:
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', match.group(0)))
        ixx, iyy, izz = (max(abs(float(attrs.get(k, 0.0))), 1e-5) for k in ("ixx", "iyy", "izz"))
        return f'<inertia ixx="{ixx:g}" ixy="0" ixz="0" iyy="{iyy:g}" iyz="0" izz="{izz:g}"/>'

    return re.sub(r"<inertia\b[^>]*/>", rep, text)


def _replace_collada(text: str) -> str:
    """MuJoCo reads no COLLADA: use the matching STL visual meshes, a box for the Xtion camera."""
    text = re.sub(r"torso_lift_collision_\w+\.dae", "torso_lift_with_arm.stl", text)
    text = re.sub(r"_collision(-wrist-2010)?\.dae", r"\1.stl", text)
    return re.sub(r'<mesh filename="[^"]*xtion_pro_live\.dae"[^>]*/>', '<box size="0.04 0.18 0.04"/>', text)


@functools.lru_cache(maxsize=8)
def urdf_text(relative_path: str) -> str:
    """URDF text of `relative_path` (relative to `robot_data_dir()`) ready for `MjSpec.from_string`."""
    root = robot_data_dir()
    path = root / relative_path
    if not path.is_file():
        raise SimulationError(f"URDF {relative_path!r} not found under {root}")
    text = path.read_text()
    text = text.replace("package://example-robot-data/", str(root) + "/")
    if ".dae" in text:
        text = _replace_collada(text)
        text = _fix_inertia(text)
    return re.sub(r"(<robot\b[^>]*>)", r"\1" + _COMPILER, text, count=1)
