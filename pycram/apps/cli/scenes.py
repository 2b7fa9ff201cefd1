"""`pycram scene` and `pycram costmap`: labelled pictures of a scene, of what the robot
believes, and of a location designator's costmap."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from pycram.apps.cli.app import (
    RobotOption,
    app,
    console,
    fail,
)
from pycram.environments import ENVIRONMENT_HELP

#: The objects `pycram scene` places by default (a breakfast).
_SCENE_OBJECTS = "cup,bowl,spoon,cereal,milk,plate"
#: The scene options `pycram scene` and `pycram costmap` share.
_SceneEnvOption = typer.Option("apartment", "--env", help=f"Environment: {ENVIRONMENT_HELP}.")
_SceneSeedOption = typer.Option(0, "--seed", help="Random seed of the scene (same seed, same scene).")
_SceneObjectsOption = typer.Option(
    _SCENE_OBJECTS, "--objects", help="Comma-separated object types to place at random ('' for none)."
)
_SceneSupportsOption = typer.Option(
    "",
    "--supports",
    help="Comma-separated surface names the objects may start on, e.g. 'counter,table' ('': any surface or "
    "container inside that fits them).",
)


@app.command("scene")
def scene_command(
    env: str = _SceneEnvOption,
    seed: int = _SceneSeedOption,
    objects: str = _SceneObjectsOption,
    robot: str = RobotOption,
    supports: str = _SceneSupportsOption,
    output: Path = typer.Option(Path("scene.png"), "--output", "-o", help="PNG file to write."),
    costmap: str = typer.Option(
        "",
        "--costmap",
        help="Draw a location designator's costmap layers and chosen poses instead, "
        'e.g. "to_reach cup" or "on table, for bowl".',
    ),
    belief: bool = typer.Option(
        False, "--belief", help="Let the robot look around and draw its belief beside the ground truth."
    ),
) -> None:
    """A labelled picture of a scene: plan and overview with surfaces, containers and objects
    (with --belief: what the robot perceived from where it stands beside what is). With
    --supports the objects start only on the surfaces named (as `World(supports=...)`).

    With --costmap: the costmap layers of a location designator over the floor plan and the
    poses it chose (or why there are none)."""
    try:
        from pycram.apps.demos.scene_picture import VIEW_SIZE, write_scene_picture
        from pycram.backends.sim import World
    except ModuleNotFoundError as e:
        fail(f"`pycram scene` needs the 'sim' and 'db' extras (pip install 'pycram[all]'): {e}")
    from pycram.environments import KitchenFileError
    from pycram.world.scenes import PlacementError

    types = [t.strip() for t in objects.split(",") if t.strip()]
    try:
        world = World(
            robot,
            environment=env,
            seed=seed,
            objects=types or None,
            supports=[n.strip() for n in supports.split(",") if n.strip()] or None,
            offscreen_size=VIEW_SIZE,
            stepping="lockstep",
        )
    except (KeyError, PlacementError, KitchenFileError) as e:
        fail(str(e).strip("'\""))
    if costmap:
        _costmap_picture(world, robot, costmap, output, f"{env} · seed {seed} · {robot} · {costmap}")
        return
    try:
        if belief:
            path = _belief_picture(world, robot, output, title=f"{env} · seed {seed} · {robot}: belief")
        else:
            path = write_scene_picture(world, output, title=f"{env} · seed {seed} · {robot}")
        for p in world.placements:
            where = p.support + (f" (in {p.container})" if p.container else "")
            console.print(f"  {escape(p.name):<10} {escape(where)}")
    finally:
        world.close()
    console.print(f"wrote {escape(str(path))}")


def _costmap_picture(world: Any, robot_name: str, text: str, output: Path, title: str) -> None:
    """`pycram scene --costmap`: resolve the location `text` with the robot, draw its costmap."""
    from pycram.apps.demos.costmap_picture import draw_location_costmap, parse_location

    try:
        try:
            properties = parse_location(text)
        except ValueError as e:
            fail(str(e))
        drawn = draw_location_costmap(world, robot_name, properties, output, title=title)
    finally:
        world.close()
    for warning in drawn.not_found:
        console.print(f"[yellow]{escape(warning)}[/yellow]")
    for s in drawn.solutions:
        console.print(f"  {escape(repr(s))}")
    if drawn.error:
        console.print(f"[red]{escape(drawn.error)}[/red]")
    console.print(f"wrote {escape(str(drawn.path))}")


@app.command("costmap")
def costmap_command(
    location: str = typer.Argument(..., help='The location, e.g. "to_reach cup" or "on table, for bowl".'),
    env: str = _SceneEnvOption,
    seed: int = _SceneSeedOption,
    objects: str = _SceneObjectsOption,
    robot: str = RobotOption,
    output: Path = typer.Option(Path("costmap.png"), "--output", "-o", help="PNG file to write."),
) -> None:
    """The costmap layers of a location designator over the floor plan, and the poses it chose."""
    scene_command(
        env=env, seed=seed, objects=objects, robot=robot, supports="", output=output, costmap=location, belief=False
    )


def _belief_picture(world: Any, robot_name: str, output: Path, title: str) -> Path:
    """The robot looks around from where it stands; its belief is drawn beside the truth."""
    from pycram.apps.demos.belief_picture import look_around_and_draw

    path, believed = look_around_and_draw(world, robot_name, output, title=title)
    for obj in believed:
        console.print(f"  believed: {escape(repr(obj))}")
    return path
