"""The simulated world: a MuJoCo environment with a robot whose sensors feed fluents.

A public face: the simulator backend is :mod:`pycram.backends.sim`. Import it only when a
simulation is wanted: it imports numpy and mujoco. Quick start::

    from pycram.sim import World
    with World("pr2") as world:
        world.drive_to(*world.description.KITCHEN_BASE_POSES["cooker #2"]).wait(30)
        world.snapshot("kitchen.png")
"""

from pycram.backends.sim import *  # noqa: F401,F403
from pycram.backends.sim import __all__  # noqa: F401
