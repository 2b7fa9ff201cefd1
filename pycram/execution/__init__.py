"""The execution layer: process modules (the only code that talks to hardware or a simulator),
the robot abstraction (a resolver set with process modules, and which robot is active),
performing designators, and the typed failures plans and actions raise.

May import: :mod:`pycram.core`, :mod:`pycram.designators` and the standard library.
"""
