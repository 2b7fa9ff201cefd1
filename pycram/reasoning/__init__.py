"""The reasoning layer: location designators (where to stand, where to look, where to put
things; :mod:`pycram.reasoning.locations`), answered from the environment description and the
belief; grasp planning (grasp candidates from an object's measured shape and pose,
:mod:`pycram.reasoning.grasps`); arm motion planning (:mod:`pycram.reasoning.motion`).

May import: :mod:`pycram.core`, :mod:`pycram.designators`, :mod:`pycram.execution`,
:mod:`pycram.world`, :mod:`pycram.environments` and numpy. It asks prospection (an interface of
the world layer) "what if"; it never imports a backend.
"""
