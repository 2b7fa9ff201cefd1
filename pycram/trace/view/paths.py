"""The entity paths and timelines of a run's view (what a recording holds, and where).

==========================  ================================================================
entity path                 what
==========================  ================================================================
``truth/robot/...``         the robot's links (one entity per body, nested as the kinematic
                            tree; transforms relative to the parent link)
``truth/furniture/...``     the environment: furniture with its drawers and doors
``truth/objects/NAME``      each object the simulator has, under its simulator name
``belief/objects/NAME``     each object the robot believes in (a box at its believed pose;
                            its label says when it was last seen, or that it is believed gone)
``belief/containers/NAME``  each container's believed opening [m or rad] (a time series)
``camera/head``             the head camera's image at each look (``detecting``), with the
                            detections drawn on it (``camera/head/detections``)
``reasoning/costmap/...``   the sum of the costmaps of the latest base-pose resolution, as
                            coloured points on the floor in 3D
``reasoning/layers/...``    each costmap layer of it, as an image over the floor
``reasoning/candidates``    the candidates tried, coloured by why each was ruled out (green:
                            accepted), and ``reasoning/chosen`` the pose chosen
``reasoning/motion/ARM``    the tool path of the arm's latest motion plan (its waypoints as
                            points)
``tree/status``             one text-log row per change of a task's status (running,
                            succeeded, failed, evaporated) -- as many as the trace database has
``tree/graph``              the task tree as a graph, nodes coloured by status
``tree/failures``           each failure where it was raised, with its typed reason
``plan/current``            the current action, motion and object, and the running tasks
``log``                     the run's log lines
==========================  ================================================================

Timelines: ``sim`` (simulated time [s], or the run's clock) and ``wall`` (wall-clock time).
"""

from __future__ import annotations

__all__ = [
    "TRUTH",
    "ROBOT",
    "FURNITURE",
    "OBJECTS",
    "BELIEF_OBJECTS",
    "BELIEF_CONTAINERS",
    "CAMERA",
    "DETECTIONS",
    "COSTMAP",
    "COSTMAP_LAYERS",
    "CANDIDATES",
    "CHOSEN",
    "MOTION",
    "TREE_STATUS",
    "TREE_GRAPH",
    "TREE_FAILURES",
    "CURRENT",
    "LOG",
    "RUN",
    "SIM_TIMELINE",
    "WALL_TIMELINE",
    "APPLICATION_ID",
]

#: The simulator's truth (robot, furniture, objects).
TRUTH = "truth"
#: The robot's links, nested as its kinematic tree.
ROBOT = "truth/robot"
#: The environment: furniture, drawers, doors (and obstacles).
FURNITURE = "truth/furniture"
#: The simulator's objects, one entity per object name.
OBJECTS = "truth/objects"
#: The believed objects, one entity per belief name.
BELIEF_OBJECTS = "belief/objects"
#: Each container's believed opening [m or rad] (time series).
BELIEF_CONTAINERS = "belief/containers"
#: The head camera's image at each look.
CAMERA = "camera/head"
#: The objects seen in a look, drawn on its image.
DETECTIONS = "camera/head/detections"
#: The sum of the costmaps of the latest base-pose resolution, as coloured points on the floor.
COSTMAP = "reasoning/costmap"
#: Each costmap layer of the latest base-pose resolution, as an image over the floor.
COSTMAP_LAYERS = "reasoning/layers"
#: The candidates of the latest search, coloured by why each was ruled out.
CANDIDATES = "reasoning/candidates"
#: The first accepted candidate (an arrow along its heading).
CHOSEN = "reasoning/chosen"
#: The tool path of each arm's latest motion plan (``reasoning/motion/ARM``).
MOTION = "reasoning/motion"
#: One text-log row per change of a task's status.
TREE_STATUS = "tree/status"
#: The task tree as a graph, nodes coloured by status.
TREE_GRAPH = "tree/graph"
#: Each failure where it was raised, with its typed reason.
TREE_FAILURES = "tree/failures"
#: The current action, motion and object, and the running tasks.
CURRENT = "plan/current"
#: The run's log lines (and, rebuilt from the database, its executions).
LOG = "log"
#: A summary of the run (robot, trace database run).
RUN = "run"
#: The timeline of the run's clock: simulated time [s] in a simulation.
SIM_TIMELINE = "sim"
#: The wall-clock timeline.
WALL_TIMELINE = "wall"
#: The Rerun application id of every PyCRAM recording.
APPLICATION_ID = "pycram"
