"""`pycram view RUN` and the `--view` / `--rrd` options of `pycram demo` and `pycram run`: a
run's view in Rerun's web viewer, live or afterwards (`pycram.trace.view`)."""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from pycram.apps.cli.app import DbOption, RunArgument, app, err, fail, reading

#: The web viewer's port unless `--view-port` says otherwise (Rerun's default).
VIEW_PORT = 9090
#: Where the viewer listens unless `--view-host` says otherwise: this machine only.
VIEW_HOST = "127.0.0.1"

ViewOption = typer.Option(
    False, "--view", help="Serve Rerun's web viewer (127.0.0.1) and stream the run into it; prints its URL."
)
ViewPortOption = typer.Option(
    VIEW_PORT, "--view-port", help="Port of the web viewer (0: any free port).", min=0, max=65535
)
ViewHostOption = typer.Option(
    VIEW_HOST,
    "--view-host",
    help="Address the viewer listens on (default: this machine only; 0.0.0.0 lets every machine on the network in).",
)
ViewWaitOption = typer.Option(
    None,
    "--view-wait/--no-view-wait",
    help="After the run, keep serving the view until Ctrl-C (default: when the terminal is interactive).",
)


class LiveView:
    """The `--view` / `--rrd` of one run (a context manager around it): serves the web viewer
    (printing its URL) and logs the run into it and/or into an ``.rrd`` file (written in a
    temporary folder), which ends next to the run's pictures (``run.rrd`` in `output`, or in the
    folder the run wrote its pictures to, else in ``output/view-DATE-TIME``); when nothing ran
    (no task, no world) it is removed. Inactive when neither is asked for. Exits with code 2
    and a one-line message when the viewer cannot start."""

    def __init__(
        self,
        *,
        view: bool,
        rrd: bool,
        port: int = VIEW_PORT,
        host: str = VIEW_HOST,
        wait: bool | None = None,
        output: str | Path | None = None,
        name: str = "pycram run",
    ) -> None:
        self.view, self.rrd, self.port, self.host = view, rrd, port, host
        self.wait = sys.stdin.isatty() if wait is None else wait
        self.output = Path(output) if output else None
        self.name = name
        self.server: Any = None
        self.session: Any = None
        self.saved: Path | None = None

    @property
    def active(self) -> bool:
        return self.view or self.rrd

    def __enter__(self) -> LiveView:
        return self.prepare()

    def prepare(self) -> LiveView:
        """Start the viewer and the view's recording (idempotent; `__enter__` does it too): call
        it before anything is recorded, so that a viewer that cannot start stops nothing that
        ran. Returns self."""
        if not self.active or self.session is not None:
            return self
        try:
            from pycram.trace.view.server import ViewError, ViewerServer
            from pycram.trace.view.session import ViewSession
        except ImportError as e:
            fail(f"the view needs the 'view' extra (pip install 'pycram[view]'): {e}", code=2)
        try:
            connect = None
            if self.view:
                self.server = ViewerServer(port=self.port, host=self.host).start()
                connect = self.server.grpc_url
                err.print(f"view: open [bold]{escape(self.server.url)}[/bold] in a browser", soft_wrap=True)
            target = None
            if self.rrd:  # written aside, moved next to the run's pictures once it ran (nothing: removed)
                target = Path(tempfile.mkdtemp(prefix="pycram-view-")) / "run.rrd"
            self.session = ViewSession(rrd=target, connect=connect, name=self.name).start()
        except ViewError as e:
            if self.server is not None:
                self.server.stop()
            fail(str(e), code=2)
        except OSError as e:
            if self.server is not None:
                self.server.stop()
            fail(f"--rrd: cannot write the recording: {e.strerror or e}", code=2)
        return self

    def __exit__(self, *exc: Any) -> None:
        if not self.active or self.session is None:
            return
        path = self.session.close()
        ran = {"task status", "world states"} & set(self.session.counts)
        if path is not None and not ran:  # no task ran, no world: no recording to keep
            shutil.rmtree(path.parent, ignore_errors=True)
            path = None
        if path is not None:
            from pycram.trace.view.session import find_run_folder

            folder = self.output or find_run_folder(self.session.started_wall)
            if folder is None:
                folder = Path("output") / f"view-{time.strftime('%Y%m%d-%H%M%S')}"
            self.saved = self.session.move_rrd(folder)
            shutil.rmtree(path.parent, ignore_errors=True)
            if self.saved is not None:
                how = f"`pycram view {self.session.run_id}`" if self.session.run_id is not None else "`rerun FILE`"
                err.print(f"view saved in {escape(str(self.saved))} (open it with {how})", soft_wrap=True)
        if self.server is not None:
            _serve_on(self.server, self.wait and exc[0] is None)


def _serve_on(server: Any, wait: bool) -> None:
    """With `wait`, keep serving the view after the run until the viewer ends or Ctrl-C; then
    stop the viewer in any case."""
    try:
        if wait:
            err.print(f"view: still at {escape(server.url)}; Ctrl-C to stop", soft_wrap=True)
            server.wait()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()


def run_rrd(run_id: int, output: Path = Path("output")) -> Path | None:
    """The ``run.rrd`` of recorded run `run_id` in its own folder below `output` (a folder whose
    name ends in ``-RUNID``, as `pycram demo` names them), or None."""
    if not output.is_dir():
        return None
    found = sorted(output.glob(f"*-{run_id}/run.rrd"), key=lambda p: p.stat().st_mtime, reverse=True)
    return found[0] if found else None


@app.command("view")
def view_command(
    run: str | None = RunArgument,
    db: str | None = DbOption,
    rrd: Path | None = typer.Option(
        None,
        "--rrd",
        help="The run's .rrd recording (default: output/*-RUN/run.rrd when there is one).",
        dir_okay=False,
    ),
    no_rrd: bool = typer.Option(False, "--no-rrd", help="Use the trace database alone, even when the run has an .rrd."),
    save: Path | None = typer.Option(
        None, "--save", help="Write the view rebuilt from the database to this .rrd file and exit (serve nothing)."
    ),
    port: int = ViewPortOption,
    host: str = ViewHostOption,
) -> None:
    """Show a recorded run in Rerun's web viewer: the task tree with each task's status over
    time, the failures with their reasons and the process-module executions, rebuilt from the
    trace database, plus the world, the belief and the camera from the run's .rrd when it has one
    (`pycram demo` saves it; `--rrd` for `pycram run`). Scrub the timeline to see any moment.

    Serves until Ctrl-C (exit code 0); exit code 1 for an unknown run or an unusable database, 2
    when the viewer cannot start."""
    from pycram.trace.query import find_run

    try:
        from pycram.trace.view.from_db import recording_from_database
        from pycram.trace.view.rrd import RecordingContents
        from pycram.trace.view.server import ViewError, ViewerServer
    except ImportError as e:
        fail(f"the view needs the 'view' extra (pip install 'pycram[view]'): {e}", code=2)
    info = reading(db, find_run, run, db)
    if rrd is not None and not rrd.is_file():
        fail(f"--rrd {rrd}: no such file", code=2)
    recorded = None if no_rrd else (rrd or run_rrd(info.id))
    recording_id = None
    if recorded is not None:
        try:
            recording_id = RecordingContents.read(recorded).recording_id
        except Exception as e:  # noqa: BLE001 - a broken file: say so, show the database's view
            err.print(f"[yellow]cannot read {escape(str(recorded))} ({escape(str(e))}); showing the database alone")
            recorded = None
    if save is not None:
        target = save
    else:  # removed when the viewer stops
        target = Path(tempfile.mkdtemp(prefix="pycram-view-")) / f"run-{info.id}-db.rrd"
    try:
        built = reading(
            db, recording_from_database, info.id, target, db, recording_id=recording_id, tree=recorded is None
        )
    except OSError as e:
        fail(f"cannot write {target}: {e.strerror or e}", code=2)
    finally:
        if save is None and not target.exists():  # it failed: leave no temporary folder behind
            shutil.rmtree(target.parent, ignore_errors=True)
    what = f"{built.status_changes} task-status changes, {built.failures} failures, {built.executions} executions"
    if save is not None:
        err.print(f"run {info.id}: wrote {escape(str(save))} ({what})")
        return
    files = [target] + ([recorded] if recorded is not None else [])
    try:
        server = ViewerServer(port=port, host=host, files=files).start()
    except ViewError as e:
        shutil.rmtree(target.parent, ignore_errors=True)
        fail(str(e), code=2)
    source = f"the database and {recorded}" if recorded is not None else "the database alone"
    err.print(f"run {info.id} ({escape(what)}; from {escape(str(source))})")
    err.print(f"view: open [bold]{escape(server.url)}[/bold] in a browser; Ctrl-C to stop", soft_wrap=True)
    try:
        server.wait()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
        shutil.rmtree(target.parent, ignore_errors=True)


class ExperimentView:
    """`pycram experiment --view RUN`: serves the web viewer (printing its URL) and has the
    worker processes stream the run RUN (``SEED`` or ``ROBOT:SEED``; every variant and
    environment of it) into it (`pycram.trace.view.session.viewed_run`, through environment
    variables the workers inherit). After the experiment it keeps serving until Ctrl-C when
    `wait` (default: when the terminal is interactive)."""

    def __init__(self, run: str, port: int = VIEW_PORT, host: str = VIEW_HOST, wait: bool | None = None) -> None:
        self.robot, self.seed = parse_view_run(run)
        self.port, self.host = port, host
        self.wait = sys.stdin.isatty() if wait is None else wait
        self.server: Any = None

    def __enter__(self) -> ExperimentView:
        import os

        try:
            from pycram.trace.view.server import ViewError, ViewerServer
            from pycram.trace.view.session import VIEW_CONNECT_ENV, VIEW_RUN_ENV
        except ImportError as e:
            fail(f"the view needs the 'view' extra (pip install 'pycram[view]'): {e}", code=2)
        try:
            self.server = ViewerServer(port=self.port, host=self.host).start()
        except ViewError as e:
            fail(str(e), code=2)
        os.environ[VIEW_CONNECT_ENV] = self.server.grpc_url
        os.environ[VIEW_RUN_ENV] = f"{self.robot or ''}:{self.seed}"
        which = f"{self.robot} seed {self.seed}" if self.robot else f"seed {self.seed}"
        err.print(f"view: {which} streams into [bold]{escape(self.server.url)}[/bold]", soft_wrap=True)
        return self

    def __exit__(self, kind: Any, error: Any, tb: Any) -> None:
        import os

        from pycram.trace.view.session import VIEW_CONNECT_ENV, VIEW_RUN_ENV

        os.environ.pop(VIEW_CONNECT_ENV, None)
        os.environ.pop(VIEW_RUN_ENV, None)
        if self.server is not None:
            _serve_on(self.server, self.wait and (error is None or isinstance(error, typer.Exit)))


def parse_view_run(run: str) -> tuple[str | None, int]:
    """``SEED`` or ``ROBOT:SEED`` -> (robot or None, seed); exits with code 2 and a one-line
    message for anything else."""
    robot, _, seed = run.strip().rpartition(":")
    if not seed.isdigit():
        fail(f"--view: name a run of the experiment as SEED or ROBOT:SEED (e.g. 7 or pr2:7), not {run!r}", code=2)
    return (robot or None), int(seed)
