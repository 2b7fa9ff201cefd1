"""A labelled picture of a simulated scene: a top-down plan beside the overview camera's view.

`write_scene_picture(world, path)` renders the world's orthographic plan camera and its overview
camera and labels, from the environment's description and the scene's placements: surfaces
(counters, table, cookers), containers (with the direction they open in, and a door's swing),
objects (those hidden inside a closed container drawn as dashed outlines), named places and the
robot. `pycram scene` writes it from the command line.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

#: Pixels of each rendered view (the plan camera's images are 4:3).
VIEW_SIZE = (1200, 900)
_BOX = {"boxstyle": "round,pad=0.25", "linewidth": 0.0, "alpha": 0.85}
_SURFACE_STYLE = {"fontsize": 10, "color": "#1a1a1a", "bbox": {**_BOX, "facecolor": "#fff8e1"}}
_CONTAINER_STYLE = {"fontsize": 10, "color": "white", "bbox": {**_BOX, "facecolor": "#5d4037"}}
_PLACE_STYLE = {"fontsize": 8, "color": "#37474f", "style": "italic"}
_OBJECT_COLOR = "#0d47a1"


def _hex(rgba: Any) -> tuple[float, float, float]:
    return (float(rgba[0]), float(rgba[1]), float(rgba[2]))


class _Labels:
    """Places object labels next to their objects without overlapping each other (greedy)."""

    OFFSETS = [
        (0.35, 0.25),
        (-0.35, 0.25),
        (0.35, -0.25),
        (-0.35, -0.25),
        (0.0, 0.4),
        (0.0, -0.4),
        (0.55, 0.0),
        (-0.55, 0.0),
        (0.5, 0.55),
        (-0.5, 0.55),
        (0.5, -0.55),
        (-0.5, -0.55),
    ]

    def __init__(self, char_width: float, line_height: float, unit: float = 1.0) -> None:
        """`char_width` and `line_height` of the text and `unit` (the length of 1 m of offset)
        in the units of the axes the labels go into."""
        self.char_width, self.line_height, self.unit = char_width, line_height, unit
        self.taken: list[tuple[float, float, float, float]] = []

    def spot(self, x: float, y: float, text: str) -> tuple[float, float]:
        pad = 0.03 * abs(self.unit)
        w, h = self.char_width * len(text) / 2 + pad, self.line_height / 2 + pad
        for dx, dy in self.OFFSETS:
            dx, dy = dx * self.unit, dy * self.unit
            cx, cy = x + dx + math.copysign(w, dx) * (abs(dx) > 0.3 * abs(self.unit)), y + dy
            box = (cx - w, cy - h, cx + w, cy + h)
            if not any(b[0] < box[2] and box[0] < b[2] and b[1] < box[3] and box[1] < b[3] for b in self.taken):
                self.taken.append(box)
                return cx, cy
        self.taken.append((x - w, y - h, x + w, y + h))
        return x + 0.35 * self.unit, y + 0.25 * self.unit


def _project(camera: Any, point: Any, width: int, height: int) -> tuple[float, float] | None:
    """Pixel (u, v) of a map point [m] in an image of the pinhole `camera` (None behind it)."""
    pos, target = np.asarray(camera.position, float), np.asarray(camera.target, float)
    forward = (target - pos) / np.linalg.norm(target - pos)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(point, float) - pos
    z = float(d @ forward)
    if z <= 0.05:
        return None
    f = (height / 2) / math.tan(math.radians(camera.fovy) / 2)
    return (width / 2 + f * float(d @ right) / z, height / 2 - f * float(d @ up) / z)


def write_scene_picture(world: Any, path: str | Path, title: str | None = None) -> Path:
    """Render `world` (a running `pycram.sim.World` built with an offscreen size of at least
    `VIEW_SIZE`) and write the labelled picture to `path` (PNG); returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Arc, Circle

    from pycram.backends.sim.environment_builder import PLAN_CAMERA, plan_view

    env = world.environment
    width, height = VIEW_SIZE
    plan_image = _render(world, PLAN_CAMERA, width, height)
    view_image = _render(world, env.camera.name, width, height)
    x0, y0, x1, y1 = plan_view(env)

    fig, (ax, view) = plt.subplots(1, 2, figsize=(20, 7.9), gridspec_kw={"wspace": 0.03})
    ax.imshow(plan_image, extent=(x0, x1, y0, y1), interpolation="bilinear")
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("plan (top-down)", fontsize=12)
    view.imshow(view_image)
    view.set_axis_off()
    view.set_title(f"overview camera '{env.camera.name}'", fontsize=12)

    # surfaces (cookers side by side get their labels above and below them in turn)
    for i, surface in enumerate(env.surfaces):
        cx, cy, cz = surface.centroid
        small = surface.kind == "cooker"
        style = {**_SURFACE_STYLE, "fontsize": 8 if small else 10}
        ax.text(
            cx, cy + ((0.22 if i % 2 else -0.22) if small else 0.0), surface.name, ha="center", va="center", **style
        )
        if not small:
            uv = _project(env.camera, (cx, cy, cz), width, height)
            if uv is not None:
                view.text(*uv, surface.name, ha="center", va="bottom", **{**style, "fontsize": 8})
    # containers: group those one above the other (a drawer cabinet) into one label
    groups: dict[tuple[float, float], list[Any]] = {}
    for c in env.containers:
        groups.setdefault((round(c.handle[0], 2), round(c.handle[1], 2)), []).append(c)
    for (hx, hy), members in groups.items():
        c = members[0]
        dx, dy = c.opening_direction
        ax.annotate(
            "",
            xy=(hx + 0.3 * dx, hy + 0.3 * dy),
            xytext=(hx, hy),
            arrowprops={"arrowstyle": "-|>", "color": "#5d4037", "lw": 2},
        )
        names = [m.name for m in sorted(members, key=lambda m: -m.handle[2])]  # the top one first
        label = "\n".join(names) if c.kind == "drawer" else f"{c.name} (door)"
        ax.text(
            hx + 0.38 * dx + 0.3 * abs(dy),
            hy + 0.38 * dy,
            label,
            ha="left" if dx >= 0 else "right",
            va="center",
            **{**_CONTAINER_STYLE, "fontsize": 9},
        )
        if c.kind == "door":
            _door_swing(ax, Arc, c)
        for m in members:
            uv = _project(env.camera, m.handle, width, height)
            if uv is not None:
                view.text(*uv, m.name, ha="left", va="center", **{**_CONTAINER_STYLE, "fontsize": 7})
    # named places (robot-independent base poses)
    for place in env.places:
        px, py, yaw = place.pose
        ax.annotate(
            "",
            xy=(px + 0.25 * math.cos(yaw), py + 0.25 * math.sin(yaw)),
            xytext=(px, py),
            arrowprops={"arrowstyle": "->", "color": "#455a64", "lw": 1.2},
        )
        ax.plot([px], [py], "o", ms=4, color="#455a64")
        ax.text(px + 0.08, py - 0.1, place.name, ha="left", va="top", **_PLACE_STYLE)
    # the robot
    base = world.base_pose.get_value()
    ax.text(
        base.x,
        base.y + 0.45,
        world.robot.upper(),
        ha="center",
        va="bottom",
        fontsize=10,
        fontweight="bold",
        color="#1b5e20",
    )
    # objects
    labels = _Labels(char_width=0.075 * (x1 - x0) / 8.0, line_height=0.16 * (y1 - y0) / 6.0)
    for box in ax.texts:  # keep object labels off the other labels
        bx, by = box.get_position()
        labels.taken.append((bx - 0.3, by - 0.1, bx + 0.3, by + 0.1))
    view_labels = _Labels(char_width=7.5, line_height=18.0, unit=-110.0)  # image rows grow downwards
    poses = world.item_poses.get_value()
    rows = []
    for item in world.scene.items:
        pose = poses[item.name]
        x, y, z = pose.position
        placement = next((p for p in world.placements if p.name == item.name), None)
        inside = placement.container if placement is not None else None
        where = placement.support if placement is not None else "—"
        radius = math.hypot(item.size[0], item.size[1]) if item.shape == "box" else item.size[0]
        ax.add_patch(
            Circle((x, y), max(radius, 0.04), fill=False, lw=1.5, ls="--" if inside else "-", edgecolor=_OBJECT_COLOR)
        )
        text = item.name + (f" (in {inside})" if inside else "")
        lx, ly = labels.spot(x, y, text)
        ax.annotate(
            text,
            xy=(x, y),
            xytext=(lx, ly),
            ha="center",
            va="center",
            fontsize=9,
            color=_OBJECT_COLOR,
            fontstyle="italic" if inside else "normal",
            bbox={**_BOX, "facecolor": "white"},
            arrowprops={"arrowstyle": "-", "color": _OBJECT_COLOR, "lw": 0.8},
        )
        uv = _project(env.camera, (x, y, z + item.half_height), width, height)
        if uv is not None and not inside:
            view.annotate(
                item.name,
                xy=uv,
                xytext=view_labels.spot(*uv, item.name),
                ha="center",
                va="center",
                fontsize=8,
                color=_OBJECT_COLOR,
                bbox={**_BOX, "facecolor": "white"},
                arrowprops={"arrowstyle": "-", "color": _OBJECT_COLOR},
            )
        rows.append(f"{item.name:<9} {item.type:<7} {where}" + (f"  (in {inside})" if inside else ""))
    if rows:
        view.text(
            12,
            height - 12,
            "objects\n" + "\n".join(rows),
            ha="left",
            va="bottom",
            family="monospace",
            fontsize=8.5,
            color="#1a1a1a",
            bbox={**_BOX, "facecolor": "white", "alpha": 0.9},
        )
    legend_w, legend_h = 0.6 * (x1 - x0), 0.07 * (y1 - y0)  # roughly, in [m] of the plan
    corners = [
        (x1 - 0.1, y0 + 0.1, "right", "bottom"),
        (x1 - 0.1, y1 - 0.1, "right", "top"),
        (x0 + 0.1, y0 + 0.1, "left", "bottom"),
        (x0 + 0.1, y1 - 0.1, "left", "top"),
    ]
    footprints = [b.footprint for b in env.static] + [c.body.footprint for c in env.containers]

    def free(corner: tuple) -> bool:
        cx, cy, ha, va = corner
        bx0, bx1 = (cx - legend_w, cx) if ha == "right" else (cx, cx + legend_w)
        by0, by1 = (cy, cy + legend_h) if va == "bottom" else (cy - legend_h, cy)
        return not any(f[0] < bx1 and bx0 < f[2] and f[1] < by1 and by0 < f[3] for f in footprints)

    lx, ly, ha, va = next((c for c in corners if free(c)), corners[0])
    ax.text(
        lx,
        ly,
        "solid circle: object in view   dashed: inside a closed container\n"
        "brown arrow: how a container opens   grey arrow: a named place (base pose)",
        ha=ha,
        va=va,
        fontsize=8,
        color="#263238",
        bbox={**_BOX, "facecolor": "white"},
    )
    return _save(fig, path, title or f"{env.name}: {env.title}")


def _save(fig: Any, path: str | Path, title: str) -> Path:
    """Give `fig` its title, write it to `path` (PNG) and close it; returns the path."""
    import matplotlib.pyplot as plt

    fig.suptitle(title, fontsize=14, y=0.95)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return path


def _door_swing(ax: Any, arc_type: Any, door: Any) -> None:
    """Draw a door's hinge and the arc its free edge sweeps (a floor plan's door symbol)."""
    hx, hy = door.hinge
    bx0, by0, bx1, by1 = door.body.footprint
    far = max(((bx0, by0), (bx1, by0), (bx0, by1), (bx1, by1)), key=lambda p: math.hypot(p[0] - hx, p[1] - hy))
    radius = math.hypot(far[0] - hx, far[1] - hy)
    closed = math.degrees(math.atan2(far[1] - hy, far[0] - hx))
    opened = closed + door.hinge_sign * 90.0
    ax.add_patch(
        arc_type(
            (hx, hy),
            2 * radius,
            2 * radius,
            theta1=min(closed, opened),
            theta2=max(closed, opened),
            ls="--",
            lw=1.2,
            color="#5d4037",
        )
    )
    ax.plot([hx], [hy], "s", ms=5, color="#5d4037")


def _render(world: Any, camera: str, width: int, height: int, hide_objects: bool = False) -> np.ndarray:
    outcome = world.request_image(camera, width, height, hide_objects).wait(60.0)
    if outcome is None or not outcome.succeeded:
        raise RuntimeError(f"rendering camera {camera!r} failed: {outcome}")
    return outcome.value


__all__ = ["write_scene_picture", "VIEW_SIZE"]
