"""`pycram run FILE.py`: a plan script with the block syntax on, recorded by default."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from pycram.apps.cli.app import (
    DbOption,
    app,
    err,
    record_flag,
    trace_errors,
)
from pycram.apps.cli.view import LiveView, ViewHostOption, ViewOption, ViewPortOption, ViewWaitOption


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
    view: bool = ViewOption,
    rrd: bool = typer.Option(
        False, "--rrd/--no-rrd", help="Save the run's view as run.rrd (next to its pictures, else in output/view-DATE)."
    ),
    view_port: int = ViewPortOption,
    view_host: str = ViewHostOption,
    view_wait: bool | None = ViewWaitOption,
    verbose: bool = typer.Option(
        False,
        "--verbose",
        help="Tell a failure of the plan in full (its traceback with every cause, then every message and "
        "attempt) instead of its traceback ending in two lines; `pycram show RUN` always has the whole of it.",
    ),
) -> None:
    """Run a plan script; arguments after FILE go to the script (in sys.argv).

    The script owns logging (`logging.basicConfig` in it works as under `python FILE.py`);
    an exception it raises is reported with a traceback that starts at the script's code, and
    the exit code is 1. SIGINT (Ctrl-C) and SIGTERM stop the script so that its clean-up runs
    (in plain Python code as a KeyboardInterrupt, inside PyCRAM by evaporating the script's
    tasks): the run is recorded as "interrupted" with the reason, the exit code is 130 / 143; a
    second signal while stopping exits at once. A typed failure of the plan (`pycram.failures`)
    ends its traceback with what failed, why and what to try in two lines, without the nested
    causes; `--verbose` shows them all.
    """
    from pycram.apps.terminal import set_verbose
    from pycram.core.interrupts import StopSignals
    from pycram.core.macros import run_script
    from pycram.core.runtime import end_thread_root
    from pycram.execution.failures import SimulationFault

    set_verbose(verbose)
    # before the recorder: a viewer that cannot start stops the command before anything is recorded
    live = LiveView(
        view=view, rrd=rrd, port=view_port, host=view_host, wait=view_wait, name=f"pycram run {file.name}"
    ).prepare()
    recorder = None
    if record_flag(record):
        from pycram.trace.recorder import Recorder

        recorder = trace_errors(
            lambda: Recorder(
                db, plan=plan or file.name, robot=robot, command=" ".join(["pycram run", str(file), *ctx.args])
            ).start()
        )
    error: BaseException | str | None  # what the trace records as the run's error
    outcome, error, code = "succeeded", None, 0
    ended: BaseException | None = None  # what ended the main thread's root task
    with live, StopSignals(stop_main=True) as stop:
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
                if not isinstance(e, (Exception, SimulationFault)):  # a broken simulation is a failure too
                    raise
                sys.stderr.write(_script_error(e, file, verbose))  # as `python FILE` would print it
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


def _script_error(error: BaseException, file: Path, verbose: bool) -> str:
    """The report of the script's `error`: its traceback as `python FILE` prints it. For a typed
    failure of the plan (a `PlanFailure` or `SimulationFault` in its chain), unless `verbose`,
    the traceback of the error alone (no chained causes), ending in `failure_text`'s two lines
    and where the rest is; `verbose`: the whole traceback, then every message and attempt
    (`failure_text(verbose=True)`, as `pycram demo --verbose` tells a failure)."""
    import traceback

    from pycram.apps.terminal import failure_text
    from pycram.core.macros import format_script_error
    from pycram.execution.failures import PlanFailure, SimulationFault, failure_chain

    typed = any(isinstance(e, (PlanFailure, SimulationFault)) for e in failure_chain(error))
    if not typed:
        return format_script_error(error, file)
    if verbose:
        return f"{format_script_error(error, file)}\nthe whole failure:\n{failure_text(error, verbose=True)}\n"
    short = failure_text(error, verbose=False)
    chained = (error.__cause__, error.__context__)
    error.__cause__ = error.__context__ = None
    try:
        text = format_script_error(error, file)
    finally:
        error.__cause__, error.__context__ = chained
    last = "".join(traceback.format_exception_only(type(error), error))
    if text.endswith(last):
        text = text[: -len(last)]
    return f"{text}{short}\n(its causes in full: pycram run --verbose, or `pycram show RUN` for a recorded run)\n"
