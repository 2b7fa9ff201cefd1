"""The cameras and perception of a `World`: RGB images and segmentation of any camera,
snapshots to PNG, and the head camera's object perception (`perceive`: what the simulator sees;
`detect`: measured detections for the belief, with perception faults).

Rendering happens in the simulation thread (its own renderers, created on first use); each
command returns a `CommandHandle` at once. `snapshot` (pictures for people) draws the published
state in the caller's thread instead and costs the simulation nothing. Images are height x width arrays [px].
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np

from pycram.core.fluent import Fluent
from pycram.world.types import VisibleItem

from .camera import FollowView
from .commands import CommandQueue
from .engine import Engine
from .errors import WorldClosedError
from .handle import CommandHandle
from .perception import MAX_RANGE, MIN_PIXELS, PerceptionFaults, measure_detections, view_of
from .recording import StateSnapshot
from .render import Renderers, write_png
from .robot_model import HEAD_CAMERA


class Sensing(CommandQueue):
    """The camera and perception commands of a `World` (a part of it: `World` inherits them)."""

    camera_image: Fluent
    perception_faults: PerceptionFaults
    _fault_rng: np.random.Generator
    _renderers: Renderers | None
    _perception_renderers: Renderers | None
    _state: StateSnapshot  #: what the sensors last published (`World._publish`)
    _closed: bool

    def _get_renderers(self) -> Renderers:
        if self._renderers is None:
            self._renderers = Renderers(self.scene.model)
        return self._renderers

    def _get_perception_renderers(self) -> Renderers:
        """Renderers of object perception, on a copy of the model without multisampling (~2x
        cheaper with a software renderer; the geometry is the model's, the state `eng.data`)."""
        if self._perception_renderers is None:
            model = copy.copy(self.scene.model)  # mj_copyModel: nothing shared afterwards
            model.vis.quality.offsamples = 0
            self._perception_renderers = Renderers(model)
        return self._perception_renderers

    def request_image(
        self, camera: str | FollowView = HEAD_CAMERA, width: int = 320, height: int = 240, hide_objects: bool = False
    ) -> CommandHandle:
        """Render an RGB image (height x width x 3, uint8) from `camera` (a camera name or a
        `FollowView`); also set `camera_image`.

        `hide_objects` leaves the items out of the picture (e.g. a plan to draw a belief on).
        """
        self._check_camera(camera)

        def fn(eng: Engine) -> np.ndarray:
            geoms = [g for gs in eng.item_part_geoms.values() for g in gs] if hide_objects else []
            saved = eng.model.geom_rgba[geoms, 3].copy()
            eng.model.geom_rgba[geoms, 3] = 0.0  # fully transparent geoms are not drawn
            try:
                img = self._get_renderers().rgb(eng.data, camera, width, height)
            finally:
                eng.model.geom_rgba[geoms, 3] = saved
            self.camera_image.set_value(img)
            return img

        return self._call(f"image:{camera}", fn)

    def snapshot(
        self,
        path: str | Path,
        camera: str | FollowView = "overview",
        width: int = 640,
        height: int = 480,
    ) -> Path:
        """Draw `camera` (a camera name or a `FollowView`) and write a PNG to `path`.

        The picture shows the state the sensors last published -- in a lock-step world, while
        plan code (the caller) runs, exactly the present; in a free-running one at most one
        sensor period old -- and is drawn in the calling thread (`StateSnapshot.picture`): it
        sends the simulation no command, so it costs no simulated time and writing pictures
        never changes a run. Raises `WorldClosedError` once the world is closed."""
        self._check_camera(camera)
        if self._closed:
            raise WorldClosedError("snapshot of a closed world")
        return write_png(path, self._state.picture(self.scene.model, camera, width, height))

    def perceive(self, min_pixels: int = 20, width: int = 320, height: int = 240) -> CommandHandle:
        """Items visible to the head camera (segmentation render): value `list[VisibleItem]`,
        most visible first. An item hidden behind others or outside the view is not reported."""

        def fn(eng: Engine) -> list[VisibleItem]:
            ids = self._get_renderers().segmentation(eng.data, HEAD_CAMERA, width, height)
            seen = []
            for name, geoms in eng.item_part_geoms.items():
                rows, cols = np.nonzero(np.isin(ids, geoms))
                if len(rows) >= min_pixels:
                    seen.append(
                        VisibleItem(
                            name,
                            self.scene.item(name).type,
                            eng.item_pose(name),
                            len(rows),
                            (float(cols.mean()), float(rows.mean())),
                        )
                    )
            return sorted(seen, key=lambda v: -v.pixels)

        return self._call("perceive", fn)

    def detect(
        self, width: int = 320, height: int = 240, min_pixels: int = MIN_PIXELS, max_range: float = MAX_RANGE
    ) -> CommandHandle:
        """One look of the head camera's object perception: value a
        `pycram.world.belief.PerceptionReport` (detections measured from segmentation, depth and
        colour images of `width` x `height` [px], most visible first; the camera view with its
        depth image; the joint positions of the containers whose handle is in the image or that
        an object was seen inside; where each gripper's tool frame is),
        stamped with the simulated time.

        Objects with fewer than `min_pixels` visible pixels or farther than `max_range` [m] are
        not reported; `perception_faults` apply. No simulator names or poses are reported.
        """
        return self._call("detect", lambda eng: self._detect(eng, width, height, min_pixels, max_range))

    def _detect(self, eng: Engine, width: int, height: int, min_pixels: int, max_range: float) -> Any:
        """`detect`'s work, in the simulation thread: render, measure, report."""
        from pycram.world.belief import PerceptionReport

        renderers = self._get_perception_renderers()
        ids, depth = renderers.segmentation_and_depth(eng.data, HEAD_CAMERA, width, height)

        def rgb() -> np.ndarray:  # rendered only if an object is in view (its colour is measured)
            return renderers.rgb(eng.data, HEAD_CAMERA, width, height, shadows=False)

        cam = eng.camera
        view = view_of(eng.data.cam_xpos[cam], eng.data.cam_xmat[cam], float(eng.model.cam_fovy[cam]), depth, max_range)
        objects = {it.name: (it.type, eng.item_part_geoms[it.name]) for it in self.scene.items}
        states = eng.furniture.positions(eng.data) if eng.furniture.containers else {}
        detections = measure_detections(
            ids,
            depth,
            rgb,
            view,
            objects,
            self.environment,
            states,
            self.perception_faults,
            self._fault_rng,
            min_pixels,
        )
        # the joint positions of the containers whose handle is in the image, and of those an
        # object was seen inside (their inside is in view): the belief moves objects in a drawer
        # with its measured opening, so an object's pose and its drawer's opening come together
        in_view = {
            name: q
            for name, q in states.items()
            if view.in_image(self.environment.container(name).handle_position(q))
            or any(d.container == name for d in detections)
        }
        tools = eng.deferred_tool_poses()()  # by arm: the robot's own joints, measured as it looks
        hands = {
            str(arm["gripper"]): tools[name].position
            for name, arm in self.scene.description.ARMS.items()
            if name in tools and arm.get("gripper")
        }
        return PerceptionReport(eng.time, tuple(detections), view, in_view, hands)

    def request_segmentation(self, camera: str = HEAD_CAMERA, width: int = 320, height: int = 240) -> CommandHandle:
        """Render geom ids per pixel (height x width, -1: background) from `camera`."""
        self.scene.camera(camera)
        return self._call(
            f"segmentation:{camera}", lambda eng: self._get_renderers().segmentation(eng.data, camera, width, height)
        )


__all__ = ["Sensing"]
