"""Experiments in the trace database: one row per experiment, one per finished run.

The tables are `pycram_experiments` and `pycram_experiment_runs` of the trace schema
(`pycram.trace.db`: schema 4 created them, schema 5 gave each run an ``environment`` column;
both are brought about in older databases on connect). Only the process driving an experiment
writes these rows (the scenario runs themselves record their traces into the same database):
every result is committed as soon as it arrives, so an interrupted experiment keeps every run
that finished, and `finished_keys` tells a resumed one what is left to do.

A run is keyed by (robot, seed, variant, environment): the variant is its fault set
(`variant_key`), the environment the name it ran in (`pycram experiment --env`), ``""`` for
the scenario's own (an experiment without ``--env``). A database of schema 4 that could not be
migrated (a read-only file) is still read: there the environment is split off the variant
column (`split_variant`).
"""

from __future__ import annotations

import datetime as _dt
import json
import logging
import os
import socket
import sys
from dataclasses import dataclass, field
from typing import Any

import sqlalchemy as sa
from sqlalchemy import exc as sa_exc
from sqlalchemy.engine import Engine

from pycram.trace.db import (
    TraceDatabaseError,
    connect,
    database_error,
    display_url,
    experiment_runs_table,
    experiments_table,
    present_columns,
)

log = logging.getLogger(__name__)

__all__ = [
    "ExperimentRecord",
    "RunRecord",
    "ExperimentNotFound",
    "variant_key",
    "RunKey",
    "ENVIRONMENT_SEPARATOR",
    "split_variant",
    "create_experiment",
    "find_experiment",
    "finished_keys",
    "record_run",
    "run_records",
    "set_status",
]


class ExperimentNotFound(LookupError):
    """No experiment with that id or name is recorded; the message names the recorded ones."""


def variant_key(faults: frozenset[str] | list[str] | tuple[str, ...]) -> str:
    """The variant a fault set stands for, as stored: sorted fault names joined by "," ("" for none)."""
    return ",".join(sorted(set(faults)))


#: A run of an experiment: (robot, seed, variant key, environment -- "" for the scenario's own).
RunKey = tuple[str, int, str, str]

#: How trace schema 4 stored a run's environment: after this in its `variant` column
#: ("moved,taken@procedural:3"); schema 5 has a column for it (databases are migrated on connect).
ENVIRONMENT_SEPARATOR = "@"


def split_variant(column: str) -> tuple[str, str | None]:
    """(variant key, environment or None) of a `variant` column as schema 4 wrote it
    ("faults@environment", or the variant key alone)."""
    variant, separator, environment = column.partition(ENVIRONMENT_SEPARATOR)
    return (variant, environment if separator else None)


@dataclass(frozen=True)
class ExperimentRecord:
    """A recorded experiment: its id, name, scenario spec, robots, seeds and variants (each a
    sorted tuple of fault names), its status and when it was created."""

    id: int
    name: str
    scenario: str
    robots: tuple[str, ...]
    seeds: tuple[int, ...]
    variants: tuple[tuple[str, ...], ...]
    status: str | None = None
    created_at: _dt.datetime | None = None
    #: How its simulations kept time with the plans ("lockstep" or "free"); experiments recorded
    #: before PyCRAM stored it ran free.
    stepping: str = "free"
    #: The environments its runs run in (`pycram experiment --env`): every robot, seed and
    #: variant in each; empty: the scenario's own environment.
    environments: tuple[str, ...] = ()

    def keys(self) -> list[RunKey]:
        """Every run of the experiment as (robot, seed, variant key, environment: "" for the
        scenario's own when the experiment has no environments), in the order they run: per
        variant, per environment, per robot, by seed."""
        return [
            (robot, seed, variant_key(variant), environment)
            for variant in self.variants
            for environment in (self.environments or ("",))
            for robot in self.robots
            for seed in self.seeds
        ]


@dataclass(frozen=True)
class RunRecord:
    """A finished run of an experiment, as recorded."""

    robot: str
    seed: int
    variant: str  # the variant key (fault names)
    status: str
    success: bool
    failure_causes: list[str] = field(default_factory=list)
    sim_time: float | None = None
    wall_time: float | None = None
    trace_run_id: int | None = None
    error: str | None = None
    result: dict[str, Any] = field(default_factory=dict)
    #: The environment it ran in, for experiments with environments (`pycram experiment --env`).
    environment: str | None = None


def _now() -> _dt.datetime:
    return _dt.datetime.now(_dt.UTC)


def _engine(url: str | None) -> Engine:
    return connect(url, cached=True)


def _experiment_from_row(row: Any) -> ExperimentRecord:
    return ExperimentRecord(
        id=row.id,
        name=row.name,
        scenario=row.scenario,
        robots=tuple(json.loads(row.robots)),
        seeds=tuple(json.loads(row.seeds)),
        variants=tuple(tuple(v) for v in json.loads(row.variants)),
        status=row.status,
        created_at=row.created_at,
        stepping=_info(row.info).get("stepping", "free"),
        environments=tuple(_info(row.info).get("environments", ())),
    )


def _info(text: str | None) -> dict[str, Any]:
    try:
        info = json.loads(text) if text else {}
    except ValueError:
        return {}
    return info if isinstance(info, dict) else {}


def find_experiment(url: str | None, ref: str | int) -> ExperimentRecord:
    """The experiment with id or name `ref`. Raises `ExperimentNotFound` (naming the newest
    recorded experiments) or `TraceDatabaseError`."""
    engine = _engine(url)
    table = experiments_table
    text = str(ref).strip()
    try:
        with engine.connect() as conn:
            row = conn.execute(sa.select(table).where(table.c.name == text)).first()
            if row is None and text.isdigit():
                row = conn.execute(sa.select(table).where(table.c.id == int(text))).first()
            if row is None:
                known = conn.execute(sa.select(table.c.id, table.c.name).order_by(table.c.id.desc()).limit(10)).all()
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "read") from None
    if row is None:
        listed = ", ".join(f"{r.id} ({r.name})" for r in known) or "none yet"
        raise ExperimentNotFound(f"no experiment {text!r} in the trace database; recorded experiments: {listed}")
    return _experiment_from_row(row)


def create_experiment(
    url: str | None,
    name: str,
    scenario: str,
    robots: list[str],
    seeds: list[int],
    variants: list[tuple[str, ...]],
    command: str | None = None,
    stepping: str = "lockstep",
    environments: list[str] | tuple[str, ...] = (),
) -> ExperimentRecord:
    """Record a new experiment whose runs simulate with `stepping`, in `environments` (empty:
    the scenario's own); raises `TraceDatabaseError` (also when the name is taken)."""
    info: dict[str, Any] = {"stepping": stepping}
    if environments:
        info["environments"] = list(environments)
    engine = _engine(url)
    values = {
        "name": name,
        "scenario": scenario,
        "robots": json.dumps(list(robots)),
        "seeds": json.dumps(list(seeds)),
        "variants": json.dumps([sorted(v) for v in variants]),
        "created_at": _now(),
        "updated_at": _now(),
        "status": "running",
        "host": socket.gethostname(),
        "command": command if command is not None else " ".join(sys.argv),
        "info": json.dumps(info),
    }
    try:
        with engine.begin() as conn:
            conn.execute(sa.insert(experiments_table).values(**values))
    except sa_exc.IntegrityError:
        raise TraceDatabaseError(f"an experiment named {name!r} exists already") from None
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "write to") from None
    return find_experiment(url, name)


def set_status(url: str | None, experiment_id: int, status: str) -> None:
    """Set the experiment's status ("running", "interrupted", "finished")."""
    engine = _engine(url)
    try:
        with engine.begin() as conn:
            conn.execute(
                sa.update(experiments_table)
                .where(experiments_table.c.id == experiment_id)
                .values(status=status, updated_at=_now())
            )
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "write to") from None


def _has_environments(engine: Engine) -> bool:
    """Whether the runs table has its `environment` column (schema 5; False only in a database
    of schema 4 that could not be migrated, e.g. a read-only file)."""
    return "environment" in present_columns(engine, experiment_runs_table)


def _key_columns(engine: Engine) -> list[Any]:
    table = experiment_runs_table
    columns = [table.c.robot, table.c.seed, table.c.variant]
    return columns + [table.c.environment] if _has_environments(engine) else columns


def _variant_environment(row: Any) -> tuple[str, str]:
    """(variant key, environment: "" for the scenario's own) of a run's row, in either schema."""
    environment = getattr(row, "environment", None)
    if environment is not None:
        return row.variant, environment
    variant, old = split_variant(row.variant)
    return variant, old or ""


def finished_keys(url: str | None, experiment_id: int, *, errors: bool = False) -> set[RunKey]:
    """(robot, seed, variant key, environment) of every run of the experiment recorded as
    finished (status "done"); with `errors` also those whose scenario raised (status "error",
    which a resumed experiment runs again)."""
    table = experiment_runs_table
    engine = _engine(url)
    statuses = ("done", "error") if errors else ("done",)
    try:
        with engine.connect() as conn:
            rows = conn.execute(
                sa.select(*_key_columns(engine)).where(
                    table.c.experiment_id == experiment_id, table.c.status.in_(statuses)
                )
            ).all()
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "read") from None
    return {(r.robot, r.seed, *_variant_environment(r)) for r in rows}


def record_run(
    url: str | None,
    experiment_id: int,
    robot: str,
    seed: int,
    variant: str,
    result: dict[str, Any],
    environment: str = "",
) -> None:
    """Commit one finished run in `environment` ("" for the scenario's own): the scenario's
    `result` dict (with `error` set when the scenario raised; its trace's run id as
    ``trace_run_id`` or ``run_id``). A run recorded as "error" before is replaced; one recorded
    as "done" is kept. Raises `TraceDatabaseError` (also for a database of schema 4 that could
    not be migrated: it cannot hold the environment)."""
    table = experiment_runs_table
    error = result.get("error")
    trace = result.get("trace_run_id", result.get("run_id"))
    engine = _engine(url)
    if not _has_environments(engine):
        raise TraceDatabaseError(
            f"the trace database {display_url(engine.url)} has the schema of an older PyCRAM and could not be "
            "migrated (is it read-only?): experiment runs cannot be recorded in it"
        )
    values = {
        "experiment_id": experiment_id,
        "robot": robot,
        "seed": int(seed),
        "variant": variant,
        "environment": environment or "",
        "status": "error" if error else "done",
        "success": bool(result.get("success")) and not error,
        "failure_causes": json.dumps(list(result.get("failure_causes") or [])),
        "sim_time": _number(result.get("sim_time")),
        "wall_time": _number(result.get("wall_time")),
        "trace_run_id": int(trace) if isinstance(trace, int) else None,
        "error": error,
        "result": json.dumps(result, default=str),
        "worker": result.get("worker") or f"{socket.gethostname()}:{os.getpid()}",
        "finished_at": _now(),
    }
    try:
        with engine.begin() as conn:
            conn.execute(
                sa.delete(table).where(
                    table.c.experiment_id == experiment_id,
                    table.c.robot == robot,
                    table.c.seed == int(seed),
                    table.c.variant == variant,
                    table.c.environment == (environment or ""),
                    table.c.status == "error",
                )
            )
            conn.execute(sa.insert(table).values(**values))
    except sa_exc.IntegrityError:
        log.warning(
            "run %s seed %s (faults %s, environment %s) of experiment %s was recorded already",
            robot,
            seed,
            variant or "none",
            environment or "its own",
            experiment_id,
        )
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "write to") from None


def run_records(url: str | None, experiment_id: int) -> list[RunRecord]:
    """The recorded runs of the experiment, by variant, environment, robot and seed (each with
    its `environment`, None for the scenario's own)."""
    table = experiment_runs_table
    engine = _engine(url)
    columns = [c for c in table.columns if c.name in present_columns(engine, table)]
    try:
        with engine.connect() as conn:
            rows = conn.execute(sa.select(*columns).where(table.c.experiment_id == experiment_id)).all()
    except sa_exc.SQLAlchemyError as e:
        raise database_error(engine.url, e, "read") from None
    runs = sorted(((r, *_variant_environment(r)) for r in rows), key=lambda x: (x[1], x[2], x[0].robot, x[0].seed))
    return [
        RunRecord(
            robot=r.robot,
            seed=r.seed,
            variant=variant,
            status=r.status,
            success=bool(r.success),
            failure_causes=json.loads(r.failure_causes or "[]"),
            sim_time=r.sim_time,
            wall_time=r.wall_time,
            trace_run_id=r.trace_run_id,
            error=r.error,
            result=json.loads(r.result or "{}"),
            environment=environment or None,
        )
        for r, variant, environment in runs
    ]


def _number(value: Any) -> float | None:
    try:
        return float(value) if value is not None else None
    except (TypeError, ValueError):
        return None
