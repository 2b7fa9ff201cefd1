"""Planned arm motions for the simulated robots' arm process module: plan, time, execute, watch,
look, re-plan.

**On by default** for the PR2 and the TIAGo (their arm modules are made with the robot;
:func:`pycram.robots.common.sim_modules.plan_arm_motions` switches it off, or on for a robot built
otherwise).

:class:`ArmMotionPlanner` is what :class:`pycram.robots.common.sim_modules.ArmModule` does for
``move_arm`` (joint goal) and ``reach`` (tool pose) when its robot has a prospection that plans
arm motion:

1. **goal** -- the joint goal as given, or for a tool pose an IK solution from prospection
   (:meth:`~pycram.world.prospection.Prospection.solve_ik`, seeded with the current joints,
   collision-free with the held and grasped objects as below);
2. **plan** -- a collision-free joint-space path from the arm's current joints in prospection's
   world (:class:`~pycram.reasoning.motion.OMPLPlanner`: the straight line when it is free, else
   RRT-Connect), with the object the arm's gripper holds (the belief's ``in_hand``) moving with
   the hand and the object being grasped (the motion's ``object``) exempt at the fingers;
3. **timing** -- :func:`~pycram.reasoning.motion.time_parameterize` within `VELOCITY_SCALE` x
   the joints' velocity limits;
4. **execution** -- the simulator's monitored path controller
   (:meth:`pycram.sim.World.follow_arm_path`, :mod:`pycram.backends.sim.arm_path`): an
   unexpected contact or a joint that lags stops the arm where it is;
5. **looking and re-planning** -- after such a stop the head looks at the tool and one detection
   goes into the belief (the module's ``look``), the arm backs off along the way it came (to the
   last configuration prospection -- knowing now what it saw -- finds free, at least `BACK_OFF`
   back), and the motion is planned again from there, from the world as prospection knows it
   then; at most `REPLANS` times, then the stop's typed failure (``SimMotionFailed`` with
   reason ``'collision'`` or ``'blocked'``). When prospection still sees nothing in the way (the re-plan is the straight
   line again: what was hit is not in the believed world even after the look) the motion goes
   on directly, as before planning existed.

A `LINE_PHASES` motion (the grasp, the lift, the retreat after letting go) moves the tool along
its straight line to the goal (:func:`~pycram.reasoning.motion.cartesian.plan_cartesian_line`)
where that line is free and the arm follows it without flipping: the joints' straight line
between two IK solutions bows (measured: 6.8 cm sideways over a PR2 side grasp's last 10 cm; the
fingers knocked the cup over). A `STRAIGHT_PHASES` motion (towards an object being grasped, or away
from one just let go) is otherwise executed planned only when the joints' straight line is free;
otherwise it moves directly: the object is exempt at the fingers in planning, so a detour could
sweep it away with them (measured). On the way to the pre-grasp pose
(`UNTOUCHED_PHASES`) the object is not exempt but an obstacle like any other. A held object moves
with the hand where the hand holds it (``pycram.backends.sim.believed_world``). A tool position
asked for without an orientation keeps the tool's orientation (when IK finds no such solution, the
motion is direct, as before).

A plan keeps `OBJECT_CLEARANCE` from believed objects (measured poses are a few cm off); a motion
without such a path is planned again allowing touches, then tolerating shallow contacts
(`TOLERATED_PENETRATION`, as location reasoning does when it validates a grasp): `CLEARANCES`.

**Contact motions are not planned.** A motion that touches on purpose has no collision-free path
by definition; it is executed as before planning existed: the direct joint interpolation
(``World.move_arm`` / ``World.reach``), which ends with ``'blocked'`` when the arm cannot follow
(the drawer at its stop). Such are: a motion whose start touches something even tolerating shallow
contacts; one whose gripper squeezes something the belief puts no object in (a handle:
`FIXTURE_EFFORT`); a ``contact`` reach (a hand pushing a door); a `HANDLE_PHASES` reach near a
container's handle; the `DIRECT_PHASES`. A motion for which the planner finds no path within its
budget (``'no_path'``: a narrow passage, or a goal walled in), or whose goal touches something
(``'goal_in_collision'``), moves along the joints' straight line with the watched path controller
(`WATCHED_LINE`): a contact stops it, and it is planned again from there, or fails with the
stop. Directly, too, when prospection's IK finds no solution for a tool pose (the simulator's own
IK is tried, as before), when the robot has no prospection that plans (``NotImplementedError``),
and while the base or the torso moves (`MOVING`: a plan holds for the robot standing where it
stands; the thesis demo raises the arm while the base drives up). The ROS robot's arm modules
use this planner too (:mod:`pycram.robots.common.ros_arm_motion`).

**The torso is not planned** (``include_torso=False``): torso motions are the actions' explicit
``setting_torso`` motions, and the torso's lift is slow (0.05 m/s on the PR2): planning it with
every arm motion would slow each of them and move the head camera the plans point.

Determinism: every plan's seed is the module's count of plans so far, so the same run plans the
same paths (lock-step).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

__all__ = [
    "ArmMotionPlanner",
    "BACK_OFF",
    "CLEARANCES",
    "DIRECT_PHASES",
    "FIXTURE_EFFORT",
    "HANDLE_PHASES",
    "HANDLE_RADIUS",
    "HELD_TILT",
    "MOVING",
    "OBJECT_CLEARANCE",
    "PERIOD",
    "REPLANS",
    "STRAIGHT_PHASES",
    "LINE_PHASES",
    "TOLERATED_PENETRATION",
    "UNTOUCHED_PHASES",
    "VELOCITY_SCALE",
    "WATCHED_LINE",
]

logger = logging.getLogger(__name__)

#: The object being grasped: its name (as prospection knows it) and believed position [m, map];
#: either may be None.
Grasped = tuple[str | None, tuple[float, float, float] | None]

#: Re-plans after a monitored stop (contact or lag) before the motion fails.
REPLANS = 2
#: Fraction of the joints' velocity limits (the URDF's) planned motions move at.
VELOCITY_SCALE = 0.5
#: Sample period [s] of a timed path (the controller interpolates between samples).
PERIOD = 0.02
#: After a stop the arm backs off along the way it came at least this far [rad or m, Euclidean
#: over the arm's joints] (and on until prospection finds it free) before planning again.
BACK_OFF = 0.1
#: The base (linear [m/s], turning [rad/s]) or the torso [m/s] moves faster than this: the arm's
#: motion is not planned (the plan would hold for where the robot was), it moves directly.
MOVING = (0.01, 0.02, 0.005)
#: A motion with no collision-free path is planned again tolerating contacts this deep [m]: what
#: location reasoning tolerates when it validates a grasp (``pycram.backends.sim.prospection``'s
#: ``COLLISION_TOLERANCE``: link meshes collide as their convex hulls, a little larger than the
#: links), so a pose it found reachable is not refused on the way for a brush.
TOLERATED_PENETRATION = 0.015
#: Plans keep this far [m] from believed objects when they can: an object is believed where it
#: was measured, and a box seen from one side is measured a few cm off its centre (measured: the
#: TIAGo's cereal box, 2.6 cm; its forearm, planned to pass the believed box, hit the real one).
OBJECT_CLEARANCE = 0.03
#: A held object is tilted at most this far [rad] from how it stands when a motion starts (or as
#: far as the motion's goal tilts it): a plan free to turn the wrist turned a plate carried by its
#: rim 107 deg on the way to placing it, and it fell (measured: PR2, set-table-anywhere,
#: ``procedural:4``, seed 1).
HELD_TILT = math.radians(30.0)
#: Reaching phases at a container's handle that move directly (not planned), for now: the grasp
#: closes in on the handle (a contact), and a planned retreat from the handle of a door just
#: pushed shut pulled it open again (3.4 deg, the PR2's cupboard). The approach to the pre-grasp
#: pose is planned: moved directly, the TIAGo Pro's arm swept into a wide-open cupboard door and
#: stopped 0.18-0.33 m short from every standing pose (set-table seeds 8 and 27: cupboard left
#: open). (An earlier measurement, before grasps were validated by prospection's IK: a planned
#: approach ended in another arm configuration, from which the door's arc was out of reach.)
HANDLE_PHASES = ("grasp", "retreat")
#: A reaching target within this distance [m] of a container's handle (anywhere on the handle's
#: way) goes for the handle.
HANDLE_RADIUS = 0.15
#: A gripper squeezing with more than this effort [N] while the belief puts no object in it holds a
#: fixture (a handle): its arm's motions are contact motions, moved directly.
FIXTURE_EFFORT = 1.0
#: What a plan keeps clear of, tried in turn until one has a path: (environment and robot [m],
#: believed objects [m]). First `OBJECT_CLEARANCE` from believed objects, then touching allowed,
#: then shallow contacts tolerated (`TOLERATED_PENETRATION`) with the furniture, then with the
#: believed objects too -- rather than the direct motion, which watches nothing on its way: a
#: carried bowl's goal 3 mm into a believed milk carton's top, moved directly, swept through the
#: plate the other hand held (measured: PR2, set-table-anywhere, ``procedural:4``, seed 1).
CLEARANCES: tuple[tuple[float, float], ...] = (
    (0.0, OBJECT_CLEARANCE),
    (0.0, 0.0),
    (-TOLERATED_PENETRATION, 0.0),
    (-TOLERATED_PENETRATION, -TOLERATED_PENETRATION),
)
#: The planner name of a motion the planner found no path for within its budget, or whose goal
#: touches something, moved along the joints' straight line by the watched path controller (a
#: contact stops it) instead of directly.
WATCHED_LINE = "watched_line"
#: Reaching phases executed directly (not planned): they end with the held object touching down
#: (``place``: 1 cm above the believed surface; touching down earlier stops the arm with
#: ``'blocked'``, which the place action takes for "down").
DIRECT_PHASES = ("place",)
#: Reaching phases with the fingers round an object that is not held (yet, or any more): the
#: grasp, which ends at an object that may not be known to prospection (a plan that names no
#: ``object``), and the retreat from an object just let go, exempt at the fingers. The tool's
#: straight line, else the joints' straight line or the direct motion, never a detour (measured:
#: the thesis demo's hand, planned round the counter's edge, swept the unperceived item away; the
#: PR2's retreat from a cereal box put down from the top, planned through another IK branch,
#: swung the fingers 15 cm sideways and knocked it over).
STRAIGHT_PHASES = ("grasp", "retreat")
#: Reaching phases that try the tool's straight line first (`plan_cartesian_line`), then plan as
#: any motion: the `STRAIGHT_PHASES`, and the lift of an object just grasped (straight up off its
#: surface: the joints' line between two IK solutions drags it sideways first; and straight out
#: of a doorway, `pycram.actions.pick_up._withdraw`).
LINE_PHASES = (*STRAIGHT_PHASES, "lift")
#: Reaching phases towards an object that must not touch it (the object a motion names is then an
#: obstacle like any other, not exempt at the fingers).
UNTOUCHED_PHASES = ("pre_grasp",)


class _Direct(Exception):
    """Internal: execute this motion the direct way (a contact motion, or no planning)."""


class ArmMotionPlanner:
    """Plans and executes the motions of one arm of a simulated robot (see the module docstring).

    ``world``: the :class:`pycram.sim.World`; ``arm``: the physical arm; ``robot``: a callable
    returning the robot (its ``prospection`` and ``belief`` are read at each motion: they may be
    replaced); ``run``: the process module's ``_run_command`` (send, wait, raise
    ``SimMotionFailed``); ``failure``: that exception class (raised with ``(command, reason,
    message, outcome)``; its ``reason``, ``message``, ``command`` and ``outcome`` are read);
    ``look``: points the head at a point [m, map] and detects into the belief (after a stop, so
    that the next plan knows what was hit), or None.
    """

    def __init__(
        self,
        world: Any,
        arm: str,
        robot: Callable[[], Any],
        run: Callable[..., Any],
        failure: type[Any],
        look: Callable[[tuple[float, float, float]], Any] | None = None,
    ) -> None:
        from pycram.reasoning.motion import OMPLPlanner

        self.world, self.arm = world, arm
        self._look = look
        self._robot, self._run, self._failure = robot, run, failure
        self.planner = OMPLPlanner()
        self.plans = 0  #: plans made so far (each plan's seed)
        #: The last motion's plans (:class:`~pycram.reasoning.motion.MotionPlan`, one per attempt)
        #: and its monitored stops (``SimMotionFailed``, reason ``'collision'`` or ``'blocked'``).
        self.last_plans: list[Any] = []
        self.last_stops: list[Any] = []
        self.description = world.description
        self.joints = tuple(self.description.ARMS[arm]["joints"])
        self.gripper = self.description.ARMS[arm]["gripper"]

    # ------------------------------------------------------------------ the world as known
    def prospection(self) -> Any:
        robot = self._robot()
        prospection = getattr(robot, "prospection", None)
        if prospection is None:
            raise _Direct("no prospection")
        return prospection

    def _still(self) -> None:
        """Raise `_Direct` while the base or the torso moves: a plan is made for the robot standing
        as it stands now (e.g. an arm raised to carry while the base still drives up: the thesis
        demo's)."""
        velocity = self.world.joint_states.get_value().velocity
        base = math.hypot(velocity.get("base_x", 0.0), velocity.get("base_y", 0.0))
        turn = abs(velocity.get("base_yaw", 0.0))
        torso = abs(velocity.get(self.description.TORSO["joint"], 0.0))
        if base > MOVING[0] or turn > MOVING[1] or torso > MOVING[2]:
            raise _Direct(f"the robot moves (base {base:.3f} m/s, {turn:.3f} rad/s, torso {torso:.3f} m/s)")

    def _current(self) -> list[float]:
        positions = self.world.joint_states.get_value().position
        return [float(positions[j]) for j in self.joints]

    def _held(self) -> tuple[str, ...]:
        """Names the object in this arm's gripper may have in prospection, best first: the
        belief's (its ``in_hand``), then the gripper's own reading of what it holds (the name a
        prospection of the simulation's state knows it by); empty when it holds nothing."""
        belief = getattr(self._robot(), "belief", None)
        held = getattr(belief, "in_hand", {}).get(self.gripper) if belief is not None else None
        names = [getattr(held, "name", None)]
        states = getattr(self.world, "gripper_states", None)
        if held is not None and states is not None and self.gripper in states:
            names.append(getattr(states[self.gripper].get_value(), "holding", None))
        return tuple(dict.fromkeys(n for n in names if isinstance(n, str)))

    def _holds(self) -> bool:
        """Whether this arm's gripper holds an object (the belief's ``in_hand``)."""
        belief = getattr(self._robot(), "belief", None)
        return belief is not None and getattr(belief, "in_hand", {}).get(self.gripper) is not None

    # ------------------------------------------------------------------ motions
    def move(self, goal: Sequence[float], what: str, direct: Callable[[], Any], grasped: Grasped = (None, None)) -> Any:
        """Move the arm to the joint ``goal`` [rad or m]; ``direct()`` runs it the direct way;
        ``grasped``: the object being grasped (name, believed position [m, map]), if any."""
        try:
            self._still()
            self._grips_fixture()
            return self._planned(list(goal), what, grasped, PathGoal())
        except _Direct as why:
            logger.debug("%s: direct (%s)", what, why)
            return direct()

    def reach(
        self,
        position: Sequence[float],
        orientation: Sequence[float] | None,
        tolerance: float,
        what: str,
        direct: Callable[[], Any],
        grasped: Grasped = (None, None),
        phase: str | None = None,
        contact: bool = False,
        guess: Sequence[float] | None = None,
    ) -> Any:
        """Move the tool to ``position`` [m, map] (``orientation`` (w, x, y, z) or None); returns
        the reached tool pose; ``direct()`` runs it the direct way (always for the phases of
        `DIRECT_PHASES`, for ``contact`` motions -- the tool meant to touch what it reaches, a
        door it pushes -- and for `HANDLE_PHASES` towards a container's handle); ``grasped`` as in
        :meth:`move`; ``guess``: arm joint positions found for this pose before (location
        reasoning's validated solution), IK's first seed, before the arm's current joints."""
        if phase in UNTOUCHED_PHASES:
            # the fingers keep off the object until the grasp itself: exempt on the way to the
            # pre-grasp pose, they swept a bowl 8 cm aside (measured: the TIAGo's, the bowl was then
            # held by its far rim and put down 13 cm off); not exempt, it is planned around
            grasped = (None, None)
        exempt = grasped[0]
        try:
            if phase in DIRECT_PHASES:
                raise _Direct(f"the {phase} phase")
            if contact:
                raise _Direct("a contact motion (the motion's contact)")
            if phase in HANDLE_PHASES and self._at_a_handle(position):
                raise _Direct(f"the {phase} phase towards a container's handle")
            self._still()
            self._grips_fixture()
            prospection = self.prospection()
            held = self._held()
            base = self.world.base_pose.get_value()
            current = self._current()
            leaving = self._let_go(prospection, held) if exempt is None and phase not in UNTOUCHED_PHASES else None
            if leaving is not None:
                grasped, exempt = leaving, leaving[0]
            self._not_in_contact(prospection, base, current, held, exempt)
            if orientation is None:
                # the tool keeps its orientation, as the direct reach (a local solver) keeps it
                # nearly: IK for the position alone from other seeds turns the wrist (measured: the
                # TIAGo's bowl, held by the rim, swung to the tool's other side and was put down
                # 13 cm off; the thesis demo's fingers closed beside the item)
                orientation = self.world.tool_poses.get_value()[self.arm].orientation
            pose = (tuple(position), None if orientation is None else tuple(orientation))
            seeds = [*([list(guess)] if guess else []), current]
            ik = _with_known_objects(partial(prospection.solve_ik, self.arm, pose, base, seeds=seeds), held, exempt)
            if not ik and ik.reason == "no_solution":
                # no seed converged to 1 mm: a solution within half the motion's own tolerance
                # still ends where the motion counts as arrived (measured: a PR2 side grasp of
                # a cup 20 cm deep on the counter, location reasoning's solution 4 mm off)
                loose = partial(prospection.solve_ik, position_tolerance=tolerance / 2)
                ik = _with_known_objects(partial(loose, self.arm, pose, base, seeds=seeds), held, exempt)
            if not ik:  # no solution, or only touching ones (a contact motion): as before
                raise _Direct(f"IK: {ik.reason}: {ik.message}")
            goal = PathGoal(position=tuple(float(v) for v in position), tolerance=tolerance)
            line = None
            if phase in LINE_PHASES:  # the tool along the line, not the joints' bow
                line = self._cartesian_line(prospection, current, pose, base, held, exempt)
            return self._planned(
                list(line.path[-1]) if line else list(ik.positions),
                what,
                grasped,
                goal,
                leaving=leaving is not None,
                straight=phase in STRAIGHT_PHASES,
                line=line,
            )
        except (NotImplementedError, _Direct) as why:
            logger.debug("%s: direct (%s)", what, why)
            return direct()

    def _cartesian_line(
        self, prospection: Any, current: list[float], pose: Any, base: Any, held: Sequence[str], exempt: str | None
    ) -> Any:
        """The tool's straight line to ``pose`` (`plan_cartesian_line`, the first of `CLEARANCES`
        it keeps), or None (then the joints' straight line or the direct motion, as before)."""
        from pycram.reasoning.motion.cartesian import plan_cartesian_line

        ask = partial(plan_cartesian_line, prospection, self.arm, current, pose, base, clearances=CLEARANCES)
        line = _with_known_objects(ask, held, exempt)
        logger.debug("the tool's straight line: %s", "planned" if line else f"{line.reason}: {line.message}")
        return line if line else None

    def _planned(
        self,
        goal: list[float],
        what: str,
        grasped: Grasped,
        target: PathGoal,
        leaving: bool | None = None,
        straight: bool = False,
        line: Any = None,
    ) -> Any:
        """Plan, execute and re-plan (see the module docstring); ``leaving``: the motion leaves an
        object at the fingers (`_let_go`; None: find out here); ``straight``: the straight line
        or the direct motion, no detour; ``line``: a plan of the tool's straight line to
        ``goal`` (`plan_cartesian_line`), the first attempt's path."""
        from pycram.reasoning.motion import MotionPlan, time_parameterize

        prospection = self.prospection()
        limits = prospection.arm_joint_limits(self.arm)
        held = self._held()
        if leaving is None:
            let_go = self._let_go(prospection, held) if grasped[0] is None else None
            leaving = let_go is not None
            if let_go is not None:
                grasped = let_go
        exempt, near = grasped
        stopped: Any = None  # the last monitored stop
        self.last_plans, self.last_stops = [], []
        for attempt in range(REPLANS + 1):
            base = self.world.base_pose.get_value()
            current = self._current()
            seed = self.plans
            self.plans += 1
            planned_line = line is not None and attempt == 0
            if planned_line:  # the tool's straight line, planned already
                plan = line
                self.last_plans.append(plan)
            # after a stop, contacts with believed objects are no longer tolerated: the object hit
            # may be one (a plan 15 mm into a believed milk carton stopped on it, and the line
            # planned again through it, moved directly, knocked it over: procedural:4, seed 1)
            levels = CLEARANCES if stopped is None else tuple(c for c in CLEARANCES if c[1] >= 0.0)
            for clearance, object_clearance in () if planned_line else levels:
                plan = _with_known_objects(
                    partial(
                        self.planner.plan,
                        prospection,
                        self.arm,
                        current,
                        goal,
                        base,
                        clearance=clearance,
                        object_clearance=object_clearance,
                        held_tilt=HELD_TILT,
                        seed=seed,
                    ),
                    held,
                    exempt,
                )
                self.last_plans.append(plan)
                if plan or plan.reason == "outside_limits":
                    break
            logger.debug(
                "%s: plan %d: %s", what, seed, f"{plan.planner}, {len(plan.path)} waypoints" if plan else plan.reason
            )
            grasping = straight or (exempt is not None and exempt not in held and not leaving)
            if plan and plan.planner not in ("straight_line", "cartesian_line", WATCHED_LINE) and grasping:
                # the planner lets the fingers through the object being grasped: a detour could
                # sweep it away with them (measured: the PR2's hand swung round a mug and pushed it
                # 14 cm) -- a motion towards an object being grasped is the straight line or direct
                raise _Direct(f"a detour ({plan.planner}) towards an object being grasped")
            if plan and stopped is not None and plan.planner == "straight_line":
                # prospection sees nothing in the way of the line just stopped on: what was hit is
                # not in the believed world (nobody looked), so planning again cannot go round it;
                # the motion goes on directly, as before planning (looking at what was hit and
                # putting it into the belief is left to the actions)
                raise _Direct(f"after {stopped.reason}: {stopped.message}, nothing known in the way")
            if not plan:
                if stopped is not None:  # no way on from where it stopped: the stop is the failure
                    raise self._failure(
                        stopped.command,
                        stopped.reason,
                        f"{stopped.message}; planning again: {plan.reason}: {plan.message}",
                        stopped.outcome,
                    )
                if plan.reason not in ("no_path", "goal_in_collision"):
                    raise _Direct(f"plan: {plan.reason}: {plan.message}")
                # no path within the budget (a narrow passage), or a goal that touches something
                # even tolerating shallow contacts: the joints' straight line, watched -- moved
                # directly it swept a carried bowl through the plate the other hand held, and a
                # carried bowl into a milk carton beside it (PR2, set-table-anywhere,
                # procedural:4 and 8, seed 1); watched, a contact stops it
                logger.info("%s: %s: the joints' straight line, watched", what, plan.message)
                plan = MotionPlan(plan.joints, (tuple(current), tuple(goal)), None, "", WATCHED_LINE)
                self.last_plans.append(plan)
            timed = time_parameterize(plan.path, limits, period=PERIOD, velocity_scale=VELOCITY_SCALE)
            samples = timed.samples()
            try:
                value = self._run(
                    partial(
                        self.world.follow_arm_path,
                        self.arm,
                        plan.joints,
                        samples,
                        exempt_near=near,
                    ),
                    what,
                    timeout=timed.duration + 10.0,
                )
            except self._failure as failure:
                if failure.reason == "blocked" and target.position is not None:
                    try:  # the tool there all the same (fingers pressing on what they grasp): reached
                        return self._tool_check(what, target)
                    except self._failure:
                        pass
                stop = getattr(failure.outcome, "value", None)
                if failure.reason not in ("collision", "blocked") or attempt == REPLANS or stop is None:
                    raise
                stopped = failure
                self.last_stops.append(failure)
                logger.info("%s: %s: %s; backing off to plan again", what, failure.reason, failure.message)
                self._look_at_stop(what)  # first: backing off then goes to where it is free of what was seen
                held = self._held()
                self._back_off(prospection, samples, stop, held, grasped, limits)
                continue
            if target.position is None:
                return value
            return self._tool_check(what, target)
        raise AssertionError("unreachable")  # pragma: no cover - the loop returns or raises

    def _back_off(
        self, prospection: Any, samples: list, stop: Any, held: Sequence[str], grasped: Grasped, limits: Any
    ) -> None:
        """Back along the executed samples from where the arm stopped: to the first one at least
        `BACK_OFF` away that prospection finds free (else the path's start), then stop there.
        Best effort: a back-off that itself stops leaves the arm where it stopped."""
        from pycram.reasoning.motion import time_parameterize

        here = list(stop.positions)
        exempt, near = grasped
        base = self.world.base_pose.get_value()
        target = list(samples[0][1])
        try:
            checker = _with_known_objects(
                partial(prospection.configuration_checker, self.arm, base),
                held,
                exempt,
            )
        except ValueError:
            checker = None
        try:
            for k in range(min(stop.sample, len(samples) - 1), -1, -1):
                q = list(samples[k][1])
                if math.dist(q, here) >= BACK_OFF and (checker is None or checker.is_free(q)):
                    target = q
                    break
        finally:
            if checker is not None:
                checker.close()
        timed = time_parameterize([here, target], limits, period=PERIOD, velocity_scale=VELOCITY_SCALE)
        try:
            self._run(
                lambda: self.world.follow_arm_path(self.arm, self.joints, timed.samples(), exempt_near=near),
                f"back off with the {self.arm} arm",
                timeout=timed.duration + 10.0,
            )
        except self._failure as failure:
            logger.info("backing off stopped: %s", failure)

    def _let_go(self, prospection: Any, held: Sequence[str]) -> Grasped | None:
        """The object the gripper touches where the arm stands now, if it touches nothing else:
        one just let go of (or not yet grasped), at the fingers. The motion that leaves it keeps
        it exempt at the fingers -- as the object being grasped, but detours allowed: the hand
        moves away from it (measured: after putting a cereal box down, the arm's way to carry
        started with the fingers at the box, and every plan was refused). None otherwise."""
        believed = getattr(prospection, "believed", None)
        if believed is None:
            return None
        base = self.world.base_pose.get_value()
        current = self._current()
        touching = partial(self._contacts, prospection, base, current, held)
        try:
            names = {believed.name_of(other) for _, other in touching(None)}
            if len(names) != 1 or None in names:
                return None
            (name,) = names
            if name in held or touching(name):
                return None
        except ValueError:
            return None
        obj = next((o for o in getattr(self._robot().belief, "objects", lambda: [])() if o.name == name), None)
        position = getattr(obj, "pose", None)
        if position is None:
            return name, None
        x, y, z = (float(v) for v in position[:3])
        return name, (x, y, z)

    def _at_a_handle(self, point: Sequence[float]) -> bool:
        """Whether ``point`` [m, map] is within `HANDLE_RADIUS` of a container's handle anywhere
        on its way (the environment's description: the handle at 11 openings over the joint's
        range -- the belief's opening may be stale while the hand moves the container)."""
        belief = getattr(self._robot(), "belief", None)
        environment = getattr(belief, "environment", None)
        for container in getattr(environment, "containers", ()):
            low, high = container.limits
            for k in range(11):
                handle = container.handle_position(low + (high - low) * k / 10)
                if math.dist(handle, tuple(point)[:3]) <= HANDLE_RADIUS:
                    return True
        return False

    def _grips_fixture(self) -> None:
        """Raise `_Direct` when this arm's gripper squeezes something (its measured effort above
        `FIXTURE_EFFORT`) while the belief puts no object in it: a handle or a door's edge -- the
        motion is a contact motion (measured: the fridge's handle, dragged along its arc by planned
        straight lines, was lost at the first step)."""
        if self._holds():
            return
        states = getattr(self.world, "gripper_states", None)
        state = None if states is None or self.gripper not in states else states[self.gripper].get_value()
        effort = float(getattr(state, "effort", 0.0) or 0.0)
        if effort > FIXTURE_EFFORT:
            raise _Direct(
                f"a contact motion: the {self.gripper} gripper squeezes something not an object ({effort:.1f} N)"
            )

    def _contacts(
        self,
        prospection: Any,
        base: Any,
        q: Sequence[float],
        held: Sequence[str],
        exempt: str | None,
        clearance: float = 0.0,
    ) -> list[tuple[str, str]]:
        """The pairs (arm part, obstacle) touching with the arm at ``q`` in prospection (closer
        than ``clearance`` [m]), the held object moving with the hand and ``exempt`` allowed at
        the fingers; ``ValueError`` when prospection knows none of the names."""
        ask = partial(prospection.configuration_checker, self.arm, base, clearance=clearance)
        with _with_known_objects(ask, held, exempt) as checker:
            return list(checker.contacts(q))

    def _not_in_contact(
        self, prospection: Any, base: Any, current: Sequence[float], held: Sequence[str], exempt: str | None
    ) -> None:
        """Raise `_Direct` when the arm touches something where it stands now, even tolerating
        shallow contacts (a contact motion: fingers round a handle, a hand at a door), before the
        IK for its goal is sought: such a goal touches too, and IK would try every seed for a
        free solution first (measured: 7-9 s per step of closing a drawer, under load)."""
        try:
            contacts = self._contacts(prospection, base, current, held, exempt, clearance=CLEARANCES[-1][0])
        except ValueError:
            return
        if contacts:
            raise _Direct(f"a contact motion: {contacts[0][0]} touches {contacts[0][1]}")

    def _look_at_stop(self, what: str) -> None:
        """Look where the arm stopped (the head at the tool, then one detection into the belief),
        so that the next plan knows what was hit. Best effort: a head that cannot point there, or
        a robot without the motions, leaves the belief as it was."""
        if self._look is None:
            return
        x, y, z = (float(v) for v in self.world.tool_poses.get_value()[self.arm].position)
        point = (x, y, z)
        try:
            self._look(point)
        except Exception as failure:  # noqa: BLE001 - a look that fails leaves the belief as it was
            logger.info("%s: looking at where the arm stopped failed: %s", what, failure)

    def _tool_check(self, what: str, target: PathGoal) -> Any:
        """The reached tool pose; ``SimMotionFailed('blocked')`` when it is farther than the
        tolerance from the target position (as the direct reach reports it)."""
        pose = self.world.tool_poses.get_value()[self.arm]
        assert target.position is not None and target.tolerance is not None
        error = math.dist(pose.position, target.position)
        if error > target.tolerance:
            raise self._failure(what, "blocked", f"tool stopped {error:.3f} m from the goal")
        return pose


class PathGoal:
    """What a planned motion must reach: nothing beyond its joint goal (``position`` None), or the
    tool within ``tolerance`` [m] of ``position`` [m, map]."""

    def __init__(self, position: tuple[float, ...] | None = None, tolerance: float | None = None) -> None:
        self.position, self.tolerance = position, tolerance


def _with_known_objects(ask: Callable[..., Any], held: Sequence[str], exempt: str | None) -> Any:
    """``ask(held_object=..., exempt_object=...)`` with the first of the ``held`` names and
    ``exempt``; an object prospection does not know (``ValueError``, e.g. one the belief names
    differently) is replaced by the next name or left out, and the question asked again."""
    for h in (*held, None):
        for e in dict.fromkeys((exempt, None)):
            try:
                return ask(held_object=h, exempt_object=e)
            except ValueError:
                if h is None and e is None:
                    raise
    raise AssertionError("unreachable")  # pragma: no cover - the last question raises or returns
