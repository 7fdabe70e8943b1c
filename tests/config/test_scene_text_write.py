"""Scenes written as MoveIt's text `.scene`, as PlanningScene::saveGeometryToStream writes one.

Whatever the scene was read from (a .scene, a moveplan scene YAML, a PlanningScene YAML), the
objects are written where they are in the planning frame, and read back the same.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import ROOT, UR10E

from moveplan.core.config import format_scene_text, parse_scene_text
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene import Scene
from moveplan.core.model.scene_file import load_scene
from moveplan.core.pipeline import RobotSource, export_scene
from moveplan.core.types import CollisionObject, Shape

SCENES = ROOT / "tests" / "data" / "scenes"
MOVEIT_WRITTEN = ROOT / "tests" / "data" / "moveit_written"

# What RViz exports for a turned two-shape object, a sphere and a tetrahedron mesh (colours as MoveIt
# writes them for an object without one). Half turns and binary fractions: exact through any reading.
EXPORTED = """\
cell
* fixture
0.5 -0.25 0.125
1 0 0 0
2
box
0.3 0.2 0.1
0 0 0
0 0 0 1
0 0 0 0
cylinder
0.05 0.4
0.125 0 0.25
0 1 0 0
0 0 0 0
0
* ball
1 0.5 0.75
0 0 0 1
1
sphere
0.0625
0 0 0
0 0 0 1
0 0 0 0
0
* wedge
-0.5 0.75 0.25
0 0 1 0
1
mesh
4 4
0 0 0
0.2 0 0
0 0.2 0
0 0 0.2
0 2 1
0 1 3
0 3 2
1 2 3
0 0 0
0 0 0 1
0 0 0 0
0
.
"""


@pytest.fixture(scope="module")
def ur10e() -> Robot:
    return Robot(load_robot_config(UR10E))


def written(scene: Scene) -> str:
    """Return the .scene text of a resolved scene's world objects."""
    return format_scene_text(scene.name, scene.object_groups(), scene.source)


def read_back(text: str, tmp_path: Path, robot: Robot) -> Scene:
    """Return the scene a written .scene text reads as."""
    path = tmp_path / "written.scene"
    path.write_text(text)
    return load_scene(path, robot)


def assert_same_objects(got: Scene, want: Scene) -> None:
    """Assert two scenes hold the same world objects: names, shapes, and poses within 1e-9."""
    assert [o.name for o in got.objects] == [o.name for o in want.objects]
    for a, b in zip(got.objects, want.objects, strict=True):
        assert a.shape.kind == b.shape.kind and a.shape.dims == pytest.approx(b.shape.dims, abs=1e-12), a.name
        if a.shape.kind == "mesh":
            np.testing.assert_allclose(a.shape.vertices, b.shape.vertices, atol=1e-12)
            np.testing.assert_array_equal(a.shape.triangles, b.shape.triangles)
        np.testing.assert_allclose(a.transform, b.transform, atol=1e-9, err_msg=a.name)


def test_the_layout_is_moveits_line_by_line(ur10e: Robot, tmp_path: Path) -> None:
    """PlanningScene::saveGeometryToStream (moveit_core planning_scene.cpp) with writePoseToText and
    geometric_shapes' saveAsText: name; per object `* id`, pose, shape count, per shape its type, sizes,
    pose and colour, then the subframe count; `.` at the end."""
    scene = read_back(EXPORTED, tmp_path, ur10e)
    assert written(scene).splitlines() == EXPORTED.splitlines()


def test_a_scene_file_read_and_written_reads_back_the_same(ur10e: Robot, tmp_path: Path) -> None:
    for path in (SCENES / "rviz_table.scene", SCENES / "rviz_old_format.scene"):
        scene = load_scene(path, ur10e)
        again = read_back(written(scene), tmp_path, ur10e)
        assert_same_objects(again, scene)
        assert again.name == scene.name and again.parts == scene.parts


def test_shapes_at_any_rotation_read_back_within_1e_9(ur10e: Robot, tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    objects = []
    for k in range(20):
        quaternion = rng.normal(size=4)
        x, y, z, w = quaternion / np.linalg.norm(quaternion)
        pose = np.eye(4)
        pose[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
        pose[:3, 3] = rng.uniform(-2, 2, size=3)
        objects.append(CollisionObject(f"thing/{k}", Shape("box", (0.1, 0.2, 0.3)), pose))
    scene = Scene("made.yaml", (), tuple(objects), {}, parts={"thing": tuple(o.name for o in objects)})
    again = read_back(written(scene), tmp_path, ur10e)
    assert_same_objects(again, scene)


def test_objects_in_scene_frames_and_on_links_are_written_at_their_world_poses(ur10e: Robot, tmp_path: Path) -> None:
    source = tmp_path / "cell.yaml"
    source.write_text(yaml.safe_dump({
        "frames": [{"name": "fixture", "parent": "base_link", "xyz": [0.7, -0.3, 0.1], "rpy": [0, 0.733, 0]},
                   {"name": "slot", "parent": "fixture", "xyz": [0, 0.1, 0]}],
        "objects": [{"name": "ball", "frame": "slot", "sphere": 0.04, "xyz": [0, 0, 0.1]},
                    {"name": "plate", "frame": "base", "box": [0.2, 0.2, 0.01], "xyz": [0.5, 0, 0]}],
    }))
    text = written(load_scene(source, ur10e))
    objects = {o.name: o for o in parse_scene_text(text, tmp_path / "out.scene").objects}
    c, s = math.cos(0.733), math.sin(0.733)
    base_T_fixture = np.array([[c, 0, s, 0.7], [0, 1, 0, -0.3], [-s, 0, c, 0.1], [0, 0, 0, 1]])
    np.testing.assert_allclose(objects["ball"].transform[:3, 3], (base_T_fixture @ [0, 0.1, 0.1, 1])[:3], atol=1e-9)
    np.testing.assert_allclose(objects["ball"].transform[:3, :3], base_T_fixture[:3, :3], atol=1e-9)
    # `base` is base_link turned half a turn about z (the UR description's REP-103 base frame).
    np.testing.assert_allclose(objects["plate"].transform[:3, 3], [-0.5, 0, 0], atol=1e-9)
    np.testing.assert_allclose(objects["plate"].transform[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-9)


def test_a_planning_scene_is_written_with_its_name_ids_and_meshes(tmp_path: Path) -> None:
    panda = Robot(load_robot_config("panda", (MOVEIT_WRITTEN,)))
    for path in (MOVEIT_WRITTEN / "panda_scene.yaml", MOVEIT_WRITTEN / "mesh_scene.yaml"):
        out = tmp_path / f"{path.stem}.scene"
        result = export_scene(path, RobotSource("panda", (MOVEIT_WRITTEN,)), out)
        scene, again = load_scene(path, panda), load_scene(out, panda)
        assert result.objects == tuple(scene.parts) == tuple(again.parts)
        assert again.name == scene.name and again.name in ("pick_cup", "bin_and_post")
        world = [o for o in scene.objects if not o.link]
        assert [o.name for o in again.objects] == [o.name for o in world]
        for a, b in zip(again.objects, world, strict=True):
            np.testing.assert_allclose(a.transform, b.transform, atol=1e-9)
    post = next(o for o in again.objects if o.name == "post")
    assert post.shape.kind == "mesh" and post.shape.vertices is not None
    assert np.ptp(post.shape.vertices[:, 2]) == pytest.approx(0.6, abs=1e-6)  # the 30 cm post, scaled by 2 in z


def test_attached_objects_are_left_out_with_a_warning(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    source = tmp_path / "held.yaml"
    source.write_text(yaml.safe_dump({
        "objects": [{"name": "table", "box": [1, 1, 0.05], "xyz": [0.5, 0, -0.03]}],
        "attached": [{"name": "gripper", "link": "tool0", "cylinder": {"radius": 0.04, "length": 0.12}}],
    }))
    with caplog.at_level(logging.WARNING):
        result = export_scene(source, RobotSource("ur10e"), tmp_path / "held.scene")
    assert result.objects == ("table",) and result.skipped == ("gripper",) and result.name == "held"
    assert "attached objects not written (gripper)" in caplog.text
    assert [o.name for o in parse_scene_text((tmp_path / "held.scene").read_text(), tmp_path).objects] == ["table"]


@pytest.mark.parametrize(("name", "object_id", "message"), [
    ("two\nlines", "box", r"scene name 'two\\nlines': a .scene file cannot hold a name with a line break"),
    ("cell", "a\nb", r"object id 'a\\nb': a .scene file cannot hold an empty id or one with a line break"),
    ("cell", " ", r"object id ' ': a .scene file cannot hold an empty id"),
])
def test_a_name_a_scene_file_cannot_hold_is_refused(name: str, object_id: str, message: str) -> None:
    box = CollisionObject(object_id, Shape("box", (0.1, 0.1, 0.1)), np.eye(4))
    with pytest.raises(ConfigError, match=f"made.yaml: {message}"):
        format_scene_text(name, {object_id: (box,)}, "made.yaml")
