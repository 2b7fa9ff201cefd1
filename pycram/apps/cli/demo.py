"""`pycram demo`: the thesis demo or another scenario, headless, with pictures and the trace."""

from __future__ import annotations

import typer

from pycram.apps.cli.app import (
    DbOption,
    RobotOption,
    app,
    check_output_folder,
    fail,
    record_flag,
    trace_errors,
)
from pycram.apps.cli.view import LiveView, ViewHostOption, ViewOption, ViewPortOption, ViewWaitOption
from pycram.apps.run_options import check_until

#: `--steal` above this is refused: the plan gives up long before (it retries a few times).
_MAX_STEALS = 100


@app.command("demo")
def demo_command(
    robot: str = RobotOption,
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
    stepping: str | None = typer.Option(
        None,
        "--stepping",
        help="sim backend: 'lockstep' (the default: the simulation stands still while plan code runs, so the "
        "same seed gives the same run) or 'free' (it runs beside the plan as fast as it can, so what the plan "
        "computes costs simulated time: not reproducible).",
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
        "starting on an open surface; clear-table: everything on the table into the drawers and the cupboard; "
        "put-away: groceries from the counter into the fridge and the cupboard; serve: two requested objects "
        "to a seat at the table (the last three also in generated apartments: --env procedural:SEED).",
    ),
    env: str | None = typer.Option(
        None,
        "--env",
        help="The environment: apartment, thesis-kitchen, procedural:SEED (a generated apartment) or "
        "file:PATH.toml [default: the scenario's own]. A scenario written for one environment refuses others.",
    ),
    faults: str = typer.Option(
        "",
        "--faults",
        help="Comma-separated faults drawn from the seed: set-table: moved, taken, stuck, obstacle, missed; "
        "clear-table: moved, taken, stuck, missed; put-away: moved, taken, missed; serve: moved, taken, obstacle, "
        "missed.",
    ),
    verbose: bool = typer.Option(
        False,
        "--verbose",
        "-v",
        help="Tell a failure in full (every message and cause) instead of in two lines; `pycram show RUN` "
        "always has the whole of it.",
    ),
    until: float | None = typer.Option(
        None,
        "--until",
        metavar="T",
        help="Stop the run at simulated time T [s] (sim backend): write the scene and belief pictures and the "
        "task tree of that moment into the output folder (until-T.Ts), stop the plan there; exit code 0 "
        "once they are written (a plan that ends before T: its usual exit code).",
    ),
    view: bool = ViewOption,
    rrd: bool = typer.Option(
        True, "--rrd/--no-rrd", help="Save the run's view as run.rrd next to its pictures (`pycram view RUN`)."
    ),
    view_port: int = ViewPortOption,
    view_host: str = ViewHostOption,
    view_wait: bool | None = ViewWaitOption,
) -> None:
    """The thesis demo (fetch and place in the simulated kitchen, with recovery from failures),
    or another scenario (`--scenario set-table`: search, fetch and place a breakfast setting).

    Exit code: 0 on success (or, with --until, once the pictures of that moment are written);
    1 when the plan failed; 2 for bad options; 130 / 143 when stopped by SIGINT / SIGTERM.
    A recorded run can be run again with `pycram replay RUN`."""
    from pycram.apps.terminal import set_verbose

    set_verbose(verbose)
    try:
        check_until(until)
    except ValueError as error:
        fail(str(error), code=2)
    if until is not None and backend != "sim":
        fail("--until applies to --backend sim only", code=2)
    if output is not None:
        check_output_folder(output)
    from pycram.apps.experiments.scenarios import demo_scenario_names, get_scenario

    scenarios = ["thesis", *demo_scenario_names()]  # the thesis demo has options of its own
    if scenario not in scenarios:
        fail(f"--scenario: unknown scenario {scenario!r}; valid scenarios: {', '.join(scenarios)}", code=2)
    # the options every scenario's front end takes (the thesis demo has more of its own)
    common = dict(
        robot=robot,
        seed=seed,
        output=output,
        db=db,
        record=record_flag(record),
        quiet=quiet,
        animation=animation,
        stepping=stepping,
    )
    if until is not None:
        common["until"] = until
    environment = _environment_option(env, scenario)
    if environment is not None:
        common["environment"] = environment
    live = LiveView(
        view=view,
        rrd=rrd,
        port=view_port,
        host=view_host,
        wait=view_wait,
        output=output,
        name=f"pycram demo {scenario}",
    )
    if scenario != "thesis":
        with live:
            code = trace_errors(get_scenario(scenario).load_demo(), faults=faults, **common)
        raise typer.Exit(int(code or 0))
    if faults:
        fail("--faults applies to the household scenarios, not the thesis demo (it has --steal)", code=2)
    try:
        from pycram.apps.demos.kitchen import main as demo_main
    except ModuleNotFoundError as e:
        if e.name and e.name.startswith("pycram.apps.demos"):
            fail("the kitchen demo (pycram.apps.demos.kitchen) is not available in this installation")
        fail(f"the demo needs the 'sim' extra (pip install 'pycram[sim]'): {e}")
    with live:
        code = trace_errors(
            demo_main,
            item_at=item_at,
            steal=steal,
            realtime=realtime,
            interactive=interactive,
            backend=backend,
            **common,
        )
    raise typer.Exit(int(code or 0))


def _environment_option(env: str | None, scenario: str) -> str | None:
    """`pycram demo --env`: the environment to pass to the scenario's front end (None: its own);
    exits with code 2 for a name `load` does not read, or an environment the scenario is not
    written for when its front end takes no ``environment`` keyword."""
    if env is None:
        return None
    from pycram.apps.experiments.scenarios import accepts_keyword, get_scenario
    from pycram.environments import DEFAULT_ENVIRONMENT, check_name

    try:
        name = check_name(env)
    except KeyError as e:
        fail(f"--env: {str(e).strip(chr(34) + chr(39))}", code=2)
    own: str | None = DEFAULT_ENVIRONMENT  # the thesis demo's
    takes = False
    if scenario != "thesis":
        entry = get_scenario(scenario)
        own, takes = entry.environment, accepts_keyword(entry.load_demo(), "environment")
    if takes:
        return name
    if name != own:
        where = f"the {own} only" if own else "one environment"
        fail(f"--env: scenario {scenario} is written for {where} (it takes no other environment yet), not {name}", 2)
    return None
