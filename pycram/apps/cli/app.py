"""The `pycram` Typer application and what its commands share: the consoles, the
`--db` option, one-line errors and exit codes, recording flags."""

from __future__ import annotations

import datetime as _dt
import logging
import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape
from typer.models import OptionInfo

from pycram.world.robot_registry import DEFAULT_ROBOT, robot_choices, robot_names

#: The `pycram` command line; each module of `pycram.apps.cli` registers its commands on it.
app = typer.Typer(
    name="pycram",
    help="PyCRAM: concurrent, reactive robot plans. Run plans and the kitchen demo; inspect recorded runs.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
#: Standard output of the commands (tables, trees, results).
console = Console(highlight=False)
#: Standard error of the commands (errors, warnings, where a run was recorded).
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
COLLAPSE = 3

DbOption = typer.Option(
    None,
    "--db",
    help="SQLAlchemy URL of the trace database (default: $PYCRAM_DB_URL or ~/.local/share/pycram/runs.sqlite3).",
    metavar="URL",
)
RunArgument = typer.Argument(None, help="Run id (default: the newest run).", show_default=False)


def fail(message: str, code: int = 1) -> None:
    err.print(f"[bold red]error:[/bold red] {escape(message)}", soft_wrap=True)
    raise typer.Exit(code)


def trace_errors(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Call fn, turning database and lookup errors into a clear message and exit code 1."""
    try:
        from pycram.trace.db import TraceDatabaseError
    except ImportError as e:  # the db extra is missing
        fail(f"run traces need the 'db' extra (pip install 'pycram[db]'): {e}")
    from pycram.trace.query import RunNotFound

    try:
        return fn(*args, **kwargs)
    except (TraceDatabaseError, RunNotFound) as e:
        fail(str(e))


def reading(db: str | None, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """`trace_errors` for the inspecting commands: a database named with `--db` must exist
    (reading never creates one), and any database failure is a one-line error."""
    from sqlalchemy import exc as sa_exc

    from pycram.trace.db import database_error, resolve_url, sqlite_file

    if db is not None and db.strip():
        trace_errors(resolve_url, db)  # a malformed URL is reported as such
        path = sqlite_file(db)
        if path is not None and not path.exists():
            where = f"the folder {path.parent} does not exist" if not path.parent.is_dir() else f"{path} does not exist"
            fail(f"no such database: {where} (`pycram run` and `pycram demo` create it when they record)")
    try:
        return trace_errors(fn, *args, **kwargs)
    except sa_exc.SQLAlchemyError as e:  # a failure no query layer translated
        fail(str(database_error(resolve_url(db), e, "read")))


def write_errors(fn: Any, *args: Any) -> Any:
    """`fn(*args)` writing a picture: an unwritable output path is a one-line error."""
    try:
        return fn(*args)
    except OSError as e:
        fail(f"cannot write {e.filename or 'the picture'}: {e.strerror or e}")


class LiveHelpOption(OptionInfo):
    """A `typer.Option` whose help text is ``text()`` when the command line is built -- each time
    `pycram` runs (typer builds its click command per call, before parsing) -- rather than when
    the module defining the option was imported: e.g. the robots registered at that time.
    ``option`` are `typer.Option`'s keyword arguments (``default``, ``param_decls``, ...)."""

    def __init__(self, text: Callable[[], str], **option: Any) -> None:
        self._text = text
        super().__init__(**option)

    @property  # type: ignore[override]
    def help(self) -> str:
        """The help text, made now."""
        return self._text()

    @help.setter
    def help(self, value: str | None) -> None:
        """`OptionInfo.__init__` sets the static text; ``text()`` stands in for it."""


def robot_option_help(names: Iterable[str] | None = None) -> str:
    """The help text of a ``--robot`` option: ``Robot: 'pr2', 'tiago' or 'tiago-pro'.`` -- the
    registered robots now, or `names`."""
    return f"Robot: {robot_choices(names) or '(none registered)'}."


def check_robot(name: str) -> str:
    """`name` if a robot of that name is registered now; else a one-line error naming the
    registered robots, exit code 2 (the callback of `RobotOption`)."""
    if name not in robot_names():
        fail(f"--robot must be {robot_choices()}, not {name!r}; see `pycram robot list`", code=2)
    return name


#: The ``--robot NAME`` option of the commands that run one robot (default: the PR2): its help
#: lists, and its check accepts, the robots registered when the command runs.
RobotOption: Any = LiveHelpOption(
    robot_option_help, default=DEFAULT_ROBOT, param_decls=("--robot",), callback=check_robot
)


def local_time(when: _dt.datetime | None) -> str:
    return when.astimezone().strftime("%Y-%m-%d %H:%M:%S") if when is not None else "–"


def record_flag(record: bool | None) -> bool:
    if record is not None:
        return record
    from pycram.trace.recorder import recording_enabled

    return recording_enabled(True)


def check_output_folder(output: str) -> None:
    """Refuse (exit code 2, one line) an `--output` folder that cannot be created or written.

    Leaves nothing behind: the folder must be a writable directory, or its nearest existing
    ancestor must be one in which a folder can really be made (tried with a temporary folder,
    removed at once: permission bits do not tell, e.g. in /proc or on a read-only file system).
    """

    path = Path(output).expanduser()
    existing = path
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing == path and not path.is_dir():
        fail(f"--output {output}: exists and is not a folder", code=2)
    if not existing.is_dir():
        fail(f"--output {output}: cannot create the folder, {existing} is not a folder", code=2)
    if not os.access(existing, os.W_OK | os.X_OK):
        fail(f"--output {output}: cannot write to {existing} (permission denied)", code=2)
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".pycram-probe-", dir=existing))
    except OSError as e:
        fail(f"--output {output}: cannot create a folder in {existing} ({e.strerror or e})", code=2)
