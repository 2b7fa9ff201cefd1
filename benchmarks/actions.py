"""How often `Transport` succeeds, and how long it takes: per object type and robot, random scenes.

Issue 32's measure: `Transport` of one object per scene, per robot and object type, judged with
the simulator's truth, on a documented seed split.

**Scenes.** The object starts at a spot drawn uniformly from *anywhere* on the apartment's open
surfaces (counter, cabinet top, table, cookers: their union, a cooker on the counter counted once),
upright, turned at random, fully on the surface -- kept only where some standing pose of the
robot can grasp it. That check (`pycram.apps.scenarios.reachability.ReachabilityFilter`) is a
*scene-generation filter*: it asks the robot's own location reasoning, in prospection built from
the environment's description alone (no objects, containers closed), whether any base pose, arm,
grasp and torso height (the initial one or higher) executes the grasp sequence; it never tries the
task, and the robot does not get its answer. Rejected draws are counted per surface and printed
(how much of each surface the robot reaches). Two other objects stand in the way at random free
spots of the same surfaces (not filtered). The robot starts at the apartment's start pose knowing
nothing, parks its arms, raises its torso and is asked for
``Transport(ObjectDesignator(type=T), target)``.

**Targets**, one per scene, drawn among the kinds the type is found on (`ObjectType.found_on`),
never the surface the object starts on: ``table`` and ``counter`` (the surface's name, as a user
would say it), ``fridge`` and ``cupboard`` (their shelves) and ``drawer2``, ``drawer3`` (inside
drawers 2 and 3), the latter four as ``LocationDesignator([("in", container), ("for", T)])``.
Targets where the filter finds no spot a standing pose can place a T on (the container opened as
`Open` opens it) are left out for that robot and type and listed ("not placeable").

**Seeds.** ``--split dev`` (default): seeds 0, 1, 2, ... -- what people tune on (issue 16's runs
used seeds 0-19 of an earlier scene generator). ``--split eval``: seeds `EVAL_FIRST` (32000), 32001,
... -- never used while developing; report on these. Each seed draws the start spot, the other
objects and the target from streams of their own, so both robots see the same draws (a spot one
robot does not reach is redrawn for it only). ``--seeds 3,7-9`` replays chosen seeds.

**Judged with the simulator's truth.** Success: the object stands upright (< 20 deg) on the target
surface (its centre over it, its bottom within 3 cm of it) or on a surface inside the target
container (with the containers as they are then). Knocked over: every object (the transported one
too) upright at the start and tilted more than 45 deg at the end. Failures are counted by their
typed failure and reason; for an `ObjectOutOfReach` the filter is asked again (the object where it
is then for picking up, the target for placing): "true" when it finds no standing pose either,
"false" when it does (a capability gap, not a limit of the scene).

    MUJOCO_GL=egl .venv/bin/python benchmarks/actions.py [--scenes 20] [--split dev|eval]
        [--robots pr2,tiago] [--types cup,mug,bowl,plate,spoon,cereal,milk]
        [--targets table,counter,fridge,cupboard,drawer2,drawer3] [--seeds 3,7-9] [-j 1]

Per robot and object type: successes S/N with the Wilson 95 % interval, sim and wall p50 of the
successes, objects knocked over; then successes per target, failures by cause, the truth of the
out-of-reach failures, the reachable share of each surface and the targets left out. The last
line reads ``transporting: S/N succeeded (P %), sim p50 X s, wall p50 Y s``.
"""

from __future__ import annotations

import argparse
import logging
import math
import multiprocessing
import os
import random
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402

from pycram.apps.experiments.statistics import wilson_interval  # noqa: E402
from pycram.apps.scenarios.reachability import ReachabilityFilter, draw_spot  # noqa: E402
from pycram.world.objects import OBJECT_TYPES, object_type  # noqa: E402

#: Where objects start: the apartment's open surfaces (their union; the cookers lie on the counter).
OPEN_SURFACES = ["counter", "cabinet top", "table", "cooker #1", "cooker #2"]
#: The other objects of a scene (in the way), by the transported type.
DISTRACTORS = {"cup": ["bowl", "milk"], "default": ["cup", "bowl"]}
#: Targets: option name -> (name in the apartment, the surface kind of `ObjectType.found_on`).
TARGETS = {
    "table": ("table", "table"),
    "counter": ("counter", "counter"),
    "fridge": ("fridge", "shelf"),
    "cupboard": ("cupboard", "cupboard"),
    "drawer2": ("drawer 2", "drawer"),
    "drawer3": ("drawer 3", "drawer"),
}
#: The target an object starting on a surface is not brought to (it is there already).
SAME_PLACE = {"table": "table", "counter": "counter", "cooker #1": "counter", "cooker #2": "counter"}
#: The first evaluation seed; development seeds are 0 .. EVAL_FIRST - 1.
EVAL_FIRST = 32000
#: Upright at most / knocked over beyond this tilt [deg].
UPRIGHT, KNOCKED_OVER = 20.0, 45.0

_FILTERS: dict[str, ReachabilityFilter] = {}


def seeds_of(split: str, scenes: int, explicit: str | None = None) -> list[int]:
    """The seeds of a run: `explicit` ("3,7-9") when given, else the first `scenes` of `split`."""
    if explicit:
        out: list[int] = []
        for part in explicit.split(","):
            a, _, b = part.partition("-")
            out += list(range(int(a), int(b) + 1)) if b else [int(a)]
        return out
    if split == "dev":
        if scenes > EVAL_FIRST:
            raise SystemExit(f"the development split has {EVAL_FIRST} seeds")
        return list(range(scenes))
    if split == "eval":
        return list(range(EVAL_FIRST, EVAL_FIRST + scenes))
    raise SystemExit(f"--split is dev or eval, not {split!r}")


def reachability(robot_name: str) -> ReachabilityFilter:
    """The scene-generation filter of `robot_name` (one per process)."""
    if robot_name not in _FILTERS:
        _FILTERS[robot_name] = ReachabilityFilter(robot_name, "apartment")
    return _FILTERS[robot_name]


def tilt(orientation: Any) -> float:
    """Angle [deg] between an object's up axis and the vertical ((w, x, y, z) orientation)."""
    w, x, y, z = orientation
    return math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y)))))


def yaw_of(orientation: Any) -> float:
    w, x, y, z = orientation
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def make_scene(robot_name: str, type_name: str, seed: int, target_keys: list[str]) -> dict[str, Any]:
    """The scene of `seed` for `robot_name` and `type_name`: placements, target, and what the
    filter said (see the module docstring)."""
    reach = reachability(robot_name)
    env = reach.environment
    streams = {s: random.Random(f"actions/{seed}/{type_name}/{s}") for s in ("start", "others", "target")}
    spot, checked = draw_spot(streams["start"], env, type_name, OPEN_SURFACES, [], reach)
    scene: dict[str, Any] = {"checked": dict(checked), "placements": [], "target": None, "excluded": {}}
    if spot is None:
        scene["error"] = "no reachable free spot drawn"
        return scene
    placements = [spot]
    for other in [t for t in DISTRACTORS.get(type_name, DISTRACTORS["default"]) if t != type_name][:2]:
        placed, _ = draw_spot(streams["others"], env, other, OPEN_SURFACES, placements)
        if placed is not None:
            placements.append(placed)
    scene["placements"] = placements
    otype = object_type(type_name)
    choices = []
    for key in target_keys:
        name, kind = TARGETS[key]
        if kind not in otype.found_on or SAME_PLACE.get(spot.support) == key:
            continue
        ok, why = reach.placeable(type_name, name)
        if ok:
            choices.append(key)
        else:
            scene["excluded"][key] = why
    if not choices:
        scene["error"] = "no placeable target"
        return scene
    scene["target"] = streams["target"].choice(choices)
    return scene


def on_target(world: Any, target_key: str, type_name: str, pose: Any) -> bool:
    """Whether an object of `type_name` at `pose` stands upright on the target (truth)."""
    from pycram.world.belief import support_of

    env = world.environment
    name, _ = TARGETS[target_key]
    x, y, z = pose.position
    bottom = z - object_type(type_name).half_height
    if tilt(pose.orientation) >= UPRIGHT:
        return False
    if target_key in ("table", "counter"):
        surface = env.surface(name)
        return surface.contains(x, y, 0.0) and abs(bottom - surface.height) < 0.03
    states = dict(world.container_states.get_value())
    support = support_of(env, x, y, bottom, states)
    return (
        support is not None
        and any(s.name == support.name for s in env.container(name).interior)
        and abs(bottom - support.height) < 0.03
    )


def where(world: Any, type_name: str, pose: Any) -> str:
    """Where an object of `type_name` at `pose` is (truth): its centre, tilt and support."""
    from pycram.world.belief import support_of

    x, y, z = pose.position
    otype = object_type(type_name)
    bottom = z - (otype.half_height if tilt(pose.orientation) < KNOCKED_OVER else otype.lying_height / 2)
    support = support_of(world.environment, x, y, bottom, dict(world.container_states.get_value()))
    name, height = ("the floor", 0.0) if support is None else (support.name, support.height)
    on = f"on {name}" if bottom - height <= 0.03 else f"{bottom - height:.2f} m above {name} (held?)"
    return f"({x:.2f}, {y:.2f}, {z:.2f}), tilted {tilt(pose.orientation):.0f} deg, {on}"


def run_one(job: tuple[str, str, int, list[str], bool]) -> dict[str, Any]:
    """One transport (see the module docstring): a result dict. With `scenes_only` (the job's
    last item), only the scene is drawn (``cause`` "scene only")."""
    robot_name, type_name, seed, target_keys, scenes_only = job
    logging.basicConfig(level=logging.ERROR)
    from pycram import robots
    from pycram.actions import MoveTorso, ParkArms, Transport
    from pycram.actions.core import unwrap
    from pycram.designator import LocationDesignator, ObjectDesignator, perform
    from pycram.execution.failures import ObjectOutOfReach
    from pycram.sim import ItemSpec, World

    result: dict[str, Any] = {"robot": robot_name, "type": type_name, "seed": seed, "ok": False, "cause": ""}
    scene = make_scene(robot_name, type_name, seed, target_keys)
    result.update(checked=scene["checked"], excluded=scene["excluded"], target=scene["target"], knocked=[])
    result.update(sim=float("nan"), wall=float("nan"), oor=None)
    if scene["placements"]:
        result["start"] = scene["placements"][0].support
    if "error" in scene or scenes_only:
        result["cause"] = f"scene: {scene.get('error', 'only drawn')}"
        return result
    placements, target_key = scene["placements"], scene["target"]
    start = placements[0]
    name, _ = TARGETS[target_key]
    target: Any = name if target_key in ("table", "counter") else LocationDesignator([("in", name), ("for", type_name)])
    items = [ItemSpec.of(object_type(p.type), p.name, p.position, p.yaw) for p in placements]
    world = World(robot_name, items, environment="apartment")
    upright = {n for n, pose in world.item_poses.get_value().items() if tilt(pose.orientation) < UPRIGHT}
    robot = robots.load(robot_name, world)
    t0, s0 = time.perf_counter(), world.sim_time.get_value()
    error: BaseException | None = None
    try:
        with robot:
            perform(ParkArms())
            perform(MoveTorso("up"))
            perform(Transport(ObjectDesignator(type=type_name), target))
    except Exception as raised:  # the benchmark counts every failure by its kind
        error = unwrap(raised)
    finally:
        result["wall"], result["sim"] = time.perf_counter() - t0, world.sim_time.get_value() - s0
        poses = world.item_poses.get_value()
        ok = on_target(world, target_key, type_name, poses[start.name])
        result["knocked"] = sorted(n for n in upright if tilt(poses[n].orientation) > KNOCKED_OVER)
        end = poses[start.name]
        result["end"] = where(world, type_name, end)
        robot.shutdown()
        world.close()
    if error is not None:
        result["cause"] = f"{type(error).__name__}: {getattr(error, 'reason', '')}"
        if ok:  # the failure's reason is not what happened
            result["cause"] += " (yet upright on the target)"
        result["message"] = " ".join(str(error).split())[:2000]
        if isinstance(error, ObjectOutOfReach):
            result["oor"] = out_of_reach_truth(robot_name, type_name, name, error, end)
    elif not ok:
        result["cause"] = "wrong result: not upright on the target"
    result["ok"] = ok and error is None
    return result


def out_of_reach_truth(robot_name: str, type_name: str, target: str, error: Any, end: Any) -> tuple[str, bool, str]:
    """(phase, whether the out-of-reach failure is true, the filter's answer): for placing, is
    there a spot on the target some standing pose places on; else, does some standing pose grasp
    the object where it is now (truth)."""
    reach = reachability(robot_name)
    designator = getattr(error, "designator", None)
    phase = designator.prop_value("type") if hasattr(designator, "prop_value") else None
    if phase == "placing":
        ok, why = reach.placeable(type_name, target)
        return "placing", not ok, why
    if tilt(end.orientation) > KNOCKED_OVER:
        return str(phase or "picking_up"), True, "the object lies on its side (no grasp of a lying object)"
    ok, why = reach.graspable(type_name, end.position, yaw_of(end.orientation))
    return str(phase or "picking_up"), not ok, why


def _pct(low: float, high: float) -> str:
    return f"[{100 * low:3.0f}, {100 * high:3.0f}] %"


def report(results: list[dict[str, Any]]) -> None:
    groups: dict[tuple[str, str], list[dict[str, Any]]] = defaultdict(list)
    for r in results:
        groups[(r["robot"], r["type"])].append(r)
    print(f"\n{'robot':6s} {'type':7s} {'S/N':>7s}  {'rate':>5s}  {'95 % CI':13s}  sim p50   wall p50  knocked over")
    total = succeeded = knocked = 0
    all_sim: list[float] = []
    all_wall: list[float] = []
    for (robot_name, type_name), rs in groups.items():
        runs = [r for r in rs if not r["cause"].startswith("scene:")]
        if not runs:
            continue
        ok = [r for r in runs if r["ok"]]
        sims, walls = [r["sim"] for r in ok], [r["wall"] for r in ok]
        low, high = wilson_interval(len(ok), len(runs))
        k = sum(len(r["knocked"]) for r in runs)
        sim50 = float(np.median(sims)) if sims else float("nan")
        wall50 = float(np.median(walls)) if walls else float("nan")
        print(
            f"{robot_name:6s} {type_name:7s} {len(ok):3d}/{len(runs):<3d}  {100 * len(ok) / max(len(runs), 1):4.0f} %  "
            f"{_pct(low, high)}  {sim50:6.1f} s  {wall50:6.1f} s  {k}"
        )
        total, succeeded, knocked = total + len(runs), succeeded + len(ok), knocked + k
        all_sim += sims
        all_wall += walls
    print("\nby target (robot: target S/N):")
    by_target: dict[str, Counter] = defaultdict(Counter)
    for r in results:
        if r["target"] and not r["cause"].startswith("scene:"):
            by_target[r["robot"]][(r["target"], "n")] += 1
            by_target[r["robot"]][(r["target"], "ok")] += int(r["ok"])
    for robot_name, counter in by_target.items():
        keys = [t for t in TARGETS if counter[(t, "n")]]
        print(f"  {robot_name}: " + ", ".join(f"{t} {counter[(t, 'ok')]}/{counter[(t, 'n')]}" for t in keys))
    print("\nfailures by cause:")
    for (robot_name, type_name), rs in groups.items():
        causes = Counter(r["cause"] for r in rs if not r["ok"] and not r["cause"].startswith("scene:"))
        if causes:
            print(f"  {robot_name} {type_name}: " + ", ".join(f"{c} x{n}" for c, n in causes.most_common()))
    oor = [r for r in results if r["oor"] is not None]
    truth = Counter("true" if r["oor"][1] else "false" for r in oor)
    print(f"\nout of reach (ObjectOutOfReach): true {truth['true']}, false {truth['false']}")
    for r in oor:
        phase, true, why = r["oor"]
        print(
            f"  {r['robot']} {r['type']} seed {r['seed']} ({phase}, to {r['target']}): "
            f"{'true' if true else 'false'} -- filter: {why[:160]}"
        )
    print("\nreachable share of each surface (draws some standing pose grasps from / free draws):")
    for (robot_name, type_name), rs in groups.items():
        drawn: Counter = Counter()
        for r in rs:
            for (surface, reachable), n in r["checked"].items():
                drawn[(surface, "n")] += n
                drawn[(surface, "ok")] += n if reachable else 0
        surfaces = [s for s in OPEN_SURFACES if drawn[(s, "n")]]
        print(
            f"  {robot_name} {type_name}: "
            + ", ".join(
                f"{s} {drawn[(s, 'ok')]}/{drawn[(s, 'n')]} ({100 * drawn[(s, 'ok')] / drawn[(s, 'n')]:.0f} %)"
                for s in surfaces
            )
        )
    excluded = {(r["robot"], r["type"], t): why for r in results for t, why in r["excluded"].items()}
    if excluded:
        print("\ntargets left out (no spot a standing pose places on, the container open):")
        for (robot_name, type_name, t), why in sorted(excluded.items()):
            print(f"  {robot_name} {type_name} -> {t}: {why[:200]}")
    scene_errors = Counter(
        (r["robot"], r["type"], r["cause"]) for r in results if r["cause"].startswith("scene:") and r["target"] is None
    )
    for (robot_name, type_name, cause), n in scene_errors.items():
        print(f"  no scene: {robot_name} {type_name}: {cause} x{n}")
    low, high = wilson_interval(succeeded, total)
    print(f"\nall: {succeeded}/{total}, 95 % CI {_pct(low, high)}; objects knocked over: {knocked}")
    sim50 = float(np.median(all_sim)) if all_sim else float("nan")
    wall50 = float(np.median(all_wall)) if all_wall else float("nan")
    print(
        f"transporting: {succeeded}/{total} succeeded ({100.0 * succeeded / max(total, 1):.0f} %), "
        f"sim p50 {sim50:.1f} s, wall p50 {wall50:.1f} s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=20, help="seeds per robot and type")
    parser.add_argument("--split", default="dev", choices=["dev", "eval"])
    parser.add_argument("--seeds", default=None, help="explicit seeds, e.g. 3,7-9 (replaces --split/--scenes)")
    parser.add_argument("--robots", default="pr2,tiago")
    parser.add_argument("--types", default=",".join(OBJECT_TYPES))
    parser.add_argument("--targets", default=",".join(TARGETS))
    parser.add_argument("-j", "--jobs", type=int, default=1, help="worker processes (each scene is independent)")
    parser.add_argument("--scenes-only", action="store_true", help="draw the scenes, run nothing")
    parser.add_argument("--width", type=int, default=240, help="characters of each failure's message shown")
    args = parser.parse_args()
    logging.basicConfig(level=logging.ERROR)
    target_keys = args.targets.split(",")
    unknown = [t for t in target_keys if t not in TARGETS]
    if unknown:
        raise SystemExit(f"unknown targets {unknown}; valid: {', '.join(TARGETS)}")
    seeds = seeds_of(args.split, args.scenes, args.seeds)
    jobs = [
        (r, t, s, target_keys, args.scenes_only)
        for r in args.robots.split(",")
        for t in args.types.split(",")
        for s in seeds
    ]
    print(f"split {args.split if not args.seeds else 'explicit'}: seeds {seeds[0]}..{seeds[-1]} ({len(seeds)})")
    results: list[dict[str, Any]] = []

    def show(r: dict[str, Any]) -> None:
        results.append(r)
        what = "ok  " if r["ok"] else r["cause"] if r["cause"].startswith("scene:") else f"FAIL {r['cause']}"
        knocked = f"  knocked over: {', '.join(r['knocked'])}" if r["knocked"] else ""
        print(
            f"{r['robot']:6s} {r['type']:7s} seed {r['seed']:5d}  {r.get('start', '-'):11s} -> "
            f"{r['target'] or '-':8s} sim {r['sim']:6.1f} s wall {r['wall']:5.1f} s  {what}{knocked}",
            flush=True,
        )
        if not r["ok"] and r.get("end"):
            print(f"{'':20s}truth: {r['type']} at {r['end']}", flush=True)
        if r.get("message"):
            print(f"{'':20s}{r['message'][: args.width]}", flush=True)

    if args.jobs <= 1:
        for job in jobs:
            show(run_one(job))
    else:
        with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
            for r in pool.imap(run_one, jobs):
                show(r)
    report(results)


if __name__ == "__main__":
    main()
