"""MoveIt's text `.scene` files, as RViz exports them, read as PlanningScene::loadGeometryFromStream reads them.

The newer format gives each object a pose (the line after `* id` holds spaces) and subframes;
the older one has neither, its shape poses in the planning frame (moveit_core planning_scene.cpp).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, Cli

from moveplan.core.config import parse_scene_text
from moveplan.core.errors import ConfigError

SCENES = ROOT / "tests" / "data" / "scenes"


def test_an_object_of_two_shapes_is_placed_at_its_pose() -> None:
    path = SCENES / "rviz_table.scene"
    scene = parse_scene_text(path.read_text(), path)
    by_name = {entry.name: entry for entry in scene.objects}
    assert list(by_name) == ["table top/0", "table top/1", "pole"]
    assert by_name["table top/0"].shape.kind == "box" and by_name["table top/0"].shape.dims == (0.4, 0.8, 0.02)
    np.testing.assert_allclose(by_name["table top/1"].transform[:3, 3], [0.6, 0.0, 0.0])  # 0.2 up, then 0.2 down
    assert by_name["table top/1"].shape.dims == (0.02, 0.4)  # radius, length
    np.testing.assert_allclose(by_name["pole"].transform[:3, 3], [1.0, 0.0, 0.5])


def test_the_scene_keeps_its_name_and_each_id_its_shapes() -> None:
    path = SCENES / "rviz_table.scene"
    scene = parse_scene_text(path.read_text(), path)
    assert scene.name == "(noname)+"
    assert scene.parts == {"table top": ("table top/0", "table top/1"), "pole": ("pole",)}


def test_the_older_format_without_object_poses_reads_too() -> None:
    path = SCENES / "rviz_old_format.scene"
    (box,) = parse_scene_text(path.read_text(), path).objects
    assert box.name == "box1"
    np.testing.assert_allclose(box.transform[:3, 3], [0.8, 0.2, 0.3])


def test_a_plan_avoids_the_objects_of_a_scene_file(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "plan.mcap"
    result = cli("plan", "--robot", "ur10e", "--scene", SCENES / "rviz_table.scene", "--joints",
                 "0.5,-1.2,-1.8,0,1.57,0", "-o", out)
    assert result.exit_code == 0, result.stderr


@pytest.mark.parametrize(("text", "message"), [
    ("s\n* p\n1\nplane\n0 0 1 0\n0 0 0\n0 0 0 1\n0 0 0 0\n.\n", "line 4: object 'p': shape 0: planes are not"),
    ("s\n* b\n1\nbox\n0.1 x 0.1\n0 0 0\n0 0 0 1\n0 0 0 0\n.\n", "line 5: object 'b': shape 0: box size: expected a"),
    ("s\n* b\n1\nbox\n0.1 0.1 0.1\n0 0 0\n", "the file ends where object 'b': shape 0 pose orientation was expected"),
    ("s\n* b\n1\nbox\n0.1 0.1 0.1\n0 0 0\n0 0 0 0\n0 0 0 0\n.\n", "not a rotation"),
    ("s\n* b\n1\ntorus\n1\n.\n", "unknown shape 'torus'"),
])
def test_a_malformed_scene_file_names_the_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.scene"
    path.write_text(text)
    with pytest.raises(ConfigError, match=f"{path}: .*{message}" if "line" not in message else f"{path}: {message}"):
        parse_scene_text(text, path)


def test_a_malformed_scene_file_exits_3_on_one_line_and_writes_nothing(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "bad.scene"
    scene.write_text("s\n* p\n1\nplane\n0 0 1 0\n0 0 0\n0 0 0 1\n0 0 0 0\n.\n")
    out = tmp_path / "plan.mcap"
    result = cli("plan", "--robot", "ur10e", "--scene", scene, "--joints", "0.5,-1.2,-1.8,0,1.57,0", "-o", out)
    assert result.exit_code == 3 and not out.exists()
    assert result.stderr.strip().count("\n") == 0 and "Traceback" not in result.stderr
    assert f"{scene}: line 4: object 'p': shape 0: planes are not supported" in result.stderr

