"""How fast prospection answers: collision, reachability (3-pose sequences) and visibility
checks per second, for one robot in one environment, while the simulation runs.

Issue 13 targets on this 2-core machine with the PR2: >= 2,000 collision checks/s, >= 100
reachability checks/s, >= 200 visibility checks/s.

    MUJOCO_GL=egl .venv/bin/python benchmarks/prospection.py [--env apartment] [--robot pr2]
                                                             [--seconds 3] [--threads 1]

Questions are environment-agnostic: base poses drawn over the environment's extent (free or
not, for collisions), base poses 0.5-0.8 m from each object facing it with a pre-grasp / grasp
/ lift sequence (reachability), and poses 1-2.5 m from each object (visibility).
"""

from __future__ import annotations

import argparse
import math
import random
import sys
import threading
import time

from _worlds import default_environment, floor_planner, open_world


def _questions(world, rng: random.Random, prospection) -> dict[str, list]:
    planner = floor_planner(world)
    grid = planner.grid
    rows, cols = grid.occupied.nonzero()
    lo_x = grid.origin[0] + cols.min() * grid.resolution
    hi_x = grid.origin[0] + (cols.max() + 1) * grid.resolution
    lo_y = grid.origin[1] + rows.min() * grid.resolution
    hi_y = grid.origin[1] + (rows.max() + 1) * grid.resolution
    collision = [(rng.uniform(lo_x, hi_x), rng.uniform(lo_y, hi_y), rng.uniform(-math.pi, math.pi)) for _ in range(500)]
    arms = list(world.description.ARMS)
    reach, see = [], []
    items = world.item_poses.get_value()
    for name, pose in items.items():
        x, y, z = pose.position
        asked = 0
        for _ in range(400):  # base poses where the robot fits: the IK is what is measured
            if asked == 40:
                break
            d, a = rng.uniform(0.5, 0.8), rng.uniform(-math.pi, math.pi)
            base = (x - d * math.cos(a), y - d * math.sin(a), a)
            if prospection.in_collision(base):
                continue
            asked += 1
            q = (math.cos(a / 2), 0.0, 0.0, math.sin(a / 2))
            c, s = math.cos(a), math.sin(a)
            seq = [((x - 0.1 * c, y - 0.1 * s, z), q), ((x, y, z), q), ((x, y, z + 0.1), q)]
            reach.append((rng.choice(arms), seq, base))
            d2 = rng.uniform(1.0, 2.5)
            see.append((name, (x - d2 * math.cos(a), y - d2 * math.sin(a), a)))
    return {"collision": collision, "reach": reach, "see": see}


def _rate(name: str, ask, questions: list, seconds: float, threads: int) -> tuple[float, list]:
    """Checks per second of wall time over `seconds`, asking from `threads` threads."""
    counts = [0] * threads
    answers: list = []
    stop = time.perf_counter() + seconds

    def worker(i: int) -> None:
        k = i
        while time.perf_counter() < stop:
            out = ask(questions[k % len(questions)])
            if i == 0 and k < len(questions):
                answers.append(out)
            k += threads
            counts[i] += 1

    t0 = time.perf_counter()
    pool = [threading.Thread(target=worker, args=(i,), name=f"bench-{name}-{i}") for i in range(threads)]
    for t in pool:
        t.start()
    for t in pool:
        t.join()
    return sum(counts) / (time.perf_counter() - t0), answers


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default=default_environment())
    parser.add_argument("--robot", default="pr2")
    parser.add_argument("--seconds", type=float, default=3.0, help="wall time per kind of check [s]")
    parser.add_argument("--threads", type=int, default=1, help="threads asking at once")
    args = parser.parse_args(argv)
    rng = random.Random(13)
    with open_world(args.robot, args.env) as world:
        p = world.prospection()
        qs = _questions(world, rng, p)
        print(
            f"prospection with the {args.robot} in {args.env!r}, {args.threads} thread(s), "
            f"the simulation running ({len(qs['reach'])} reach / {len(qs['see'])} visibility questions "
            f"about {len(world.item_poses.get_value())} objects)"
        )
        rate, ans = _rate("collision", lambda b: p.in_collision(b), qs["collision"], args.seconds, args.threads)
        print(f"collision checks:     {rate:8.0f} /s   (target >= 2000; {sum(ans)}/{len(ans)} in collision)")
        rate, ans = _rate("reach", lambda q: p.reachable(*q), qs["reach"], args.seconds, args.threads)
        reasons: dict = {}
        for a in ans:
            reasons[a.reason or "reachable"] = reasons.get(a.reason or "reachable", 0) + 1
        print(f"reachability checks:  {rate:8.0f} /s   (target >= 100; 3-pose sequences; {reasons})")
        feasible = [
            q
            for q, a in zip(qs["reach"], ans)
            if a.reason in (None, "joint_limit", "out_of_reach") and a.failed_index != -1
        ]
        if feasible:
            rate, ans = _rate("reach-ik", lambda q: p.reachable(*q), feasible, args.seconds, args.threads)
            print(f"  of which IK needed: {rate:8.0f} /s   (the {len(feasible)} questions whose base pose is free)")
        rate, ans = _rate("see", lambda q: p.visible(*q), qs["see"], args.seconds, args.threads)
        print(
            f"visibility checks:    {rate:8.0f} /s   (target >= 200; {sum(a.visible for a in ans)}/{len(ans)} visible)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
