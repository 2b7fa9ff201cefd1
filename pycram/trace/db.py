"""Database access for run traces: URLs, engines, the schema (SQLAlchemy Core).

Importing this module imports SQLAlchemy; `pycram.trace` imports it only when recording or
querying is actually used.

Guarantees
----------
- `resolve_url(None)` is `$PYCRAM_DB_URL` if set, else a SQLite file in the default folder
  (`$PYCRAM_HOME`, else `$XDG_DATA_HOME/pycram`, else `~/.local/share/pycram`), whose folder
  is created on demand (when recording; reading a missing SQLite file creates nothing).
  A bare file path (given or in `$PYCRAM_DB_URL`) means that SQLite file.
- `connect(url)` returns an engine whose connection was tested and whose schema exists. It
  raises `TraceDatabaseError` naming the URL (password hidden) and what is wrong for
  malformed URLs, unknown database kinds, missing drivers and unreachable servers.
- Schema creation is idempotent and safe when several processes create it at once.
- SQLite databases use write-ahead logging (WAL) and `synchronous=NORMAL`: a committed batch
  survives the writing process being killed (SIGKILL); readers never block the writer.
"""

from __future__ import annotations

import logging
import os
import threading
from pathlib import Path
from typing import Any

import sqlalchemy as sa
from sqlalchemy import exc as sa_exc
from sqlalchemy.engine import URL, Engine

log = logging.getLogger(__name__)

__all__ = [
    "TraceDatabaseError",
    "default_url",
    "resolve_url",
    "sqlite_file",
    "connect",
    "empty_engine",
    "metadata",
    "runs_table",
    "tasks_table",
    "designators_table",
    "executions_table",
    "fluent_samples_table",
]

SCHEMA_VERSION = 1


class TraceDatabaseError(RuntimeError):
    """The trace database cannot be used: bad URL, unknown kind, missing driver, unreachable."""


def default_folder() -> Path:
    """Folder of the default SQLite database (not created by this function)."""
    home = os.environ.get("PYCRAM_HOME")
    if home:
        return Path(home).expanduser()
    xdg = os.environ.get("XDG_DATA_HOME")
    if xdg:
        return Path(xdg).expanduser() / "pycram"
    return Path.home() / ".local" / "share" / "pycram"


def _path_as_url(url: str) -> str:
    """A bare filesystem path (no `://`, ending in .sqlite/.sqlite3/.db or containing a path
    separator) as a SQLite URL; anything else unchanged."""
    if "://" not in url and (url.endswith((".sqlite", ".sqlite3", ".db")) or os.sep in url):
        return f"sqlite:///{Path(url).expanduser().resolve()}"
    return url


def default_url() -> str:
    """`$PYCRAM_DB_URL` (a URL or a SQLite file path), or the default SQLite file
    `runs.sqlite3` in `default_folder()`."""
    env = os.environ.get("PYCRAM_DB_URL", "").strip()
    if env:
        return _path_as_url(env)
    return f"sqlite:///{default_folder() / 'runs.sqlite3'}"


def resolve_url(url: str | None) -> str:
    """The URL to use: `url` if given, else `default_url()`. A bare filesystem path (no
    `://`) is taken as a SQLite file."""
    if url is None or url.strip() == "":
        return default_url()
    return _path_as_url(url.strip())


def sqlite_file(url: str | None) -> Path | None:
    """The file of a SQLite URL (see `resolve_url`); None for other databases, in-memory
    SQLite and unparsable URLs."""
    try:
        parsed = sa.make_url(resolve_url(url))
    except sa_exc.ArgumentError:
        return None
    if parsed.get_backend_name() != "sqlite":
        return None
    database = parsed.database
    if not database or database == ":memory:" or database.startswith("file:"):
        return None
    return Path(database).expanduser()


def display_url(url: str | URL) -> str:
    """The URL with its password hidden (for messages and logs)."""
    try:
        parsed = url if isinstance(url, URL) else sa.make_url(url)
        return parsed.render_as_string(hide_password=True)
    except Exception:
        return str(url)


#: SQLAlchemy metadata holding the trace tables (all named ``pycram_*``).
metadata = sa.MetaData()

#: One row per recorded run: plan, robot, start/end, outcome.
runs_table = sa.Table(
    "pycram_runs", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("uuid", sa.String(36), nullable=False, unique=True),
    sa.Column("plan", sa.String(255)),
    sa.Column("robot", sa.String(255)),
    sa.Column("host", sa.String(255)),
    sa.Column("pid", sa.Integer),
    sa.Column("command", sa.Text),
    sa.Column("started_at", sa.DateTime(timezone=True), nullable=False),
    sa.Column("ended_at", sa.DateTime(timezone=True)),
    sa.Column("last_seen_at", sa.DateTime(timezone=True)),  # heartbeat: the last committed batch
    sa.Column("outcome", sa.String(32)),  # NULL while running (or when the process was killed)
    sa.Column("duration", sa.Float),  # wall time [s]
    sa.Column("clock_origin", sa.Float),  # active clock at the start [s]
    sa.Column("error", sa.Text),
    sa.Column("info", sa.Text),  # JSON object of extra metadata
)

#: One row per task of a run's task tree: name, parent, status, times, error.
tasks_table = sa.Table(
    "pycram_tasks", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("run_id", sa.Integer, sa.ForeignKey("pycram_runs.id", ondelete="CASCADE"), nullable=False),
    sa.Column("task_id", sa.Integer, nullable=False),  # Task.id, unique within the run
    sa.Column("parent_id", sa.Integer),
    sa.Column("name", sa.String(512), nullable=False),
    sa.Column("kind", sa.String(64)),
    sa.Column("path", sa.Text),
    sa.Column("thread", sa.String(255)),
    sa.Column("status", sa.String(16), nullable=False),
    sa.Column("start", sa.Float),  # active clock [s]
    sa.Column("end", sa.Float),
    sa.Column("duration", sa.Float),
    sa.Column("error_type", sa.String(255)),
    sa.Column("error_message", sa.Text),
    sa.UniqueConstraint("run_id", "task_id", name="uq_pycram_tasks_run_task"),
)
sa.Index("ix_pycram_tasks_name", tasks_table.c.name)

#: One row per performed designator: its properties and what it resolved to.
designators_table = sa.Table(
    "pycram_designators", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("run_id", sa.Integer, sa.ForeignKey("pycram_runs.id", ondelete="CASCADE"), nullable=False),
    sa.Column("task_id", sa.Integer),  # the task that performed it
    sa.Column("time", sa.Float),
    sa.Column("designator_class", sa.String(255)),
    sa.Column("designator_type", sa.String(255)),  # the ('type', ...) property, if any
    sa.Column("designator", sa.Text),
    sa.Column("solution", sa.Text),
    sa.Column("error_type", sa.String(255)),
    sa.Column("error_message", sa.Text),
)
sa.Index("ix_pycram_designators_run", designators_table.c.run_id)

#: One row per process-module execution: module, designator, outcome, times.
executions_table = sa.Table(
    "pycram_executions", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("run_id", sa.Integer, sa.ForeignKey("pycram_runs.id", ondelete="CASCADE"), nullable=False),
    sa.Column("task_id", sa.Integer),
    sa.Column("module", sa.String(255)),
    sa.Column("designator_type", sa.String(255)),
    sa.Column("designator", sa.Text),
    sa.Column("outcome", sa.String(32)),
    sa.Column("start", sa.Float),
    sa.Column("end", sa.Float),
    sa.Column("duration", sa.Float),
    sa.Column("error_type", sa.String(255)),
    sa.Column("error_message", sa.Text),
)
sa.Index("ix_pycram_executions_run", executions_table.c.run_id)

#: Sampled values of watched fluents, with the active clock's time [s].
fluent_samples_table = sa.Table(
    "pycram_fluent_samples", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("run_id", sa.Integer, sa.ForeignKey("pycram_runs.id", ondelete="CASCADE"), nullable=False),
    sa.Column("name", sa.String(255), nullable=False),
    sa.Column("time", sa.Float),  # active clock [s]
    sa.Column("value", sa.Text),  # repr of the value (enums: their value)
    sa.Column("number", sa.Float),  # the value as a number, when it is one
)
sa.Index("ix_pycram_fluent_samples_run_name", fluent_samples_table.c.run_id, fluent_samples_table.c.name)


def _enable_sqlite_wal(dbapi_connection: Any, _record: Any) -> None:
    cursor = dbapi_connection.cursor()
    try:
        cursor.execute("PRAGMA journal_mode=WAL")
        cursor.execute("PRAGMA synchronous=NORMAL")
        cursor.execute("PRAGMA foreign_keys=ON")
    finally:
        cursor.close()


_HINT = ("expected e.g. sqlite:////absolute/path/runs.sqlite3 or "
         "postgresql+psycopg://user:password@host:5432/database")

_engines: dict[str, Engine] = {}
_engines_lock = threading.Lock()


def _parse(url: str) -> URL:
    try:
        parsed = sa.make_url(url)
    except sa_exc.ArgumentError as e:
        raise TraceDatabaseError(f"invalid database URL {url!r}: {e}; {_HINT}") from None
    if parsed.drivername in ("postgresql", "postgres"):  # psycopg (3) is the driver we ship
        parsed = parsed.set(drivername="postgresql+psycopg")
    return parsed


def create_engine(url: str | None) -> Engine:
    """A new engine for `url` (see `resolve_url`) with clear errors; not yet connected."""
    text = resolve_url(url)
    parsed = _parse(text)
    shown = display_url(parsed)
    kwargs: dict[str, Any] = {}
    if parsed.get_backend_name() == "sqlite":
        database = parsed.database
        if database and database != ":memory:" and not database.startswith("file:"):
            folder = Path(database).expanduser().parent
            try:
                folder.mkdir(parents=True, exist_ok=True)
            except OSError as e:
                raise TraceDatabaseError(f"cannot create the folder {folder} for database {shown}: {e}") from None
        kwargs["connect_args"] = {"timeout": 30.0, "check_same_thread": False}
    else:
        kwargs["pool_pre_ping"] = True
    try:
        engine = sa.create_engine(parsed, **kwargs)
    except sa_exc.NoSuchModuleError:
        raise TraceDatabaseError(
            f"unknown database kind {parsed.drivername!r} in URL {shown}; {_HINT}") from None
    except ModuleNotFoundError as e:
        raise TraceDatabaseError(
            f"the database driver for {shown} is not installed ({e}); install pycram[db]") from None
    except sa_exc.ArgumentError as e:
        raise TraceDatabaseError(f"invalid database URL {shown}: {e}; {_HINT}") from None
    if parsed.get_backend_name() == "sqlite":
        sa.event.listen(engine, "connect", _enable_sqlite_wal)
    return engine


def connect(url: str | None = None, *, create_schema: bool = True, cached: bool = False) -> Engine:
    """An engine for `url` whose connection works and whose schema exists.

    With `cached`, engines are shared per URL within the process (for queries). Raises
    `TraceDatabaseError` (see the module guarantees).
    """
    text = resolve_url(url)
    if cached:
        with _engines_lock:
            engine = _engines.get(text)
        if engine is not None:
            return engine
    engine = create_engine(text)
    try:
        if create_schema:
            ensure_schema(engine)
        else:
            with engine.connect():
                pass
    except sa_exc.DBAPIError as e:
        engine.dispose()
        reason = str(getattr(e, "orig", e)).strip().splitlines()[0] if str(getattr(e, "orig", e)).strip() else type(e).__name__
        raise TraceDatabaseError(f"cannot use database {display_url(engine.url)}: {reason}") from None
    if cached:
        with _engines_lock:
            engine = _engines.setdefault(text, engine)
    return engine


_empty: Engine | None = None


def empty_engine() -> Engine:
    """A shared in-memory SQLite engine with the (empty) schema: what queries read when the
    SQLite file they were pointed at does not exist yet -- so reading never creates it."""
    global _empty
    with _engines_lock:
        if _empty is None:
            from sqlalchemy.pool import StaticPool

            engine = sa.create_engine("sqlite://", poolclass=StaticPool,
                                      connect_args={"check_same_thread": False})
            metadata.create_all(engine)
            _empty = engine
        return _empty


def ensure_schema(engine: Engine) -> None:
    """Create the trace tables and indexes that do not exist yet (idempotent, concurrent-safe)."""
    for attempt in range(3):
        try:
            metadata.create_all(engine, checkfirst=True)
            return
        except (sa_exc.IntegrityError, sa_exc.ProgrammingError, sa_exc.OperationalError) as e:
            # another process created a table between our check and our CREATE
            if attempt == 2 or "already exists" not in str(e).lower() and "duplicate" not in str(e).lower():
                raise
            log.debug("schema creation raced with another process; retrying: %s", e)
