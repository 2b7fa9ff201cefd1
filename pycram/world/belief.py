"""The robot's belief state: the objects it has perceived, where it last saw them, and when.

Backend-neutral: a perception backend (the simulator's head camera today, a ROS perception
pipeline tomorrow) fills it with `PerceptionReport`s; object designators resolve against it
(`BeliefState.resolver`); plans read it, never the simulator.

A `PerceptionReport` holds what one look of the camera measured: a `Detection` per object seen
(type from the recogniser; centre, size and colour measured from segmentation, depth and colour
images; the surface and container it rests on/in from the environment's description), the
`CameraView` it was taken with (pose, field of view and depth image, to decide which believed
objects *should* have been seen) and the measured joint positions of the containers.

`BeliefState.update(report)`:

- associates each detection with the nearest believed object of the same type within `gate`
  [m] (objects marked gone included, so an object that comes back is the same object again);
  the object's pose, size, colour, support and container are refreshed in place, its
  `last_seen` set to the report's time stamp [s of the active clock, simulated time in a
  simulation], and its `pose_fluent` set (so it pulses);
- adds a new `PerceivedObject` for each detection left over, named "<type>-<n>" in order of
  first sight (belief names: nothing is taken from the simulator);
- moves the objects believed inside a drawer along with it when the drawer's measured opening
  changed since it was last measured (`container_states`);
- counts a *miss* for each believed object that was not seen although the view says it should
  have been (in the image, within range, nothing measured in front of it), and marks it *gone*
  after `misses_to_gone` (`MISSES_TO_GONE`) such looks in a row: one look is no proof of absence
  (a detector misses objects now and then); a sighting resets the count. Gone objects are not
  resolved by designators until seen again.

Thread-safe: updates and reads may come from any thread.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np

from pycram.core.fluent import Fluent
from pycram.designators.object import Belief, BelievedObject

from .environment import Environment, Surface
from .objects import OBJECT_TYPES
from .types import matrix_to_quat

__all__ = [
    "COLOR_NAMES",
    "MISSES_TO_GONE",
    "HELD_RADIUS",
    "BeliefState",
    "BeliefUpdate",
    "CameraView",
    "Detection",
    "PerceivedObject",
    "PerceptionReport",
    "color_name",
    "lying_orientation",
    "support_of",
    "AXIS_KEPT_WITHIN",
    "HEIGHT_KEPT_WITHIN",
]

Vec3 = tuple[float, float, float]
#: How many looks a `BeliefState` remembers.
MAX_LOOKS = 100
#: Looks in a row that should have seen an object and did not, before it is believed gone. One
#: look is no proof of absence: a detector misses a visible object now and then (the simulated
#: camera with the ``missed`` fault: 3 looks in 10); two misses in a row are (for independent
#: misses) 1 in 11, and an action that needs to know looks again (`PickUp`, `Place`).
MISSES_TO_GONE = 2
#: A look that measures no turn of an object (property "axis") keeps the one measured before
#: while the object is seen within this distance [m] of where it was.
AXIS_KEPT_WITHIN = 0.02
#: A look that measures a standing object of a known type shorter than the look before (its top
#: hidden -- by the robot's own arm, a shelf above, the view's edge) keeps the height measured
#: before while the object stands on the same surface within this horizontal distance [m] of
#: where it stood: standing where it stood, it cannot have shrunk. (Measured: the TIAGo Pro's
#: looks at a milk carton swung its believed centre 1.00 <-> 0.96 m, and each swing made
#: `PickUp` plan its grasp again, three times, then fail.)
HEIGHT_KEPT_WITHIN = 0.03
#: A look that saw an object only in part (its detection's `Detection.slack`) keeps the centre
#: believed before while that lies within the slack and this margin [m] of what it measured.
SLACK_MARGIN = 0.01
#: A look whose centre may be off by no more than this [m] (`Detection.slack`) is taken as it is:
#: a look seen "whole" may be that far off too (a milk carton's near side seen, 1.6 cm), and a
#: close look at most of an object is better news than an older one. (Measured: the apartment's
#: set-table, PR2, seed 203: a look from beside the carton, slack 1.1 cm, kept an older centre
#: 1.6 cm off and the side grasp knocked the carton over.)
SLACK_TRUSTED = 0.02

#: Colour names a recogniser reports (see `color_name`).
COLOR_NAMES = ("red", "orange", "yellow", "green", "blue", "purple", "white", "grey", "black")


def color_name(rgb: Iterable[float]) -> str:
    """The name (one of `COLOR_NAMES`) of an RGB(A) colour with channels in [0, 1].

    Unsaturated colours are white, grey or black by brightness; the others are named by hue.
    """
    r, g, b = (float(c) for c in tuple(rgb)[:3])
    high, low = max(r, g, b), min(r, g, b)
    saturation = 0.0 if high <= 0.0 else (high - low) / high
    if saturation < 0.25:
        return "white" if high > 0.7 else "grey" if high > 0.25 else "black"
    if high == r:
        hue = (60.0 * (g - b) / (high - low)) % 360.0
    elif high == g:
        hue = 60.0 * (b - r) / (high - low) + 120.0
    else:
        hue = 60.0 * (r - g) / (high - low) + 240.0
    for limit, name in (
        (18, "red"),
        (40, "orange"),
        (70, "yellow"),
        (165, "green"),
        (260, "blue"),
        (330, "purple"),
        (360, "red"),
    ):
        if hue < limit:
            return name
    return "red"


@dataclass(frozen=True)
class Detection:
    """One object seen in one look of the camera.

    `type` comes from the recogniser; `position` is the measured centre [m, map frame] and
    `size` the measured (width across the view, depth along it, height) [m] — when the camera
    does not see the object's top, its depth is assumed equal to its width; `color` is the name of the measured
    mean colour (`rgb`, channels in [0, 1]); `support` the surface it rests on and `container`
    the container that surface is in (None when it rests on none known / an open surface);
    `pixels` how many pixels of it were visible; `axis` [rad] the direction of the longer
    horizontal axis of its top when seen from above, or of a square top's sides (up to quarter
    turns); None when the top is round or not seen from above. `slack` [m]: how far off the
    measured centre may be horizontally because the object was seen only in part (hidden by
    something nearer the camera where its known shape cannot complete it: both ends of its
    extent in view, a box's end, a round one whose rim is not seen); 0 when it was seen whole, or
    its hidden part could be completed.
    """

    type: str
    position: Vec3
    size: Vec3
    color: str
    rgb: Vec3 = (0.0, 0.0, 0.0)
    support: str | None = None
    container: str | None = None
    pixels: int = 0
    axis: float | None = None
    slack: float = 0.0


@dataclass(frozen=True, eq=False)
class CameraView:
    """The pinhole camera a look was taken with, and its measured depth image.

    `position` [m, map]; `rotation` the camera's axes in the map frame as the columns of a 3x3
    matrix (OpenGL convention: x right, y up, the camera looks along -z); `fovy` the vertical
    field of view [deg]; `depth` the distance along the optical axis per pixel [m] (height x
    width); objects farther than `max_range` [m] from the camera are not detected.
    """

    position: Vec3
    rotation: Any
    fovy: float
    depth: Any
    max_range: float = 4.0

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) [px]."""
        return int(self.depth.shape[1]), int(self.depth.shape[0])

    def project(self, point: Iterable[float]) -> tuple[float, float, float] | None:
        """(u, v) pixel coordinates and depth [m] of a map point; None behind the camera."""
        rotation = np.asarray(self.rotation, float).reshape(3, 3)
        local = rotation.T @ (np.asarray(tuple(point), float) - np.asarray(self.position, float))
        depth = -local[2]
        if depth <= 1e-6:
            return None
        width, height = self.size
        focal = 0.5 * height / math.tan(math.radians(self.fovy) / 2.0)
        return (width / 2.0 + focal * local[0] / depth, height / 2.0 - focal * local[1] / depth, float(depth))

    def in_image(self, point: Iterable[float], border: float = 0.0) -> bool:
        """True when the map point [m] projects into the image (`border` [px] inside its edges)
        and lies within `max_range` of the camera, whatever stands in front of it."""
        projected = self.project(point)
        if projected is None:
            return False
        u, v, _ = projected
        width, height = self.size
        return (
            border <= u < width - border
            and border <= v < height - border
            and math.dist(tuple(point), self.position) <= self.max_range
        )

    def expects_visible(self, point: Iterable[float], border: float = 4.0, tolerance: float = 0.06) -> bool:
        """True when an object at `point` [m, map] should be seen: it projects into the image
        (`border` [px] inside its edges), lies within `max_range`, and the measured depth there
        is not nearer than the point by more than `tolerance` [m] (nothing stands in front)."""
        if not self.in_image(point, border):
            return False
        u, v, depth = self.project(point)  # type: ignore[misc]
        measured = float(self.depth[int(v), int(u)])
        return measured >= depth - tolerance


@dataclass(frozen=True)
class Look:
    """Where the camera looked from, for a record of the looks: time stamp [s], camera position
    [m, map], unit viewing direction, vertical field of view [deg] and range [m]."""

    stamp: float
    position: Vec3
    direction: Vec3
    fovy: float
    max_range: float


@dataclass(frozen=True)
class PerceptionReport:
    """What one look of the camera measured, at time `stamp` [s of the active clock]."""

    stamp: float
    detections: tuple[Detection, ...]
    view: CameraView | None = None
    #: Measured joint position of each container in view [m or rad], 0 when closed: at least of
    #: every container a detection lies inside (its pose was measured with the container so).
    container_states: dict[str, float] = field(default_factory=dict)
    #: Where each gripper's tool frame was when the image was taken, gripper name -> (x, y, z)
    #: [m, map] (the robot's own joints: proprioception); empty when not measured.
    hands: dict[str, Vec3] = field(default_factory=dict)


@dataclass(eq=False)
class PerceivedObject(BelievedObject):
    """An object the robot believes in because it perceived it.

    `pose` is its centre (x, y, z) [m, map frame] as last measured; `properties` hold "color",
    "size", "on" (the surface's name), "in" (the container's name or None), "first_seen",
    "last_seen" [s] and "pixels". `pose_fluent` holds the pose and pulses on every refresh;
    `gone` is True while it should have been seen but was not.
    `misses` counts the looks in a row that should have seen it and did not. `yaw`,
    `lying_axis` and `orientation` say how it stands or lies, as far as its measured size and
    the measured direction of its top's longer axis tell.
    """

    pose_fluent: Fluent = field(default_factory=lambda: Fluent(None))
    gone: bool = False
    times_seen: int = 0
    misses: int = 0

    @property
    def yaw(self) -> float:
        """Its turn about the vertical [rad] as far as perception measured it: from the measured
        direction of its top's longer axis (property "axis") and its type's shape (a box whose
        y side is the longer one is turned by that direction - 90 deg; a box with a square top
        by the measured direction of its sides, in [-45, 45) deg: the same box a quarter turn
        on); 0 when not measured or when the shape is not a box."""
        axis = self.properties.get("axis")
        otype = OBJECT_TYPES.get(self.type)
        if axis is None or otype is None or otype.shape != "box":
            return 0.0
        if otype.size[0] == otype.size[1]:  # a square top: its sides' direction, up to quarter turns
            return (float(axis) + math.pi / 4) % (math.pi / 2) - math.pi / 4
        yaw = float(axis) - (math.pi / 2 if otype.size[1] > otype.size[0] else 0.0)
        return (yaw + math.pi) % (2 * math.pi) - math.pi

    @property
    def lying_axis(self) -> str | None:
        """Which of its own axes (``"x"``/``"y"``) perception measured standing vertical, the
        object lying on its side; None while it stands upright (or its type or size is not
        known). From the measured size (`ObjectType.lying_axis`)."""
        otype = OBJECT_TYPES.get(self.type)
        size = self.properties.get("size")
        return None if otype is None or not size else otype.lying_axis(size)

    @property
    def orientation(self) -> tuple[float, float, float, float] | None:
        """Its orientation (w, x, y, z) in the map frame as far as perception measured it, up to
        the symmetries of its shape: standing, turned by `yaw` about the vertical; lying
        (`lying_axis`), that axis up and the longer of its two other axes along the measured
        direction of its top's longer axis (property "axis"). None when it lies and that
        direction was not measured (not seen from above)."""
        up = self.lying_axis
        if up is None:
            return (math.cos(self.yaw / 2), 0.0, 0.0, math.sin(self.yaw / 2))
        axis = self.properties.get("axis")
        otype = OBJECT_TYPES.get(self.type)
        if axis is None or otype is None:
            return None
        return lying_orientation(otype.extents, up, float(axis))

    @property
    def last_seen(self) -> float:
        """When it was last seen [s of the active clock]."""
        return float(self.properties.get("last_seen", -math.inf))

    def moved(self, threshold: float = 0.02) -> Fluent:
        """A fluent network that becomes True once the believed pose is more than `threshold` [m]
        away from where it is believed now (None until then): ``cup.moved().wait_for(10)``.

        The caller must hold the returned fluent while waiting (networks are held weakly).
        """
        start = self.pose

        def value() -> bool | None:
            pose = self.pose_fluent.get_value()
            if pose is None or start is None:
                return None
            return True if math.dist(pose, start) > threshold else None

        network = Fluent(value, name=f"{self.name} moved > {threshold} m")
        self.pose_fluent.add_child(network)
        return network

    def __repr__(self) -> str:
        pose = "?" if self.pose is None else "(" + ", ".join(f"{v:.2f}" for v in self.pose) + ")"
        where = self.properties.get("on")
        return (
            f"<{self.name}: {self.properties.get('color')} {self.type} at {pose}"
            f"{' on ' + where if where else ''}{' (gone)' if self.gone else ''}>"
        )


@dataclass(frozen=True)
class BeliefUpdate:
    """What one report changed: objects `added`, `refreshed` (seen again), newly `gone`, and
    `missed` (should have been seen, were not, but are not believed gone yet)."""

    added: tuple[PerceivedObject, ...] = ()
    refreshed: tuple[PerceivedObject, ...] = ()
    gone: tuple[PerceivedObject, ...] = ()
    missed: tuple[PerceivedObject, ...] = ()

    @property
    def seen(self) -> tuple[PerceivedObject, ...]:
        """Every object seen in the report (refreshed first, then added)."""
        return self.refreshed + self.added


#: A detection whose bottom is this high [m] above the floor, resting on no known surface, is in
#: the air (held).
IN_THE_AIR = 0.3


#: A detection of the type a gripper holds whose centre is this close [m] to that gripper's tool
#: frame is the held object, wherever it is (over a surface too): a plate held by its rim has its
#: centre 11 cm from the tool frame, a cereal box held by its near side 10 cm.
HELD_RADIUS = 0.25


def _in_the_air(detection: Detection) -> bool:
    return detection.position[2] - detection.size[2] / 2.0 > IN_THE_AIR


class BeliefState(Belief):
    """A robot's belief: the `PerceivedObject`s it saw, filled by `update`.

    `environment` (a description) gives perception its surfaces and containers; `gate` [m] is
    how far an object may have moved between two looks and still be taken for the same one;
    `misses_to_gone` how many looks in a row must miss an object in view before it is believed
    gone. `container_states` holds the containers' joint positions last measured.
    """

    def __init__(
        self, environment: Environment | None = None, gate: float = 0.3, misses_to_gone: int = MISSES_TO_GONE
    ) -> None:
        super().__init__()
        if misses_to_gone < 1:
            raise ValueError(f"misses_to_gone must be at least 1, got {misses_to_gone}")
        self.environment = environment
        self.gate = gate
        self.misses_to_gone = misses_to_gone
        self.container_states: dict[str, float] = {}
        #: When [s, the reports' clock] each container was last measured.
        self.container_stamps: dict[str, float] = {}
        self._counts: dict[str, int] = {}
        self._update_lock = threading.Lock()
        #: The most recent looks (at most `MAX_LOOKS`), oldest first.
        self.looks: list[Look] = []
        #: Pulses after every update (a plan may wait for the next look).
        self.updated = Fluent(None, name="belief updated")
        #: The objects the robot's grippers hold, by gripper (`picked_up`).
        self.in_hand: dict[str, PerceivedObject] = {}
        #: Surfaces a search looked at from close by (`looked_into`): what was visible there then
        #: is believed.
        self.searched: set[str] = set()

    # --- reading ----------------------------------------------------------------------------
    def present(self) -> list[PerceivedObject]:
        """The objects believed present (not gone), best first: most recently seen, then the most
        visible."""
        objects = [o for o in self.objects() if isinstance(o, PerceivedObject) and not o.gone]
        return sorted(objects, key=lambda o: (-o.last_seen, -int(o.properties.get("pixels", 0))))

    def resolver(self, designator: Any) -> list[BelievedObject]:
        """Object resolver: the objects believed present, best first (the designator filters
        them). Objects added by hand (plain `BelievedObject`s) follow."""
        plain = [o for o in self.objects() if not isinstance(o, PerceivedObject)]
        return [*self.present(), *plain]

    def container_open(self, container: str, threshold: float = 0.05) -> bool | None:
        """Whether `container` was measured open (joint beyond `threshold` [m or rad]); None
        when it was never measured."""
        q = self.container_states.get(container)
        return None if q is None else abs(q) > threshold

    # --- writing ----------------------------------------------------------------------------
    def update(self, report: PerceptionReport) -> BeliefUpdate:
        """Fold `report` into the belief (see the module's description); returns what changed."""
        with self._update_lock:
            held = {id(o): o for o in self.in_hand.values()}
            self._ride_along(report.container_states, held)
            self.container_states.update(report.container_states)
            self.container_stamps.update(dict.fromkeys(report.container_states, report.stamp))
            known = [o for o in self.objects() if isinstance(o, PerceivedObject) and id(o) not in held]
            held_types = {o.type for o in held.values()}
            # what a gripper holds is seen in the air, where the hand carries it: not a new object;
            # nor where a hand that holds its type is, over a counter too (measured: a plate held
            # 20 cm over the counter was believed a second plate standing on it, and a pick-up
            # went for that one: PR2, set-table-anywhere, procedural:4, seed 1)
            at_hands = [(o.type, report.hands[g]) for g, o in self.in_hand.items() if g in report.hands]
            detections = [
                d
                for d in report.detections
                if not (d.type in held_types and _in_the_air(d) and d.support is None)
                and not any(d.type == t and math.dist(d.position, hand) <= HELD_RADIUS for t, hand in at_hands)
            ]
            pairs = sorted(
                (
                    (math.dist(d.position[:2], o.pose[:2]), i, j)
                    for i, d in enumerate(detections)
                    for j, o in enumerate(known)
                    if o.type == d.type and o.pose is not None
                ),
                key=lambda p: (p[0], known[p[2]].gone),
            )
            detection_of: dict[int, int] = {}
            used: set[int] = set()
            for distance, i, j in pairs:
                if distance > self.gate or i in detection_of or j in used:
                    continue
                detection_of[i] = j
                used.add(j)
            refreshed, added = [], []
            for i, detection in enumerate(detections):
                if i in detection_of:
                    obj = known[detection_of[i]]
                    refreshed.append(obj)
                else:
                    obj = self._new_object(detection.type, report.stamp)
                    added.append(obj)
                self._refresh(obj, detection, report.stamp)
            gone, missed = [], []
            if report.view is not None:
                view = report.view
                forward = -np.asarray(view.rotation, float).reshape(3, 3)[:, 2]
                self.looks = [
                    *self.looks[-(MAX_LOOKS - 1) :],
                    Look(
                        report.stamp,
                        cast(Vec3, tuple(view.position)),
                        cast(Vec3, tuple(float(v) for v in forward)),
                        view.fovy,
                        view.max_range,
                    ),
                ]
                for j, obj in enumerate(known):
                    if (
                        j not in used
                        and not obj.gone
                        and obj.pose is not None
                        and report.view.expects_visible(obj.pose)
                    ):
                        obj.misses += 1
                        if obj.misses >= self.misses_to_gone:
                            obj.gone = True
                            gone.append(obj)
                        else:
                            missed.append(obj)
        self.updated.set_value(report.stamp)
        return BeliefUpdate(tuple(added), tuple(refreshed), tuple(gone), tuple(missed))

    def _ride_along(self, states: dict[str, float], held: dict[int, PerceivedObject]) -> None:
        """Objects believed inside a drawer move with it: a drawer measured pulled out (or pushed
        in) by dq [m] since it was last measured carries them dq along its opening direction.
        A cup seen in a drawer pulled out 0.36 m was believed there after the drawer had been
        closed and pulled out again only 0.27 m; the grasp planned for it missed (measured:
        TIAGo, set-table seeds 12, 27, the cup in drawer 2). Only objects believed on the
        drawer's inside at its opening before move (not one put down elsewhere since it was last
        seen there). Their pose fluents pulse."""
        if self.environment is None:
            return
        for container in self.environment.containers:
            before, now = self.container_states.get(container.name), states.get(container.name)
            if container.kind != "drawer" or before is None or now is None or now == before:
                continue
            dx, dy = ((now - before) * d for d in container.opening_direction)
            inside = set(container.interior)
            for obj in self.objects():
                if (
                    isinstance(obj, PerceivedObject)
                    and id(obj) not in held
                    and obj.pose is not None
                    and obj.properties.get("in") == container.name
                    and _rests_in(self.environment, obj, {container.name: before}, inside)
                ):
                    x, y, z = obj.pose
                    obj.pose = (x + dx, y + dy, z)
                    obj.pose_fluent.set_value(obj.pose)

    def looked_into(self, surface: str) -> None:
        """A search looked at the surface `surface` from close by (inside an open container, or
        from in front of an open surface): note it in `searched`, so that a later search for
        something it did not see there looks there last."""
        with self._update_lock:
            self.searched.add(surface)

    def picked_up(self, obj: PerceivedObject, gripper: str) -> None:
        """The robot's `gripper` holds `obj` (its grasp was measured): until it is put down or
        lost, looks neither refresh it nor count it missed where it was, and a detection of its
        type in the air on no surface is taken for it (the carried object, seen from the head)
        rather than for a new object: a carried milk carton was believed a second carton
        standing in the air, and a later pick-up went for it (measured: PR2, set-table with
        faults, 3 of 46 seeds)."""
        with self._update_lock:
            self.in_hand[gripper] = obj

    def released(self, obj: PerceivedObject) -> None:
        """No gripper holds `obj` any more (e.g. a pick-up attempt failed after the grasp); the
        belief of where it is stays as it was until a look refreshes it."""
        with self._update_lock:
            self._out_of_hand(obj)

    def _out_of_hand(self, obj: PerceivedObject) -> None:
        for gripper in [g for g, o in self.in_hand.items() if o is obj]:
            del self.in_hand[gripper]

    def put_down(self, obj: PerceivedObject, position: Iterable[float], turn: float = 0.0) -> None:
        """The robot itself put `obj` down at `position` (x, y, z) [m, map], turned by `turn`
        [rad] about the vertical since it was last seen (it turned with the hand that carried
        it: the measured direction of its top's longer axis, property "axis", turns along):
        believe it so (not gone) until the next look refreshes it, standing on (properties "on"
        and "in") the surface under it there, drawers as last believed open; no gripper holds it
        any more. Its pose fluent pulses."""
        with self._update_lock:
            self._out_of_hand(obj)
            axis = obj.properties.get("axis")
            if axis is not None and turn:
                obj.properties["axis"] = (float(axis) + turn + math.pi / 2) % math.pi - math.pi / 2
            obj.pose = tuple(float(v) for v in position)
            if self.environment is not None and len(obj.pose) == 3:
                # a look that misses it (the arm in view, the drawer's front) must not leave it
                # believed where it was picked up from (measured: a spoon put into drawer 2 kept
                # "on": "table", and a transport judged by it failed)
                x, y, z = obj.pose
                size = obj.properties.get("size")
                bottom = z - float(size[2]) / 2 if size else z
                surface = support_of(self.environment, x, y, bottom, self.container_states)
                container = None if surface is None else self.environment.container_of(surface.name)
                obj.properties["on"] = None if surface is None else surface.name
                obj.properties["in"] = None if container is None else container.name
            obj.gone = False
            obj.misses = 0
            obj.pose_fluent.set_value(obj.pose)

    def moved_container(self, container: str, q: float) -> None:
        """The robot itself moved the drawer or door `container` to about `q` [m or rad] (its
        hand let go of the handle there): believe it so until it is measured (objects believed
        in a drawer ride along; `container_stamps` keeps the last measurement's time, so the
        next look still counts as a new measurement). Planning the arm's way off the handle in
        the world as last measured -- the drawer closed -- swept the arm through the drawer
        pulled out (measured: the TIAGo's shoved drawer 2 back in from 27 to 18 cm)."""
        if not math.isfinite(q):
            raise ValueError(f"a container's position must be finite [m or rad], got {q!r}")
        with self._update_lock:
            held = {id(o): o for o in self.in_hand.values()}
            self._ride_along({container: float(q)}, held)
            self.container_states[container] = float(q)

    def lost(self, obj: PerceivedObject) -> None:
        """The robot has evidence that `obj` is not where it was believed (e.g. its gripper
        closed on nothing there and a look did not see it, or a gripper holding it was measured
        empty): believe it gone, and held by no gripper."""
        with self._update_lock:
            self._out_of_hand(obj)
            obj.gone = True

    def _new_object(self, type_name: str, stamp: float) -> PerceivedObject:
        n = self._counts[type_name] = self._counts.get(type_name, 0) + 1
        obj = PerceivedObject(f"{type_name}-{n}", type_name, None, {"first_seen": stamp})
        obj.pose_fluent.name = f"{obj.name} pose"
        self.add(obj)
        return obj

    @staticmethod
    def _refresh(obj: PerceivedObject, detection: Detection, stamp: float) -> None:
        detection = _kept_height(obj, _kept_centre(obj, detection))
        axis = detection.axis
        if axis is None and obj.pose is not None and math.dist(obj.pose, detection.position) <= AXIS_KEPT_WITHIN:
            # a look that did not measure its turn (the top hidden or seen in part) keeps the
            # turn measured before, while it stands where it stood
            axis = obj.properties.get("axis")
        obj.properties.update(
            color=detection.color,
            size=detection.size,
            on=detection.support,
            **{"in": detection.container},
            last_seen=stamp,
            pixels=detection.pixels,
            axis=axis,
        )
        obj.gone = False
        obj.misses = 0
        obj.times_seen += 1
        obj.pose = detection.position
        obj.pose_fluent.set_value(detection.position)


def _kept_centre(obj: PerceivedObject, detection: Detection) -> Detection:
    """`detection` with the centre and size believed of `obj` when it saw `obj` only in part
    (its `slack` over `SLACK_TRUSTED`) and agrees with where it is believed -- within the slack
    (and `SLACK_MARGIN`), on the same surface: a sliver of a bowl seen from close by past the shelf
    above and the fridge's side wall was measured 6 cm off, the belief moved there and the grasp
    went for it (PR2, set-table-anywhere, procedural:5, seed 1). Else `detection` itself."""
    before = obj.properties.get("size")
    if (
        detection.slack <= SLACK_TRUSTED
        or obj.pose is None
        or not before
        or detection.support != obj.properties.get("on")
        or math.dist(detection.position[:2], obj.pose[:2]) > detection.slack + SLACK_MARGIN
    ):
        return detection
    # the horizontal centre and extent as believed; the height as measured (`_kept_height` then)
    x, y, _ = obj.pose
    kept = (float(x), float(y), float(detection.position[2]))
    size = (float(before[0]), float(before[1]), float(detection.size[2]))
    # a turn it measured is news (a box's sides seen in part still show their direction)
    axis = detection.axis if detection.axis is not None else obj.properties.get("axis")
    return replace(detection, position=kept, size=size, axis=axis)


def _kept_height(obj: PerceivedObject, detection: Detection) -> Detection:
    """`detection`, with the height (and the centre's height over its bottom) believed of `obj`
    when the detection measured it shorter while it stands upright on the same surface within
    `HEIGHT_KEPT_WITHIN` of where it stood (see there); else `detection` itself."""
    otype = OBJECT_TYPES.get(obj.type)
    before = obj.properties.get("size")
    if otype is None or not before or obj.pose is None or detection.support is None:
        return detection
    height = float(before[2])
    if (
        detection.size[2] >= height
        or detection.support != obj.properties.get("on")
        or math.dist(detection.position[:2], obj.pose[:2]) > HEIGHT_KEPT_WITHIN
        or otype.lying_axis(before) is not None
        or otype.lying_axis(detection.size) is not None
    ):
        return detection
    x, y, z = detection.position
    bottom = z - detection.size[2] / 2.0
    return replace(
        detection,
        position=(x, y, bottom + height / 2.0),
        size=(detection.size[0], detection.size[1], height),
    )


def _rests_in(environment: Environment, obj: PerceivedObject, states: dict[str, float], inside: set[Surface]) -> bool:
    """Whether believed `obj` stands on one of the `inside` surfaces with the containers opened
    as in `states` (its bottom from its measured size, when known)."""
    x, y, z = obj.pose  # type: ignore[misc]
    size = obj.properties.get("size")
    bottom = z - size[2] / 2 if size else z
    return support_of(environment, x, y, bottom, states) in inside


def lying_orientation(
    extents: tuple[float, float, float], up: str, direction: float
) -> tuple[float, float, float, float]:
    """The orientation (w, x, y, z) of an object with `extents` (its lengths along its own x, y,
    z [m]) lying with its own axis `up` (``"x"`` or ``"y"``) vertical and the longer of its other
    two axes pointing along `direction` [rad] (map frame, counter-clockwise from x)."""
    i = "xyz".index(up)
    a, b = (j for j in range(3) if j != i)
    long, short = (a, b) if extents[a] >= extents[b] else (b, a)
    columns = np.zeros((3, 3))  # the object's axes in the map frame, as columns
    columns[:, i] = (0.0, 0.0, 1.0)
    columns[:, long] = (math.cos(direction), math.sin(direction), 0.0)
    # the third axis completes a right-handed frame: x = y cross z, y = z cross x, z = x cross y
    nxt, prev = (short + 1) % 3, (short + 2) % 3
    columns[:, short] = np.cross(columns[:, nxt], columns[:, prev])
    return matrix_to_quat(columns)


def support_of(
    environment: Environment,
    x: float,
    y: float,
    bottom: float,
    container_states: dict[str, float] | None = None,
    tolerance: float = 0.04,
) -> Surface | None:
    """The surface an object whose lowest seen point is at height `bottom` [m] rests on at
    (x, y) [m]: the highest surface under (x, y) not above `bottom` + `tolerance`, drawers'
    insides moved out by their measured opening (`container_states`). None on the floor."""
    states = container_states or {}
    candidates: list[Surface] = [s for s in environment.surfaces if s.height <= bottom + tolerance and s.contains(x, y)]
    for container in environment.containers:
        dx = dy = 0.0
        if container.kind == "drawer":
            q = states.get(container.name, 0.0)
            dx, dy = q * container.opening_direction[0], q * container.opening_direction[1]
        candidates += [s for s in container.interior if s.height <= bottom + tolerance and s.contains(x - dx, y - dy)]
    # the highest; of equally high ones the smallest (a cooker on its counter)
    return min(candidates, key=lambda s: (-round(s.height, 3), s.area), default=None)
