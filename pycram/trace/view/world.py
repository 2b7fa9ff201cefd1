"""The simulated world and the robot's belief in a view (runs in the view's own thread).

`WorldLog` is built from the simulator's model (`mujoco.MjModel`, a copy: the simulation's own
data is never touched) and logs:

- once, as static data: every visible geom of every body (boxes, spheres, ellipsoids,
  capsules, cylinders, meshes; the floor plane as a thin slab), batched per body, under
  ``truth/robot/...`` (the robot's links nested as its kinematic tree), ``truth/furniture/...``
  and ``truth/objects/NAME``;
- per state (`StateSnapshot`: joint positions and mocap poses copied by the simulation
  thread), each body's transform relative to its parent -- only the bodies that moved since the
  last state logged (a drawer that opens, an arm that moves, an object carried);
- the belief: each believed object as a box at its believed pose, labelled with when it was
  last seen or that it is believed gone (``belief/objects/NAME``), the believed opening of each
  container (``belief/containers/NAME``);
- each look of the head camera (``camera/head``): the image rendered from the state of the
  look, with the objects seen in it drawn as boxes (their believed centre and size projected
  into the image).
"""

from __future__ import annotations

import copy
import logging
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import paths

__all__ = ["WorldLog", "BeliefObject", "belief_snapshot"]

log = logging.getLogger(__name__)

#: Moves smaller than this [m, or rad of a quaternion's components] are not logged again.
POSE_TOLERANCE = 1e-4
#: A state whose joints and mocap bodies moved less than this [m or rad] since the last one
#: computed is not computed again (physics' jitter while nothing moves).
STILL = 1e-5
#: Steps per straight joint-space segment of a motion plan when its tool path is drawn.
MOTION_STEPS = 8
#: The head camera image's size [px] (what perception renders).
CAMERA_SIZE = (320, 240)
_COLORS = {
    "red": (229, 57, 53),
    "orange": (251, 140, 0),
    "yellow": (253, 216, 53),
    "green": (67, 160, 71),
    "blue": (30, 136, 229),
    "purple": (142, 36, 170),
    "white": (240, 240, 240),
    "grey": (158, 158, 158),
    "black": (40, 40, 40),
}
_GONE_COLOR = (120, 120, 120, 90)


@dataclass(frozen=True)
class BeliefObject:
    """One believed object as the view logs it: belief name, type, centre [m, map], size [m],
    colour name, when it was last seen [s], whether it is believed gone or held."""

    name: str
    type: str
    position: tuple[float, float, float]
    size: tuple[float, float, float]
    color: str | None
    last_seen: float | None
    gone: bool
    held: bool


def belief_snapshot(belief: Any) -> tuple[tuple[BeliefObject, ...], tuple[tuple[str, float], ...]]:
    """The believed objects and container openings of `belief` (a
    `pycram.world.belief.BeliefState`) now, as plain values (cheap: a few objects)."""
    held = {id(o) for o in getattr(belief, "in_hand", {}).values()}
    objects = []
    for obj in belief.objects():
        pose = getattr(obj, "pose", None)
        if pose is None:
            continue
        props = getattr(obj, "properties", {}) or {}
        size = props.get("size") or (0.05, 0.05, 0.05)
        seen = props.get("last_seen")
        objects.append(
            BeliefObject(
                str(obj.name),
                str(getattr(obj, "type", "")),
                (float(pose[0]), float(pose[1]), float(pose[2])),
                (float(size[0]), float(size[1]), float(size[2])),
                props.get("color"),
                None if seen is None else float(seen),
                bool(getattr(obj, "gone", False)),
                id(obj) in held,
            )
        )
    containers = tuple(sorted((str(k), float(v)) for k, v in dict(getattr(belief, "container_states", {})).items()))
    return tuple(objects), containers


def _xyzw(wxyz: Any) -> list[float]:
    return [float(wxyz[1]), float(wxyz[2]), float(wxyz[3]), float(wxyz[0])]


def _quat_matrix(wxyz: Any) -> np.ndarray:
    w, x, y, z = (float(v) for v in wxyz)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Products of quaternions (wxyz), row by row."""
    aw, ax, ay, az = a[:, 0], a[:, 1], a[:, 2], a[:, 3]
    bw, bx, by, bz = b[:, 0], b[:, 1], b[:, 2], b[:, 3]
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


class WorldLog:
    """Logs the world of one simulation into `recording` (see the module docstring).

    `model`: the simulation's `mujoco.MjModel` (copied); `root_link`: the robot's root body;
    `items`: the simulator's object names; `camera`: the head camera's name (None: no images).
    Use from one thread only (the view's): it owns its own `MjData` and renderer."""

    def __init__(
        self, recording: Any, model: Any, root_link: str, items: Iterable[str], camera: str | None = None
    ) -> None:
        import mujoco

        self.rec = recording
        self.model = copy.copy(model)
        self.data = mujoco.MjData(self.model)
        self.camera = camera
        self._renderer: Any = None
        m = self.model
        names = [m.body(i).name for i in range(m.nbody)]
        parents = [int(m.body_parentid[i]) for i in range(m.nbody)]
        root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, root_link)
        item_ids = {mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n): n for n in items}
        item_ids.pop(-1, None)
        self.paths: list[str | None] = [None] * m.nbody
        from rerun import escape_entity_path_part as esc

        for body in range(1, m.nbody):
            chain = [body]
            while parents[chain[-1]] != 0:
                chain.append(parents[chain[-1]])
            top = chain[-1]
            chain.reverse()
            if root in chain:
                parts = [paths.ROBOT, *(esc(names[b] or f"body{b}") for b in chain[chain.index(root) :])]
            elif top in item_ids:
                parts = [paths.OBJECTS, *(esc(names[b] or f"body{b}") for b in chain)]
            else:
                parts = [paths.FURNITURE, *(esc(names[b] or f"body{b}") for b in chain)]
            self.paths[body] = "/".join(parts)
        # bodies whose transform is logged relative to their parent (the robot's root, and every
        # top body, relative to the world)
        self.parent = np.array(parents)
        self.parent[root] = 0
        self._last_pos: np.ndarray | None = None
        self._last_quat: np.ndarray | None = None
        self._belief_logged: dict[str, BeliefObject] = {}
        self._last_state: Any = None
        #: Body -> poses noted and not logged yet: (t, wall, x, y, z, qx, qy, qz, qw) each.
        self._pending: dict[int, list[tuple[float, ...]]] = {}
        self._containers_logged: dict[str, float] = {}

    # -- static geometry ---------------------------------------------------------------------------

    def log_geometry(self) -> int:
        """Log every visible geom, batched per body and shape, as static data; returns how many
        geoms were logged."""
        import mujoco
        import rerun as rr

        m = self.model
        T = mujoco.mjtGeom
        self.rec.log("/", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)  # MuJoCo's world: z up
        per_body: dict[int, dict[str, list[Any]]] = {}
        count = 0
        for g in range(m.ngeom):
            if int(m.geom_group[g]) >= 3:
                continue
            mat = int(m.geom_matid[g])
            rgba = np.array(m.mat_rgba[mat] if mat >= 0 else m.geom_rgba[g], float)
            if rgba[3] <= 0.0:
                continue
            body = int(m.geom_bodyid[g])
            color = tuple(int(round(255 * c)) for c in rgba)
            pos = np.array(m.geom_pos[g], float)
            quat = np.array(m.geom_quat[g], float)
            size = np.array(m.geom_size[g], float)
            kind = int(m.geom_type[g])
            shapes = per_body.setdefault(body, {})
            count += 1
            if kind == int(T.mjGEOM_BOX):
                shapes.setdefault("boxes", []).append((pos, quat, size[:3], color))
            elif kind == int(T.mjGEOM_PLANE):
                half = [size[0] or 10.0, size[1] or 10.0, 0.001]
                shapes.setdefault("boxes", []).append((pos - [0, 0, 0.001], quat, half, color))
            elif kind == int(T.mjGEOM_SPHERE):
                shapes.setdefault("ellipsoids", []).append((pos, quat, [size[0]] * 3, color))
            elif kind == int(T.mjGEOM_ELLIPSOID):
                shapes.setdefault("ellipsoids", []).append((pos, quat, size[:3], color))
            elif kind == int(T.mjGEOM_CAPSULE):
                shapes.setdefault("capsules", []).append((pos, quat, size[:2], color))
            elif kind == int(T.mjGEOM_CYLINDER):
                shapes.setdefault("cylinders", []).append((pos, quat, size[:2], color))
            elif kind == int(T.mjGEOM_MESH):
                mesh = int(m.geom_dataid[g])
                va, vn = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
                fa, fn = int(m.mesh_faceadr[mesh]), int(m.mesh_facenum[mesh])
                vertices = np.asarray(m.mesh_vert[va : va + vn], float) @ _quat_matrix(quat).T + pos
                faces = np.asarray(m.mesh_face[fa : fa + fn], np.int64)
                shapes.setdefault("mesh", []).append((vertices, faces, color))
            else:
                count -= 1
        self._send_layout(per_body)
        for body, shapes in per_body.items():
            where = self.paths[body] if body else paths.FURNITURE + "/world"
            for shape, entries in shapes.items():
                path = f"{where}/{shape}"
                archetype: Any
                if shape == "mesh":
                    vertex_arrays: list[np.ndarray] = []
                    face_arrays: list[np.ndarray] = []
                    color_arrays: list[np.ndarray] = []
                    offset = 0
                    for v, f, c in entries:
                        vertex_arrays.append(v)
                        face_arrays.append(f + offset)
                        color_arrays.append(np.tile(np.array(c, np.uint8), (len(v), 1)))
                        offset += len(v)
                    self.rec.log(
                        path,
                        rr.Mesh3D(
                            vertex_positions=np.concatenate(vertex_arrays).astype(np.float32),
                            triangle_indices=np.concatenate(face_arrays).astype(np.uint32),
                            vertex_colors=np.concatenate(color_arrays),
                        ),
                        static=True,
                    )
                    continue
                centers = [e[0] for e in entries]
                quats = [rr.Quaternion(xyzw=_xyzw(e[1])) for e in entries]
                colors = [e[3] for e in entries]
                if shape == "boxes":
                    archetype = rr.Boxes3D(
                        centers=centers,
                        half_sizes=[e[2] for e in entries],
                        quaternions=quats,
                        colors=colors,
                        fill_mode="solid",
                    )
                elif shape == "ellipsoids":
                    archetype = rr.Ellipsoids3D(
                        centers=centers,
                        half_sizes=[e[2] for e in entries],
                        quaternions=quats,
                        colors=colors,
                        fill_mode="solid",
                    )
                elif shape == "cylinders":
                    archetype = rr.Cylinders3D(
                        centers=centers,
                        lengths=[2 * e[2][1] for e in entries],
                        radii=[e[2][0] for e in entries],
                        quaternions=quats,
                        colors=colors,
                        fill_mode="solid",
                    )
                else:  # capsules: from one cap's centre (z = -half length) along +z
                    starts = [e[0] - _quat_matrix(e[1])[:, 2] * e[2][1] for e in entries]
                    archetype = rr.Capsules3D(
                        translations=starts,
                        lengths=[2 * e[2][1] for e in entries],
                        radii=[e[2][0] for e in entries],
                        quaternions=quats,
                        colors=colors,
                        fill_mode="solid",
                    )
                self.rec.log(path, archetype, static=True)
        return count

    def _send_layout(self, per_body: dict[int, Any]) -> None:
        """Send the layout again, its 3D view looking down at the furniture from its front left."""
        import mujoco

        from .blueprint import default_blueprint

        mujoco.mj_kinematics(self.model, self.data)
        furniture = {
            b for b in per_body if b and self.paths[b] and str(self.paths[b]).startswith(paths.FURNITURE + "/")
        }
        m = self.model
        plane = int(mujoco.mjtGeom.mjGEOM_PLANE)
        fixed = {b for b in furniture if int(m.body_mocapid[b]) < 0}  # mocap bodies: obstacles parked aside
        geoms = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in fixed and int(m.geom_type[g]) != plane]
        if not geoms:
            return
        points = np.array([self.data.geom_xpos[g] for g in geoms], float)
        low, high = points.min(axis=0), points.max(axis=0)
        center = (low + high) / 2.0
        span = max(float(max(high[0] - low[0], high[1] - low[1])), 2.0)
        position = center + np.array([-0.2 * span, -0.5 * span, 1.2 * span])
        self.rec.send_blueprint(default_blueprint(eye=(tuple(position.tolist()), tuple(center.tolist()))))

    # -- the state over time -----------------------------------------------------------------------

    def log_state(self, state: Any, t: float, wall: float) -> int:
        """Note the transforms of the bodies that moved since the last state (`state`: a
        `StateSnapshot` at simulated time `t` [s], wall-clock time `wall` [s since the epoch]);
        `flush` logs them (a column per body: one Rerun call per body per flush, not per state).
        Returns how many body poses were noted."""
        last = self._last_state
        if (
            last is not None
            and np.abs(last.qpos - state.qpos).max(initial=0.0) < STILL
            and np.abs(last.mocap_pos - state.mocap_pos).max(initial=0.0) < STILL
            and np.abs(last.mocap_quat - state.mocap_quat).max(initial=0.0) < STILL
        ):
            return 0  # nothing moved (the robot thinks, looks or waits): nothing to compute
        self._last_state = state
        state.apply(self.model, self.data)  # the kinematics of that state, in our own data
        xpos, xquat = self.data.xpos, self.data.xquat
        parent = self.parent
        # local transform: inverse(parent) * body
        pq = xquat[parent].copy()
        pq[:, 1:] *= -1.0
        local_quat = _quat_mul(pq, xquat)
        delta = xpos - xpos[parent]
        # rotate delta by the parent's inverse rotation
        local_pos = np.einsum("nij,nj->ni", _matrices(pq), delta)
        if self._last_pos is None:
            moved = np.ones(len(xpos), bool)
        else:
            moved = (np.abs(local_pos - self._last_pos).max(axis=1) > POSE_TOLERANCE) | (
                np.abs(local_quat - self._last_quat).max(axis=1) > POSE_TOLERANCE
            )
        moved[0] = False
        count = 0
        pending = self._pending
        for body in np.flatnonzero(moved):
            q = local_quat[body]
            pending.setdefault(int(body), []).append(
                (t, wall, *local_pos[body].tolist(), float(q[1]), float(q[2]), float(q[3]), float(q[0]))
            )
            count += 1
        if self._last_pos is None or self._last_quat is None:
            self._last_pos, self._last_quat = local_pos, local_quat
        else:
            self._last_pos[moved] = local_pos[moved]
            self._last_quat[moved] = local_quat[moved]
        return count

    def flush(self) -> int:
        """Log the body poses noted since the last flush, one column per body (on the ``sim`` and
        ``wall`` timelines); returns how many Rerun calls that took."""
        import rerun as rr

        pending, self._pending = self._pending, {}
        for body, rows in pending.items():
            values = np.array(rows, float)
            self.rec.send_columns(
                self.paths[body],
                indexes=[
                    rr.TimeColumn(paths.SIM_TIMELINE, duration=values[:, 0]),
                    rr.TimeColumn(paths.WALL_TIMELINE, timestamp=values[:, 1]),
                ],
                columns=rr.Transform3D.columns(translation=values[:, 2:5], quaternion=values[:, 5:9]),
            )
        return len(pending)

    def log_belief(self, objects: Sequence[BeliefObject], containers: Sequence[tuple[str, float]]) -> None:
        """Log the believed objects and container openings that changed since the last call."""
        import rerun as rr
        from rerun import escape_entity_path_part as esc

        for obj in objects:
            if self._belief_logged.get(obj.name) == obj:
                continue
            self._belief_logged[obj.name] = obj
            if obj.gone:
                label = f"{obj.name}: believed gone (last seen t={obj.last_seen or 0:.1f} s)"
                color: tuple[int, ...] = _GONE_COLOR
            else:
                held = ", held" if obj.held else ""
                label = f"{obj.name} (seen t={obj.last_seen or 0:.1f} s{held})"
                color = (*_COLORS.get(obj.color or "", (200, 200, 200)), 160)
            self.rec.log(
                f"{paths.BELIEF_OBJECTS}/{esc(obj.name)}",
                rr.Boxes3D(
                    centers=[obj.position],
                    half_sizes=[[s / 2.0 for s in obj.size]],
                    colors=[color],
                    labels=[label],
                    fill_mode="majorwireframe" if obj.gone else "solid",
                ),
                rr.AnyValues(
                    last_seen=obj.last_seen if obj.last_seen is not None else float("nan"),
                    gone=obj.gone,
                    type=obj.type,
                ),
            )
        for name, opening in containers:
            if self._containers_logged.get(name) == opening:
                continue
            self._containers_logged[name] = opening
            self.rec.log(f"{paths.BELIEF_CONTAINERS}/{esc(name)}", rr.Scalars(opening))

    # -- motion plans --------------------------------------------------------------------------

    def log_motion(self, arm: str, joints: Sequence[str], path: Sequence[Sequence[float]], tool: str) -> bool:
        """Log the tool path of a motion plan of `arm` (`path`: configurations of `joints`, joined
        by straight segments in joint space) as the body `tool` follows it, the other joints as
        in the last state logged: a line through the tool's positions (each segment in
        `MOTION_STEPS` steps) and the waypoints as points. Returns False when it cannot (no state
        yet, an unknown joint or body)."""
        import mujoco
        import rerun as rr
        from rerun import escape_entity_path_part as esc

        m = self.model
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, tool)
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in joints]
        if self._last_state is None or body < 0 or min(ids, default=-1) < 0 or len(path) < 2:
            return False
        addresses = [int(m.jnt_qposadr[j]) for j in ids]
        configurations = np.asarray(path, float)
        steps = np.linspace(0.0, 1.0, MOTION_STEPS, endpoint=False)
        dense = [a + f * (b - a) for a, b in zip(configurations, configurations[1:]) for f in steps]
        dense.append(configurations[-1])
        self._last_state.apply(m, self.data)
        points = []
        for q in dense:
            self.data.qpos[addresses] = q
            mujoco.mj_kinematics(m, self.data)
            points.append(self.data.xpos[body].copy())
        waypoints = [points[i * MOTION_STEPS] for i in range(len(configurations))]
        self._last_state.apply(m, self.data)  # leave our data as the state it was
        self.rec.log(
            f"{paths.MOTION}/{esc(arm)}",
            rr.LineStrips3D([np.array(points)], colors=[(255, 193, 7)], radii=0.006, labels=[f"{arm} arm plan"]),
            rr.Points3D(np.array(waypoints), colors=[(255, 143, 0)], radii=0.015),
        )
        return True

    # -- the head camera -----------------------------------------------------------------------

    def log_look(self, state: Any, seen: Sequence[BeliefObject]) -> bool:
        """Render the head camera from `state` and log the image with the objects `seen` in that
        look drawn on it; returns False when no image could be rendered (no camera, no GL)."""
        import mujoco
        import rerun as rr

        if self.camera is None:
            return False
        camera = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, self.camera)
        if camera < 0:
            return False
        width, height = CAMERA_SIZE
        try:
            if self._renderer is None:
                self._renderer = mujoco.Renderer(self.model, height=height, width=width)
            state.apply(self.model, self.data)
            self._renderer.update_scene(self.data, camera=camera)
            image = self._renderer.render().copy()
        except Exception as error:  # no GL here: log the detections without the picture
            log.warning("view: cannot render the head camera (%s); the view has no camera images", error)
            self.camera = None
            return False
        self.rec.log(paths.CAMERA, rr.Image(image))
        position = np.array(self.data.cam_xpos[camera], float)
        rotation = np.array(self.data.cam_xmat[camera], float).reshape(3, 3)
        focal = 0.5 * height / math.tan(math.radians(float(self.model.cam_fovy[camera])) / 2.0)
        boxes, labels, colors = [], [], []
        for obj in seen:
            corners = np.array(
                [
                    [obj.position[i] + sx * obj.size[i] / 2.0 for i, sx in enumerate(signs)]
                    for signs in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)
                ]
            )
            local = (corners - position) @ rotation
            depth = -local[:, 2]
            if (depth <= 1e-3).any():
                continue
            u = width / 2.0 + focal * local[:, 0] / depth
            v = height / 2.0 - focal * local[:, 1] / depth
            x0, x1 = max(0.0, u.min()), min(float(width), u.max())
            y0, y1 = max(0.0, v.min()), min(float(height), v.max())
            if x1 <= x0 or y1 <= y0:
                continue
            boxes.append((x0, y0, x1 - x0, y1 - y0))
            labels.append(f"{obj.name} ({obj.color or obj.type})")
            colors.append(_COLORS.get(obj.color or "", (255, 255, 0)))
        self.rec.log(
            paths.DETECTIONS,
            rr.Boxes2D(array=boxes, array_format=rr.Box2DFormat.XYWH, labels=labels, colors=colors)
            if boxes
            else rr.Clear(recursive=False),
        )
        return True

    def close(self) -> None:
        """Free the renderer (in the thread that made it)."""
        if self._renderer is not None:
            try:
                self._renderer.close()
            except Exception:  # noqa: BLE001 - closing anyway
                pass
            self._renderer = None


def _matrices(wxyz: np.ndarray) -> np.ndarray:
    """Rotation matrices of quaternions (wxyz), one per row."""
    w, x, y, z = wxyz[:, 0], wxyz[:, 1], wxyz[:, 2], wxyz[:, 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )
