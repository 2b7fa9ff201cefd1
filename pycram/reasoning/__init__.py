"""The reasoning layer: location designators (where to stand, where to look, where to put
things; :mod:`pycram.reasoning.locations`), answered from the environment description and the
belief.

May import: :mod:`pycram.core`, :mod:`pycram.designators`, :mod:`pycram.execution`,
:mod:`pycram.world`, :mod:`pycram.environments` and numpy. It asks prospection (an interface of
the world layer) "what if"; it never imports a backend.
"""
