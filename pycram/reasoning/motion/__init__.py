"""Arm motion planning in the believed world: collision-free joint-space paths, timed within the
joints' limits.

- :mod:`~pycram.reasoning.motion.planner` -- the :class:`MotionPlanner` interface, its
  :class:`MotionPlan` answer (a path or a typed reason) and :func:`plan_to_pose` (IK, then a plan);
- :mod:`~pycram.reasoning.motion.ompl_planner` -- :class:`OMPLPlanner`: straight line first, else
  RRT-Connect with OMPL's path simplification and string pulling, deterministic per seed;
- :mod:`~pycram.reasoning.motion.cartesian` -- :func:`plan_cartesian_line`: a path whose tool
  follows the straight line to a pose (a grasp's approach), IK step by step;
- :mod:`~pycram.reasoning.motion.timing` -- :func:`time_parameterize`: a path as samples (t, q)
  within the joints' velocity and acceleration limits (Ruckig).

The world is prospection's (:class:`pycram.world.prospection.Prospection`): its
``configuration_checker`` (the collision query), ``arm_joint_limits`` and ``solve_ik`` (IK with
mink in the simulator: mink needs the backend's MuJoCo model, so it lives in the backend behind
that method, not here). Nothing here imports a backend.

Typical use (an action or a process module, the robot standing at ``base``)::

    planner = OMPLPlanner()
    plan = planner.plan(prospection, "right", current_q, goal_q, base, exempt_object="cup-1")
    if not plan:
        ...  # plan.reason in PLAN_FAILURES, plan.message says more
    timed = time_parameterize(plan.path, prospection.arm_joint_limits("right"), period=0.02,
                              velocity_scale=0.5)
    # timed.samples(): (t [s], q) for a joint trajectory controller

OMPL and Ruckig (the `sim` extra) are imported when first used.
"""

from .cartesian import plan_cartesian_line
from .ompl_planner import OMPLPlanner
from .planner import PLAN_FAILURES, MotionPlan, MotionPlanner, PoseMotionPlan, plan_to_pose
from .timing import TimedTrajectory, time_parameterize

__all__ = [
    "MotionPlan",
    "MotionPlanner",
    "OMPLPlanner",
    "PLAN_FAILURES",
    "PoseMotionPlan",
    "TimedTrajectory",
    "plan_cartesian_line",
    "plan_to_pose",
    "time_parameterize",
]
