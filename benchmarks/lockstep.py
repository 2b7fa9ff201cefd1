"""The price of lock-step (issue 31): simulated time / wall time of whole runs, free-running and
in lock-step, each beside the speed of stepping the same scene's physics alone.

For each robot, in one process:
- **physics alone**: after each run, `mj_step` on copies of that run's state taken every 2 s of
  its simulated time (the same model and the state then: robot, furniture, objects, motions,
  contacts, controls), `--physics` seconds of simulated time in all, nothing else running: the
  ceiling of that run;
- **thesis demo** (a theft, seed 3; no recording, no pictures): free and lock-step;
- **set-table** (seed 7; no faults, no pictures): free and lock-step;
- **experiment throughput** (`--throughput N`): the thesis scenario with a theft on seeds 1-N,
  in lock-step, with 1 and then 2 local worker processes: runs per minute of wall time, and
  whether every seed's result (simulated time, success) is the same with 1 and with 2 workers.
Each run prints its simulated time, its wall time, the speed (sim / wall) and that speed as a
share of physics alone, and a second table says where the wall time of each lock-step run
went (`World.time_spent()`: physics, controllers, starting commands -- IK, path planning,
perception's rendering --, publishing sensors, recording, and the plan's own code while the
world stood still; "other" is outside the loop: building the scene, closing; "loop overhead" is
the simulation loop's own work besides `mj_step`, as a share of that work without "plan": what
the simulation thread pays per step, which depends far less on how loaded the machine is than
the time spent handing the turn to plan threads and back); lock-step runs
also print their fingerprint, which repeats run after run
(free-running ones differ). The target of issue 31: a set-table run at >= 70 % of physics
alone in lock-step.

    MUJOCO_GL=egl .venv/bin/python benchmarks/lockstep.py [--robots pr2,tiago] [--repeat 2]
        [--physics 60] [--skip-set-table] [--throughput 8]

Numbers depend on the machine's load; run it on an otherwise idle machine for the record.

Measured (2-core machine, 2026-11-27; docs/simulator.md "What it costs" has the whole story):
idle, before the second pass of cuts: set-table 61-62 % of physics alone (PR2), 61-65 %
(TIAGo), thesis demo 36-43 %. The second pass (outlines in one pass, sensor values built when
read, cached servo and contact lookups) changed no fingerprint; beside 2-4 busy processes, as
alternating pairs before/after: PR2 set-table 43-49 % -> 53-54 % of physics alone, loop
overhead ~28 % -> ~21 %; thesis demo (PR2) loop overhead ~43 % -> ~35 %. A third pass (pulses
that leave a computed value None wake nobody; notifying nobody skips the clock's lock; the arm
path keeps its contact roles) cut the set-table run's hand-overs 1,926 -> 112 (PR2) and 1,770 ->
102 (TIAGo) and its simulation thread's CPU outside `mj_step` by ~7 % (PR2), fingerprints
unchanged; at load 9-10 the PR2 set-table run read 51-53 % of physics alone before and after.
The target of 70 % is not shown.

Idle machine (load 0.5-0.7), 2026-11-27, one run each: on b35c22d PR2 set-table 63 % of physics
alone, TIAGo 62 %, thesis demo 32 % / 35 %; on this stop's last commit (watchdog 2x cheaper;
perception measures square tops' turn, which changed the PR2 seed-7 run: 172.4 s simulated,
fingerprint 55179776a47e) PR2 62 %, TIAGo 61 % (d946f200b93e, unchanged), thesis 37 % / 34 %.
Physics is 67-70 % of a set-table run's wall time, the plan's reasoning 9-11 %, the loop's own
work 21-26 %: 70 % needs about a third of all non-physics work gone; no single part is that big.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")


#: `World.time_spent()` of the last world closed (see `_keep_time_spent`).
_SPENT: dict[str, float] = {}
#: Copies of the running world's state, one every `SAMPLE_PERIOD` of simulated time, with its
#: model and the number of physics steps per control tick (see `_keep_states`).
_STATES: list = []
SAMPLE_PERIOD = 2.0  # [s] of simulated time


def _keep_time_spent() -> None:
    """Keep the time spent by each world's simulation loop when the world is closed."""
    from pycram.backends.sim.world import World

    close = World.close

    def closing(self, *args, **kwargs):
        if self.running:
            _SPENT.clear()
            _SPENT.update(self.time_spent())
        return close(self, *args, **kwargs)

    World.close = closing


def _keep_states() -> None:
    """Keep a copy of the simulation's state (`MjData`) every `SAMPLE_PERIOD` of simulated time,
    taken in the simulation thread between two control ticks (a copy costs ~0.1 ms)."""
    import copy

    from pycram.backends.sim.engine import Engine

    step = Engine.step

    def stepping(self, nstep):
        if not _STATES or _STATES[-1][0] is not self.model:
            _STATES.clear()
        if not _STATES or self.data.time >= _STATES[-1][1].time + SAMPLE_PERIOD:
            _STATES.append((self.model, copy.copy(self.data), nstep))
        return step(self, nstep)

    Engine.step = stepping


def physics_alone(seconds: float) -> float:
    """Simulated seconds per wall second of bare `mj_step` on copies of the last run's states
    (one every `SAMPLE_PERIOD` of its simulated time: the same model -- robot, furniture,
    objects --, the state then -- motions, contacts, grasp welds, the controls of that moment),
    each stepped by as many steps per call as the run's control ticks, `seconds` of simulated
    time in all: the ceiling of that run."""
    import mujoco

    states = list(_STATES)
    _STATES.clear()
    model, _, nstep = states[0]
    calls = max(1, round(seconds / len(states) / (nstep * model.opt.timestep)))
    wall = 0.0
    for _, data, _ in states:
        t0 = time.perf_counter()
        for _ in range(calls):
            mujoco.mj_step(model, data, nstep=nstep)
        wall += time.perf_counter() - t0
    return len(states) * calls * nstep * model.opt.timestep / wall


def thesis(robot: str, stepping: str) -> tuple[float, float, str]:
    from pycram.apps.demos.kitchen import DemoOptions, run_demo
    from pycram.trace.fingerprint import run_fingerprint

    options = DemoOptions(robot=robot, steal=1, seed=3, record=False, quiet=True, animation=False, pictures=False)
    options.stepping = stepping
    t0 = time.perf_counter()
    result = run_demo(options)
    wall = time.perf_counter() - t0
    return result.sim_time, wall, run_fingerprint(result.plan_task, result.final_poses)[:12]


def set_table(robot: str, stepping: str) -> tuple[float, float, str]:
    from pycram.apps.scenarios.set_table.driver import run_scenario
    from pycram.trace.fingerprint import run_fingerprint

    t0 = time.perf_counter()
    result, task = run_scenario(robot, 7, frozenset(), stepping=stepping)
    wall = time.perf_counter() - t0
    return result.sim_time, wall, run_fingerprint(task, result.final_poses)[:12]


def throughput(seeds: int, workers: int) -> tuple[float, dict[int, tuple[float, bool]]]:
    """Runs per minute of wall time of the thesis scenario (a theft, lock-step) on seeds
    1..`seeds` with `workers` local processes, and each seed's (simulated time, success)."""
    import tempfile

    from pycram.apps.experiments.runner import prepare_experiment, run_experiment

    with tempfile.TemporaryDirectory() as folder:
        db = str(Path(folder) / "throughput.sqlite3")
        prepared = prepare_experiment(scenario="thesis", seeds=f"1-{seeds}", faults=["steal"], db=db)
        results: dict[int, tuple[float, bool]] = {}

        def finished(key, result):
            if result is not None:
                results[key[1]] = (round(float(result["sim_time"]), 6), bool(result["success"]))

        t0 = time.perf_counter()
        run_experiment(prepared, workers=workers, progress=finished)
        wall = time.perf_counter() - t0
    return 60.0 * len(results) / wall, results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", default="pr2,tiago")
    parser.add_argument("--repeat", type=int, default=2, help="runs per scenario and stepping")
    parser.add_argument("--physics", type=float, default=60.0, help="simulated seconds of physics alone")
    parser.add_argument("--skip-set-table", action="store_true")
    parser.add_argument("--throughput", type=int, default=0, help="seeds of the experiment throughput (0: skip)")
    args = parser.parse_args()
    from rich.console import Console
    from rich.table import Table

    _keep_time_spent()
    _keep_states()
    breakdown = Table(title="where the wall time of the lock-step runs went (World.time_spent, % of the run's wall)")
    for column in ("robot", "run", "physics", "controllers", "commands", "sensors", "recording", "plan", "other"):
        breakdown.add_column(column, justify="left" if column in ("robot", "run") else "right")
    breakdown.add_column("loop overhead", justify="right")
    table = Table(
        title="lock-step vs free-running (sim / wall: x real time; physics alone: x real time of `mj_step` "
        "on copies of the run's states; share: the run's speed / physics alone)"
    )
    for column in ("robot", "run", "stepping", "sim [s]", "wall [s]", "x real time", "physics alone", "share"):
        table.add_column(column, justify="right" if column not in ("robot", "run", "stepping") else "left")
    table.add_column("fingerprint")
    for robot in args.robots.split(","):
        cases = [("thesis demo", thesis)]
        if not args.skip_set_table:
            cases.append(("set-table", set_table))
        for name, run in cases:
            for stepping in ("free", "lockstep"):
                for _ in range(args.repeat):
                    sim, wall, fingerprint = run(robot, stepping)
                    ceiling = physics_alone(args.physics)
                    speed = sim / wall if wall > 0 else 0.0
                    if stepping == "lockstep" and _SPENT and wall > 0:
                        shares = {part: 100 * seconds / wall for part, seconds in _SPENT.items()}
                        other = 100 - sum(shares.values())
                        busy = sum(seconds for part, seconds in _SPENT.items() if part != "plan")
                        overhead = 100 * (busy - _SPENT["physics"]) / busy if busy > 0 else 0.0
                        breakdown.add_row(
                            robot, name, *(f"{shares[p]:.0f} %" for p in _SPENT), f"{other:.0f} %", f"{overhead:.0f} %"
                        )
                    table.add_row(
                        robot,
                        name,
                        stepping,
                        f"{sim:.2f}",
                        f"{wall:.1f}",
                        f"{speed:.1f}",
                        f"{ceiling:.1f}",
                        f"{100 * speed / ceiling:.0f} %",
                        fingerprint,
                    )
    console = Console(width=140)
    console.print(table)
    console.print(breakdown)
    if args.throughput:
        per_minute = {}
        for workers in (1, 2):
            per_minute[workers] = throughput(args.throughput, workers)
            console.print(
                f"experiment throughput, thesis with a theft, seeds 1-{args.throughput}, lock-step, "
                f"{workers} worker(s): {per_minute[workers][0]:.1f} runs/min"
            )
        same = per_minute[1][1] == per_minute[2][1]
        console.print(
            f"the same results with 1 and 2 workers: {'yes' if same else 'NO'} "
            f"({len(per_minute[1][1])} seeds; speed-up {per_minute[2][0] / per_minute[1][0]:.2f}x)"
        )


if __name__ == "__main__":
    main()
