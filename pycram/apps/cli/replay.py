"""`pycram replay RUN`: run a recorded run again and say whether it was the same run."""

from __future__ import annotations

import os
from pathlib import Path

import typer
from rich.markup import escape

from pycram.apps.cli.app import DbOption, app, console, err, fail
from pycram.apps.run_options import check_until


@app.command("replay")
def replay_command(
    run: str | None = typer.Argument(None, help="Run id or uuid (default: the newest run).", show_default=False),
    db: str | None = DbOption,
    until: float | None = typer.Option(
        None,
        "--until",
        metavar="T",
        help="Stop the replay at simulated time T [s] and write the scene and belief pictures and the task tree "
        "of that moment (compared: the trajectory up to T).",
    ),
    output: str | None = typer.Option(
        None, "--output", "-o", help="Folder for the pictures of --until (default: output/replay-RUN)."
    ),
) -> None:
    """Run a recorded run again (headless, not recorded: same scenario, robot, seed and options)
    and compare it with its record: prints "identical", or where the replay first diverged (the
    simulated time, the task path, which pose). Exit code 0 only when identical; 1 when it
    diverged; 2 when the run cannot be replayed (not found, recorded without what a replay needs,
    free-running, stopped early) -- one line saying why."""
    try:
        check_until(until)
    except ValueError as error:
        fail(str(error), code=2)
    try:
        from pycram.apps.replay import CannotReplay, load_replay, replay_run
        from pycram.trace.db import TraceDatabaseError, resolve_url, sqlite_file
        from pycram.trace.query import RunNotFound
    except ImportError as e:
        fail(f"`pycram replay` needs the 'sim' and 'db' extras (pip install 'pycram[all]'): {e}", code=2)
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        if db is not None and db.strip():
            resolve_url(db)  # a malformed URL is reported as such
            path = sqlite_file(db)
            if path is not None and not path.exists():
                fail(f"no such database: {path} does not exist", code=2)
        info, replay, _ = load_replay(run, db)
    except (RunNotFound, CannotReplay, TraceDatabaseError) as error:
        fail(f"cannot replay: {error}", code=2)
    options = ", ".join(f"{k} {v}" for k, v in (replay.get("options") or {}).items() if k != "pictures")
    err.print(
        f"replaying run {info.id}: {replay['scenario']}, robot {replay['robot']}, seed {replay['seed']}"
        + (f", in {escape(str(replay['environment']))}" if replay.get("environment") else "")
        + (f", {escape(options)}" if options else "")
        + f" (recorded by PyCRAM {replay.get('pycram')})",
        soft_wrap=True,
    )
    folder = Path(output) if output is not None else Path("output") / f"replay-{info.id}"
    try:
        report = replay_run(info.id, db, until=until, output=folder if until is not None else None)
    except (RunNotFound, CannotReplay, TraceDatabaseError) as error:
        fail(f"cannot replay: {error}", code=2)
    for warning in report.warnings:
        err.print(f"[yellow]warning:[/yellow] {escape(warning)}")
    if report.stop_folder is not None:
        err.print(f"the scene, the belief and the task tree at t={until:g} s are in {escape(str(report.stop_folder))}")
    if report.identical:
        up_to = f" up to t={until:g} s" if until is not None else ""
        console.print(f"identical{up_to} (replayed in {report.wall_time:.1f} s of wall time)")
        raise typer.Exit(0)
    console.print(escape(str(report.divergence)), soft_wrap=True)
    raise typer.Exit(1)
