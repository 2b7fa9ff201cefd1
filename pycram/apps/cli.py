"""The `pycram` command line (typer + rich).

    pycram run FILE.py [ARGS...]        run a plan script (block syntax on), recorded by default
    pycram demo [--robot pr2|tiago]...  the thesis demo in the simulated kitchen, recorded by default
    pycram scene --env apartment --seed 3 -o scene.png   a labelled picture of a random scene
    pycram runs                         recorded runs, newest first, one line each (with why they failed)
    pycram show [RUN]                   a run's task tree with statuses, durations, failures
    pycram graph [RUN] -o tree.svg      the task tree as an SVG picture
    pycram timeline [RUN] -o tl.png     which branches ran when (Gantt chart)
    pycram experiment --scenario thesis --robot pr2,tiago --seeds 1-200   many runs in parallel

The database is `--db URL`, else `$PYCRAM_DB_URL`, else the default SQLite file (see
`pycram.trace.db`); a database named with `--db` must exist for the inspecting commands, and
one that cannot be read gives a one-line error and exit code 1. Recording for `run`/`demo` is
on unless `--no-record` or `PYCRAM_RECORD=0`; records the database could not take are counted
and reported at the end of the run (the plan's outcome does not depend on them).
Heavy modules (SQLAlchemy, matplotlib, the simulator) are imported only by the commands that
need them.
"""

from __future__ import annotations

import datetime as _dt
import logging
import os
import signal
import sys
from pathlib import Path
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape

app = typer.Typer(
    name="pycram",
    help="PyCRAM: concurrent, reactive robot plans. Run plans and the kitchen demo; inspect recorded runs.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(highlight=False)
err = Console(stderr=True, highlight=False)


def _print_version(value: bool) -> None:
    if value:
        from pycram._version import __version__

        console.print(f"pycram {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    ctx: typer.Context,
    version: bool = typer.Option(
        False, "--version", help="Print PyCRAM's version and exit.", callback=_print_version, is_eager=True
    ),
) -> None:
    """PyCRAM: concurrent, reactive robot plans. Run plans and the kitchen demo; inspect recorded runs."""
    # `pycram run` leaves logging to the script (its basicConfig must not be a no-op); the
    # other commands show the library's warnings.
    if ctx.invoked_subcommand != "run":
        logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")


#: Runs of this many identical successful siblings are shown as one line / box / row (×N);
#: `pycram.trace.collapse.MIN_RUN`, not imported here to keep `pycram --help` light.
_COLLAPSE = 3

DbOption = typer.Option(
    None,
    "--db",
    help="SQLAlchemy URL of the trace database (default: $PYCRAM_DB_URL or ~/.local/share/pycram/runs.sqlite3).",
    metavar="URL",
)
RunArgument = typer.Argument(None, help="Run id (default: the newest run).", show_default=False)


def _fail(message: str, code: int = 1) -> None:
    err.print(f"[bold red]error:[/bold red] {escape(message)}", soft_wrap=True)
    raise typer.Exit(code)


def _trace_errors(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Call fn, turning database and lookup errors into a clear message and exit code 1."""
    try:
        from pycram.trace.db import TraceDatabaseError
    except ImportError as e:  # the db extra is missing
        _fail(f"run traces need the 'db' extra (pip install 'pycram[db]'): {e}")
    from pycram.trace.query import RunNotFound

    try:
        return fn(*args, **kwargs)
    except (TraceDatabaseError, RunNotFound) as e:
        _fail(str(e))


def _reading(db: str | None, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """`_trace_errors` for the inspecting commands: a database named with `--db` must exist
    (reading never creates one), and any database failure is a one-line error."""
    from sqlalchemy import exc as sa_exc

    from pycram.trace.db import database_error, resolve_url, sqlite_file

    if db is not None and db.strip():
        _trace_errors(resolve_url, db)  # a malformed URL is reported as such
        path = sqlite_file(db)
        if path is not None and not path.exists():
            where = f"the folder {path.parent} does not exist" if not path.parent.is_dir() else f"{path} does not exist"
            _fail(f"no such database: {where} (`pycram run` and `pycram demo` create it when they record)")
    try:
        return _trace_errors(fn, *args, **kwargs)
    except sa_exc.SQLAlchemyError as e:  # a failure no query layer translated
        _fail(str(database_error(resolve_url(db), e, "read")))


def _write_errors(fn: Any, *args: Any) -> Any:
    """`fn(*args)` writing a picture: an unwritable output path is a one-line error."""
    try:
        return fn(*args)
    except OSError as e:
        _fail(f"cannot write {e.filename or 'the picture'}: {e.strerror or e}")


def _local(when: _dt.datetime | None) -> str:
    return when.astimezone().strftime("%Y-%m-%d %H:%M:%S") if when is not None else "–"


def _record_flag(record: bool | None) -> bool:
    if record is not None:
        return record
    from pycram.trace.recorder import recording_enabled

    return recording_enabled(True)


# -- inspecting runs ------------------------------------------------------------------------------


@app.command("runs")
def runs_command(
    limit: int = typer.Option(20, "--limit", "-n", help="Show at most this many runs (0: all)."),
    plan: str | None = typer.Option(None, "--plan", help="Only runs whose plan name contains this."),
    db: str | None = DbOption,
) -> None:
    """List recorded runs, newest first: id, start, plan, robot, outcome, wall-clock duration
    and why a run failed."""
    from rich.table import Table

    from pycram.trace import query
    from pycram.trace.display import STATUS_STYLE, format_duration

    found = _reading(db, query.runs, db, limit or None, plan)
    if not found:
        err.print("no runs recorded yet (run `pycram run FILE.py` or `pycram demo`)")
        return
    table = Table(box=None, pad_edge=False, header_style="bold")
    for name in ("id", "started", "plan", "robot", "outcome"):
        table.add_column(name, no_wrap=name != "plan")
    table.add_column("took", no_wrap=True, justify="right")
    table.add_column("reason", overflow="fold")
    for run in found:
        state = run.state
        style = STATUS_STYLE.get(state, "white")
        table.add_row(
            str(run.id),
            _local(run.started_at),
            escape(run.plan or "–"),
            escape(run.robot or "–"),
            f"[{style}]{state}[/{style}]",
            format_duration(run.elapsed),
            escape(_reason(run)),
        )
    console.print(table)


def _reason(run: Any) -> str:
    """Why the run did not succeed (its recorded error), "" for a successful run."""
    if run.error:
        return run.error
    if run.state == "unfinished":
        return "the process ended without finishing the record (killed?)"
    return ""


@app.command("show")
def show_command(
    run: int | None = RunArgument,
    max_nodes: int = typer.Option(2000, "--max-nodes", help="Stop printing after this many tree lines."),
    expand: bool = typer.Option(
        False,
        "--expand",
        help="One line per task: do not collapse runs of identical successful siblings into one line (×N).",
    ),
    db: str | None = DbOption,
) -> None:
    """Print a run's task tree with statuses, durations and failures.

    Every process-module execution is shown (a blocking one under the task that performed it).
    A failure shows its error where it was raised; enclosing tasks it failed say "passed on".
    Tree times are on the plan's clock (the header says: simulated or wall clock); the run's
    duration and start are wall-clock. Runs of 3 or more consecutive identical successful
    sibling tasks (e.g. a motion repeated by a `whenever` loop) are shown as one line with a
    count, unless --expand.
    """
    from pycram.trace import query
    from pycram.trace.display import STATUS_STYLE, clock_label, format_duration, task_tree

    info = _reading(db, query.get_run, run, db)
    records, execution_records = _reading(db, query.tree_records, info.id, db)
    executions = _reading(db, query.executions, info.id, url=db)
    state = info.state
    style = STATUS_STYLE.get(state, "white")
    title = (
        f"run {info.id}: {escape(info.plan or '–')} · robot {escape(info.robot or '–')} · "
        f"[{style}]{state}[/{style}] · took {format_duration(info.elapsed)} (wall-clock) · "
        f"started {_local(info.started_at)}\n[grey50]times in the tree: {escape(clock_label(info.clock))}[/grey50]"
    )
    shown_records = records + execution_records
    tree, shown = task_tree(title, shown_records, expand=expand, max_nodes=max_nodes)
    console.print(tree)
    failed = [r for r in records if r.status == "failed"]
    raised = sum(1 for r in failed if not r.propagated)
    summary = f"{len(records)} tasks, {len(failed)} failed"
    if raised < len(failed):
        summary += f" ({raised} where the error was raised, {len(failed) - raised} passing it on)"
    if executions:
        summary += f", {len(executions)} process-module executions"
    if shown < len(shown_records):
        summary += f" ({len(shown_records) - shown} not shown; raise --max-nodes)"
    console.print(summary)
    if info.error:
        console.print(f"[red]{escape(info.error)}[/red]")
    if info.lost_records:
        console.print(
            f"[yellow]{info.lost_records} trace records of this run could not be written: "
            "the tree may be incomplete[/yellow]"
        )


@app.command("graph")
def graph_command(
    run: int | None = RunArgument,
    output: Path = typer.Option(Path("task-tree.svg"), "--output", "-o", help="SVG file to write."),
    expand: bool = typer.Option(False, "--expand", help="One box per task (do not collapse identical siblings)."),
    db: str | None = DbOption,
) -> None:
    """Draw a run's task tree as an SVG picture (identical successful siblings: one box ×N)."""
    from pycram.trace.pictures import write_tree_svg

    path = _reading(db, _write_errors, write_tree_svg, run, output, db, 0 if expand else _COLLAPSE)
    console.print(f"wrote {path}")


@app.command("timeline")
def timeline_command(
    run: int | None = RunArgument,
    output: Path = typer.Option(Path("timeline.png"), "--output", "-o", help="PNG file to write."),
    max_rows: int = typer.Option(200, "--max-rows", help="At most this many task rows (deeper tasks are left out)."),
    expand: bool = typer.Option(
        False, "--expand", help="One row per task (do not share rows between identical siblings)."
    ),
    db: str | None = DbOption,
) -> None:
    """Draw which branches ran when (a Gantt chart, one row per task; identical successful
    siblings share a row) as a PNG picture."""
    from pycram.trace.pictures import write_timeline_png

    path = _reading(db, _write_errors, write_timeline_png, run, output, db, max_rows, 0 if expand else _COLLAPSE)
    console.print(f"wrote {path}")


# -- running plans --------------------------------------------------------------------------------


@app.command("run", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def run_command(
    ctx: typer.Context,
    file: Path = typer.Argument(
        ..., help="Plan script to run (block syntax is switched on).", exists=True, dir_okay=False
    ),
    record: bool | None = typer.Option(
        None, "--record/--no-record", help="Record the run in the trace database [default: on, or $PYCRAM_RECORD]."
    ),
    db: str | None = DbOption,
    plan: str | None = typer.Option(None, "--plan", help="Plan name recorded for the run (default: the file name)."),
    robot: str | None = typer.Option(None, "--robot", help="Robot name recorded for the run."),
) -> None:
    """Run a plan script; arguments after FILE go to the script (in sys.argv).

    The script owns logging (`logging.basicConfig` in it works as under `python FILE.py`);
    an exception it raises is reported with a traceback that starts at the script's code, and
    the exit code is 1. SIGINT (Ctrl-C) and SIGTERM stop the script so that its clean-up runs
    (in plain Python code as a KeyboardInterrupt, inside PyCRAM by evaporating the script's
    tasks): the run is recorded as "interrupted" with the reason, the exit code is 130 / 143; a
    second signal while stopping exits at once.
    """
    from pycram.core.interrupts import StopSignals
    from pycram.core.macros import format_script_error, run_script
    from pycram.core.runtime import end_thread_root

    recorder = None
    if _record_flag(record):
        from pycram.trace.recorder import Recorder

        recorder = _trace_errors(
            lambda: Recorder(
                db, plan=plan or file.name, robot=robot, command=" ".join(["pycram run", str(file), *ctx.args])
            ).start()
        )
    error: BaseException | str | None  # what the trace records as the run's error
    outcome, error, code = "succeeded", None, 0
    ended: BaseException | None = None  # what ended the main thread's root task
    with StopSignals(stop_main=True) as stop:
        try:
            run_script(file, list(ctx.args))
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
            outcome = "succeeded" if code == 0 else "failed"
            error = None if code == 0 else f"SystemExit: {e.code}"
            ended = None if code == 0 else e
        except BaseException as e:
            if not (stop.requested or isinstance(e, KeyboardInterrupt)):
                outcome, error, code, ended = "failed", e, 1, e
                if not isinstance(e, Exception):
                    raise
                sys.stderr.write(format_script_error(e, file))  # as `python FILE` would print it
            else:
                # SIGINT / SIGTERM (as `Interrupted`, or as `Evaporated` of the script's tasks), or a
                # KeyboardInterrupt raised by the script itself
                stop.request(getattr(e, "signum", signal.SIGINT))
                outcome, error, code, ended = "interrupted", stop.reason, stop.exit_code, e
                err.print(f"[bold yellow]pycram run:[/bold yellow] {stop.reason}; the script was stopped")
        finally:
            end_thread_root(ended)
            if recorder is not None:
                _robot_from_active(recorder)
                run_id = recorder.finish(outcome, error)
                err.print(f"recorded as run {run_id} ({outcome}); see `pycram show {run_id}`")
                if recorder.lost_records:
                    err.print(
                        f"[yellow]trace of run {run_id} incomplete: {escape(recorder.loss_report())}[/yellow]",
                        soft_wrap=True,
                    )
    raise typer.Exit(code)


def _robot_from_active(recorder: Any) -> None:
    if recorder.robot is not None:
        return
    try:
        from pycram.execution.robot import current_robot

        robot = current_robot()
    except Exception:
        return
    if robot is not None:
        recorder.set_run_info(robot=str(getattr(robot, "name", robot)))


#: `--steal` above this is refused: the plan gives up long before (it retries a few times).
_MAX_STEALS = 100


def _check_output_folder(output: str) -> None:
    """Refuse (exit code 2, one line) an `--output` folder that cannot be created or written.

    Creates nothing: the folder must be a writable directory, or its nearest existing ancestor
    must be one (the demo creates the rest).
    """
    import os

    path = Path(output).expanduser()
    existing = path
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing == path and not path.is_dir():
        _fail(f"--output {output}: exists and is not a folder", code=2)
    if not existing.is_dir():
        _fail(f"--output {output}: cannot create the folder, {existing} is not a folder", code=2)
    if not os.access(existing, os.W_OK | os.X_OK):
        _fail(f"--output {output}: cannot write to {existing} (permission denied)", code=2)


@app.command("demo")
def demo_command(
    robot: str = typer.Option("pr2", "--robot", help="Robot: pr2 or tiago."),
    output: str | None = typer.Option(
        None,
        "--output",
        "-o",
        help="Folder for pictures (default: the run's "
        "own, output/demo-ROBOT-RUNID, or output/demo-ROBOT-DATE-TIME when not recorded).",
    ),
    item_at: int = typer.Option(
        1, "--item-at", min=0, max=3, help="Where the item starts: position 1, 2 or 3 (0: no item)."
    ),
    steal: int = typer.Option(
        0,
        "--steal",
        min=0,
        max=_MAX_STEALS,
        help="How many times the item is taken from the gripper while the robot carries it.",
    ),
    seed: int = typer.Option(0, "--seed", min=0, help="Random seed (a non-negative integer)."),
    realtime: bool = typer.Option(False, "--realtime", help="Run at real-time speed instead of as fast as possible."),
    interactive: bool = typer.Option(False, "--interactive", help="Ask the operator in the terminal."),
    record: bool | None = typer.Option(
        None, "--record/--no-record", help="Record the run in the trace database [default: on, or $PYCRAM_RECORD]."
    ),
    db: str | None = DbOption,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No live progress line."),
    animation: bool = typer.Option(
        True, "--animation/--no-animation", help="Record the animation run.gif (--no-animation: a faster run)."
    ),
    backend: str = typer.Option(
        "sim",
        "--backend",
        help="sim: process modules drive the simulator in-process; ros: over ROS 1 "
        "(starts roscore and sim-ros-bridge on 127.0.0.1 unless ROS_MASTER_URI is set).",
    ),
    scenario: str = typer.Option(
        "thesis",
        "--scenario",
        help="thesis: fetch and place in the thesis kitchen; set-table: set the table for breakfast in the "
        "apartment (objects on counters and in a closed drawer); set-table-open: the same, every object "
        "starting on an open surface.",
    ),
    faults: str = typer.Option(
        "",
        "--faults",
        help="set-table only: comma-separated faults drawn from the seed: moved, taken, stuck, obstacle, missed.",
    ),
) -> None:
    """The thesis demo (fetch and place in the simulated kitchen, with recovery from failures),
    or another scenario (`--scenario set-table`: search, fetch and place a breakfast setting)."""
    if output is not None:
        _check_output_folder(output)
    scenarios = ("thesis", "set-table", "set-table-open")  # pycram.apps.demos.set_table.SCENARIOS (imported lazily)
    if scenario not in scenarios:
        _fail(f"--scenario: unknown scenario {scenario!r}; valid scenarios: {', '.join(scenarios)}", code=2)
    if scenario.startswith("set-table"):
        from pycram.apps.demos.set_table import main as set_table_main

        code = _trace_errors(
            set_table_main,
            robot=robot,
            seed=seed,
            faults=faults,
            output=output,
            db=db,
            record=_record_flag(record),
            quiet=quiet,
            animation=animation,
            in_containers=scenario != "set-table-open",
        )
        raise typer.Exit(int(code or 0))
    if faults:
        _fail("--faults applies to --scenario set-table only (the thesis demo has --steal)", code=2)
    try:
        from pycram.apps.demos.kitchen import main as demo_main
    except ModuleNotFoundError as e:
        if e.name and e.name.startswith("pycram.apps.demos"):
            _fail("the kitchen demo (pycram.apps.demos.kitchen) is not available in this installation")
        _fail(f"the demo needs the 'sim' extra (pip install 'pycram[sim]'): {e}")
    code = _trace_errors(
        demo_main,
        robot=robot,
        output=output,
        item_at=item_at,
        steal=steal,
        seed=seed,
        realtime=realtime,
        interactive=interactive,
        db=db,
        record=_record_flag(record),
        quiet=quiet,
        animation=animation,
        backend=backend,
    )
    raise typer.Exit(int(code or 0))


#: The objects `pycram scene` places by default (a breakfast).
_SCENE_OBJECTS = "cup,bowl,spoon,cereal,milk,plate"
#: The scene options `pycram scene` and `pycram costmap` share.
_SceneEnvOption = typer.Option("apartment", "--env", help="Environment: apartment or thesis-kitchen.")
_SceneSeedOption = typer.Option(0, "--seed", help="Random seed of the scene (same seed, same scene).")
_SceneObjectsOption = typer.Option(
    _SCENE_OBJECTS, "--objects", help="Comma-separated object types to place at random ('' for none)."
)
_SceneRobotOption = typer.Option("pr2", "--robot", help="Robot: pr2 or tiago.")


@app.command("scene")
def scene_command(
    env: str = _SceneEnvOption,
    seed: int = _SceneSeedOption,
    objects: str = _SceneObjectsOption,
    robot: str = _SceneRobotOption,
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
    (with --belief: what the robot perceived from where it stands beside what is).

    With --costmap: the costmap layers of a location designator over the floor plan and the
    poses it chose (or why there are none)."""
    try:
        from pycram.apps.demos.scene_picture import VIEW_SIZE, write_scene_picture
        from pycram.backends.sim import World
    except ModuleNotFoundError as e:
        _fail(f"`pycram scene` needs the 'sim' and 'db' extras (pip install 'pycram[all]'): {e}")
    from pycram.world.scenes import PlacementError

    types = [t.strip() for t in objects.split(",") if t.strip()]
    try:
        world = World(robot, environment=env, seed=seed, objects=types or None, offscreen_size=VIEW_SIZE)
    except (KeyError, PlacementError) as e:
        _fail(str(e).strip("'\""))
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


def _perceive_named_objects(robot: Any, properties: list) -> None:
    """Reasoning knows objects only once perceived: the robot looks around from where it stands,
    then searches for each object type the location names that it has not seen yet."""
    from pycram.actions import ObjectNotFound, look_around, search_for
    from pycram.designators.object import ObjectDesignator
    from pycram.world.objects import OBJECT_TYPES

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
                    console.print(f"[yellow]{escape(str(e))}[/yellow]")


def _costmap_picture(world: object, robot_name: str, text: str, output: Path, title: str) -> None:
    """`pycram scene --costmap`: resolve the location `text` with the robot, draw its costmap."""
    from pycram import robots
    from pycram.apps.demos.costmap_picture import parse_location, write_costmap_picture

    try:
        try:
            properties = parse_location(text)
        except ValueError as e:
            _fail(str(e))
        robot = robots.load(robot_name, world)
        up = robot.description.TORSO_POSITIONS["up"]
        world.set_torso(up).wait(30.0)  # type: ignore[attr-defined]  # as plans do before reaching
        try:
            _perceive_named_objects(robot, properties)
            path, solutions, error = write_costmap_picture(world, robot, properties, output, title=title)
        finally:
            robot.shutdown()
    finally:
        world.close()  # type: ignore[attr-defined]
    for s in solutions:
        console.print(f"  {escape(repr(s))}")
    if error:
        console.print(f"[red]{escape(error)}[/red]")
    console.print(f"wrote {escape(str(path))}")


@app.command("costmap")
def costmap_command(
    location: str = typer.Argument(..., help='The location, e.g. "to_reach cup" or "on table, for bowl".'),
    env: str = _SceneEnvOption,
    seed: int = _SceneSeedOption,
    objects: str = _SceneObjectsOption,
    robot: str = _SceneRobotOption,
    output: Path = typer.Option(Path("costmap.png"), "--output", "-o", help="PNG file to write."),
) -> None:
    """The costmap layers of a location designator over the floor plan, and the poses it chose."""
    scene_command(env=env, seed=seed, objects=objects, robot=robot, output=output, costmap=location, belief=False)


@app.command("sim-ros-bridge")
def sim_ros_bridge_command(
    robot: str = typer.Option("pr2", "--robot", help="Robot: pr2 or tiago."),
    item_at: int = typer.Option(
        1, "--item-at", min=0, max=3, help="Where the demo's mug starts: position 1, 2 or 3 (0: no item)."
    ),
    realtime: bool = typer.Option(
        False,
        "--realtime",
        help="Simulate at real-time speed (default: as fast as possible; /clock carries the simulation time).",
    ),
    publish_rate: float = typer.Option(50.0, "--publish-rate", min=1.0, help="Sensor topics per second [Hz, wall]."),
    host: str = typer.Option(
        "127.0.0.1",
        "--host",
        help="Address the node binds to and advertises (ROS_IP). "
        "Loopback by default: nothing outside this machine can command the robot.",
    ),
    allow_remote_master: bool = typer.Option(
        False, "--allow-remote-master", help="Accept a ROS_MASTER_URI that is not on loopback."
    ),
    pose_noise: float = typer.Option(
        0.0, "--pose-noise", min=0.0, help="Perception fault: std. dev. of the noise on measured centres [m]."
    ),
    miss_probability: float = typer.Option(
        0.0, "--miss-probability", min=0.0, max=1.0, help="Perception fault: probability that a seen object is missed."
    ),
    wrong_color_probability: float = typer.Option(
        0.0, "--wrong-color-probability", min=0.0, max=1.0, help="Perception fault: probability of a wrong colour."
    ),
    perception_seed: int = typer.Option(0, "--perception-seed", help="Seed of the perception faults."),
) -> None:
    """Serve the simulated robot over ROS 1 (move_base, PointHead, arm/torso trajectories, grippers,
    /amcl_pose, /joint_states, /clock, the head camera's detections), as a real robot's drivers
    would. Needs ROS_MASTER_URI."""
    if robot not in ("pr2", "tiago"):
        _fail(f"--robot must be 'pr2' or 'tiago', not {robot!r}", code=2)
    try:
        from pycram.backends.ros.launch import check_master_uri
    except ImportError as e:
        _fail(f"sim-ros-bridge needs ROS 1 (run scripts/install_ros.sh): {e}")
    try:
        check_master_uri(os.environ.get("ROS_MASTER_URI"), allow_remote=allow_remote_master)
    except ValueError as e:
        _fail(str(e), code=2)
    os.environ["ROS_IP"] = os.environ["ROS_HOSTNAME"] = host
    os.environ.setdefault("MUJOCO_GL", "egl")
    from pycram.backends.sim.perception import PerceptionFaults
    from pycram.backends.sim.ros_bridge import run_bridge

    run_bridge(
        robot,
        item_at=item_at,
        realtime=realtime,
        publish_rate=publish_rate,
        perception_faults=PerceptionFaults(pose_noise, miss_probability, wrong_color_probability, perception_seed),
        ready=lambda: print(f"sim-ros-bridge ready: {robot} on {os.environ['ROS_MASTER_URI']}", flush=True),
    )


def _belief_picture(world: Any, robot_name: str, output: Path, title: str) -> Path:
    """The robot looks around from where it stands; its belief is drawn beside the truth."""
    from pycram import robots
    from pycram.actions import look_around
    from pycram.apps.demos.belief_picture import write_belief_picture

    robot = robots.load(robot_name, world)
    try:
        with robot:
            look_around()
    finally:
        robot.shutdown()
    for obj in robot.belief.objects():
        console.print(f"  believed: {escape(repr(obj))}")
    return write_belief_picture(world, robot.belief, output, title=title)


# -- experiments ----------------------------------------------------------------------------------


@app.command("experiment")
def experiment_command(
    scenario: str | None = typer.Option(
        None,
        "--scenario",
        help="Scenario: thesis (default), set-table, set-table-open, or an import path package.module:function.",
    ),
    robot: str | None = typer.Option(None, "--robot", help="Robots, comma-separated: pr2,tiago [default: pr2]."),
    seeds: str | None = typer.Option(None, "--seeds", help="Seeds: a range 1-200, a list 1,5,9 or both (1,5,10-20)."),
    faults: list[str] | None = typer.Option(
        None,
        "--faults",
        help="A variant: comma-separated faults ('none': no faults, 'all': every fault of the scenario). "
        "Repeat for several variants, e.g. --faults none --faults all [default: none].",
    ),
    workers: int = typer.Option(2, "--workers", "-j", help="Worker processes (with --ray local: Ray's CPUs)."),
    ray: str | None = typer.Option(
        None,
        "--ray",
        help="Run on Ray: a cluster address (auto, HOST:PORT, ray://HOST:10001) or 'local' to start one here.",
        metavar="ADDRESS",
    ),
    name: str | None = typer.Option(
        None, "--name", help="Name of the experiment (default: SCENARIO-DATE-TIME); an existing name resumes it."
    ),
    resume: str | None = typer.Option(
        None,
        "--resume",
        help="Resume the experiment with this id or name: run only the seeds not finished.",
        metavar="ID",
    ),
    output: Path | None = typer.Option(
        None, "--output", "-o", help="Folder for the plot and summary (default: output/experiment-NAME)."
    ),
    db: str | None = DbOption,
) -> None:
    """Run a scenario over many robots, seeds and faults in parallel; report success and times.

    Each run is headless and recorded in the trace database; at the end a table shows the
    success rate per robot and variant, the failure causes and the simulated and wall time
    (p50/p95), and a plot is written.

    Ctrl-C stops it: the runs under way finish and are recorded (a second Ctrl-C exits at once);
    `--resume ID` runs the rest. Exit code 0 when every run is recorded, 130 when stopped, 1 when
    runs were lost (a worker died) or raised an error (a resume runs them again), 2 for bad options.
    """
    import contextlib

    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        from pycram.apps.experiments.runner import ExperimentInputError, RayUnavailable, prepare_experiment, ray_session
    except ImportError as e:
        _fail(f"experiments need the 'db' extra (pip install 'pycram[all]'): {e}")
    if workers < 1:
        _fail(f"--workers must be at least 1, not {workers}", code=2)
    if output is not None:
        _check_output_folder(str(output))
    options = dict(scenario=scenario, robots=robot, seeds=seeds, faults=faults, name=name, resume=resume, db=db)
    with contextlib.ExitStack() as session:
        try:
            if ray is not None:  # check the input, then connect (before an experiment is created)
                _trace_errors(prepare_experiment, check_only=True, **options)
                session.enter_context(ray_session(ray, workers))
            prepared = _trace_errors(prepare_experiment, command=" ".join(["pycram", *sys.argv[1:]]), **options)
        except ExperimentInputError as e:
            _fail(str(e), code=2)
        except RayUnavailable as e:
            _fail(str(e))
        _run_experiment(prepared, workers, ray, output, db)


def _run_experiment(prepared: Any, workers: int, ray: str | None, output: Path | None, db: str | None) -> None:
    """`pycram experiment` once its input is checked: run with a progress bar, then report."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from pycram.apps.experiments import report, store
    from pycram.apps.experiments.runner import ExperimentInputError, RayUnavailable, run_experiment
    from pycram.core.interrupts import StopSignals

    record = prepared.record
    where = f"Ray ({ray})" if ray else f"{workers} worker processes"
    total = len(record.keys())
    verb = "resuming" if prepared.resumed else "experiment"
    err.print(
        f"{verb} {record.id} ({escape(record.name)}): scenario {escape(record.scenario)}, "
        f"robots {escape(','.join(record.robots))}, {len(record.seeds)} seeds, "
        f"{len(record.variants)} variant(s): {total} runs, {prepared.done_before} recorded before, "
        f"{len(prepared.todo)} to run on {where}"
    )
    counts = {"ok": 0, "failed": 0}
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=err,
        transient=False,
    ) as bar:
        job = bar.add_task("runs", total=len(prepared.todo))

        def progress(key: tuple[str, int, str], result: dict[str, Any] | None) -> None:
            if result is not None:
                counts["ok" if result.get("success") else "failed"] += 1
            bar.update(
                job,
                advance=1 if result is not None else 0,
                description=f"succeeded {counts['ok']}, failed {counts['failed']} · last: {key[0]} seed {key[1]}",
            )

        with StopSignals() as stop:
            try:
                outcome = _trace_errors(
                    run_experiment, prepared, workers=workers, ray=ray, stop=stop, progress=progress
                )
            except RayUnavailable as e:
                _fail(str(e))
            except ExperimentInputError as e:
                _fail(str(e), code=2)
    runs = _trace_errors(store.run_records, db, record.id)
    groups = report.summarize(runs)
    title = f"experiment {record.id} ({record.name}): {record.scenario}, {len(runs)} of {total} runs"
    console.print(report.summary_table(groups, title=escape(title)))
    console.print(report.causes_table(groups))
    folder = output if output is not None else Path("output") / f"experiment-{record.name}"
    if groups:
        plot = _write_errors(report.write_plot, groups, folder / "experiment.png", title)
        console.print(f"wrote {escape(str(plot))}")
    console.print(
        f"{outcome.recorded} runs in {outcome.wall_time:.1f} s "
        f"({60.0 * outcome.recorded / outcome.wall_time if outcome.wall_time > 0 else 0.0:.1f} runs/min); "
        f"see `pycram runs` for their traces"
        + ("" if outcome.traced else " (not traced: SQLite is not reachable from the Ray workers)")
    )
    if outcome.errors:
        err.print(f"[red]{len(outcome.errors)} runs were lost:[/red] " + escape("; ".join(outcome.errors[:5])))
    raised = [r for r in runs if r.status == "error"]
    if raised:
        err.print(
            f"[red]{len(raised)} runs raised an error[/red] (e.g. {escape(raised[0].robot)} seed {raised[0].seed}: "
            f"{escape(raised[0].error or '')}); `pycram experiment --resume {record.id}` runs them again"
        )
    left = total - len(runs)
    if outcome.interrupted or left:
        err.print(
            f"[yellow]{'stopped: ' if outcome.interrupted else ''}{left} runs not finished; "
            f"resume with `pycram experiment --resume {record.id}`[/yellow]"
        )
        raise typer.Exit(stop.exit_code if outcome.interrupted and stop.signum else 1)
    raise typer.Exit(1 if raised or outcome.errors else 0)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `pycram` script. Returns the exit code (also when typer exits)."""
    try:
        app(args=argv, prog_name="pycram", standalone_mode=True)
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
