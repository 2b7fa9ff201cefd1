"""How an experiment scales with workers: the thesis scenario over a few seeds, 1 and 2 workers.

Issue 17 asks that each run is at least 5x faster than real time and that an experiment's
throughput grows near-linearly with the workers. This script runs the same experiment
(`pycram experiment --scenario thesis`, each run recorded into a temporary SQLite database) with
1 and with 2 local worker processes (and with `--ray` on a local Ray instance when asked) and
prints the throughput [runs/min], the speed-up over 1 worker and, per run, the simulated time,
the wall time and the real-time factor (simulated / wall time of the whole run: world, plan,
recording).

    MUJOCO_GL=egl .venv/bin/python benchmarks/experiment.py [--seeds 1-8] [--robot pr2] [--faults none] [--ray]

The wall time of an experiment includes starting the worker processes (spawn: a fresh
interpreter importing MuJoCo, ~1 s each), as `pycram experiment` pays it.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

from pycram.apps.experiments import store  # noqa: E402
from pycram.apps.experiments.report import percentile  # noqa: E402
from pycram.apps.experiments.runner import prepare_experiment, run_experiment  # noqa: E402


def _experiment(db: str, name: str, args: argparse.Namespace, workers: int, ray: str | None) -> tuple[float, list]:
    prepared = prepare_experiment(
        scenario="thesis", robots=args.robot, seeds=args.seeds, faults=[args.faults], name=name, db=db
    )
    outcome = run_experiment(prepared, workers=workers, ray=ray)
    return outcome.wall_time, store.run_records(db, prepared.record.id)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1-8")
    parser.add_argument("--robot", default="pr2")
    parser.add_argument("--faults", default="none")
    parser.add_argument("--ray", action="store_true", help="also run with 2 CPUs on a local Ray instance")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        db = f"sqlite:///{folder}/bench.sqlite3"
        configurations = [("1 worker", 1, None), ("2 workers", 2, None)]
        if args.ray:
            configurations.append(("Ray, 2 CPUs", 2, "local"))
        results = []
        for label, workers, ray in configurations:
            wall, runs = _experiment(db, label.replace(" ", "-").replace(",", ""), args, workers, ray)
            results.append((label, wall, runs))
        base = len(results[0][2]) / results[0][1]
        print(f"thesis scenario, robot {args.robot}, seeds {args.seeds}, faults {args.faults}")
        print(f"{'configuration':<14} {'runs':>5} {'ok':>4} {'wall [s]':>9} {'runs/min':>9} {'speed-up':>9}")
        for label, wall, runs in results:
            rate = len(runs) / wall
            ok = sum(r.success for r in runs)
            print(f"{label:<14} {len(runs):>5} {ok:>4} {wall:>9.1f} {60 * rate:>9.1f} {rate / base:>8.2f}x")
        print("\nper run (1 worker): seed, simulated [s], wall [s], real-time factor")
        factors = []
        for r in results[0][2]:
            factor = r.sim_time / r.wall_time
            factors.append(factor)
            print(f"  seed {r.seed:>3}: {r.sim_time:6.1f} {r.wall_time:6.2f} {factor:6.1f}x")
        print(f"real-time factor (1 worker): min {min(factors):.1f}x, p50 {percentile(factors, 50):.1f}x")
        for label, _, runs in results[1:]:
            f = [r.sim_time / r.wall_time for r in runs]
            print(f"real-time factor ({label}): min {min(f):.1f}x, p50 {percentile(f, 50):.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
