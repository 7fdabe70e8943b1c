"""MoveIt's own YAML as input: PlanningScene as --scene, MotionPlanRequest as --request."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import yaml
from conftest import ROOT, Cli
from rosbags.highlevel import AnyReader

from moveplan.core.bag import read_plan
from moveplan.core.collision.checker import CollisionChecker, coal_geometry
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import FrameNotFound
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene

MBM = ROOT / "tests" / "data" / "mbm"
SCENE, REQUEST = MBM / "problems" / "box_panda" / "scene0001.yaml", MBM / "problems" / "box_panda" / "request0001.yaml"
START = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
GOAL = [0.4534448383669427, 1.7628, 0.1941262264518609, -0.8667848896139277, -0.3798524112731043,
        2.606927984171601, -0.1898611792470702]
# Where a 2 cm ball touches the Panda's hand, and nothing else, with the arm at START.
HAND_POINT = [0.337, 0.0, 0.5503]


@pytest.fixture(scope="module")
def panda() -> Robot:
    return Robot(load_robot_config("panda"))


def write(path: Path, content: dict[str, Any]) -> Path:
    path.write_text(yaml.safe_dump(content, sort_keys=False))
    return path


def ball(name: str, position: list[float], radius: float = 0.02) -> dict[str, Any]:
    return {"id": name, "primitives": [{"type": "sphere", "dimensions": [radius]}],
            "primitive_poses": [{"position": position}]}


def request_with(**changes: Any) -> dict[str, Any]:
    content = yaml.safe_load(REQUEST.read_text())
    content.update(changes)
    return content


# --- PlanningScene ---------------------------------------------------------------------------


def test_mbm_scene_has_its_objects_with_sizes_and_poses(panda: Robot) -> None:
    scene = load_scene(SCENE, panda)
    objects = {o.name: o for o in scene.objects}
    assert list(objects) == ["Can1", "base", "side_back", "side_cap", "side_front", "side_left", "side_right"]
    base = objects["base"]
    assert base.shape.kind == "box" and base.shape.dims == (0.7, 0.7, 0.04)
    np.testing.assert_allclose(base.transform[:3, 3], [0.5699634262116842, 0.1630262043531711, -0.4862264457751538])
    quat = pin.Quaternion(0.9972531602635496, 0, 0, 0.07406844364750123)  # w, x, y, z
    np.testing.assert_allclose(base.transform[:3, :3], quat.normalized().toRotationMatrix(), atol=1e-12)
    # SolidPrimitive cylinders are [height, radius]; moveplan's are (radius, length).
    assert objects["Can1"].shape.kind == "cylinder" and objects["Can1"].shape.dims == (0.03, 0.14)
    assert [f.name for f in scene.frames] == ["world"]
    assert scene.robot_state == {f"panda_joint{i}": 0.0 for i in range(1, 8)} | {
        "panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}


def test_mbm_acm_allows_the_pairs_it_lists(panda: Robot) -> None:
    allowed = load_scene(SCENE, panda).allowed
    assert frozenset(("panda_hand", "panda_leftfinger")) in allowed
    assert frozenset(("panda_hand", "panda_link3")) in allowed
    assert frozenset(("panda_link5", "panda_link6")) in allowed
    assert frozenset(("panda_hand", "panda_link5")) not in allowed
    assert frozenset(("panda_link0", "panda_link5")) not in allowed


def test_colliding_pair_allowed_by_the_acm_is_not_reported(panda: Robot, tmp_path: Path) -> None:
    q = panda.configuration(START)
    world = {"collision_objects": [ball("ball", HAND_POINT)]}
    plain = load_scene(write(tmp_path / "plain.yaml", {"world": world}), panda)
    assert CollisionChecker(panda, plain.objects, allowed=plain.allowed).colliding_pair(q) == ("panda_hand", "ball")
    acm = {"entry_names": ["ball", "panda_hand", "unknown_link"],
           "entry_values": [[False, True, True], [True, False, False], [True, False, False]]}
    scene = load_scene(write(tmp_path / "acm.yaml", {"world": world, "allowed_collision_matrix": acm}), panda)
    assert CollisionChecker(panda, scene.objects, allowed=scene.allowed).colliding_pair(q) is None


def test_acm_entry_naming_an_object_applies_to_all_its_parts(panda: Robot, tmp_path: Path) -> None:
    balls = {"id": "balls", "primitives": [{"type": "SPHERE", "dimensions": [0.02]}, {"type": 2, "dimensions": [0.1]}],
             "primitive_poses": [{"position": HAND_POINT}, {"position": {"x": 1.5, "y": 1.5}}]}
    acm = {"default_entry_names": ["balls"], "default_entry_values": [True]}
    scene = load_scene(write(tmp_path / "s.yaml", {"world": {"collision_objects": [balls]},
                                                   "allowed_collision_matrix": acm}), panda)
    assert [o.name for o in scene.objects] == ["balls/0", "balls/1"]
    np.testing.assert_allclose(scene.objects[1].transform[:3, 3], [1.5, 1.5, 0.0])
    assert frozenset(("balls/0", "panda_hand")) in scene.allowed
    assert frozenset(("balls/1", "panda_hand")) in scene.allowed
    checker = CollisionChecker(panda, scene.objects, allowed=scene.allowed)
    assert checker.colliding_pair(panda.configuration(START)) is None


def test_shape_poses_are_relative_to_the_object_pose_in_its_header_frame(panda: Robot, tmp_path: Path) -> None:
    table = {"id": "table", "header": {"frame_id": "table_frame"},
             "pose": {"position": [0.1, 0, 0], "orientation": {"z": 0.7071067811865476, "w": 0.7071067811865476}},
             "primitives": [{"type": "box", "dimensions": [1, 1, 0.1]}, {"type": 3, "dimensions": [0.5, 0.02]}],
             "primitive_poses": [{"position": [0, 0, 0]}, {"position": [0.2, 0, 0.3]}],
             "subframe_names": ["corner"], "subframe_poses": [{"position": [0.5, 0.5, 0]}]}
    fixed = [{"child_frame_id": "table_frame", "transform": {"translation": [1, 0, 0], "rotation": [0, 0, 0, 1]}},
             {"child_frame_id": "panda_link0", "transform": {"translation": [0, 0, 0], "rotation": [0, 0, 0, 1]}}]
    scene = load_scene(write(tmp_path / "s.yaml", {"fixed_frame_transforms": fixed,
                                                   "world": {"collision_objects": [table]}}), panda)
    top, post = scene.objects
    np.testing.assert_allclose(top.transform[:3, 3], [1.1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(post.transform[:3, 3], [1.1, 0.2, 0.3], atol=1e-12)  # turned 90 deg about z
    assert post.shape.dims == (0.02, 0.5)
    assert [f.name for f in scene.frames] == ["table_frame", "table/corner"]
    np.testing.assert_allclose(scene.anchors["table/corner"][1][:3, 3], [0.6, 0.5, 0], atol=1e-12)


def test_inline_mesh_becomes_a_coal_mesh_and_a_cone_its_enclosing_cylinder(
    panda: Robot, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    tetra = {"id": "tetra", "meshes": [{"vertices": [[0, 0, 0], {"x": 0.1}, [0, 0.1, 0], [0, 0, 0.1]],
                                        "triangles": [{"vertex_indices": [0, 1, 2]}, {"vertex_indices": [0, 1, 3]},
                                                      {"vertex_indices": [0, 2, 3]}, {"vertex_indices": [1, 2, 3]}]}],
             "mesh_poses": [{"position": [1, 1, 1]}]}
    cone = {"id": "cone", "primitives": [{"type": "cone", "dimensions": [0.4, 0.1]}],
            "primitive_poses": [{"position": [-1, 1, 0]}]}
    with caplog.at_level(logging.WARNING):
        scene = load_scene(write(tmp_path / "s.yaml", {"world": {"collision_objects": [tetra, cone]}}), panda)
    mesh, cylinder = scene.objects
    assert mesh.shape.kind == "mesh" and mesh.shape.mesh_path == ""
    assert mesh.shape.vertices is not None and mesh.shape.vertices.shape == (4, 3)
    assert mesh.shape.triangles is not None and mesh.shape.triangles.shape == (4, 3)
    geometry = coal_geometry(mesh.shape)
    assert (geometry.num_vertices, geometry.num_tris) == (4, 4)
    assert cylinder.shape.kind == "cylinder" and cylinder.shape.dims == (0.1, 0.4)
    assert "cone" in caplog.text
    CollisionChecker(panda, scene.objects)  # builds with both


def test_attached_object_is_placed_on_its_link_where_the_scene_state_puts_it(panda: Robot, tmp_path: Path) -> None:
    state = {"joint_state": {"name": [f"panda_joint{i}" for i in range(1, 8)], "position": START},
             "attached_collision_objects": [{"link_name": "panda_hand", "touch_links": ["panda_leftfinger"],
                                             "object": {**ball("tool", HAND_POINT, 0.02),
                                                        "header": {"frame_id": "panda_link0"}}}]}
    scene = load_scene(write(tmp_path / "s.yaml", {"robot_state": state}), panda)
    [tool] = scene.objects
    assert (tool.link, tool.touch_links) == ("panda_hand", ("panda_leftfinger",))
    hand = panda.frame_pose(panda.configuration(START), "panda_hand")
    np.testing.assert_allclose(hand @ tool.transform[:, 3], [*HAND_POINT, 1.0], atol=1e-9)
    assert scene.robot_state["panda_joint4"] == -2.356


# --- the command line --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def mbm_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("mbm") / "out.mcap"
    result = Cli()("plan", "--robot", "panda", "--scene", SCENE, "--request", REQUEST, "--planner", "RRTConnect",
                   "--planning-time", "5", "-o", out)
    assert result.exit_code == 0, result.stderr
    return out


def test_request_start_and_goal_are_the_trajectory_ends(mbm_plan: Path) -> None:
    plan = read_plan(mbm_plan)
    [step] = plan.steps
    assert step.name == "request0001"
    np.testing.assert_allclose(step.trajectory.positions[0], START, atol=1e-12)
    np.testing.assert_allclose(step.trajectory.positions[-1], GOAL, atol=1e-12)
    assert plan.attachments["request.yaml"] == REQUEST.read_bytes()
    assert plan.attachments["scene.yaml"] == SCENE.read_bytes()


def test_plan_from_moveit_yaml_reads_back_with_rosbags(mbm_plan: Path) -> None:
    with AnyReader([mbm_plan]) as reader:
        wanted = [c for c in reader.connections if c.topic in ("/planned_trajectory", "/planning_scene_markers")]
        messages = {c.topic: reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=wanted)}
    assert len(messages["/planning_scene_markers"].markers) == 7
    np.testing.assert_allclose(messages["/planned_trajectory"].points[-1].positions, GOAL, atol=1e-12)


def test_flag_overrides_the_request_goal_and_scene_mesh_is_a_triangle_list_marker(cli: Cli, tmp_path: Path) -> None:
    tetra = {"id": "tetra", "meshes": [{"vertices": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
                                        "triangles": [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]}],
             "mesh_poses": [{"position": [1.5, 1.5, 0]}]}
    scene = write(tmp_path / "scene.yaml", {"world": {"collision_objects": [tetra]}})
    out = tmp_path / "out.mcap"
    goal = [0.1, *START[1:]]
    result = cli("plan", "--robot", "panda", "--scene", scene, "--request", REQUEST,
                 "--joints", ",".join(map(str, goal)), "--planner", "RRTConnect", "-o", out)
    assert result.exit_code == 0, result.stderr
    trajectory = read_plan(out).steps[0].trajectory
    np.testing.assert_allclose(trajectory.positions[-1], goal, atol=1e-12)
    with AnyReader([out]) as reader:
        wanted = [c for c in reader.connections if c.topic == "/planning_scene_markers"]
        [markers] = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=wanted)]
    [marker] = markers.markers
    assert marker.type == 11 and len(marker.points) == 12  # TRIANGLE_LIST, three points a triangle
    assert (marker.points[4].x, marker.pose.position.x) == (0.1, 1.5)


def _malformed(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _scene_with(tmp_path: Path, obj: dict[str, Any], **extra: Any) -> Path:
    return write(tmp_path / "bad_scene.yaml", {"world": {"collision_objects": [obj]}, **extra})


BOX = {"id": "box", "primitives": [{"type": "box", "dimensions": [0.1, 0.1, 0.1]}],
       "primitive_poses": [{"position": [1, 1, 0]}]}


@pytest.mark.parametrize(("make", "message"), [
    (lambda d: _malformed(d / "bad_scene.yaml", "world: {collision_objects: [\n"), "bad_scene.yaml: line"),
    (lambda d: write(d / "bad_scene.yaml", {"world": {"collision_objects": 5}}),
     "bad_scene.yaml: world.collision_objects: expected a list"),
    (lambda d: _scene_with(d, {**BOX, "primitives": [{"type": "pyramid", "dimensions": [1]}]}),
     "world.collision_objects[0].primitives[0].type: unknown primitive type 'pyramid'"),
    (lambda d: _scene_with(d, {**BOX, "primitives": [{"type": 7, "dimensions": [1]}]}),
     "primitives[0].type: unknown primitive type 7"),
    (lambda d: _scene_with(d, {**BOX, "primitives": [{"type": "box", "dimensions": [0.1, 0.1]}]}),
     "primitives[0].dimensions: a box takes 3 numbers"),
    (lambda d: _scene_with(d, {**BOX, "primitives": [{"type": "cylinder", "dimensions": "tall"}]}),
     "primitives[0].dimensions: a cylinder takes 2 numbers [height, radius]"),
    (lambda d: _scene_with(d, {**BOX, "primitive_poses": [{"position": [1, float("nan"), 0]}]}),
     "primitive_poses[0].position[1]: expected a finite number, got nan"),
    (lambda d: _scene_with(d, {**BOX, "primitive_poses": [{"position": [1, 0, True]}]}),
     "primitive_poses[0].position[2]: expected a finite number, got True"),
    (lambda d: _scene_with(d, {**BOX, "primitive_poses": [{"position": [10**400, 0, 0]}]}),
     "primitive_poses[0].position[0]: expected a finite number"),
    (lambda d: _scene_with(d, {**BOX, "primitive_poses": [{"position": [0, 2e6, 0]}]}),
     "primitive_poses[0].position[1]: 2e+06 is out of range"),
    (lambda d: _scene_with(d, {**BOX, "primitive_poses": [{"orientation": [0, 0, "a", 1]}]}),
     "primitive_poses[0].orientation[2]: expected a finite number, got 'a'"),
    (lambda d: _scene_with(d, {**BOX, "header": {"frame_id": "shelf"}}),
     "frame 'shelf' not found in "),
    (lambda d: _scene_with(d, {**BOX, "operation": 2}),
     "world.collision_objects[0].operation: only ADD (0)"),
    (lambda d: _scene_with(d, {**BOX, "colour": "red"}),
     "world.collision_objects[0]: unknown key 'colour'"),
    (lambda d: _scene_with(d, BOX, robot_state={"joint_state": {"name": ["elbow"], "position": [0]}}),
     "joint 'elbow' not found in "),
    (lambda d: _scene_with(d, BOX, allowed_collision_matrix={"entry_names": ["a", "b"], "entry_values": [[1, 0]]}),
     "allowed_collision_matrix.entry_values: 1 rows for 2 entry_names"),
    (lambda d: _scene_with(d, {**BOX, "planes": [{"coef": [0, 0, 1, 0]}]}),
     "world.collision_objects[0].planes: planes are not supported"),
    (lambda d: write(d / "bad_scene.yaml", {"world": {"octomap": {"octomap": {"data": [1, 2]}}}}),
     "world.octomap: octomaps are not supported"),
    (lambda d: _scene_with(d, BOX, robot_state={"multi_dof_joint_state": {
        "joint_names": ["virtual_joint"], "transforms": [{"translation": [1, 0, 0], "rotation": [0, 0, 0, 1]}]}}),
     "robot_state.multi_dof_joint_state.transforms[0]: joint 'virtual_joint' is away from the identity"),
])
def test_bad_planning_scene_exits_3_naming_file_and_key(cli: Cli, tmp_path: Path, make: Any, message: str) -> None:
    scene = make(tmp_path)
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--scene", scene, "--request", REQUEST, "-o", out)
    assert result.exit_code == 3, result.stderr
    assert message in result.stderr and str(scene) in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    assert not out.exists()


def _start_with(names: list[str]) -> dict[str, Any]:
    return request_with(start_state={"joint_state": {"name": names, "position": [0.0] * len(names)}})


@pytest.mark.parametrize(("content", "message"), [
    ("group_name: panda_arm\nstart_state: [\n", "bad_request.yaml: line"),
    (_start_with(["panda_joint1", "wrist_joint"]),
     "joint 'wrist_joint' not found in {file}: start_state.joint_state.name"),
    (request_with(group_name="arm"), "group 'arm' not found in {file}: group_name"),
    (request_with(planner_id="CHOMP"), "{file}: planner_id: 'CHOMP' names no available OMPL geometric planner"),
    (request_with(goal_constraints=[{"joint_constraints": [{"joint_name": "elbow", "position": 1.0}]}]),
     "joint 'elbow' not found in {file}: goal_constraints[0].joint_constraints"),
    (request_with(goal_constraints=[{"joint_constraints": [{"joint_name": "panda_joint1", "position": float("nan")}]}]),
     "{file}: goal_constraints[0].joint_constraints[0].position: expected a finite number"),
    (request_with(allowed_planning_time="long"), "{file}: allowed_planning_time: expected a finite number"),
    (request_with(max_velocity_scaling_factor=float("nan")), "{file}: max_velocity_scaling_factor: expected a finite"),
    (request_with(start_state={"joint_state": {"name": ["panda_joint1"], "position": [0, 1]}}),
     "{file}: start_state.joint_state.position: 2 positions for 1 names"),
    (request_with(path_constraints={"joint_constraints": [{"joint_name": "panda_joint1", "tolerance_above": -1}]}),
     "{file}: path_constraints.joint_constraints[0].tolerance_above: expected a tolerance >= 0, got -1"),
    (request_with(path_constraints={"visibility_constraints": [{}]}),
     "{file}: path_constraints.visibility_constraints: not supported"),
    (request_with(goal_constraint=[]), "{file}: unknown key 'goal_constraint'"),
    (request_with(start_state={"attached_collision_objects": [{"link_name": "panda_hand"}]}),
     "{file}: start_state.attached_collision_objects[0].object.id: expected an object name, got None"),
    (b"group_name: panda_arm\nplanner_id: \xff\n",  # read once, for the plan and its embedded copy alike
     "{file}: cannot read: not UTF-8 text (invalid start byte at byte 34)"),
])
def test_bad_motion_plan_request_exits_3_naming_file_and_key(
    cli: Cli, tmp_path: Path, content: Any, message: str
) -> None:
    path = tmp_path / "bad_request.yaml"
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content)
    else:
        write(path, content)
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--scene", SCENE, "--request", path, "-o", out)
    assert result.exit_code == 3, result.stderr
    assert message.format(file=path) in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    assert not out.exists()


def test_unknown_frame_of_an_object_lists_the_known_frames(panda: Robot, tmp_path: Path) -> None:
    scene = _scene_with(tmp_path, {**BOX, "header": {"frame_id": "/shelf"}})
    with pytest.raises(FrameNotFound, match=r"collision_objects\[0\].header.frame_id; known: .*panda_link0"):
        load_scene(scene, panda)
