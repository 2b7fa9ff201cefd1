"""Kitchens from files (`file:PATH.toml`, `pycram.environments.from_file`): the shipped example
loads with its surfaces, containers and places; bad sidecars get clear errors; it builds in the
simulator, its drawers and its door open physically, objects placed on its surfaces stay there,
and `pycram scene` draws it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from sim_helpers import ok
from typer.testing import CliRunner

from pycram import environments
from pycram.apps.cli import app
from pycram.environments import checks
from pycram.environments.from_file import KitchenFileError, load_file
from pycram.sim import World
from pycram.world.errors import UnknownNameError
from pycram.world.objects import object_type

REPO = Path(__file__).resolve().parents[2]
SIDECAR = REPO / "examples" / "kitchens" / "small_kitchen.toml"
NAME = f"file:{SIDECAR}"


def _wait(world: World, seconds: float) -> None:
    t = world.sim_time.get_value() + seconds
    assert (world.sim_time >= t).wait_for(seconds + 10.0)


def test_the_example_kitchen_loads_with_its_parts_named_in_the_sidecar():
    env = environments.load(NAME)
    assert env is load_file(SIDECAR) and env.name == "small-kitchen"
    assert {s.name: s.height for s in env.surfaces} == {"counter": 0.9, "cabinet top": 0.9, "table": 0.75}
    assert env.surface("table").bounds == pytest.approx((2.4, 1.3, 3.6, 2.1))
    assert [c.name for c in env.containers] == ["drawer 1", "drawer 2", "cupboard"]
    drawer = env.container("drawer 1")
    assert drawer.body.footprint == pytest.approx((0.03, 1.625, 0.6, 2.575))  # the model's body
    assert drawer.handle == pytest.approx((0.64, 2.1, 0.34))  # the default: 4 cm in front, near the top
    assert env.surface("drawer 1 inside").height == pytest.approx(0.105)
    assert env.container("cupboard").hinge_sign == 1.0  # hinged on its east edge
    assert env.container_of("cupboard shelf").name == "cupboard"
    # the containers' bodies are not static geometry too; the sink is decoration; the bin a box
    names = {b.name for b in env.static}
    assert not names & {"drawer 1", "drawer 2", "cupboard"} and "cupboard side east" in names
    assert not env.static_box("sink").collides and env.static_box("bin").half == pytest.approx((0.15, 0.15, 0.3))
    assert "bin" in env.notes  # said to be approximated by its bounding box
    assert [p.name for p in env.places][:1] == ["start"]
    assert checks.environment_problems(env) == []


@pytest.mark.parametrize(
    "sidecar, message",
    [
        ('model = "small_kitchen.xml"\nfloor = [[0, 0, 4, 4]]\n', "a place named 'start' is needed"),
        ('model = "nowhere.xml"\n', "does not exist"),
        ("floor = [[0, 0, 4, 4]]\n", "'model' must name"),
        (
            'model = "small_kitchen.xml"\nfloor = [[0, 0, 4, 4]]\n[[surfaces]]\nname = "top"\nbody = "oven"\n',
            "no body 'oven'",
        ),
        (
            'model = "small_kitchen.xml"\nfloor = [[0, 0, 4, 4]]\n[[containers]]\nname = "d"\nkind = "door"\n'
            'body = "drawer_1"\nopening_direction = [1, 0]\nlimits = [0, 1]\n',
            "'hinge' is missing",
        ),
        ('model = "small_kitchen.xml"\nflor = 1\n', "unknown key"),
        ("model = [", "not a TOML file"),
    ],
)
def test_bad_sidecars_are_refused_naming_the_problem(tmp_path, sidecar, message):
    (tmp_path / "small_kitchen.xml").write_text((SIDECAR.parent / "small_kitchen.xml").read_text())
    path = tmp_path / "bad.toml"
    path.write_text(sidecar)
    with pytest.raises(KitchenFileError, match=message):
        load_file(path)
    with pytest.raises(UnknownNameError, match="no sidecar file"):
        environments.load(f"file:{tmp_path / 'missing.toml'}")


@pytest.fixture(scope="module")
def world():
    with World("pr2", environment=NAME, objects=["cup", "bowl", "plate"], seed=4) as w:
        yield w


def test_objects_placed_on_its_surfaces_stay_there(world):
    _wait(world, 1.5)
    poses = world.item_poses.get_value()
    assert world.placements
    for placement in world.placements:
        surface = world.environment.surface(placement.support)
        x, y, z = poses[placement.name].position
        assert surface.contains(x, y), placement
        assert abs(z - object_type(placement.type).half_height - surface.height) < 0.02, placement


def test_its_drawers_and_door_open_when_pulled_and_stay_shut_otherwise(world):
    assert all(abs(q) < 1e-3 for q in world.container_states.get_value().values())
    for container in world.environment.containers:
        dx, dy = container.opening_direction
        drawer = container.kind == "drawer"
        force = 40.0 if drawer else 25.0
        ok(world.push_container(container.name, (force * dx, force * dy, 0.0), 0.4 if drawer else 0.5))
        _wait(world, 1.0)
        opened = world.container_states.get_value()[container.name]
        assert (0.15 if drawer else math.radians(30)) < opened <= container.limits[1] + 1e-3, container.name


def test_scene_command_draws_the_kitchen_from_files(tmp_path):
    import imageio.v3 as iio

    out = tmp_path / "kitchen.png"
    result = CliRunner().invoke(app, ["scene", "--env", NAME, "--seed", "2", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "counter" in result.output or "table" in result.output
    image = iio.imread(out)
    assert image.shape[1] > 1200 and np.asarray(image).std() > 20


URDF = """<robot name="tiny_kitchen">
  <link name="world"/>
  <link name="counter"><collision><geometry><box size="2 0.6 0.9"/></geometry></collision></link>
  <joint name="counter_joint" type="fixed">
    <parent link="world"/><child link="counter"/><origin xyz="1 3 0.45"/>
  </joint>
  <link name="drawer_1"><collision><geometry><box size="0.57 0.9 0.3"/></geometry></collision></link>
  <joint name="drawer_joint" type="fixed">
    <parent link="world"/><child link="drawer_1"/><origin xyz="0.3 1 0.3"/>
  </joint>
</robot>
"""
URDF_SIDECAR = """model = "tiny.urdf"
floor = [[0, 0, 4, 4]]
[[surfaces]]
name = "counter"
body = "counter"
[[containers]]
name = "drawer 1"
kind = "drawer"
body = "drawer_1"
opening_direction = [1, 0]
limits = [0, 0.3]
[[places]]
name = "start"
pose = [2, 1, 0]
"""


def test_a_urdf_model_is_read_link_by_link(tmp_path):
    (tmp_path / "tiny.urdf").write_text(URDF)
    (tmp_path / "tiny.toml").write_text(URDF_SIDECAR)
    env = load_file(tmp_path / "tiny.toml")
    assert env.surface("counter").bounds == pytest.approx((0.0, 2.7, 2.0, 3.3))
    assert env.surface("counter").height == pytest.approx(0.9)
    assert env.container("drawer 1").body.footprint == pytest.approx((0.015, 0.55, 0.585, 1.45))
    assert [b.name for b in env.static] == ["counter"]  # the drawer is not static too


MJCF_FEATURES = """<mujoco>
  <compiler angle="degree" meshdir="meshes"/>
  <default>
    <geom type="box" rgba="0.2 0.3 0.4 1"/>
    <default class="thin"><geom size="0.5 0.02 0.3"/></default>
  </default>
  <asset>
    <material name="red" rgba="1 0 0 1"/>
    <mesh name="wedge" file="wedge.stl" scale="2 1 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="unit" pos="1 2 0" euler="0 0 90">
      <geom name="panel" class="thin" pos="0.2 0 0.3"/>
      <body name="tilted" pos="0 1 0.5" axisangle="1 0 0 30">
        <geom name="slab" size="0.3 0.2 0.05" material="red"/>
      </body>
      <frame pos="0 0 1" quat="0.9238795 0 0.3826834 0">
        <geom name="rod" type="cylinder" size="0.05 0.4"/>
      </frame>
    </body>
    <geom name="pipe" type="capsule" fromto="0 0 0.1 1 0.5 0.1" size="0.04"/>
    <geom name="ball" type="sphere" pos="3 3 0.2" size="0.2" contype="0" conaffinity="0"/>
    <body name="mesh body" pos="2 0 0.5" euler="0 0 30">
      <geom name="wedge" type="mesh" mesh="wedge"/>
    </body>
  </worldbody>
</mujoco>
"""


def _write_wedge_stl(path: Path) -> None:
    import struct

    triangles = [
        ((0, 0, 0), (0.4, 0, 0), (0, 0.3, 0)),
        ((0, 0, 0), (0, 0.3, 0), (0, 0, 0.2)),
        ((0.4, 0, 0), (0, 0.3, 0), (0, 0, 0.2)),
        ((0, 0, 0), (0.4, 0, 0), (0, 0, 0.2)),
    ]
    data = b"\0" * 80 + struct.pack("<I", len(triangles))
    for tri in triangles:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in tri) + b"\0\0"
    path.write_bytes(data)


def test_the_model_reader_agrees_with_mujoco(tmp_path):
    """`pycram.environments.model_files` reads geoms without a simulator: its boxes are those
    MuJoCo compiles (defaults, frames, the orientation forms, fromto, meshes)."""
    import mujoco

    from pycram.environments.model_files import read_model

    (tmp_path / "meshes").mkdir()
    _write_wedge_stl(tmp_path / "meshes" / "wedge.stl")
    model_path = tmp_path / "features.xml"
    model_path.write_text(MJCF_FEATURES)
    geoms = {g.name: g for g in read_model(model_path)}
    assert "floor" not in geoms  # planes are left out
    model = mujoco.MjModel.from_xml_path(str(model_path))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    # a capsule from end to end: the spheres around its ends
    assert geoms["pipe"].lo == pytest.approx((-0.04, -0.04, 0.06)) and geoms["pipe"].hi == pytest.approx(
        (1.04, 0.54, 0.14)
    )
    for name, geom in geoms.items():
        if name == "pipe":
            continue
        g = model.geom(name).id
        rot = data.geom_xmat[g].reshape(3, 3)
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            mesh = model.geom_dataid[g]
            adr, num = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            local = model.mesh_vert[adr : adr + num]
        else:
            local = model.geom_aabb[g, :3] + corners * model.geom_aabb[g, 3:]
        points = local @ rot.T + data.geom_xpos[g]
        assert geom.lo == pytest.approx(points.min(axis=0), abs=1e-5), name
        assert geom.hi == pytest.approx(points.max(axis=0), abs=1e-5), name
    assert geoms["panel"].exact and not geoms["slab"].exact and not geoms["rod"].exact
    assert geoms["slab"].rgba == (1.0, 0.0, 0.0, 1.0) and geoms["panel"].rgba == pytest.approx((0.2, 0.3, 0.4, 1.0))
    assert not geoms["ball"].collides and geoms["panel"].collides
    assert geoms["slab"].bodies == ("tilted", "unit") and geoms["rod"].bodies == ("unit",)
