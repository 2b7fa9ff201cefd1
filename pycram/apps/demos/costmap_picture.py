"""A picture of a location designator's costmap over the floor plan, with the poses it chose.

`write_costmap_picture(world, robot, properties, path)` resolves the location designator made
of `properties` with `robot` active, takes its first `count` solutions (or the error saying
why there are none), renders the world's top-down plan camera and draws over it each costmap
layer (one panel per layer, and their sum), the chosen base poses as arrows (spots as dots),
and the target. `pycram scene --costmap "to_reach cup"` writes it: the picture to look at when a
location is not found.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["write_costmap_picture", "parse_location", "perceive_named_objects", "draw_location_costmap", "DrawnCostmap"]


def parse_location(text: str) -> list[tuple[str, Any]]:
    """``"to_reach cup, arm left"`` -> ``[('to_reach', 'cup'), ('arm', 'left')]``: comma-separated
    ``key value`` pairs; a value of three numbers separated by spaces is a point."""
    out: list[tuple[str, Any]] = []
    for part in text.split(","):
        words = part.split()
        if len(words) < 2:
            raise ValueError(f"a location property is 'key value', got {part.strip()!r} in {text!r}")
        key, rest = words[0], words[1:]
        try:
            value: Any = tuple(float(w) for w in rest)
            if len(value) != 3:
                value = " ".join(rest)
        except ValueError:
            value = " ".join(rest)
        out.append((key, value))
    return out


def write_costmap_picture(
    world: Any,
    robot: Any,
    properties: Sequence[tuple[str, Any]],
    path: str | Path,
    count: int = 5,
    title: str | None = None,
) -> tuple[Path, list[Any], str | None]:
    """Resolve ``LocationDesignator(properties)`` with `robot` active and draw it (see the module
    docstring). Returns (path, solutions found, error message or None)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pycram.apps.demos.scene_picture import _render
    from pycram.backends.sim.environment_builder import PLAN_CAMERA, plan_view
    from pycram.designators.core import DesignatorError
    from pycram.designators.location import LocationDesignator

    generator = next((g for g in robot.location_generators if hasattr(g, "reasoner")), None)
    solutions: list[Any] = []
    error = None
    with robot:
        designator = LocationDesignator(list(properties))
        try:
            designator.reference()  # raises the error saying why, when there is no solution
            solutions = [s for s, _ in zip(designator.solutions(), range(count))]
        except DesignatorError as e:
            error = str(e)
    maps = getattr(generator.reasoner, "last_costmaps", {}) if generator is not None else {}
    env = world.environment
    x0, y0, x1, y1 = plan_view(env)
    plan = _render(world, PLAN_CAMERA, 800, 600)
    panels: list[tuple[str, np.ndarray | None, Any]] = []
    for name, costmap in maps.items():
        for layer, values in costmap.layers.items():
            panels.append((f"{name}: {layer}", values, costmap.grid))
        panels.append((f"{name}: sum (solutions)", costmap.total(), costmap.grid))
    if not panels:
        panels.append(("solutions", None, None))
    columns = min(4, len(panels))
    rows = (len(panels) + columns - 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(5.5 * columns, 4.4 * rows + 0.8), squeeze=False)
    for ax in axes.ravel()[len(panels) :]:
        ax.set_axis_off()
    for ax, (label, values, grid) in zip(axes.ravel(), panels):
        ax.imshow(plan, extent=(x0, x1, y0, y1))
        if values is not None:
            shown = np.where(np.isfinite(values), values, np.nan)
            gx0, gy0, gx1, gy1 = grid.bounds
            finite = shown[np.isfinite(shown)]
            vmax = float(np.percentile(finite, 95)) if finite.size else 1.0
            ax.imshow(
                shown,
                extent=(gx0, gx1, gy0, gy1),
                origin="lower",
                cmap="viridis_r",
                alpha=0.6,
                vmin=0.0,
                vmax=max(vmax, 1e-6),
            )
            blocked = np.where(np.isinf(values), 1.0, np.nan)
            ax.imshow(blocked, extent=(gx0, gx1, gy0, gy1), origin="lower", cmap="Reds", alpha=0.35, vmin=0, vmax=1)
        _draw_solutions(ax, solutions)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_title(label, fontsize=10)
        ax.tick_params(labelsize=7)
    head = title or f"{env.name} · {robot.name} · {properties}"
    foot = error or ", ".join(_describe(s) for s in solutions)
    fig.suptitle(f"{head}\n{foot}" if len(foot) < 160 else f"{head}\n{foot[:157]}...", fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90, bbox_inches="tight")
    plt.close(fig)
    return path, solutions, error


def _draw_solutions(ax: Any, solutions: Sequence[Any]) -> None:
    import math

    for i, s in enumerate(solutions):
        color = "#d50000" if i == 0 else "#ff6d00"
        if hasattr(s, "yaw"):
            ax.annotate(
                "",
                xy=(s.x + 0.35 * math.cos(s.yaw), s.y + 0.35 * math.sin(s.yaw)),
                xytext=(s.x, s.y),
                arrowprops={"arrowstyle": "-|>", "color": color, "lw": 2},
            )
            ax.plot([s.x], [s.y], "o", ms=5, color=color)
            ax.text(s.x + 0.08, s.y - 0.15, str(i + 1), fontsize=8, color=color, fontweight="bold")
        else:
            ax.plot([s[0]], [s[1]], "o", ms=6, color=color)
            ax.text(s[0] + 0.05, s[1] + 0.05, str(i + 1), fontsize=8, color=color, fontweight="bold")


def _describe(s: Any) -> str:
    if hasattr(s, "yaw"):
        extra = "".join(f" {k}={getattr(s, k)}" for k in ("arm", "grasp") if getattr(s, k, None))
        return f"({s.x:.2f}, {s.y:.2f}, {s.yaw:.2f}){extra}"
    return "(" + ", ".join(f"{v:.2f}" for v in s) + ")"


def perceive_named_objects(robot: Any, properties: list[tuple[str, Any]]) -> list[str]:
    """Reasoning knows objects only once perceived: ``robot`` looks around from where it stands,
    then searches for each object type the location's ``properties`` name that it has not seen
    yet. Returns the messages of the searches that found nothing (the picture is drawn anyway)."""
    from pycram.actions import ObjectNotFound, look_around, search_for
    from pycram.designators.object import ObjectDesignator
    from pycram.world.objects import OBJECT_TYPES

    not_found: list[str] = []
    with robot:
        look_around()
        for _, value in properties:
            if (
                isinstance(value, str)
                and value in OBJECT_TYPES
                and not any(obj.type == value for obj in robot.belief.objects())
            ):
                try:
                    search_for(ObjectDesignator(type=value))
                except ObjectNotFound as e:
                    not_found.append(str(e))
    return not_found


@dataclass(frozen=True)
class DrawnCostmap:
    """What :func:`draw_location_costmap` drew: the picture's ``path``, the location's
    ``solutions`` (poses), its resolution ``error`` (``None`` when it had solutions) and the
    searches that found nothing (``not_found``)."""

    path: Path
    solutions: list[Any]
    error: str | None
    not_found: list[str]


def draw_location_costmap(
    world: Any, robot_name: str, properties: list[tuple[str, Any]], output: str | Path, title: str
) -> DrawnCostmap:
    """The robot ``robot_name`` of the simulated ``world`` raises its torso (as plans do before
    reaching), perceives the objects the location names (:func:`perceive_named_objects`), and
    the location's costmap is drawn to ``output`` (:func:`write_costmap_picture`). The robot is
    shut down afterwards; the world stays open."""
    from pycram import robots

    robot = robots.load(robot_name, world)
    try:
        world.set_torso(robot.description.TORSO_POSITIONS["up"]).wait(30.0)
        not_found = perceive_named_objects(robot, properties)
        path, solutions, error = write_costmap_picture(world, robot, properties, output, title=title)
    finally:
        robot.shutdown()
    return DrawnCostmap(Path(path), list(solutions), error, not_found)
