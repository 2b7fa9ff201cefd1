"""Shared by the benchmarks: which environments exist and how to open a world in one.

The `--env` option of the benchmarks names an environment; the default is `apartment` when
this version of PyCRAM has it, else the thesis kitchen.
"""

from __future__ import annotations

import importlib.util
import inspect
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

KITCHEN = "thesis-kitchen"


def has_environment(name: str) -> bool:
    """Whether `pycram.environments.<name>` exists (environments as data, issue 13)."""
    module = name.replace("-", "_")
    try:
        return importlib.util.find_spec(f"pycram.environments.{module}") is not None
    except ModuleNotFoundError:
        return False


def default_environment() -> str:
    return "apartment" if has_environment("apartment") else KITCHEN


#: The objects of a scene in an environment without items of its own (a random scene, seed 3).
SCENE_OBJECTS = ("cup", "milk", "bowl", "cereal")


def open_world(robot: str, env: str):
    """A running `World` with `robot` in environment `env` (with a random breakfast scene,
    seed 3, where the environment has no items of its own)."""
    from pycram.sim import World

    if "environment" in inspect.signature(World).parameters:
        if env == KITCHEN:
            return World(robot, environment=env)
        return World(robot, environment=env, objects=list(SCENE_OBJECTS), seed=3)
    if env != KITCHEN:
        raise SystemExit(f"environment {env!r} is not available in this version; only {KITCHEN!r}")
    return World(robot)


def floor_planner(world):
    """The world's current `PathPlanner` (built in the simulation thread; pure afterwards)."""
    from pycram.backends.sim.path_drive import navigation_of

    out = world._call("planner", lambda eng: navigation_of(eng).planner(eng)[0]).wait(60)
    assert out is not None and out.succeeded, out
    return out.value


def free_poses(planner, rng, n: int) -> list[tuple[float, float, float]]:
    """`n` random base poses where the footprint fits, inside the environment's extent."""
    grid = planner.grid
    rows, cols = grid.occupied.nonzero()
    lo_x, hi_x = grid.origin[0] + cols.min() * grid.resolution, grid.origin[0] + (cols.max() + 1) * grid.resolution
    lo_y, hi_y = grid.origin[1] + rows.min() * grid.resolution, grid.origin[1] + (rows.max() + 1) * grid.resolution
    out: list[tuple[float, float, float]] = []
    while len(out) < n:
        p = (rng.uniform(lo_x, hi_x), rng.uniform(lo_y, hi_y), rng.uniform(-math.pi, math.pi))
        if planner.pose_free(*p):
            out.append(p)
    return out


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = (len(ordered) - 1) * q / 100.0
    f = math.floor(k)
    c = min(f + 1, len(ordered) - 1)
    return ordered[f] + (ordered[c] - ordered[f]) * (k - f)
