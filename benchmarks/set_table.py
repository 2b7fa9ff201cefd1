"""How often the set-table scenario succeeds, why it fails, and how long it takes (issue 17).

Runs `pycram.apps.scenarios.set_table.run_set_table` for each robot and seed, one run per fresh process
(as `pycram experiment` does), and prints per robot: success rate, failure causes, simulated and
wall time p50/p95, and the speed factor (simulated / wall time). The scenes are those of
`pycram experiment --scenario set-table` (the cup in drawer 2 in about a third of the seeds);
`--open` starts every object on an open surface (``set-table-open``).

    MUJOCO_GL=egl .venv/bin/python benchmarks/set_table.py [--robots pr2,tiago] [--seeds 100-109]
        [--faults moved,taken,stuck,obstacle,missed] [--objects cup,milk] [--open] [--jobs 1]
        [--json results.jsonl]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

from _worlds import percentile  # noqa: E402


def _one(args: tuple) -> dict:
    from pycram.apps.scenarios.set_table import OBJECTS, run_set_table

    robot, seed, faults, objects, in_containers = args
    return run_set_table(robot, seed, frozenset(faults), objects=tuple(objects or OBJECTS), in_containers=in_containers)


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b) + 1)) if b else [int(a)]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="pr2,tiago")
    parser.add_argument("--seeds", default="100-109")
    parser.add_argument("--faults", default="")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--objects", default="", help="object types to bring (default: the scenario's)")
    parser.add_argument("--open", action="store_true", help="every object starts on an open surface")
    parser.add_argument("--json", default=None, help="append one JSON line per run to this file")
    args = parser.parse_args()
    faults = tuple(f for f in args.faults.split(",") if f)
    objects = tuple(o for o in args.objects.split(",") if o)
    jobs = [(r, s, faults, objects, not args.open) for r in args.robots.split(",") for s in _seeds(args.seeds)]
    ctx = multiprocessing.get_context("spawn")
    results: list[dict] = []
    with ctx.Pool(args.jobs, maxtasksperchild=1) as pool:
        for out in pool.imap_unordered(_one, jobs):
            results.append(out)
            line = (
                f"{out['robot']:5} seed {out['seed']:4} {'ok  ' if out['success'] else 'FAIL'} "
                f"sim {out['sim_time']:6.1f} s wall {out['wall_time']:6.1f} s  "
                f"{'' if out['success'] else out['summary']}  faults: {'; '.join(out['faults_injected'])}"
            )
            print(line, flush=True)
            if args.json:
                with open(args.json, "a") as f:
                    f.write(json.dumps(out) + "\n")
    for robot in args.robots.split(","):
        rs = [r for r in results if r["robot"] == robot]
        if not rs:
            continue
        ok = sum(r["success"] for r in rs)
        causes = Counter(c for r in rs for c in r["failure_causes"])
        sims, walls = [r["sim_time"] for r in rs], [r["wall_time"] for r in rs]
        placed = Counter(n for r in rs for n, o in r["objects"].items() if o["placed"])
        print(
            f"{robot}: {ok}/{len(rs)} succeeded ({100 * ok / len(rs):.0f} %), objects {','.join(objects) or 'all'}, "
            f"faults {','.join(faults) or 'none'}; "
            f"sim p50 {percentile(sims, 50):.0f} s p95 {percentile(sims, 95):.0f} s; "
            f"wall p50 {percentile(walls, 50):.0f} s p95 {percentile(walls, 95):.0f} s; "
            f"speed {sum(sims) / sum(walls):.1f}x real time"
        )
        print(f"  objects placed: {dict(placed)}; failure causes: {dict(causes) or 'none'}")


if __name__ == "__main__":
    main()
