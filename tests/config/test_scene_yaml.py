"""Scene files read into checked values without a robot: moveplan's format and MoveIt's PlanningScene YAML."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from moveplan.core.config.planning_scene_yaml import AllowedCollisions, parse_planning_scene
from moveplan.core.config.robot_config import RobotConfig, load_robot_config
from moveplan.core.config.scene_yaml import parse_scene
from moveplan.core.errors import ConfigError


@pytest.fixture(scope="module")
def panda_config() -> RobotConfig:
    return load_robot_config("panda")


def read(path: Path, content: dict[str, Any]) -> dict[str, Any]:
    path.write_text(yaml.safe_dump(content, sort_keys=False))
    top: dict[str, Any] = yaml.safe_load(path.read_text())
    return top


def test_moveplan_scene_keeps_frame_and_link_names_for_the_model_to_resolve(tmp_path: Path) -> None:
    path = tmp_path / "scene.yaml"
    top = read(path, {
        "frames": [{"name": "shelf", "parent": "no_such_link", "xyz": [1, 0, 0]}],
        "objects": [{"name": "box", "frame": "shelf", "box": [0.1, 0.2, 0.3], "xyz": [0, 0, 0.5]}],
        "attached": [{"name": "cup", "link": "no_such_hand", "sphere": 0.05, "touch_links": ["finger"]}],
    })
    scene = parse_scene(top, path)
    [frame] = scene.frames
    assert (frame.name, frame.parent) == ("shelf", "no_such_link")
    [box] = scene.objects
    assert (box.where, box.name, box.frame, box.shape.dims) == (f"{path}: objects[0]", "box", "shelf", (0.1, 0.2, 0.3))
    np.testing.assert_allclose(box.transform[:3, 3], [0, 0, 0.5])
    [cup] = scene.attached
    assert (cup.link, cup.touch_links, cup.frame) == ("no_such_hand", ("finger",), None)


@pytest.mark.parametrize(("content", "message"), [
    ({"objects": [{"name": "box", "box": [0.1, -0.2, 0.3]}]}, r"objects\[0\].box: sizes must be positive"),
    ({"objects": [{"name": "a", "sphere": 0.1}], "attached": [{"name": "a", "link": "l", "sphere": 0.1}]},
     "object name 'a' is used twice"),
    ({"frames": [{"name": "f", "parent": "p", "xzy": [0, 0, 0]}]}, r"frames\[0\]: unknown key 'xzy'"),
])
def test_moveplan_scene_errors_name_the_file_and_key(tmp_path: Path, content: dict[str, Any], message: str) -> None:
    path = tmp_path / "scene.yaml"
    with pytest.raises(ConfigError, match=f"{path}: {message}"):
        parse_scene(read(path, content), path)


def test_planning_scene_objects_become_parts_with_their_poses(panda_config: RobotConfig, tmp_path: Path) -> None:
    path = tmp_path / "scene.yaml"
    top = read(path, {"world": {"collision_objects": [
        {"id": "pair", "header": {"frame_id": "/table"}, "pose": {"position": {"x": 1.0}},
         "primitives": [{"type": "box", "dimensions": [0.1, 0.1, 0.1]}, {"type": 2, "dimensions": [0.05]}],
         "primitive_poses": [{"position": {"z": 0.1}}, {"position": {"z": 0.2}}]},
        {"id": "lone", "primitives": [{"type": "sphere", "dimensions": [0.05]}],
         "primitive_poses": [{"position": [0.0, 2.0, 0.0]}]},
    ]}})
    scene = parse_planning_scene(top, path, panda_config)
    pair, lone = scene.objects
    assert (pair.frame, [name for name, _, _ in pair.parts]) == ("table", ["pair/0", "pair/1"])
    assert pair.where == f"{path}: world.collision_objects[0]"
    np.testing.assert_allclose(pair.header_T_object[:3, 3], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(pair.parts[1][2][:3, 3], [0.0, 0.0, 0.2])
    # MoveIt: a lone shape with no object pose gives the object its pose.
    np.testing.assert_allclose(lone.header_T_object[:3, 3], [0.0, 2.0, 0.0])
    assert [name for name, _, _ in lone.parts] == ["lone"]


def test_planning_scene_object_defined_twice_is_an_error(panda_config: RobotConfig, tmp_path: Path) -> None:
    path = tmp_path / "scene.yaml"
    ball = {"id": "ball", "primitives": [{"type": "sphere", "dimensions": [0.05]}], "primitive_poses": [{}]}
    with pytest.raises(ConfigError, match=f"{path}: collision object 'ball' is defined twice"):
        parse_planning_scene(read(path, {"world": {"collision_objects": [ball, ball]}}), path, panda_config)


def test_allowed_collision_matrix_reads_the_upper_triangle_then_defaults(
    panda_config: RobotConfig, tmp_path: Path
) -> None:
    path = tmp_path / "scene.yaml"
    top = read(path, {"allowed_collision_matrix": {
        "entry_names": ["a", "b", "c"],
        "entry_values": [[False, True, False], [False, False, False], [True, False, False]],
        "default_entry_names": ["d", "e"], "default_entry_values": [True, False],
    }})
    allowed = parse_planning_scene(top, path, panda_config).allowed
    assert allowed.pairs(["a", "b", "c", "d", "e"]) == {
        frozenset(p) for p in (("a", "b"), ("d", "a"), ("d", "b"), ("d", "c"))}


def test_default_entry_does_not_override_an_explicit_one() -> None:
    allowed = AllowedCollisions({frozenset(("a", "d")): False}, {"d": True})
    assert allowed.pairs(["a", "b"]) == {frozenset(("d", "b"))}
