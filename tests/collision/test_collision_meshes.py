"""Collision meshes: the Panda's STL meshes exact or as convex hulls, scene mesh objects."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli

from moveplan.core.collision import checker as checker_module
from moveplan.core.collision import motion
from moveplan.core.collision._verdicts import COLLIDES
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError, StartInCollision
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene

PANDA = ROOT / "configs" / "panda"
SHELF_SCENE = SAMPLES / "panda_shelf_scene.yaml"
TRAY = SAMPLES / "panda_tray.obj"
# The bay goals documented in the shelf scene.
BAY_GOALS = [
    [1.513, -1.043, -1.364, -2.306, -2.866, 2.438, -0.46],
    [1.335, 0.91, -1.024, -2.285, -2.66, 2.169, 1.317],
    [0.758, -0.295, -0.641, -1.742, 1.878, 3.284, 1.869],
]


@pytest.fixture(scope="module")
def panda() -> Robot:
    return Robot(load_robot_config(PANDA))


@pytest.fixture(scope="module")
def shelf(panda: Robot) -> dict[str, CollisionChecker]:
    objects = load_scene(SHELF_SCENE, panda).objects
    return {mode: CollisionChecker(panda, objects, str(SHELF_SCENE), geometry=mode)
            for mode in ("exact", "convex")}


def panda_copy(tmp_path: Path, planning: str) -> Path:
    """A copy of configs/panda whose moveplan.yaml has the given `planning:` line."""
    folder = tmp_path / "panda"
    shutil.copytree(PANDA, folder)
    manifest = folder / "moveplan.yaml"
    text = manifest.read_text()
    line = next(x for x in text.splitlines() if x.startswith("planning:"))
    manifest.write_text(text.replace(line, f"planning: {planning}"))
    return folder


def scene_file(tmp_path: Path, objects: str) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(f"objects:\n{objects}\n")
    return path


def test_panda_loads_with_its_stl_meshes_and_ready_is_free(panda: Robot) -> None:
    checker = CollisionChecker(panda, geometry="exact")
    meshes = [g for g in checker.geometry.geometryObjects if isinstance(g.geometry, coal.BVHModelBase)]
    assert {checker.owner[checker.geometry.getGeometryId(g.name)] for g in meshes} >= {"panda_link0", "panda_hand"}
    assert all(g.meshPath.endswith(".stl") for g in meshes)
    assert checker.colliding_pair(panda.neutral()) is None
    default = CollisionChecker(panda, geometry=panda.config.planning["collision"])  # what `plan` checks
    assert default.colliding_pair(panda.neutral()) is None


def test_convex_mode_replaces_each_robot_mesh_by_its_hull_and_keeps_scene_meshes(
    shelf: dict[str, CollisionChecker],
) -> None:
    exact, convex = (shelf[m].geometry.geometryObjects for m in ("exact", "convex"))
    for before, after in zip(exact, convex, strict=True):
        if isinstance(before.geometry, coal.BVHModelBase) and before.name != "tray":
            assert isinstance(after.geometry, coal.ConvexBase), before.name
            assert after.geometry.num_points <= before.geometry.num_vertices
        else:
            assert type(after.geometry) is type(before.geometry), before.name


def test_a_state_free_under_hulls_is_free_under_the_meshes(
    panda: Robot, shelf: dict[str, CollisionChecker],
) -> None:
    values = np.random.default_rng(7).uniform(panda.lower, panda.upper, (200, panda.dof))
    states = panda.configurations(values)
    free = {mode: checker.free_batch(states) for mode, checker in shelf.items()}
    assert 20 < free["convex"].sum() < 190  # both outcomes occur: the claim is tested
    assert not np.any(free["convex"] & ~free["exact"])


def test_shelf_scene_has_a_mesh_and_its_bay_goals_and_ready_are_free_in_both_modes(
    panda: Robot, shelf: dict[str, CollisionChecker],
) -> None:
    tray = next(o for o in load_scene(SHELF_SCENE, panda).objects if o.name == "tray")
    assert tray.shape.kind == "mesh" and Path(tray.shape.mesh_path) == TRAY
    for checker in shelf.values():
        assert checker.colliding_pair(panda.neutral()) is None
        for goal in BAY_GOALS:
            assert checker.colliding_pair(panda.configuration(goal)) is None
            # The tool is in the shelf, between its side walls, 10-12 cm past its front edge.
            x, y, _ = panda.frame_pose(panda.configuration(goal), "panda_hand_tcp")[:3, 3]
            assert 0.59 < x < 0.63 and abs(y) < 0.28


def test_collision_key_in_moveplan_yaml_selects_convex_mode(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cli: Cli,
) -> None:
    folder = panda_copy(tmp_path, "{group: panda_arm, planner: RRTConnect, planning_time: 1.0, collision: convex}")
    assert load_robot_config(folder).planning["collision"] == "convex"
    modes = []

    class Spy(CollisionChecker):
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            modes.append(self.mode)

    monkeypatch.setattr(motion, "CollisionChecker", Spy)
    result = cli("plan", "--robot", folder, "--start-named", "ready", "--joints", "panda_joint1=0.3",
                 "-o", tmp_path / "out.mcap")
    assert result.exit_code == 0, result.stderr
    assert modes == ["convex"]


def test_collision_mode_defaults_to_exact(tmp_path: Path) -> None:
    folder = panda_copy(tmp_path, "{group: panda_arm}")
    assert load_robot_config(folder).planning["collision"] == "exact"


def test_unknown_collision_mode_exits_3_naming_file_and_key(tmp_path: Path, cli: Cli) -> None:
    folder = panda_copy(tmp_path, "{group: panda_arm, collision: hull}")
    with pytest.raises(ConfigError, match=r"moveplan\.yaml: planning\.collision: expected one of exact, convex, "
                                          r"got 'hull'"):
        load_robot_config(folder)
    result = cli("robot", folder)
    assert result.exit_code == 3
    assert "planning.collision" in result.stderr and str(folder / "moveplan.yaml") in result.stderr


def test_scene_mesh_object_loads_and_a_link_inside_it_collides_naming_the_pair(
    panda: Robot, tmp_path: Path,
) -> None:
    # The tray's bottom at the height of the hand's body, in `ready`: the hand is in the tray.
    x, y, z = panda.frame_pose(panda.neutral(), "panda_hand")[:3, 3]
    scene = scene_file(tmp_path, f"  - {{name: tray, mesh: {TRAY}, xyz: [{x}, {y}, {z - 0.04}]}}")
    objects = load_scene(scene, panda).objects
    assert [o.shape.kind for o in objects] == ["mesh"]
    for mode in ("exact", "convex"):
        checker = CollisionChecker(panda, objects, str(scene), geometry=mode)
        assert checker.colliding_pair(panda.neutral()) == ("panda_hand", "tray")
        assert not checker.free_batch(panda.neutral()[:, None])[0]
        turned = panda.configuration([1.5, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # hand beside the tray
        assert checker.colliding_pair(turned) is None


def test_missing_scene_mesh_exits_3_naming_the_file(tmp_path: Path, cli: Cli) -> None:
    scene = scene_file(tmp_path, "  - {name: bin, mesh: no_such_bin.stl, xyz: [0.5, 0.5, 0.0]}")
    result = cli("plan", "--robot", PANDA, "--scene", scene, "--start-named", "ready",
                 "--joints", "panda_joint1=0.3", "-o", tmp_path / "out.mcap")
    assert result.exit_code == 3
    assert str(tmp_path / "no_such_bin.stl") in result.stderr and "not found" in result.stderr
    assert not (tmp_path / "out.mcap").exists()


def test_convex_mode_keeps_a_flat_robot_mesh_as_a_mesh(tmp_path: Path) -> None:
    # qhull has no hull for coplanar points (and coal's call crashes the process on them).
    (tmp_path / "plate.obj").write_text("v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0.2 0.2 0\nf 1 2 3\nf 2 4 3\n")
    shutil.copy(TRAY, tmp_path / "tray.obj")
    (tmp_path / "arm.urdf").write_text("""<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><geometry><mesh filename="plate.obj"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="0 0 0.5"/><geometry><mesh filename="tray.obj"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
</robot>
""")
    (tmp_path / "arm.srdf").write_text('<robot name="arm"><group name="arm"><joint name="j1"/></group></robot>')
    robot = Robot(load_robot_config(tmp_path))
    checker = CollisionChecker(robot, geometry="convex")
    kinds = {checker.owner[k]: type(g.geometry) for k, g in enumerate(checker.geometry.geometryObjects)}
    assert issubclass(kinds["base"], coal.BVHModelBase) and issubclass(kinds["tip"], coal.ConvexBase)
    assert checker.colliding_pair(robot.neutral()) is None


def test_the_meshes_checker_built_after_the_hulls_checks_the_pairs_one_built_alone_does(panda: Robot) -> None:
    scene = load_scene(SHELF_SCENE, panda)
    checker, hulls = motion.scene_checkers(panda, scene, "exact")
    alone = CollisionChecker(panda, scene.objects, scene.source, "exact", scene.allowed)
    assert hulls is not None and hulls.mode == "convex" and checker.mode == "exact"
    assert checker.owner == alone.owner
    assert [(p.first, p.second) for p in checker.geometry.collisionPairs] == \
        [(p.first, p.second) for p in alone.geometry.collisionPairs]
    q = panda.configuration(np.array(BAY_GOALS[0]), panda.neutral())
    assert checker.colliding_pair(q) == alone.colliding_pair(q)


@pytest.mark.parametrize("through", ["panda_link0", "nothing"])
def test_an_object_through_the_fixed_base_is_refused_at_every_state_with_the_hulls_first(
    panda: Robot, tmp_path: Path, through: str
) -> None:
    # The base's mesh and hull both reach 0.1 m up from its origin; a box 1 cm across around
    # a point 5 cm up is inside both, one 30 cm away touches neither.
    x = 0.0 if through == "panda_link0" else -0.3
    path = scene_file(tmp_path, f"  - {{name: grit, box: [0.01, 0.01, 0.01], xyz: [{x}, 0, 0.05]}}")
    scene = load_scene(path, panda)
    if through == "nothing":
        motion.scene_checkers(panda, scene, "exact")
        return
    with pytest.raises(StartInCollision, match="panda_link0.*grit|grit.*panda_link0"):
        motion.scene_checkers(panda, scene, "exact")


def test_a_scene_mesh_file_is_read_once_for_all_its_checks(panda: Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    # The hulls' checker reads the tray; the meshes' checker and the sphere filter's bounding box take its shape.
    read: list[str] = []
    real = checker_module.coal_geometry

    def counted(shape: Any, source: str = "scene") -> coal.CollisionGeometry:
        read.append(shape.kind)
        return real(shape, source)

    monkeypatch.setattr(checker_module, "coal_geometry", counted)
    scene = load_scene(SHELF_SCENE, panda)
    checker, hulls = motion.scene_checkers(panda, scene, "exact")
    spheres = motion.build_sphere_filter(panda, checker, hulls, scene, panda.neutral())
    assert spheres is not None and read.count("mesh") == 1 and len(read) == len(scene.objects)
    tray = next(obj for obj in checker.geometry.geometryObjects if obj.name == "tray")
    assert isinstance(tray.geometry, coal.BVHModelBase)  # the meshes' checker holds the mesh itself
    q = panda.configuration(np.array(BAY_GOALS[0]), panda.neutral())
    assert checker.colliding_pair(q) is None and spheres.classify(np.array([BAY_GOALS[0]]))[0][0] != COLLIDES
