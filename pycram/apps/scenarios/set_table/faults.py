"""The set-table scenario's faults: a simulated person and a flaky camera, acting on the simulator.

`check_faults` parses the fault names of `FAULTS`; `Faults` injects the chosen ones while the plan
runs, one daemon thread per fault waiting on fluents of the world's sensors and the plan's
`current_object` (which object, which drawer, where: drawn from the seed). This is the plan's
environment, not the plan: the plan learns of a fault only through its sensors.
"""

from __future__ import annotations

import logging
import math
import random
import threading
from typing import Any

from pycram.apps.scenarios.set_table.data import FAULTS, START_REGIONS, WALL_TIME_LIMIT
from pycram.apps.scenarios.set_table.plan import PlaceSetting
from pycram.core.runtime.lockstep import PlanThread

__all__ = [
    "check_faults",
    "Faults",
]

log = logging.getLogger("pycram.demo")


def check_faults(faults: Any) -> frozenset[str]:
    """The fault names of `faults` (an iterable or a comma-separated string) as a set; raises
    `ValueError` naming the valid choices for an unknown one."""
    if isinstance(faults, str):
        faults = [f.strip() for f in faults.split(",") if f.strip()]
    names = frozenset(faults or ())
    unknown = sorted(names - set(FAULTS))
    if unknown:
        raise ValueError(f"unknown fault(s) {', '.join(map(repr, unknown))}; valid faults: {', '.join(FAULTS)}")
    return names


class Faults:
    """Injects the chosen faults into `world` while the plan runs (a daemon thread per fault,
    each waiting on fluent networks of the world's sensors and the plan's `current_object`).
    Which object, which drawer, where: drawn from `rng`. `injected` lists what happened."""

    def __init__(
        self, world: Any, kinds: frozenset[str], rng: random.Random, settings: list[PlaceSetting], placements: list[Any]
    ) -> None:
        from pycram.core.fluent import Fluent

        self.world, self.kinds, self.rng, self.settings = world, kinds, rng, settings
        self.injected: list[str] = []
        self._stop = Fluent(None, name="faults.stop")
        self._threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self.moved_object = rng.choice([p.name for p in placements if p.container is None] or [None])
        self.taken_object = rng.choice([s.type for s in settings])
        drawers = [c.name for c in world.environment.containers if c.kind == "drawer"]
        in_drawers = sorted({p.container for p in placements if p.container in drawers})
        self.stuck_drawer = rng.choice(in_drawers or drawers) if drawers else None
        self.stuck_for = rng.uniform(4.0, 10.0)
        self.obstacle_fraction = rng.uniform(0.35, 0.6)

    def note(self, what: str) -> None:
        with self._lock:
            self.injected.append(what)
        log.warning("fault: %s", what)

    def start(self) -> None:
        jobs = {
            "moved": self._move_object,
            "taken": self._take_object,
            "stuck": self._stuck_drawer,
            "obstacle": self._obstacle,
        }
        if "stuck" in self.kinds and self.stuck_drawer is not None:
            self.world.set_container_stuck(self.stuck_drawer, True).wait(10.0)
        for kind, job in jobs.items():
            if kind in self.kinds:
                thread = PlanThread(target=self._guard(job), name=f"pycram-fault-{kind}", daemon=True)
                self._threads.append(thread)
                thread.start()

    def _guard(self, job: Any) -> Any:
        def run() -> None:
            try:
                job()
            except Exception:  # a fault that cannot be injected must not end the run
                log.exception("fault injection failed")

        return run

    def stop(self) -> None:
        self._stop.set_value(True)
        for thread in self._threads:
            thread.join(5.0)

    def _wait(self, condition: Any, *sources: Any, timeout: float = WALL_TIME_LIMIT) -> bool:
        """Wait until `condition()` holds (re-evaluated when a source fluent changes) or stop."""
        from pycram.core.fluent import Fluent

        network = Fluent(lambda: True if self._stop.get_value() or condition() else None)
        for source in (*sources, self._stop):
            source.add_child(network)
        network.wait_for(timeout)
        return not self._stop.get_value()

    def _holding(self) -> set[str]:
        return {s.get_value().holding for s in self.world.gripper_states.values()} - {None}

    def _counter_region(self, name: str) -> tuple[float, float, float, float]:
        """Where [m, map: x0, y0, x1, y1] a person puts `name` down on the counter: its counter
        start region in the apartment (`START_REGIONS`), else a strip 6-16 cm inside the
        counter's front edge -- the edge nearest the ``kitchen`` place, where the robot stands
        to work at the counter -- 10 cm from its ends."""
        environment = self.world.environment
        regions = START_REGIONS.get(name, {})
        if environment.name == "apartment" and "counter" in regions:
            return regions["counter"]
        kx, ky, _ = environment.place("kitchen").pose

        def distance(edge: tuple[Any, Any, Any]) -> float:  # from the kitchen place to the edge
            (ax, ay), (bx, by), _ = edge
            length2 = (bx - ax) ** 2 + (by - ay) ** 2 or 1.0
            f = min(1.0, max(0.0, ((kx - ax) * (bx - ax) + (ky - ay) * (by - ay)) / length2))
            return math.hypot(kx - ax - f * (bx - ax), ky - ay - f * (by - ay))

        (ax, ay), (bx, by), (nx, ny) = min(environment.surface("counter").edges(), key=distance)
        length = math.hypot(bx - ax, by - ay)
        ux, uy = (bx - ax) / length, (by - ay) / length
        corners = [
            (ax + ux * along - nx * inward, ay + uy * along - ny * inward)
            for along in (0.1, length - 0.1)
            for inward in (0.06, 0.16)
        ]
        xs, ys = [c[0] for c in corners], [c[1] for c in corners]
        return (min(xs), min(ys), max(xs), max(ys))

    def _free_counter_spot(self, name: str, near: tuple[float, float] | None = None) -> tuple[float, float, float]:
        """A spot [m] for `name` standing upright in its counter region (`_counter_region`),
        clear of every object standing around (objects in a gripper do not count) by 0.4 m if
        possible, else the clearest spot tried (and at least 0.15 m from `near`, within 0.6 m
        of it, when given and such spots exist)."""
        from pycram.world.objects import object_type

        surface = self.world.environment.surface("counter")
        x0, y0, x1, y1 = self._counter_region(name)
        held = self._holding()
        poses = {n: p for n, p in self.world.item_poses.get_value().items() if n != name and n not in held}
        z = surface.height + object_type(name).half_height + 0.002
        best: tuple[float, float, float] | None = None
        for _ in range(300):
            x, y = self.rng.uniform(x0, x1), self.rng.uniform(y0, y1)
            if near is not None and not 0.15 < math.hypot(x - near[0], y - near[1]) < 0.6:
                continue
            clearance = min((math.hypot(p.position[0] - x, p.position[1] - y) for p in poses.values()), default=9.0)
            if clearance >= 0.4:
                return (x, y, z)
            if best is None or clearance > best[0]:
                best = (clearance, x, y)
        if best is not None:  # no spot 0.4 m clear: the clearest one (never one next to an object)
            return (best[1], best[2], z)
        if near is not None:
            # `near` is not on the counter (an object that started on the cabinet top): no spot
            # is within 0.6 m of it; the clearest spot on the counter (this fell back to the
            # region's middle, whatever stood there: a plate put 0.12 m from the milk carton,
            # into it, seeds 6, 15, 24)
            return self._free_counter_spot(name)
        return ((x0 + x1) / 2, (y0 + y1) / 2, z)

    def _move_object(self) -> None:
        """Once the robot comes within 1.5 m of the object it is about to fetch, a person moves
        it along the counter."""
        from pycram.apps.scenarios.set_table.plan import current_object

        name = self.moved_object
        if name is None:
            return

        def near() -> bool:
            pose = self.world.item_poses.get_value().get(name)
            here = self.world.base_pose.get_value()
            return (
                current_object.get_value() == name
                and name not in self._holding()
                and pose is not None
                and math.hypot(pose.position[0] - here.x, pose.position[1] - here.y) < 1.5
            )

        if not self._wait(near, self.world.base_pose, current_object):
            return
        pose = self.world.item_poses.get_value()[name]
        to = self._free_counter_spot(name, (pose.position[0], pose.position[1]))
        self.world.move_item(name, to).wait(10.0)
        self.note(f"moved: a person moved the {name} to ({to[0]:.2f}, {to[1]:.2f}) as the robot came near")

    def _take_object(self) -> None:
        """Once the robot carries the chosen object 0.5 m, a person takes it out of the gripper
        and puts it on the counter."""
        name = self.taken_object
        if not self._wait(lambda: name in self._holding(), *self.world.gripper_states.values()):
            return
        start = self.world.base_pose.get_value()

        def away() -> bool:
            here = self.world.base_pose.get_value()
            return name in self._holding() and math.hypot(here.x - start.x, here.y - start.y) > 0.5

        if not self._wait(away, self.world.base_pose, *self.world.gripper_states.values()):
            return
        gripper = next(g for g, s in self.world.gripper_states.items() if s.get_value().holding == name)
        to = self._free_counter_spot(name)
        outcome = self.world.take_item(gripper=gripper, to=to).wait(10.0)
        if outcome is not None and outcome.succeeded and outcome.value:
            self.note(
                f"taken: a person took the {name} from the {gripper} gripper, put it at ({to[0]:.2f}, {to[1]:.2f})"
            )

    def _stuck_drawer(self) -> None:
        """The drawer is stuck (from the start); `stuck_for` [s of simulated time] after the
        robot's gripper first comes near its handle, it frees itself."""
        from pycram.core.runtime import sleep

        drawer = self.world.environment.container(self.stuck_drawer)
        self.note(f"stuck: {drawer.name} is stuck")
        hx, hy, hz = drawer.handle

        def at_handle() -> bool:
            tools = self.world.tool_poses.get_value()
            return any(math.dist(p.position, (hx, hy, hz)) < 0.1 for p in tools.values())

        if not self._wait(at_handle, self.world.tool_poses):
            return
        sleep(self.stuck_for)
        self.world.set_container_stuck(drawer.name, False).wait(10.0)
        self.note(f"stuck: {drawer.name} came free {self.stuck_for:.0f} s after the first pull")

    def _obstacle(self) -> None:
        """Once the robot first carries an object towards the table, a box appears on the floor
        ahead of it (on the straight line to the table, part of the way)."""
        table = self.world.environment.surface("table")
        tx, ty = (table.bounds[0] + table.bounds[2]) / 2, table.bounds[1] - 0.6
        if not self._wait(lambda: bool(self._holding()), *self.world.gripper_states.values()):
            return
        here = self.world.base_pose.get_value()
        f = self.obstacle_fraction
        x, y = here.x + f * (tx - here.x), here.y + f * (ty - here.y)
        if math.hypot(tx - here.x, ty - here.y) < 1.2:
            return
        outcome = self.world.place_obstacle(x, y).wait(10.0)
        if outcome is not None and outcome.succeeded:
            self.note(f"obstacle: a box on the floor at ({x:.2f}, {y:.2f})")
