"""The registered robots at a glance: `pycram robot list`.

`robot_rows` gives one :class:`RobotRow` per registered robot (the ``pycram.robots`` entry points,
:mod:`pycram.world.robot_registry`): its arms with their joint counts and tool frames, its
grippers, its base kind, torso range, camera and model file -- or, for a description that does
not validate, the validation error. `robots_table` renders them as a rich table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["RobotRow", "robot_rows", "robots_table"]


@dataclass(frozen=True)
class RobotRow:
    """One registered robot: `name`, its `package`, and from its description `arms` (name ->
    (number of joints, tool link)), `grippers` (name -> maximum opening [m]), `base` (its kind:
    ``omnidirectional`` or ``differential``), `torso` (joint range [m]), `camera` (link), `urdf`
    (relative to example-robot-data's share directory); `error` instead when the description
    does not validate."""

    name: str
    package: str
    arms: dict[str, tuple[int, str]]
    grippers: dict[str, float]
    base: str = ""
    torso: tuple[float, float] | None = None
    camera: str = ""
    urdf: str = ""
    error: str | None = None

    def as_dict(self) -> dict[str, Any]:
        """JSON-serialisable."""
        return {
            "name": self.name,
            "package": self.package,
            "arms": {a: {"joints": n, "tool_link": t} for a, (n, t) in self.arms.items()},
            "grippers": {g: {"max_opening": m} for g, m in self.grippers.items()},
            "base": self.base,
            "torso": list(self.torso) if self.torso else None,
            "camera": self.camera,
            "urdf": self.urdf,
            "error": self.error,
        }


def robot_rows() -> list[RobotRow]:
    """One row per registered robot, sorted by name (see the module docstring)."""
    from pycram.world.robot_description import RobotDescriptionError
    from pycram.world.robot_registry import robot_description, robot_names, robot_package

    rows = []
    for name in robot_names():
        try:
            d = robot_description(name)
        except (RobotDescriptionError, ImportError) as error:
            rows.append(RobotRow(name, robot_package(name), {}, {}, error=f"{type(error).__name__}: {error}"))
            continue
        rows.append(
            RobotRow(
                name,
                robot_package(name),
                {a: (len(s["joints"]), s["tool_link"]) for a, s in d.ARMS.items()},
                {g: float(s["max_opening"]) for g, s in d.GRIPPERS.items()},
                base=str(d.BASE.get("kind", "omnidirectional")),
                torso=tuple(float(v) for v in d.TORSO["range"]),  # type: ignore[arg-type]
                camera=str(d.HEAD.get("camera_link", "")),
                urdf=d.URDF,
            )
        )
    return rows


def robots_table(rows: list[RobotRow]) -> Any:
    """The rows as a :class:`rich.table.Table`."""
    from rich.table import Table
    from rich.text import Text

    table = Table(title="registered robots", caption="check one with: pycram robot check NAME")
    table.add_column("robot", no_wrap=True)
    for column in ("arms: joints, tool frame", "grippers: opening", "base", "torso [m]", "camera", "URDF"):
        table.add_column(Text(column), overflow="fold")
    for row in rows:
        if row.error is not None:
            table.add_row(
                Text(row.name), Text(f"invalid description: {row.error}", style="bold red"), "", "", "", "", ""
            )
            continue
        arms = "\n".join(f"{a} ({n}, {t})" for a, (n, t) in row.arms.items())
        grippers = "\n".join(f"{g} ({m * 1000:.0f} mm)" for g, m in row.grippers.items())
        torso = f"{row.torso[0]:.2f}..{row.torso[1]:.2f}" if row.torso else "–"
        table.add_row(
            Text(row.name), Text(arms), Text(grippers), Text(row.base), Text(torso), Text(row.camera), Text(row.urdf)
        )
    return table
