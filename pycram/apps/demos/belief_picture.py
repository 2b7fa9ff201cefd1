"""What the robot believes beside what is: two top-down plans of a simulated scene.

`write_belief_picture(world, belief, path)` draws, left, the ground truth (every object where the
simulator has it, objects inside closed containers dashed) and, right, the robot's belief (each
believed object where it was last measured, with its measured size, perceived colour, support
and the time it was last seen; objects believed gone crossed out) with the camera's looks as
view wedges. `pycram scene --belief` writes it after the robot looked around from where it stands.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pycram.apps.demos.scene_picture import _BOX, _OBJECT_COLOR, VIEW_SIZE, _Labels, _render, _save

__all__ = ["write_belief_picture", "look_around_and_draw"]

#: Matplotlib colours of the perceived colour names.
_COLORS = {
    "red": "#d32f2f",
    "orange": "#f57c00",
    "yellow": "#fbc02d",
    "green": "#388e3c",
    "blue": "#1976d2",
    "purple": "#7b1fa2",
    "white": "#fafafa",
    "grey": "#9e9e9e",
    "black": "#212121",
}
_LOOK_COLOR = "#29b6f6"


def _plan_axes(ax: Any, image: Any, extent: tuple[float, float, float, float], title: str) -> None:
    x0, y0, x1, y1 = extent
    ax.imshow(image, extent=(x0, x1, y0, y1), interpolation="bilinear")
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x [m]")
    ax.set_title(title, fontsize=12)


def _robot(ax: Any, world: Any) -> None:
    base = world.base_pose.get_value()
    ax.annotate(
        "",
        xy=(base.x + 0.35 * math.cos(base.yaw), base.y + 0.35 * math.sin(base.yaw)),
        xytext=(base.x, base.y),
        arrowprops={"arrowstyle": "-|>", "color": "#1b5e20", "lw": 2},
    )
    ax.text(
        base.x,
        base.y - 0.3,
        world.robot.upper(),
        ha="center",
        va="top",
        fontsize=10,
        fontweight="bold",
        color="#1b5e20",
    )


def write_belief_picture(world: Any, belief: Any, path: str | Path, title: str | None = None) -> Path:
    """Render `world`'s plan (a running `pycram.sim.World` with an offscreen size of at least
    `VIEW_SIZE`) and write the ground truth beside `belief` (a
    `pycram.world.belief.BeliefState`) to `path` (PNG); returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Wedge

    from pycram.backends.sim.environment_builder import PLAN_CAMERA, plan_view

    env = world.environment
    width, height = VIEW_SIZE
    image = _render(world, PLAN_CAMERA, width, height)
    bare = _render(world, PLAN_CAMERA, width, height, hide_objects=True)  # no truth under the belief
    extent = plan_view(env)
    x0, y0, x1, y1 = extent
    fig, (truth_ax, belief_ax) = plt.subplots(1, 2, figsize=(20, 7.9), gridspec_kw={"wspace": 0.08})
    _plan_axes(truth_ax, image, extent, "what is (the simulator's ground truth)")
    truth_ax.set_ylabel("y [m]")
    _plan_axes(belief_ax, (bare * 0.55 + 114).astype("uint8"), extent, "what the robot believes (its perception)")

    def labels() -> _Labels:
        return _Labels(char_width=0.075 * (x1 - x0) / 8.0, line_height=0.16 * (y1 - y0) / 6.0)

    # ground truth
    truth_labels = labels()
    poses = world.item_poses.get_value()
    states = world.container_states.get_value()
    for item in world.scene.items:
        x, y, _ = poses[item.name].position
        placement = next((p for p in world.placements if p.name == item.name), None)
        inside = placement.container if placement is not None else None
        hidden = inside is not None and abs(states.get(inside, 0.0)) < 0.05
        radius = math.hypot(item.size[0], item.size[1]) if item.shape == "box" else item.size[0]
        truth_ax.add_patch(
            Circle((x, y), max(radius, 0.04), fill=False, lw=1.5, ls="--" if hidden else "-", edgecolor=_OBJECT_COLOR)
        )
        text = f"{item.type}" + (f" (in closed {inside})" if hidden else "")
        truth_ax.annotate(
            text,
            xy=(x, y),
            xytext=truth_labels.spot(x, y, text),
            ha="center",
            va="center",
            fontsize=9,
            color=_OBJECT_COLOR,
            bbox={**_BOX, "facecolor": "white"},
            arrowprops={"arrowstyle": "-", "color": _OBJECT_COLOR, "lw": 0.8},
        )
    _robot(truth_ax, world)
    # the belief: looks, then objects
    for look in belief.looks:
        heading = math.degrees(math.atan2(look.direction[1], look.direction[0]))
        half = math.degrees(math.atan(math.tan(math.radians(look.fovy) / 2) * 4 / 3))  # 4:3 images
        belief_ax.add_patch(
            Wedge(
                look.position[:2], look.max_range, heading - half, heading + half, alpha=0.08, color=_LOOK_COLOR, lw=0
            )
        )
    belief_labels = labels()
    rows = []
    for obj in belief.objects():
        if obj.pose is None:
            continue
        x, y, _ = obj.pose
        size = obj.properties.get("size") or (0.08, 0.08, 0.0)
        colour = obj.properties.get("color") or "grey"
        belief_ax.add_patch(
            Circle(
                (x, y),
                max(size[0], size[1], 0.08) / 2,
                lw=1.5,
                facecolor=_COLORS.get(colour, "#9e9e9e"),
                edgecolor="#212121",
                alpha=0.35 if obj.gone else 0.95,
                ls="--" if obj.gone else "-",
            )
        )
        if obj.gone:
            belief_ax.plot([x - 0.08, x + 0.08], [y - 0.08, y + 0.08], color="#b71c1c", lw=2)
            belief_ax.plot([x - 0.08, x + 0.08], [y + 0.08, y - 0.08], color="#b71c1c", lw=2)
        seen = obj.properties.get("last_seen")
        text = f"{obj.name}" + (" (gone)" if obj.gone else "")
        belief_ax.annotate(
            text,
            xy=(x, y),
            xytext=belief_labels.spot(x, y, text),
            ha="center",
            va="center",
            fontsize=9,
            color=_OBJECT_COLOR,
            bbox={**_BOX, "facecolor": "white"},
            arrowprops={"arrowstyle": "-", "color": _OBJECT_COLOR, "lw": 0.8},
        )
        where = obj.properties.get("on") or "?"
        inside = obj.properties.get("in")
        rows.append(
            f"{obj.name:<9} {colour:<6} {where}{' (in ' + inside + ')' if inside else ''}"
            f"  seen {seen:.1f} s{'  GONE' if obj.gone else ''}"
        )
    _robot(belief_ax, world)
    text = "believed objects\n" + ("\n".join(rows) if rows else "(none perceived)")
    belief_ax.text(
        x1 - 0.1,
        y0 + 0.1,
        text,
        ha="right",
        va="bottom",
        family="monospace",
        fontsize=8,
        color="#1a1a1a",
        bbox={**_BOX, "facecolor": "white", "alpha": 0.9},
    )
    belief_ax.text(
        x0 + 0.1,
        y1 - 0.1,
        f"blue wedges: the camera's {len(belief.looks)} looks\n"
        "disc: believed object, perceived colour and measured size\ncrossed: believed gone",
        ha="left",
        va="top",
        fontsize=8,
        color="#263238",
        bbox={**_BOX, "facecolor": "white"},
    )
    return _save(fig, path, title or f"{env.name}: belief and ground truth")


def look_around_and_draw(world: Any, robot_name: str, output: str | Path, title: str) -> tuple[Path, list[Any]]:
    """The robot ``robot_name`` of the simulated ``world`` looks around from where it stands; its
    belief is drawn beside the truth to ``output`` (:func:`write_belief_picture`). Returns the
    picture's path and the believed objects. The robot is shut down afterwards."""
    from pycram import robots
    from pycram.actions import look_around

    robot = robots.load(robot_name, world)
    try:
        with robot:
            look_around()
    finally:
        robot.shutdown()
    return write_belief_picture(world, robot.belief, output, title=title), list(robot.belief.objects())
