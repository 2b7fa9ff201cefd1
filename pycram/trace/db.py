"""Database access for run traces: URLs, engines, the schema (SQLAlchemy Core).

Importing this module imports SQLAlchemy; `pycram.trace` imports it only when recording or
querying is actually used.

Guarantees
----------
- `resolve_url(None)` is `$PYCRAM_DB_URL` if set, else a SQLite file in the default folder
  (`$PYCRAM_HOME`, else `$XDG_DATA_HOME/pycram`, else `~/.local/share/pycram`), whose folder
  is created on demand (when recording; reading a missing SQLite file creates nothing).
  A bare file path (given or in `$PYCRAM_DB_URL`) means that SQLite file.
- Supported database kinds: SQLite (`sqlite:///relative.sqlite3`, `sqlite:////absolute.sqlite3`,
  or a bare file path) and PostgreSQL (`postgresql://user:password@host:5432/database`, driven
  by psycopg 3, which the `db` extra ships). Other kinds (MySQL, ...) are refused, saying so.
- `connect(url)` returns an engine whose connection was tested and whose schema exists. It
  raises `TraceDatabaseError` naming the URL (password hidden) and what is wrong for
  malformed URLs (a non-numeric port, `sqlite:/x` with too few slashes), unsupported
  database kinds, missing drivers, unreachable servers and files that are not databases.
- Schema creation is idempotent and safe when several processes create it at once. A
  database written by an older PyCRAM is migrated on connect: missing columns are added
  (`ALTER TABLE ... ADD COLUMN`, NULL in old rows); when that is impossible (a read-only file),
  readers still work (see `present_columns`). Schema 5 moved the environment of an
  experiment's run out of its ``variant`` column (schema 4 wrote ``"faults@environment"``) into
  a column of its own, ``environment``, and made it part of the run's key: an older
  `pycram_experiment_runs` table is rebuilt (SQLite) or altered (PostgreSQL) on connect, in one
  transaction under a lock, keeping every run (`migrate_experiment_runs`).
- SQLite databases use write-ahead logging (WAL) and `synchronous=NORMAL`: a committed batch
  survives the writing process being killed (SIGKILL); readers never block the writer.
"""

from __future__ import annotations

import logging
import os
import re
import sqlite3
import threading
import weakref
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
    "experiments_table",
    "experiment_runs_table",
    "present_columns",
    "migrate_experiment_runs",
    "SUPPORTED_KINDS",
    "SCHEMA_VERSION",
]

#: 2: `pycram_tasks.error_origin`, `pycram_runs.clock` and `pycram_runs.lost_records`; 3:
#: `pycram_tasks.location` (added to older databases on connect); 4: the tables
#: `pycram_experiments` and `pycram_experiment_runs` (`pycram experiment`; created on connect); 5:
#: `pycram_experiment_runs.environment`, part of the run's key (migrated on connect:
#: `migrate_experiment_runs`).
SCHEMA_VERSION = 5

#: Database kinds (SQLAlchemy backend names) that can hold run traces.
SUPPORTED_KINDS = ("sqlite", "postgresql")


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


#: `kind:` at the start of a URL (two letters at least, so that `C:\\x.db` stays a path).
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]+):")


def _path_as_url(url: str) -> str:
    """A bare filesystem path (no `://`, ending in .sqlite/.sqlite3/.db or containing a path
    separator) as a SQLite URL; anything else unchanged.

    Raises `TraceDatabaseError` for a URL whose kind is not followed by `://` (e.g.
    `sqlite:/relative.db`), instead of taking it for a path in a folder named `sqlite:`.
    """
    if "://" not in url:
        scheme = _SCHEME.match(url)
        if scheme is not None:
            raise TraceDatabaseError(
                f"invalid database URL {url!r}: a URL needs '://' after its kind {scheme.group(1)!r} "
                "(sqlite:///relative/path.sqlite3 for a file below the current folder, "
                "sqlite:////absolute/path.sqlite3 for an absolute one, or just the file's path)"
            )
        if url.endswith((".sqlite", ".sqlite3", ".db")) or os.sep in url:
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
    except (sa_exc.ArgumentError, TraceDatabaseError, ValueError):
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
    "pycram_runs",
    metadata,
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
    # the kind of clock task and execution times were taken from: "simulated", "wall-clock",
    # both joined by "+" in order of appearance; NULL in runs recorded before schema 2
    sa.Column("clock", sa.String(64)),
    sa.Column("lost_records", sa.Integer),  # trace rows that could not be written (NULL: not known)
)

#: One row per task of a run's task tree: name, parent, status, times, error.
tasks_table = sa.Table(
    "pycram_tasks",
    metadata,
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
    # task_id of the task the error was raised in: this task's own id where it originated,
    # a descendant's where it only passed through; NULL without error and before schema 2
    sa.Column("error_origin", sa.Integer),
    # where the task's code is (`file.py:line` of the call it was made for); NULL before schema 3
    sa.Column("location", sa.String(512)),
    sa.UniqueConstraint("run_id", "task_id", name="uq_pycram_tasks_run_task"),
)
sa.Index("ix_pycram_tasks_name", tasks_table.c.name)

#: One row per performed designator: its properties and what it resolved to.
designators_table = sa.Table(
    "pycram_designators",
    metadata,
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
    "pycram_executions",
    metadata,
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
    "pycram_fluent_samples",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("run_id", sa.Integer, sa.ForeignKey("pycram_runs.id", ondelete="CASCADE"), nullable=False),
    sa.Column("name", sa.String(255), nullable=False),
    sa.Column("time", sa.Float),  # active clock [s]
    sa.Column("value", sa.Text),  # repr of the value (enums: their value)
    sa.Column("number", sa.Float),  # the value as a number, when it is one
)
sa.Index("ix_pycram_fluent_samples_run_name", fluent_samples_table.c.run_id, fluent_samples_table.c.name)


#: One row per experiment (`pycram experiment`): its name, scenario, robots, seeds and variants.
experiments_table = sa.Table(
    "pycram_experiments",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("name", sa.String(255), nullable=False, unique=True),
    sa.Column("scenario", sa.String(512), nullable=False),  # registry name or `module:function`
    sa.Column("robots", sa.Text, nullable=False),  # JSON list of robot names
    sa.Column("seeds", sa.Text, nullable=False),  # JSON list of seeds
    sa.Column("variants", sa.Text, nullable=False),  # JSON list of variants (lists of fault names)
    sa.Column("created_at", sa.DateTime(timezone=True), nullable=False),
    sa.Column("updated_at", sa.DateTime(timezone=True)),
    sa.Column("status", sa.String(32)),  # "running", "interrupted", "finished"
    sa.Column("host", sa.String(255)),
    sa.Column("command", sa.Text),
    sa.Column("info", sa.Text),  # JSON object of extra metadata
)

#: One row per finished run of an experiment: robot, seed, variant, environment and the
#: scenario's result.
experiment_runs_table = sa.Table(
    "pycram_experiment_runs",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("experiment_id", sa.Integer, sa.ForeignKey("pycram_experiments.id", ondelete="CASCADE"), nullable=False),
    sa.Column("robot", sa.String(255), nullable=False),
    sa.Column("seed", sa.Integer, nullable=False),
    sa.Column("variant", sa.String(512), nullable=False),  # sorted fault names joined by ",", "" for none
    # the environment it ran in (`pycram experiment --env`: "procedural:3", "apartment", ...), "" for
    # the scenario's own (an experiment without --env); schema 5 (older runs: migrated on connect)
    sa.Column("environment", sa.String(512), nullable=False, server_default=""),
    sa.Column("status", sa.String(16), nullable=False),  # "done", or "error" when the scenario raised
    sa.Column("success", sa.Boolean, nullable=False),
    sa.Column("failure_causes", sa.Text),  # JSON list of failure type names
    sa.Column("sim_time", sa.Float),  # [s]
    sa.Column("wall_time", sa.Float),  # [s]
    sa.Column("trace_run_id", sa.Integer),  # the run's trace in `pycram_runs`, when it was recorded
    sa.Column("error", sa.Text),  # why the scenario raised (status "error")
    sa.Column("result", sa.Text),  # the scenario's whole result (JSON)
    sa.Column("worker", sa.String(255)),  # host:pid that ran it
    sa.Column("finished_at", sa.DateTime(timezone=True)),
    sa.UniqueConstraint(
        "experiment_id", "robot", "seed", "variant", "environment", name="uq_pycram_experiment_runs_run"
    ),
)

#: The unique constraint of `pycram_experiment_runs` before schema 5 (without the environment).
_OLD_RUN_KEY = "uq_pycram_experiment_runs_key"
#: How schema 4 joined a run's variant and environment in its ``variant`` column.
_OLD_ENVIRONMENT_SEPARATOR = "@"


def _enable_sqlite_wal(dbapi_connection: Any, _record: Any) -> None:
    cursor = dbapi_connection.cursor()
    try:
        try:
            cursor.execute("PRAGMA journal_mode=WAL")
        except Exception as e:  # a read-only file cannot switch its journal; reading still works
            log.debug("SQLite: cannot switch to write-ahead logging: %s", e)
        cursor.execute("PRAGMA synchronous=NORMAL")
        cursor.execute("PRAGMA foreign_keys=ON")
    finally:
        cursor.close()


_HINT = "expected e.g. sqlite:////absolute/path/runs.sqlite3 or postgresql://user:password@host:5432/database"
_SUPPORTED = (
    "run traces can be kept in SQLite (sqlite:///path/runs.sqlite3 or a file path) "
    "or PostgreSQL (postgresql://user:password@host:5432/database)"
)


def _hide_password(url: str) -> str:
    """`url` with the password of `scheme://user:password@host` replaced by ***."""
    return re.sub(r"(://[^/:@]*:)[^/@]*@", r"\1***@", url)


_engines: dict[str, Engine] = {}
_engines_lock = threading.Lock()


def _parse(url: str) -> URL:
    try:
        parsed = sa.make_url(url)
    except sa_exc.ArgumentError as e:
        raise TraceDatabaseError(f"invalid database URL {_hide_password(url)!r}: {e}; {_HINT}") from None
    except ValueError:  # SQLAlchemy's int() of the port
        host = url.split("://", 1)[-1].split("/", 1)[0].rsplit("@", 1)[-1]
        port = host.rsplit(":", 1)[-1] if ":" in host else ""
        raise TraceDatabaseError(
            f"invalid database URL {_hide_password(url)!r}: the port {port!r} is not a number; {_HINT}"
        ) from None
    if parsed.drivername in ("postgresql", "postgres"):  # psycopg (3) is the driver we ship
        parsed = parsed.set(drivername="postgresql+psycopg")
    backend = parsed.get_backend_name()
    if backend not in SUPPORTED_KINDS:
        shown = display_url(parsed)
        try:
            parsed.get_dialect()
        except sa_exc.NoSuchModuleError:
            raise TraceDatabaseError(
                f"unknown database kind {parsed.drivername!r} in URL {shown}; {_SUPPORTED}"
            ) from None
        raise TraceDatabaseError(f"database kind {backend!r} (URL {shown}) is not supported: {_SUPPORTED}") from None
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
        if "connect_timeout" not in parsed.query:  # [s]: a vanished server is an error, not a hang
            kwargs["connect_args"] = {"connect_timeout": 10}
    try:
        engine = sa.create_engine(parsed, **kwargs)
    except sa_exc.NoSuchModuleError:
        raise TraceDatabaseError(f"unknown database kind {parsed.drivername!r} in URL {shown}; {_HINT}") from None
    except ModuleNotFoundError as e:
        raise TraceDatabaseError(
            f"the database driver for {shown} is not installed ({e}); the 'db' extra (pip install "
            "'pycram[db]') ships the drivers for sqlite:// and postgresql:// (psycopg 3)"
        ) from None
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
    except sa_exc.SQLAlchemyError as e:
        engine.dispose()
        raise database_error(engine.url, e) from None
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

            engine = sa.create_engine("sqlite://", poolclass=StaticPool, connect_args={"check_same_thread": False})
            metadata.create_all(engine)
            _empty = engine
        return _empty


def database_error(url: str | URL, error: BaseException, doing: str = "use") -> TraceDatabaseError:
    """A `TraceDatabaseError` "cannot {doing} database URL: first line of the driver's message"
    for a SQLAlchemy or driver `error` (password hidden)."""
    text = str(getattr(error, "orig", None) or error).strip()
    reason = text.splitlines()[0] if text else type(error).__name__
    return TraceDatabaseError(f"cannot {doing} database {display_url(url)}: {reason}")


def ensure_schema(engine: Engine) -> None:
    """Create the trace tables and indexes that do not exist yet and add the columns an older
    schema lacks (idempotent, concurrent-safe). A failed migration (e.g. a read-only file) is
    logged, not raised: reading such a database still works (`present_columns`)."""
    for attempt in range(3):
        try:
            metadata.create_all(engine, checkfirst=True)
            break
        except (sa_exc.IntegrityError, sa_exc.ProgrammingError, sa_exc.OperationalError) as e:
            text = str(e).lower()
            if "readonly" in text or "read-only" in text:
                # a database opened read-only cannot get the tables a newer schema added (e.g.
                # the experiment tables): reading what it has still works
                log.warning("trace database %s is read-only: tables of a newer schema not created", engine.url)
                break
            # another process created a table between our check and our CREATE
            if attempt == 2 or "already exists" not in text and "duplicate" not in text:
                raise
            log.debug("schema creation raced with another process; retrying: %s", e)
    migrate_experiment_runs(engine)
    _add_missing_columns(engine)


_present: weakref.WeakKeyDictionary[Engine, dict[str, frozenset[str]]] = weakref.WeakKeyDictionary()


def present_columns(engine: Engine, table: sa.Table) -> frozenset[str]:
    """The names of the columns `table` has in the database of `engine` (cached per engine):
    all of them after a migration, fewer in an old database that could not be migrated."""
    known = _present.setdefault(engine, {})
    columns = known.get(table.name)
    if columns is None:
        columns = frozenset(c["name"] for c in sa.inspect(engine).get_columns(table.name))
        known[table.name] = columns
    return columns


def _add_missing_columns(engine: Engine) -> None:
    """ALTER TABLE ... ADD COLUMN for every column of `metadata` an existing table lacks."""
    for table in metadata.sorted_tables:
        if not sa.inspect(engine).has_table(table.name):
            continue  # a read-only database without a table of a newer schema: nothing to add to
        for attempt in range(2):
            _present.get(engine, {}).pop(table.name, None)
            missing = [c for c in table.columns if c.name not in present_columns(engine, table)]
            if not missing:
                break
            try:
                with engine.begin() as conn:
                    for column in missing:
                        kind = column.type.compile(dialect=engine.dialect)
                        conn.exec_driver_sql(
                            f"ALTER TABLE {table.name} ADD COLUMN "
                            f"{engine.dialect.identifier_preparer.quote(column.name)} {kind}"
                        )
                log.info(
                    "trace database %s: added %s to %s",
                    display_url(engine.url),
                    ", ".join(c.name for c in missing),
                    table.name,
                )
            except sa_exc.DBAPIError as e:
                text = str(e).lower()
                if attempt == 0 and ("duplicate" in text or "already exists" in text):
                    continue  # another process added them first: look again
                log.warning(
                    "cannot add the columns %s to %s in %s (an older schema; reading still works): %s",
                    ", ".join(c.name for c in missing),
                    table.name,
                    display_url(engine.url),
                    str(getattr(e, "orig", e)).strip(),
                )
                break
        _present.get(engine, {}).pop(table.name, None)


def migrate_experiment_runs(engine: Engine) -> bool:
    """Bring a `pycram_experiment_runs` table of schema 4 (no ``environment`` column; a run's
    environment after ``@`` in its ``variant``) to schema 5: the column added, ``"faults@env"``
    split into ``variant`` ``"faults"`` and ``environment`` ``"env"`` (``""`` where there was no
    ``@``), the run's key made (experiment, robot, seed, variant, environment). Every run is kept.

    SQLite cannot change a table's constraints, so the table is rebuilt (copied into a new one,
    which replaces it) inside one ``BEGIN IMMEDIATE`` transaction; PostgreSQL alters it in one
    transaction holding an exclusive lock on it. Either way another process migrating at the same
    time waits, then finds the work done. Returns True when this call migrated the table; a
    failure (e.g. a read-only file) is logged, not raised: readers of the old layout still work
    (`present_columns` tells them which it has)."""
    name = experiment_runs_table.name
    inspector = sa.inspect(engine)
    if not inspector.has_table(name) or "environment" in {c["name"] for c in inspector.get_columns(name)}:
        return False
    try:
        if engine.dialect.name == "sqlite":
            migrated = _migrate_sqlite(engine)
        else:
            migrated = _migrate_postgresql(engine)
    except (sa_exc.DBAPIError, sqlite3.Error) as e:  # the SQLite rebuild runs on the driver's cursor
        log.warning(
            "cannot migrate %s in %s to schema %d (the environment of each run in a column of its own); "
            "reading still works: %s",
            name,
            display_url(engine.url),
            SCHEMA_VERSION,
            str(getattr(e, "orig", e)).strip(),
        )
        return False
    finally:
        _present.get(engine, {}).pop(name, None)
    if migrated:
        log.info("trace database %s: moved the environments of experiment runs into their own column", engine.url)
    return migrated


def _split_sql(column: str, find: str, part: str) -> str:
    """SQL for the variant (`part` "variant") or environment ("environment") of a schema-4
    ``variant`` column value, with `find` the dialect's function `find(column, '@')`."""
    at = f"{find}({column}, '{_OLD_ENVIRONMENT_SEPARATOR}')"
    if part == "variant":
        return f"CASE WHEN {at} > 0 THEN substr({column}, 1, {at} - 1) ELSE {column} END"
    return f"CASE WHEN {at} > 0 THEN substr({column}, {at} + 1) ELSE '' END"


def _migrate_sqlite(engine: Engine) -> bool:
    """The schema-5 rebuild of `pycram_experiment_runs` in SQLite (see `migrate_experiment_runs`)."""
    from sqlalchemy.schema import CreateTable

    name = experiment_runs_table.name
    staging = f"{name}_migrating"
    staged = sa.MetaData()
    experiments_table.to_metadata(staged)  # what the copy's foreign key refers to
    new = experiment_runs_table.to_metadata(staged, name=staging)
    raw = engine.raw_connection()
    try:
        dbapi: Any = raw.driver_connection
        isolation = dbapi.isolation_level
        dbapi.isolation_level = None  # transactions by hand: DDL would otherwise commit on its own
        cursor = dbapi.cursor()
        try:
            cursor.execute("BEGIN IMMEDIATE")  # the write lock: a concurrent migration waits here
            try:
                old = [row[1] for row in cursor.execute(f"PRAGMA table_info({name})").fetchall()]
                if "environment" in old:
                    cursor.execute("ROLLBACK")
                    return False  # another process migrated it while we waited
                copied = [c.name for c in experiment_runs_table.columns if c.name in old]
                values = [_split_sql("variant", "instr", "variant") if c == "variant" else c for c in copied]
                cursor.execute(f"DROP TABLE IF EXISTS {staging}")
                cursor.execute(str(CreateTable(new).compile(dialect=engine.dialect)))
                cursor.execute(
                    f"INSERT INTO {staging} ({', '.join(copied)}, environment) "
                    f"SELECT {', '.join(values)}, {_split_sql('variant', 'instr', 'environment')} FROM {name}"
                )
                cursor.execute(f"DROP TABLE {name}")
                cursor.execute(f"ALTER TABLE {staging} RENAME TO {name}")
                cursor.execute("COMMIT")
            except BaseException:
                cursor.execute("ROLLBACK")
                raise
        finally:
            cursor.close()
            dbapi.isolation_level = isolation
    finally:
        raw.close()
    return True


def _migrate_postgresql(engine: Engine) -> bool:
    """The schema-5 change of `pycram_experiment_runs` in PostgreSQL (see `migrate_experiment_runs`)."""
    name = experiment_runs_table.name
    with engine.begin() as conn:
        conn.exec_driver_sql(f"LOCK TABLE {name} IN ACCESS EXCLUSIVE MODE")  # concurrent migrations wait
        present = set(
            conn.execute(
                sa.text(
                    "SELECT column_name FROM information_schema.columns "
                    "WHERE table_name = :name AND table_schema = current_schema()"
                ),
                {"name": name},
            ).scalars()
        )
        if "environment" in present:
            return False
        conn.exec_driver_sql(f"ALTER TABLE {name} ADD COLUMN environment VARCHAR(512) NOT NULL DEFAULT ''")
        # the old key first: without the environment, runs in two environments would collide
        conn.exec_driver_sql(f"ALTER TABLE {name} DROP CONSTRAINT IF EXISTS {_OLD_RUN_KEY}")
        conn.exec_driver_sql(
            f"UPDATE {name} SET environment = {_split_sql('variant', 'strpos', 'environment')}, "
            f"variant = {_split_sql('variant', 'strpos', 'variant')} "
            f"WHERE strpos(variant, '{_OLD_ENVIRONMENT_SEPARATOR}') > 0"
        )
        conn.exec_driver_sql(
            f"ALTER TABLE {name} ADD CONSTRAINT uq_pycram_experiment_runs_run "
            "UNIQUE (experiment_id, robot, seed, variant, environment)"
        )
    return True
