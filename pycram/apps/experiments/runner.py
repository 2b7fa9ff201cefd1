"""Running an experiment: many headless scenario runs, in local worker processes or on Ray.

`prepare_experiment` checks the input (scenario, robots, seeds, faults; `ExperimentInputError`
names the valid choices) and creates the experiment in the trace database, or finds the one to
resume; `run_experiment` runs what is left of it and records each result as it arrives.

Guarantees
----------
- Local runs use a `ProcessPoolExecutor` with the *spawn* start method (MuJoCo and threads do
  not survive `fork`); its workers ignore SIGINT, so a Ctrl-C reaches only the driver.
- On Ray each run is one task (`num_cpus=1`, no retries).
- Only the driver writes the experiment's rows (`pycram.apps.experiments.store`); each result is
  committed as soon as it arrives. The scenario runs record their own traces (task trees)
  into the same database: always for PostgreSQL; for SQLite only when every worker is on this
  machine (a SQLite file cannot be shared with other hosts; a warning says so and the runs
  are not traced then). Why the driver writes the results: one writer per experiment works
  for SQLite as for PostgreSQL, needs no database access from the cluster, and makes "a run
  is finished" exactly "its result is recorded", which is what resuming relies on.
- When `stop.requested` becomes true (Ctrl-C in `pycram experiment`), no further run starts;
  the runs under way finish and are recorded (a Ray task is cancelled instead), then
  `run_experiment` returns with `interrupted` set. Every recorded run stays recorded;
  `--resume` runs the others.
- A scenario that raises is recorded with status "error" (a failure whose cause is the
  exception's type; the report counts it) and a resumed experiment runs it again; a run that
  was interrupted, or whose worker died, is not recorded.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import inspect
import json
import logging
import os
import re
import signal
import socket
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pycram.apps.experiments.scenarios import (
    RunInterrupted,
    Scenario,
    UnknownScenario,
    accepts_keyword,
    get_scenario,
)
from pycram.apps.run_options import check_stepping
from pycram.core.process_lifetime import end_with_parent
from pycram.core.runtime.lockstep import DEFAULT_STEPPING
from pycram.world.robot_registry import DEFAULT_ROBOT

log = logging.getLogger(__name__)

__all__ = [
    "ExperimentInputError",
    "RayUnavailable",
    "PreparedExperiment",
    "ExperimentOutcome",
    "RunKey",
    "parse_seeds",
    "parse_environments",
    "MAX_ENVIRONMENTS",
    "parse_list",
    "parse_variants",
    "prepare_experiment",
    "run_experiment",
    "execute_run",
    "ray_runtime_env",
    "ray_session",
    "MAX_SEEDS",
]

#: At most this many seeds per experiment (a typo like 1-2000000 is refused, not started).
MAX_SEEDS = 100_000

#: At most this many environments per experiment (`--env procedural:1-50`).
MAX_ENVIRONMENTS = 10_000

#: A run of an experiment: (robot, seed, variant -- sorted fault names joined by ",", environment
#: -- its name with `--env`, "" for the scenario's own); `pycram.apps.experiments.store.RunKey`.
RunKey = tuple[str, int, str, str]


class ExperimentInputError(ValueError):
    """Bad input for an experiment (unknown scenario, robot or fault, bad seed range, a resume
    that does not match): the message says what is wrong and names the valid choices."""


class RayUnavailable(RuntimeError):
    """`--ray` was asked for but Ray is not installed (the `ray` extra) or cannot be reached."""


def parse_seeds(text: str) -> list[int]:
    """Seeds from "1-200", "7" or "1,5,10-12" (inclusive ranges of non-negative integers),
    in the order given, without repeats. Raises `ExperimentInputError`."""
    seeds: dict[int, None] = {}
    parts = [p.strip() for p in str(text).split(",")]
    hint = "expected e.g. 1-200, 7 or 1,5,10-12 (non-negative integers; ranges include both ends)"
    if not any(parts):
        raise ExperimentInputError(f"bad seed range {text!r}: {hint}")
    for part in parts:
        match = re.fullmatch(r"(\d+)(?:\s*-\s*(\d+))?", part)
        if match is None:
            raise ExperimentInputError(f"bad seed range {text!r}: {part!r} is not a seed or a range; {hint}")
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        if last < first:
            raise ExperimentInputError(f"bad seed range {text!r}: {part!r} ends before it starts; {hint}")
        if len(seeds) + (last - first + 1) > MAX_SEEDS:
            raise ExperimentInputError(f"bad seed range {text!r}: more than {MAX_SEEDS} seeds")
        for seed in range(first, last + 1):
            seeds[seed] = None
    return list(seeds)


def parse_environments(text: str) -> list[str]:
    """Environment names from a comma-separated list in which ``procedural:`` takes seeds and
    ranges as `parse_seeds` does: "procedural:1-50", "apartment,procedural:3",
    "procedural:1,5,10-12" (numbers after a ``procedural:`` entry continue it). In the order
    given, without repeats; each is checked (`pycram.environments.check_name`). Raises
    `ExperimentInputError` naming the valid names."""
    from pycram.environments import PROCEDURAL_PREFIX, check_name

    names: dict[str, None] = {}
    hint = "e.g. procedural:1-50, apartment,procedural:3 or file:kitchen.toml"
    procedural = False  # whether a bare number continues a procedural: entry
    for part in (p.strip() for p in str(text).split(",")):
        if not part:
            continue
        spec = part[len(PROCEDURAL_PREFIX) :] if part.startswith(PROCEDURAL_PREFIX) else part
        numbers = re.fullmatch(r"(\d+)\s*-\s*(\d+)", spec) or re.fullmatch(r"(\d+)", spec)
        if part.startswith(PROCEDURAL_PREFIX) or (procedural and numbers is not None):
            procedural = True
            if numbers is None:
                raise ExperimentInputError(f"bad --env {text!r}: {part!r} is not procedural:SEED or a range; {hint}")
            first = int(numbers.group(1))
            last = int(numbers.group(2)) if numbers.lastindex == 2 else first
            if last < first:
                raise ExperimentInputError(f"bad --env {text!r}: {part!r} ends before it starts; {hint}")
            if len(names) + (last - first + 1) > MAX_ENVIRONMENTS:
                raise ExperimentInputError(f"bad --env {text!r}: more than {MAX_ENVIRONMENTS} environments")
            names.update((f"{PROCEDURAL_PREFIX}{seed}", None) for seed in range(first, last + 1))
            continue
        procedural = False
        try:
            names[check_name(part)] = None
        except KeyError as e:
            raise ExperimentInputError(f"bad --env {text!r}: {str(e).strip(chr(34) + chr(39))}") from None
    if not names:
        raise ExperimentInputError(f"bad --env {text!r}: no environment given; {hint}")
    return list(names)


def parse_list(text: str) -> list[str]:
    """The non-empty, stripped items of a comma-separated list, without repeats, in order."""
    return list(dict.fromkeys(item.strip() for item in str(text).split(",") if item.strip()))


def parse_variants(values: Iterable[str], known: tuple[str, ...] | None) -> list[tuple[str, ...]]:
    """Variants from `--faults` values: each value is one variant, a comma-separated fault set;
    "none" (or "") is the variant without faults, "all" every fault the scenario knows. No
    value: one variant without faults. Fault names are checked against `known` (when the
    scenario says which it knows). Raises `ExperimentInputError`."""
    variants: dict[tuple[str, ...], None] = {}
    for value in list(values) or ["none"]:
        names = parse_list(value)
        if names in ([], ["none"]):
            variants[()] = None
            continue
        if names == ["all"]:
            if known is None:
                raise ExperimentInputError("--faults all: this scenario does not say which faults it knows")
            names = list(known)
        if known is not None:
            unknown = [n for n in names if n not in known]
            if unknown:
                raise ExperimentInputError(
                    f"unknown fault(s) {', '.join(unknown)}; this scenario knows: {', '.join(known) or 'none'} "
                    "(or 'none', 'all')"
                )
        variants[tuple(sorted(set(names)))] = None
    return list(variants)


@dataclass
class PreparedExperiment:
    """An experiment ready to run: its record, the scenario, the database and what is left."""

    record: Any  # pycram.apps.experiments.store.ExperimentRecord
    scenario: Scenario
    db: str | None
    todo: list[RunKey]
    done_before: int  # runs recorded before this invocation
    resumed: bool

    @property
    def stepping(self) -> str:
        """How the runs' simulations keep time with their plans (the record's; the default when
        only checked)."""
        return self.record.stepping if self.record is not None else DEFAULT_STEPPING


@dataclass
class ExperimentOutcome:
    """What `run_experiment` did: runs recorded now, runs not finished, whether it was stopped."""

    recorded: int = 0
    not_finished: list[RunKey] = field(default_factory=list)
    interrupted: bool = False
    wall_time: float = 0.0  # [s]
    traced: bool = True  # whether the runs recorded their traces into the database
    errors: list[str] = field(default_factory=list)  # why runs were lost (a worker died, ...)


def _default_name(scenario: str) -> str:
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "-", scenario.rsplit(":", 1)[-1]).strip("-") or "experiment"
    return f"{stem}-{_dt.datetime.now().strftime('%Y%m%d-%H%M%S')}"


def prepare_experiment(
    *,
    scenario: str | None = None,
    robots: str | None = None,
    seeds: str | None = None,
    faults: list[str] | None = None,
    name: str | None = None,
    resume: str | None = None,
    db: str | None = None,
    command: str | None = None,
    check_only: bool = False,
    stepping: str | None = None,
    environments: str | None = None,
) -> PreparedExperiment:
    """Check the input and create the experiment in the database, or find the one to resume.

    `resume` (an id or name) continues a recorded experiment: the options given must match it
    (those left out are taken from it). A `name` that is recorded already resumes that
    experiment when the options match. With `check_only`, only checks: nothing is created and
    the result's `record` is the experiment to resume or None. `stepping` ("lockstep", the default
    for a new experiment, or "free") is how its simulations keep time with the plans; a resumed
    experiment keeps its own. `environments` (`parse_environments`: "procedural:1-50", ...) runs
    every robot, seed and variant in each of them; a scenario that takes no ``environment``
    keyword runs in its own only. Raises `ExperimentInputError` for bad input,
    `pycram.trace.db.TraceDatabaseError` when the database cannot be used.
    """
    from pycram.apps.experiments import store

    existing = None
    if resume is not None:
        try:
            existing = store.find_experiment(db, resume)
        except store.ExperimentNotFound as e:
            raise ExperimentInputError(str(e)) from None
    elif name is not None:
        try:
            existing = store.find_experiment(db, name)
        except store.ExperimentNotFound:
            existing = None
    if stepping is not None:
        try:
            check_stepping(stepping)
        except ValueError as error:
            raise ExperimentInputError(str(error)) from None
    spec = scenario if scenario is not None else existing.scenario if existing is not None else "thesis"
    try:
        entry = get_scenario(spec)
    except UnknownScenario as e:
        raise ExperimentInputError(str(e)) from None
    robot_list = parse_list(robots) if robots is not None else list(existing.robots) if existing else [DEFAULT_ROBOT]
    if not robot_list:
        raise ExperimentInputError(f"--robot: no robot given; available robots: {', '.join(entry.robots)}")
    unknown = [r for r in robot_list if r not in entry.robots]
    if unknown:
        raise ExperimentInputError(
            f"unknown robot(s) {', '.join(unknown)}; available robots: {', '.join(entry.robots)}"
        )
    if seeds is not None:
        seed_list = parse_seeds(seeds)
    elif existing is not None:
        seed_list = list(existing.seeds)
    else:
        raise ExperimentInputError("--seeds is missing: which seeds to run, e.g. --seeds 1-200")
    try:
        known = entry.known_faults()
    except UnknownScenario as e:
        raise ExperimentInputError(str(e)) from None
    if faults:
        variants = parse_variants(faults, known)
    elif existing is not None:
        variants = [tuple(v) for v in existing.variants]
    else:
        variants = parse_variants([], known)
    if environments is not None:
        environment_list = parse_environments(environments)
    elif existing is not None:
        environment_list = list(existing.environments)
    else:
        environment_list = []
    _check_environments(entry, environment_list)
    if existing is not None and list(existing.environments) != environment_list:
        raise ExperimentInputError(
            f"experiment {existing.id} ({existing.name}) was recorded with --env "
            f"{','.join(existing.environments) or 'none (the scenario own)'}; these environments differ (leave "
            "--env out to resume it, or choose another --name)"
        )
    if existing is not None and stepping is not None and stepping != existing.stepping:
        raise ExperimentInputError(
            f"experiment {existing.id} ({existing.name}) was recorded with --stepping {existing.stepping}, not "
            f"{stepping} (leave --stepping out to resume it, or choose another --name)"
        )
    if existing is not None:
        given = (entry.name, robot_list, seed_list, variants)
        stored = (existing.scenario, list(existing.robots), list(existing.seeds), [tuple(v) for v in existing.variants])
        if given != stored:
            raise ExperimentInputError(
                f"experiment {existing.id} ({existing.name}) was recorded as scenario {existing.scenario}, "
                f"robots {','.join(existing.robots)}, {len(existing.seeds)} seeds, variants "
                f"{_variants_text(existing.variants)}; these options differ (leave them out to resume it, "
                "or choose another --name)"
            )
        record = existing
    elif check_only:
        return PreparedExperiment(None, entry, db, [], 0, False)
    else:
        record = store.create_experiment(
            db,
            name or _default_name(entry.name),
            entry.name,
            robot_list,
            seed_list,
            variants,
            command,
            stepping or DEFAULT_STEPPING,
            environment_list,
        )
    done = store.finished_keys(db, record.id)
    todo = [key for key in record.keys() if key not in done]
    return PreparedExperiment(record, entry, db, todo, len(done), existing is not None)


def _check_environments(entry: Scenario, environments: list[str]) -> None:
    """Refuse environments a scenario cannot run in: one that takes no ``environment`` keyword
    runs only in the environment it is written for."""
    if not environments:
        return
    try:
        takes = entry.takes_environment()
    except UnknownScenario as e:
        raise ExperimentInputError(str(e)) from None
    if takes:
        return
    others = [e for e in environments if e != entry.environment]
    if others:
        own = f"written for the {entry.environment} only" if entry.environment else "not told which environment"
        raise ExperimentInputError(
            f"--env: scenario {entry.name} is {own} (its function takes no 'environment' keyword), so it cannot "
            f"run in {', '.join(others[:3])}{' ...' if len(others) > 3 else ''}"
        )


def _variants_text(variants: Iterable[Iterable[str]]) -> str:
    return "; ".join(",".join(v) or "none" for v in variants)


# -- one run (in a worker process or a Ray task) --------------------------------------------------


def execute_run(
    scenario: str,
    robot: str,
    seed: int,
    variant: str,
    db: str | None,
    record: bool = True,
    stepping: str = DEFAULT_STEPPING,
    environment: str | None = None,
) -> dict[str, Any]:
    """Run the scenario named `scenario` once and return its result (JSON-serialisable).

    `stepping` is passed on to a scenario that takes it (every built-in one does); one that does
    not is run as it is, and refused (an error result) unless `stepping` is the default.
    `environment` (None: the scenario's own) is passed on as the ``environment`` keyword; a
    scenario that does not take it runs only in the environment it is written for (else an
    error result). The result says `environment`.

    Runs in a worker: the scenario is looked up by name or import path. An exception of the
    scenario becomes a result with `error` set and its type as the failure cause;
    `RunInterrupted` and `KeyboardInterrupt` propagate (the run is not finished).
    """
    os.environ.setdefault("MUJOCO_GL", "egl")
    faults = frozenset(f for f in variant.split(",") if f)
    previous = os.environ.get("PYCRAM_RECORD")
    if not record:
        os.environ["PYCRAM_RECORD"] = "0"
    started = time.monotonic()
    try:
        entry = get_scenario(scenario)
        function = entry.load()
        if os.environ.get("PYCRAM_VIEW_RUN"):  # `pycram experiment --view`: this run into the viewer
            from pycram.trace.view.session import viewed_run

            function = viewed_run(function, robot, seed, name=scenario)
        extra: dict[str, Any] = {}
        if environment is not None and accepts_keyword(function, "environment"):
            extra["environment"] = environment
        elif environment is not None and environment != entry.environment:
            raise ValueError(f"scenario {scenario} takes no 'environment' argument: it cannot run in {environment}")
        if _takes_stepping(function):
            result = dict(function(robot, seed, faults, db_url=db, pictures=False, stepping=stepping, **extra))
        elif stepping == DEFAULT_STEPPING:
            result = dict(function(robot, seed, faults, db_url=db, pictures=False, **extra))
        else:
            raise ValueError(f"scenario {scenario} takes no 'stepping' argument: it cannot run with {stepping!r}")
    except KeyboardInterrupt:
        raise
    except Exception as e:
        log.warning("scenario %s failed with an error for %s seed %s: %s", scenario, robot, seed, e, exc_info=True)
        result = {
            "success": False,
            "failure_causes": [type(e).__name__],
            "error": f"{type(e).__name__}: {e}",
            "wall_time": time.monotonic() - started,
        }
    finally:
        if not record:
            if previous is None:
                os.environ.pop("PYCRAM_RECORD", None)
            else:
                os.environ["PYCRAM_RECORD"] = previous
    result.setdefault("robot", robot)
    result.setdefault("seed", seed)
    result.setdefault("faults", sorted(faults))
    if environment is not None:
        result.setdefault("environment", environment)
    result.setdefault("wall_time", time.monotonic() - started)
    result["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    clean: dict[str, Any] = json.loads(json.dumps(result, default=str))
    return clean


def _takes_stepping(function: Any) -> bool:
    """Whether a scenario function takes a `stepping` keyword."""
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "stepping" or p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters)


def _worker_init(driver: int | None = None) -> None:
    """Local workers: Ctrl-C goes to the driver only (it stops the experiment in order); a worker
    ends when its driver dies however it dies (a killed driver leaves no run going on alone).
    `driver`: the driver's pid."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    end_with_parent(signal.SIGTERM, parent=driver)
    os.environ.setdefault("MUJOCO_GL", "egl")
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("pycram.demo").setLevel(logging.ERROR)  # a demo's story, once per run: noise here


# -- the driver ----------------------------------------------------------------------------------

#: Called after each run: its key and its result (None when it did not finish).
Progress = Callable[[RunKey, "dict[str, Any] | None"], None]


class _NoStop:
    requested = False


def run_experiment(
    prepared: PreparedExperiment,
    *,
    workers: int = 2,
    ray: str | None = None,
    stop: Any = None,
    progress: Progress | None = None,
) -> ExperimentOutcome:
    """Run what is left of `prepared` (see the module's guarantees); returns the outcome.

    `workers`: local worker processes (with `ray="local"`: the CPUs of the Ray instance
    started). `ray`: None for local workers, else a Ray address (`auto`, `host:port`,
    `ray://host:10001`) or `local` to start a Ray instance on this machine; an existing
    connection (`ray.is_initialized()`) is used as it is and left open. `stop`: an object whose
    `requested` attribute becomes true to stop (e.g. `pycram.core.interrupts.StopSignals`).
    Raises `RayUnavailable` when Ray is asked for but missing or unreachable.
    """
    from pycram.apps.experiments import store

    if workers < 1:
        raise ExperimentInputError(f"--workers must be at least 1, not {workers}")
    stop = stop if stop is not None else _NoStop()
    outcome = ExperimentOutcome()
    started = time.monotonic()
    record_id = prepared.record.id
    store.set_status(prepared.db, record_id, "running")

    def finished(key: RunKey, result: dict[str, Any] | None) -> None:
        if result is not None:
            store.record_run(prepared.db, record_id, key[0], key[1], key[2], result, environment=key[3])
            outcome.recorded += 1
        else:
            outcome.not_finished.append(key)
        if progress is not None:
            progress(key, result)

    try:
        if prepared.todo:
            if ray is None:
                _run_local(prepared, workers, stop, finished, outcome)
            else:
                _run_ray(prepared, ray, workers, stop, finished, outcome)
    finally:
        outcome.wall_time = time.monotonic() - started
        outcome.interrupted = bool(stop.requested)
        left = len(store.finished_keys(prepared.db, record_id, errors=True)) < len(prepared.record.keys())
        store.set_status(prepared.db, record_id, "interrupted" if left else "finished")
    return outcome


def _run_local(prepared: PreparedExperiment, workers: int, stop: Any, finished: Progress, outcome: Any) -> None:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=_worker_init, initargs=(os.getpid(),)
    )
    futures: dict[Any, RunKey] = {}
    try:
        for key in prepared.todo:
            future = pool.submit(
                execute_run,
                prepared.scenario.spec,
                key[0],
                key[1],
                key[2],
                prepared.db,
                True,
                prepared.stepping,
                key[3] or None,
            )
            futures[future] = key
        pending = set(futures)
        stopping = False
        while pending:
            done, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
            for future in done:
                finished(futures[future], _future_result(future, futures[future], outcome))
            if stop.requested and not stopping:
                stopping = True
                for future in pending:
                    if future.cancel():
                        finished(futures[future], None)
                pending = {f for f in pending if not f.cancelled()}
                if pending:
                    log.warning("stopping: waiting for the %d runs under way to finish", len(pending))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _future_result(future: Any, key: RunKey, outcome: ExperimentOutcome) -> dict[str, Any] | None:
    try:
        result: dict[str, Any] = future.result()
        return result
    except (RunInterrupted, KeyboardInterrupt):
        return None
    except Exception as e:  # the worker died (BrokenProcessPool), or the result could not be sent
        text = f"{key[0]} seed {key[1]}: {type(e).__name__}: {e}"
        log.error("run lost: %s", text)
        outcome.errors.append(text)
        return None


def ray_runtime_env() -> dict[str, Any]:
    """The runtime environment for a Ray instance started on this machine: its workers import
    the same `pycram` as this process (its folder first on `PYTHONPATH`)."""
    import pycram

    root = str(Path(pycram.__file__).resolve().parent.parent)
    path = os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH", "")) if p)
    return {"env_vars": {"PYTHONPATH": path, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}}


def _import_ray() -> Any:
    try:
        import ray
    except ImportError as e:
        raise RayUnavailable(
            f"--ray needs Ray, which is not installed ({e}); install the 'ray' extra: pip install 'pycram[ray]'"
        ) from None
    return ray


def _traces_reachable(ray: Any, db: str | None) -> bool:
    """Whether Ray's workers can record into `db`: PostgreSQL (any host) or SQLite with every
    node of the cluster on this machine."""
    from pycram.trace.db import sqlite_file

    if sqlite_file(db) is None:
        return True
    here = ray.util.get_node_ip_address()
    hosts = {n.get("NodeManagerAddress") for n in ray.nodes() if n.get("Alive")}
    return hosts <= {here}


@contextlib.contextmanager
def ray_session(address: str, workers: int = 2) -> Iterator[Any]:
    """Connect to Ray for the block and yield the `ray` module: to the cluster at `address`
    (`auto`, `HOST:PORT`, `ray://HOST:10001`), or, for `local`, to a new instance on this
    machine with `workers` CPUs. A connection made here is closed at the end (a local instance
    stops with it); an existing one (`ray.is_initialized()`) is used and left open.
    Raises `RayUnavailable` when Ray is missing or the cluster cannot be reached."""
    ray = _import_ray()
    if ray.is_initialized():
        yield ray
        return
    try:
        if address == "local":
            ray.init(
                num_cpus=workers,
                include_dashboard=False,
                runtime_env=ray_runtime_env(),
                logging_level=logging.WARNING,
            )
        else:
            ray.init(address=address, logging_level=logging.WARNING)
    except (ConnectionError, RuntimeError, ValueError) as e:
        ray.shutdown()
        raise RayUnavailable(f"cannot connect to the Ray cluster at {address!r}: {e}") from None
    try:
        yield ray
    finally:
        ray.shutdown()


def _run_ray(
    prepared: PreparedExperiment, address: str, workers: int, stop: Any, finished: Progress, outcome: Any
) -> None:
    with ray_session(address, workers) as ray:
        _run_ray_tasks(ray, prepared, stop, finished, outcome)


def _run_ray_tasks(ray: Any, prepared: PreparedExperiment, stop: Any, finished: Progress, outcome: Any) -> None:
    record = _traces_reachable(ray, prepared.db)
    if not record:
        outcome.traced = False
        log.warning(
            "the trace database is a SQLite file on this machine, which Ray workers on other hosts cannot "
            "write: the runs' traces are not recorded (their results are); use PostgreSQL (--db "
            "postgresql://...) to record them"
        )
    task = ray.remote(num_cpus=1, max_retries=0)(execute_run)
    refs: dict[Any, RunKey] = {}
    for key in prepared.todo:
        ref = task.remote(
            prepared.scenario.spec, key[0], key[1], key[2], prepared.db, record, prepared.stepping, key[3] or None
        )
        refs[ref] = key
    cancelled = False
    while refs:
        ready, _ = ray.wait(list(refs), num_returns=len(refs), timeout=0.25, fetch_local=True)
        for ref in ready:
            key = refs.pop(ref)
            finished(key, _ray_result(ray, ref, key, outcome))
        if stop.requested and not cancelled:
            cancelled = True
            for ref in refs:
                ray.cancel(ref)


def _ray_result(ray: Any, ref: Any, key: RunKey, outcome: ExperimentOutcome) -> dict[str, Any] | None:
    try:
        result: dict[str, Any] = ray.get(ref)
        return result
    except (ray.exceptions.TaskCancelledError, KeyboardInterrupt):
        return None
    except ray.exceptions.RayTaskError as e:
        if isinstance(getattr(e, "cause", None), KeyboardInterrupt):
            return None
        text = f"{key[0]} seed {key[1]}: {e}"
    except ray.exceptions.RayError as e:  # the worker died, the node was lost
        text = f"{key[0]} seed {key[1]}: {type(e).__name__}: {e}"
    log.error("run lost: %s", text.splitlines()[0])
    outcome.errors.append(text.splitlines()[0])
    return None
