"""A Franka Panda arm on a mobile base built from primitives: a robot added to PyCRAM from outside
its repository (the worked example of docs/byo-robot.md)."""
