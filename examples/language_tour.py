"""A tour of the PyCRAM plan language in the thesis' block syntax.

Run it with `pycram run examples/language_tour.py` or `python -m pycram examples/language_tour.py`.
"""

import logging

from pycram.fluent import Behavior, Fluent, whenever
from pycram.language import State, failure_handling, par, pursue, seq, try_in_order
from pycram.runtime import format_task_tree, sleep

logging.basicConfig(level=logging.INFO, format="%(message)s")
log = logging.getLogger("tour")

# Fluents: observable values. Networks like `distance < 0.1` wake their waiters on every change.
distance = Fluent(2.0, name="distance")
arrived = distance < 0.1

# par: both branches run concurrently; the plan drives while a monitor reports progress.
errors = []
with par(errors) as driving:
    if True:  # one branch of several statements
        while distance.get_value() > 0:
            sleep(0.01)
            distance.set_value(round(distance.get_value() - 0.25, 2))
    with pursue as monitor:  # a nested expression is one branch too
        arrived.wait_for()
        for _ in whenever(distance.pulsed(Behavior.ONCE)):
            log.info("distance to goal: %.2f m", distance.get_value())
log.info("driving: %s, errors: %s", driving.get_value(), errors)

# try_in_order: alternatives in order until one succeeds; errors collects the failures.
attempts = []
with try_in_order(attempts) as grasping:
    if True:
        log.info("grasp from the left ...")
        raise RuntimeError("nothing in the gripper")
    if True:
        log.info("grasp from the right ...")
log.info("grasping: %s after %d failed attempt(s)", grasping.get_value(), len(attempts))

# failure_handling: retry() restarts the body (here at most 3 times).
tries = 0
with failure_handling(3):
    try:
        tries += 1
        if tries < 3:
            raise RuntimeError("item slipped")
        log.info("placed the item on try %d", tries)
    except RuntimeError:
        retry()

# seq: in order, stops at the first failure, never raises.
with seq as tidy:
    log.info("park arms")
    log.info("lower torso")
assert tidy.get_value() is State.SUCCEEDED

log.info("\n%s", format_task_tree())
