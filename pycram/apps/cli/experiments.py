"""`pycram experiment`: many runs of a scenario, in parallel, with a report."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from pycram.apps.cli.app import (
    DbOption,
    LiveHelpOption,
    app,
    check_output_folder,
    console,
    err,
    fail,
    trace_errors,
    write_errors,
)
from pycram.apps.cli.view import ExperimentView, ViewHostOption, ViewPortOption, ViewWaitOption
from pycram.world.robot_registry import DEFAULT_ROBOT, robot_names


def _robots_help() -> str:
    """The help text of `experiment --robot`: the robots registered now."""
    return f"Robots, comma-separated (registered: {', '.join(robot_names())}; default: {DEFAULT_ROBOT})."


#: `experiment --robot`: its help lists the robots registered when the command runs (the runner
#: checks the names, exit code 2 for an unknown one).
_RobotsOption: Any = LiveHelpOption(_robots_help, default=None, param_decls=("--robot",))


@app.command("experiment")
def experiment_command(
    scenario: str | None = typer.Option(
        None,
        "--scenario",
        help="Scenario: thesis (default), set-table, set-table-open, clear-table, put-away, serve, or an import "
        "path package.module:function.",
    ),
    robot: str | None = _RobotsOption,
    seeds: str | None = typer.Option(None, "--seeds", help="Seeds: a range 1-200, a list 1,5,9 or both (1,5,10-20)."),
    env: str | None = typer.Option(
        None,
        "--env",
        help="Environments, comma-separated, each run in each: apartment, procedural:1-50 (generated apartments; "
        "ranges and lists of seeds as for --seeds), file:PATH.toml [default: the scenario's own]. Only scenarios "
        "that take an 'environment' keyword run outside their own.",
    ),
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
    compare: str | None = typer.Option(
        None,
        "--compare",
        help="Compare each robot and variant with the same in this earlier experiment (id or name; e.g. the "
        "same seeds on other code): is the difference larger than the noise?",
        metavar="ID",
    ),
    stepping: str | None = typer.Option(
        None,
        "--stepping",
        help="'lockstep' (the default: each run's simulation stands still while its plan computes, so a "
        "seed gives the same run on any machine and load) or 'free' (the simulation runs beside the plan: "
        "not reproducible). A resumed experiment keeps its own.",
    ),
    db: str | None = DbOption,
    verbose: bool = typer.Option(
        False,
        "--verbose",
        "-v",
        help="After the report, every failed run (robot, seed, environment, faults, its trace) with what ended it "
        "as recorded, and errors in full instead of in two lines; `pycram show RUN` has a run's whole failure.",
    ),
    view: str | None = typer.Option(
        None,
        "--view",
        metavar="RUN",
        help="Watch one run live: SEED or ROBOT:SEED streams into Rerun's web viewer (served on 127.0.0.1; "
        "its URL is printed). Local workers only.",
    ),
    view_port: int = ViewPortOption,
    view_host: str = ViewHostOption,
    view_wait: bool | None = ViewWaitOption,
) -> None:
    """Run a scenario over many robots, seeds and faults in parallel; report success and times.

    Each run is headless and recorded in the trace database; at the end a table shows the
    success rate per robot and variant with its 95 % confidence interval (Wilson), the failure
    causes and the simulated and wall time (p50/p95), then which differences between variants,
    robots and (with --compare) an earlier experiment are larger than the noise; a plot is
    written.

    Ctrl-C stops it: the runs under way finish and are recorded (a second Ctrl-C exits at once);
    `--resume ID` runs the rest. Exit code 0 when every run is recorded, 130 when stopped, 1 when
    runs were lost (a worker died) or raised an error (a resume runs them again), 2 for bad options.
    """
    import contextlib

    from pycram.apps.terminal import set_verbose

    set_verbose(verbose)
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        from pycram.apps.experiments.runner import ExperimentInputError, RayUnavailable, prepare_experiment, ray_session
    except ImportError as e:
        fail(f"experiments need the 'db' extra (pip install 'pycram[all]'): {e}")
    if workers < 1:
        fail(f"--workers must be at least 1, not {workers}", code=2)
    if output is not None:
        check_output_folder(str(output))
    reference = None
    if compare is not None:
        from pycram.apps.experiments import store

        try:
            reference = trace_errors(store.find_experiment, db, compare)
        except store.ExperimentNotFound as e:
            fail(str(e), code=2)
    options = dict(
        scenario=scenario,
        robots=robot,
        seeds=seeds,
        faults=faults,
        name=name,
        resume=resume,
        db=db,
        stepping=stepping,
        environments=env,
    )
    if view is not None and ray is not None:
        fail("--view watches a run of local workers: not with --ray (look at a run afterwards: `pycram view RUN`)", 2)
    watched = ExperimentView(view, view_port, view_host, view_wait) if view is not None else None
    if watched is not None and seeds is not None:  # before an experiment is created (a resume checks below)
        from pycram.apps.experiments.runner import parse_seeds

        try:
            if watched.seed not in parse_seeds(seeds):
                fail(f"--view: seed {watched.seed} is not among the experiment's seeds", code=2)
        except ValueError:
            pass  # a bad --seeds: the experiment's own check says what is wrong
    with contextlib.ExitStack() as session:
        try:
            if ray is not None:  # check the input, then connect (before an experiment is created)
                trace_errors(prepare_experiment, check_only=True, **options)
                session.enter_context(ray_session(ray, workers))
            prepared = trace_errors(prepare_experiment, command=" ".join(["pycram", *sys.argv[1:]]), **options)
        except ExperimentInputError as e:
            fail(str(e), code=2)
        except RayUnavailable as e:
            fail(str(e))
        if watched is not None:
            if watched.seed not in prepared.record.seeds:
                fail(f"--view: seed {watched.seed} is not among the experiment's seeds", code=2)
            session.enter_context(watched)
        _run_experiment(prepared, workers, ray, output, db, reference)


def _run_experiment(
    prepared: Any, workers: int, ray: str | None, output: Path | None, db: str | None, reference: Any = None
) -> None:
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
    from pycram.apps.experiments.splits import experiment_split
    from pycram.apps.terminal import failure_text, is_verbose
    from pycram.core.interrupts import StopSignals

    record = prepared.record
    where = f"Ray ({ray})" if ray else f"{workers} worker processes"
    total = len(record.keys())
    verb = "resuming" if prepared.resumed else "experiment"
    err.print(
        f"{verb} {record.id} ({escape(record.name)}): scenario {escape(record.scenario)}, "
        f"robots {escape(','.join(record.robots))}, {len(record.seeds)} seeds, "
        + (f"{len(record.environments)} environments, " if record.environments else "")
        + f"{len(record.variants)} variant(s): {total} runs, {prepared.done_before} recorded before, "
        f"{len(prepared.todo)} to run on {where}"
    )
    split = experiment_split(record.seeds, record.environments)
    _warn_split(split)
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

        def progress(key: tuple[str, int, str, str], result: dict[str, Any] | None) -> None:
            if result is not None:
                counts["ok" if result.get("success") else "failed"] += 1
            last = f"{key[0]} seed {key[1]}" + (f" in {key[3]}" if key[3] else "")
            bar.update(
                job,
                advance=1 if result is not None else 0,
                description=f"succeeded {counts['ok']}, failed {counts['failed']} · last: {escape(last)}",
            )

        with StopSignals() as stop:
            try:
                outcome = trace_errors(run_experiment, prepared, workers=workers, ray=ray, stop=stop, progress=progress)
            except RayUnavailable as e:
                fail(str(e))
            except ExperimentInputError as e:
                fail(str(e), code=2)
    runs = trace_errors(store.run_records, db, record.id)
    groups = report.summarize(runs)
    title = f"experiment {record.id} ({record.name}): {record.scenario}, {len(runs)} of {total} runs"
    console.print(report.summary_table(groups, title=escape(title)))
    # several environments: the rates per environment above, over all of them below; the causes,
    # the comparisons and (with many groups) the plot are over all of them
    pooled = report.summarize(runs, by_environment=False) if len(record.environments) > 1 else groups
    if pooled is not groups:
        console.print(report.summary_table(pooled, title=escape(f"over all {len(record.environments)} environments")))
    console.print(report.causes_table(pooled))
    for line in report.comparisons(pooled):
        console.print(escape(line), highlight=False)
    if reference is not None:
        theirs = trace_errors(store.run_records, db, reference.id)
        theirs_groups = report.summarize(theirs, by_environment=pooled is groups)
        console.print(f"compared with experiment {reference.id} ({escape(reference.name)}):")
        for line in report.comparisons(pooled, reference=theirs_groups) or ["(no robot and variant in common)"]:
            console.print("  " + escape(line), highlight=False)
    console.print(f"split: {escape(split.description)}", highlight=False)
    _warn_split(split)
    _tell_failed_runs(runs, is_verbose())
    folder = output if output is not None else Path("output") / f"experiment-{record.name}"
    if groups:
        drawn = groups if len(groups) <= _MAX_PLOTTED_GROUPS else pooled
        plot = write_errors(report.write_plot, drawn, folder / "experiment.png", title)
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
            f"{escape(failure_text(raised[0].error or ''))}); `pycram experiment --resume {record.id}` runs them again",
            soft_wrap=is_verbose(),
        )
    left = total - len(runs)
    if outcome.interrupted or left:
        err.print(
            f"[yellow]{'stopped: ' if outcome.interrupted else ''}{left} runs not finished; "
            f"resume with `pycram experiment --resume {record.id}`[/yellow]"
        )
        raise typer.Exit(stop.exit_code if outcome.interrupted and stop.signum else 1)
    raise typer.Exit(1 if raised or outcome.errors else 0)


#: The plot shows each robot, variant and environment up to this many groups, else each robot and
#: variant over all environments.
_MAX_PLOTTED_GROUPS = 12


def _warn_split(split: Any) -> None:
    """Warn (standard error) when an experiment mixes development or unsplit seeds or generated
    apartments into an evaluation (`pycram.apps.experiments.splits`)."""
    if split.problems:
        err.print(
            "[yellow]warning: not an evaluation:[/yellow] "
            + escape("; ".join(split.problems))
            + " -- report evaluation figures from evaluation seeds and worlds alone (docs/experiments.md)",
            soft_wrap=True,
        )


def _failure_of(run: Any) -> str:
    """What ended an unsuccessful run, as its result tells it: the error it raised, its summary,
    the failures of its objects, or its failure causes."""
    result = run.result or {}
    if run.error:
        return str(run.error)
    if result.get("summary"):
        return str(result["summary"])
    objects = result.get("objects") or {}
    told = [
        f"{name}: {o.get('failure') or 'not placed'} ({o.get('reason')})"
        for name, o in objects.items()
        if isinstance(o, dict) and not o.get("placed")
    ]
    return "; ".join(told) or ", ".join(run.failure_causes) or "failed (no reason recorded)"


def _tell_failed_runs(runs: list[Any], verbose: bool) -> None:
    """With `verbose`, every unsuccessful run and what ended it, in full (`failure_text`); else
    a hint that `--verbose` does so."""
    from pycram.apps.terminal import failure_text

    failed = [r for r in runs if not r.success]
    if not failed:
        return
    if not verbose:
        console.print(f"{len(failed)} runs failed; --verbose tells each of them in full", highlight=False)
        return
    console.print(f"{len(failed)} runs failed:")
    for r in failed:
        where = f" in {r.environment}" if r.environment else ""
        trace = f" (trace: run {r.trace_run_id})" if r.trace_run_id is not None else ""
        console.print(
            escape(f"- {r.robot} seed {r.seed}{where}, faults {r.variant or 'none'}{trace}: ")
            + escape(failure_text(_failure_of(r), verbose=True)),
            highlight=False,
            soft_wrap=True,
        )
