"""The layout a run's view opens with: `default_blueprint()`.

Left, the 3D world (the simulator's truth, the belief beside it, the location reasoning); right,
the head camera with its detections, the current action, the task tree as a graph, and the text
log of status changes, failures and log lines; below, the timeline (``sim``: simulated time).
"""

from __future__ import annotations

from typing import Any

from . import paths

__all__ = ["default_blueprint"]


def default_blueprint(eye: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None) -> Any:
    """A `rerun.blueprint.Blueprint` for a run's view (see the module docstring); `eye`: where
    the 3D view looks from and at ([m, map], z up; None: the viewer's choice)."""
    import rerun.blueprint as rrb

    eye_controls = (
        rrb.archetypes.EyeControls3D(position=eye[0], look_target=eye[1], eye_up=(0.0, 0.0, 1.0))
        if eye is not None
        else None
    )

    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(
                    name="world: truth, belief, reasoning",
                    origin="/",
                    contents=[
                        f"{paths.TRUTH}/**",
                        f"{paths.BELIEF_OBJECTS}/**",
                        f"{paths.COSTMAP}/**",
                        paths.CANDIDATES,
                        paths.CHOSEN,
                        f"{paths.MOTION}/**",
                    ],
                    eye_controls=eye_controls,
                    background=(48, 52, 60),
                ),
                rrb.TextLogView(
                    name="task status, failures, log",
                    origin="/",
                    contents=[f"{paths.TREE_STATUS}", f"{paths.TREE_FAILURES}", paths.LOG],
                ),
                row_shares=[3, 1],
            ),
            rrb.Vertical(
                rrb.Spatial2DView(name="head camera", origin=paths.CAMERA),
                rrb.TextDocumentView(name="current action", origin=paths.CURRENT),
                rrb.GraphView(name="task tree", origin=paths.TREE_GRAPH),
                rrb.Tabs(
                    rrb.TimeSeriesView(name="believed openings", origin=paths.BELIEF_CONTAINERS),
                    rrb.Spatial2DView(name="costmap layers", origin=paths.COSTMAP_LAYERS),
                    rrb.TextDocumentView(name="run", origin=paths.RUN),
                ),
                row_shares=[2, 1, 2, 1],
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=paths.SIM_TIMELINE, expanded=True),
        rrb.SelectionPanel(expanded=False),
        rrb.BlueprintPanel(expanded=False),
        collapse_panels=False,
    )
