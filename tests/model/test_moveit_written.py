"""PlanningScene and MotionPlanRequest YAML as MoveIt, MoveGroupInterface and robowflex write them.

tests/data/moveit_written holds a scene as MoveIt 2 serialises a moveit_msgs/PlanningScene
(fixed frames as Transforms::copyTransforms writes them, C++ message YAML), a request as
MoveGroupInterface sends one after setPositionTarget with an object attached by id (ROS 2
Humble Python message YAML), and a scene whose meshes are files, as robowflex writes them.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from conftest import REALWORLD, ROOT, Cli
from rosbags.highlevel import AnyReader

from moveplan.core.bag import read_plan
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.fields import MAX_YAML_EVENTS
from moveplan.core.config.moveit_request import PositionGoal, load_motion_plan_request
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import ConfigError, GoalUnreachable
from moveplan.core.model.kinematics import solve_ik
from moveplan.core.model.planning_scene import attach_request_objects
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.planning.goals import orientation_tolerance, tip_target

DATA = ROOT / "tests" / "data" / "moveit_written"
SCENE, REQUEST, MESH_SCENE = DATA / "panda_scene.yaml", DATA / "panda_request.yaml", DATA / "mesh_scene.yaml"
MBM_PANDA = ROOT / "tests" / "data" / "mbm" / "panda_robot"  # its SRDF hangs panda_link0 from `world`, floating
START = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
TARGET = [0.45, 0.25, 0.55]  # the request's position goal for panda_hand, in world


@pytest.fixture(scope="module")
def panda() -> Robot:
    return Robot(load_robot_config("panda", (DATA,)))


def write(path: Path, content: Any) -> Path:
    path.write_text(yaml.safe_dump(content, sort_keys=False))
    return path


def fixed(frame: str, child: str, xyz: list[float], quat: list[float] | None = None) -> dict[str, Any]:
    return {"header": {"frame_id": frame}, "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", xyz, strict=True)),
                          "rotation": dict(zip("xyzw", quat or [0, 0, 0, 1], strict=True))}}


def box(name: str, frame: str, size: float = 0.1) -> dict[str, Any]:
    return {"id": name, "header": {"frame_id": frame}, "primitives": [{"type": 1, "dimensions": [size] * 3}],
            "primitive_poses": [{"position": {"x": 0.0}}]}


def request_with(**changes: Any) -> dict[str, Any]:
    content = yaml.safe_load(REQUEST.read_text())
    content.update(changes)
    return content


# --- fixed_frame_transforms ---------------------------------------------------------------------


def test_fixed_frames_are_read_as_moveit_writes_them_child_the_planning_frame(panda: Robot) -> None:
    scene = load_scene(SCENE, panda)
    frames = {f.name: f for f in scene.frames}
    # table_frame is header.frame_id; its pose in the planning frame is the transform.
    np.testing.assert_allclose(frames["table_frame"].transform[:3, 3], [0.55, 0.0, 0.25])
    np.testing.assert_allclose(frames["table_frame"].transform[:3, 0], [0.0, 1.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(frames["world"].transform, np.eye(4))  # the planning frame, relative to itself
    table = next(o for o in scene.objects if o.name == "table")
    np.testing.assert_allclose(table.transform[:3, 3], [0.55, 0.0, 0.23], atol=1e-9)
    np.testing.assert_allclose(table.transform[:3, 0], [0.0, 1.0, 0.0], atol=1e-6)  # 0.8 m across the robot's y
    link, link_T_top = scene.anchor("table/top_centre", panda)
    assert link == "panda_link0"
    np.testing.assert_allclose(link_T_top[:3, 3], [0.55, 0.0, 0.25], atol=1e-9)


def test_the_scene_keeps_its_name_and_a_name_that_is_no_string_names_the_key(panda: Robot, tmp_path: Path) -> None:
    assert load_scene(SCENE, panda).name == "pick_cup"
    with pytest.raises(ConfigError, match=r"bad.yaml: name: expected a string, got \[1\]"):
        load_scene(write(tmp_path / "bad.yaml", {**yaml.safe_load(SCENE.read_text()), "name": [1]}), panda)


def test_planning_frame_of_the_srdf_virtual_joint_names_the_child_of_fixed_frames(tmp_path: Path) -> None:
    robot = Robot(load_robot_config(MBM_PANDA))
    # No entry for `world` itself: the SRDF's virtual joint says it is the planning frame.
    scene = load_scene(write(tmp_path / "scene.yaml", {
        "fixed_frame_transforms": [fixed("shelf", "world", [0.6, -0.2, 0.3])],
        "world": {"collision_objects": [box("book", "shelf"), box("ball", "world")]}}), robot)
    book, ball = scene.objects
    np.testing.assert_allclose(book.transform[:3, 3], [0.6, -0.2, 0.3])
    np.testing.assert_allclose(ball.transform[:3, 3], [0.0, 0.0, 0.0])
    assert [f.name for f in scene.frames] == ["shelf"]


def test_a_transform_to_another_child_frame_is_read_as_tf_reads_it(panda: Robot, tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path / "scene.yaml", {"fixed_frame_transforms": [
        fixed("world", "world", [0, 0, 0]), fixed("table_frame", "world", [1.0, 0.0, 0.0]),
        fixed("table_frame", "corner", [0.0, 0.5, 0.0])]}), panda)
    _, link_T_corner = scene.anchor("corner", panda)
    np.testing.assert_allclose(link_T_corner[:3, 3], [1.0, 0.5, 0.0])


@pytest.mark.parametrize(("entries", "message"), [
    ([fixed("world", "world", [0.1, 0, 0])],
     "fixed_frame_transforms[0]: frame 'world' relative to itself can only be the identity"),
    ([fixed("world", "world", [0, 0, 0]), fixed("world", "panda_link0", [0.1, 0, 0])],
     "fixed_frame_transforms[1]: 'world' and 'panda_link0' both name the planning frame"),
])
def test_planning_frame_away_from_itself_exits_3(cli: Cli, tmp_path: Path, entries: Any, message: str) -> None:
    scene = write(tmp_path / "scene.yaml", {"fixed_frame_transforms": entries})
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--scene", scene, "--named", "ready", "-o", out)
    assert result.exit_code == 3, result.stderr
    assert f"{scene}: {message}" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not out.exists()


# --- attached objects ---------------------------------------------------------------------------


def test_request_attaches_the_world_cup_by_id_and_it_leaves_the_world(panda: Robot) -> None:
    scene = load_scene(SCENE, panda)
    request = load_motion_plan_request(REQUEST)
    q = panda.configuration(START)
    attached = attach_request_objects(scene, request, panda, q)
    cup = next(o for o in attached.objects if o.name == "cup")
    assert (cup.link, cup.touch_links) == ("panda_hand", ("panda_hand", "panda_leftfinger", "panda_rightfinger"))
    assert [o.name for o in attached.objects] == ["table", "cup"]  # one cup: the world's is gone
    # Fixed to the hand where it stood in the world, so it moves with the hand.
    hand = panda.frame_pose(q, "panda_hand")
    np.testing.assert_allclose((hand @ cup.transform)[:3, 3], [0.307, 0.0, 0.42], atol=1e-9)
    assert CollisionChecker(panda, attached.objects, allowed=attached.allowed).colliding_pair(q) is None


def test_the_carried_cup_is_checked_against_the_world(panda: Robot) -> None:
    scene = load_scene(SCENE, panda)
    attached = attach_request_objects(scene, load_motion_plan_request(REQUEST), panda, panda.configuration(START))
    # The hand 44 cm up over the table, pointing down: its fingers clear the table top (25 cm),
    # the cup hanging 17 to 21 cm below the hand does not.
    lowered = panda.frame_pose(panda.configuration(START), "panda_hand")
    lowered[:3, 3] = [0.55, 0.0, 0.44]
    values = solve_ik(panda, lowered, "panda_hand", START).values
    q = panda.configuration(values)
    assert CollisionChecker(panda, scene.objects, allowed=scene.allowed).colliding_pair(q) is None
    # The checker names an attached object by the link that carries it.
    assert CollisionChecker(panda, attached.objects, allowed=attached.allowed).colliding_pair(q) == (
        "table", "panda_hand")


def test_attaching_an_id_no_world_object_has_names_file_key_and_world_objects(panda: Robot, tmp_path: Path) -> None:
    content = request_with()
    content["start_state"]["attached_collision_objects"][0]["object"]["id"] = "mug"
    request = load_motion_plan_request(write(tmp_path / "request.yaml", content))
    with pytest.raises(ConfigError, match=r"request.yaml: start_state.attached_collision_objects\[0\].object: "
                                          r"object 'mug' has no primitives or meshes, and no world object has "
                                          r"that id to attach \(world objects: table, cup\)"):
        attach_request_objects(load_scene(SCENE, panda), request, panda, panda.configuration(START))


def test_attached_object_with_shapes_replaces_the_world_object_of_its_id(panda: Robot, tmp_path: Path) -> None:
    content = request_with()
    content["start_state"]["attached_collision_objects"][0]["object"] |= {
        "primitives": [{"type": 2, "dimensions": [0.02]}], "primitive_poses": [{"position": {"z": 0.15}}]}
    request = load_motion_plan_request(write(tmp_path / "request.yaml", content))
    attached = attach_request_objects(load_scene(SCENE, panda), request, panda, panda.configuration(START))
    [cup] = [o for o in attached.objects if o.name == "cup"]
    assert cup.link == "panda_hand" and cup.shape.kind == "sphere"  # empty header: the link's frame
    np.testing.assert_allclose(cup.transform[:3, 3], [0.0, 0.0, 0.15], atol=1e-12)


def test_scene_robot_state_may_attach_a_world_object_by_id(panda: Robot, tmp_path: Path) -> None:
    content = yaml.safe_load(SCENE.read_text())
    content["robot_state"]["attached_collision_objects"] = [
        {"link_name": "panda_hand", "object": {"id": "cup"}, "touch_links": ["panda_leftfinger"]}]
    scene = load_scene(write(tmp_path / "scene.yaml", content), panda)
    assert [(o.name, o.link) for o in scene.objects] == [("table", ""), ("cup", "panda_hand")]


# --- position goals -----------------------------------------------------------------------------


def test_position_constraint_alone_is_a_position_goal_with_the_orientation_free(panda: Robot) -> None:
    request = load_motion_plan_request(REQUEST)
    assert request.goal is not None
    goal = request.goal.goal
    assert isinstance(goal, PositionGoal) and (goal.link, goal.frame, goal.xyz) == ("panda_hand", "world", (0.45, 0.25,
                                                                                                           0.55))
    assert goal.describe()["pose"]["orientation"] == "free"
    assert orientation_tolerance(goal) == math.inf
    link, target = tip_target(panda, load_scene(SCENE, panda), goal, panda.configuration(START), "request")
    assert link == "panda_hand"
    np.testing.assert_allclose(target[:3, 3], TARGET)
    # The orientation is one the arm reaches the position with: a full-pose solve gets there.
    solve_ik(panda, target, link, START)


def test_position_goal_plans_to_the_position_from_the_moveit_files(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    code, document = cli.json("plan", "--robot", "panda", "--scene", SCENE, "--request", REQUEST, "-o", out)
    assert code == 0, document
    [step] = document["steps"]
    assert step["goal"]["pose"]["orientation"] == "free" and step["residual"]["position_m"] < 1e-4
    robot = Robot(load_robot_config("panda"))
    plan = read_plan(out)
    end = plan.steps[-1].trajectory.positions[-1]
    reached = robot.frame_pose(robot.configuration(end, robot.configuration(START)), "panda_hand")
    np.testing.assert_allclose(reached[:3, 3], TARGET, atol=1e-4)


def test_position_goal_out_of_reach_reports_the_distance_without_an_angle(panda: Robot) -> None:
    far = PositionGoal(xyz=(3.0, 0.0, 0.5), frame="world", link="panda_hand")
    with pytest.raises(GoalUnreachable, match=r"closest reached \d+\.\d mm away after"):
        tip_target(panda, load_scene(SCENE, panda), far, panda.configuration(START), "request")


@pytest.mark.realworld
def test_real_panda_moveit_config_plans_the_moveit_files(cli: Cli, tmp_path: Path) -> None:
    config = REALWORLD / "moveit_resources" / "panda_moveit_config"
    out = tmp_path / "out.mcap"
    code, document = cli.json("plan", "--robot", config, "--scene", SCENE, "--request", REQUEST, "-o", out)
    assert code == 0, document
    assert document["steps"][0]["residual"]["position_m"] < 1e-4


# --- mesh files ---------------------------------------------------------------------------------


def test_mesh_resources_load_by_path_and_package_uri_and_collide_as_meshes(panda: Robot) -> None:
    scene = load_scene(MESH_SCENE, panda)
    bin_, post = scene.objects
    assert (Path(bin_.shape.mesh_path), bin_.shape.scale) == ((DATA / "bin.stl").resolve(), (1.0, 1.0, 1.0))
    assert Path(post.shape.mesh_path) == (DATA / "scene_meshes" / "meshes" / "post.stl").resolve()
    assert post.shape.scale == (1.0, 1.0, 2.0)  # `dimensions` scale the mesh: a 60 cm post
    checker = CollisionChecker(panda, scene.objects)
    hand = panda.frame_pose(panda.configuration(START), "panda_hand")

    def pair_with_hand_at(position: list[float]) -> tuple[str, str] | None:
        hand[:3, 3] = position
        return checker.colliding_pair(panda.configuration(solve_ik(panda, hand, "panda_hand", START).values))

    assert pair_with_hand_at([0.45, -0.35, 0.27]) is None  # fingers down into the open bin, clear of its walls
    assert pair_with_hand_at([0.45, -0.35, 0.19]) == ("panda_hand", "bin")
    assert pair_with_hand_at([0.6, 0.45, 0.45]) == ("panda_link6", "post")


def test_mesh_scene_plans_and_its_objects_are_in_the_plan_file(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--package-path", DATA, "--scene", MESH_SCENE,
                 "--joints", "0.6,-0.3,0,-2.2,0,1.9,0.8", "-o", out)
    assert result.exit_code == 0, result.stderr
    with AnyReader([out]) as reader:
        wanted = [c for c in reader.connections if c.topic == "/planning_scene_markers"]
        [markers] = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=wanted)]
    # MESH_RESOURCE markers naming the files, so that Foxglove and RViz draw them.
    assert sorted((m.type, m.mesh_resource) for m in markers.markers) == [
        (10, (DATA / "bin.stl").resolve().as_uri()),
        (10, (DATA / "scene_meshes" / "meshes" / "post.stl").resolve().as_uri())]


@pytest.mark.parametrize(("resource", "message"), [
    ("meshes/none.stl", "meshes[0].resource: mesh file not found: "),
    ("package://no_such_package/meshes/post.stl", "package 'no_such_package' not found"),
    ("http://example.com/post.stl", "unsupported resource URI 'http://example.com/post.stl'"),
])
def test_bad_mesh_resource_exits_3_naming_file_and_key(cli: Cli, tmp_path: Path, resource: str, message: str) -> None:
    scene = write(tmp_path / "scene.yaml", {"world": {"collision_objects": [
        {"id": "post", "meshes": [{"resource": resource}], "mesh_poses": [{"position": [1, 1, 0]}]}]}})
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--scene", scene, "--named", "ready", "-o", out)
    assert result.exit_code == 3, result.stderr
    assert f"{scene}: world.collision_objects[0]" in result.stderr and message in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not out.exists()


# --- hostile numbers ----------------------------------------------------------------------------


def _joint_goal(**constraint: Any) -> list[dict[str, Any]]:
    return [{"joint_constraints": [{"joint_name": "panda_joint1", "position": 0.5, **constraint}]}]


@pytest.mark.parametrize(("changes", "message"), [
    ({"allowed_planning_time": 1e9}, "allowed_planning_time: 1e+09 is out of range; values are limited to "
                                     "|value| <= 1,000,000"),
    ({"num_planning_attempts": 10**12}, "num_planning_attempts: expected an integer in 0..2147483647, got "
                                        "1000000000000"),
    ({"num_planning_attempts": -1}, "num_planning_attempts: expected an integer in 0..2147483647"),
    ({"max_velocity_scaling_factor": 1e300}, "max_velocity_scaling_factor: 1e+300 is out of range"),
    ({"goal_constraints": _joint_goal(position=1e7)},
     "goal_constraints[0].joint_constraints[0].position: 1e+07 is out of range"),
    ({"goal_constraints": _joint_goal(tolerance_above=float("inf"))},
     "goal_constraints[0].joint_constraints[0].tolerance_above: expected a finite number, got inf"),
    ({"goal_constraints": _joint_goal(weight="heavy")},
     "goal_constraints[0].joint_constraints[0].weight: expected a finite number, got 'heavy'"),
    ({"start_state": {"joint_state": {"name": ["panda_joint1"], "position": [-1e300]}}},
     "start_state.joint_state.position[0]: -1e+300 is out of range"),
    ({"workspace_parameters": {"min_corner": {"x": 1e12}}}, "workspace_parameters.min_corner.x: 1e+12 is out of range"),
    ({"max_cartesian_speed": float("nan")}, "max_cartesian_speed: expected a finite number, got nan"),
])
def test_request_numbers_are_bounded_like_flags(cli: Cli, tmp_path: Path, changes: Any, message: str) -> None:
    path = write(tmp_path / "request.yaml", request_with(**changes))
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", "panda", "--scene", SCENE, "--request", path, "-o", out)
    assert result.exit_code == 3, result.stderr
    assert f"{path}: {message}" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not out.exists()


# --- a scene too large to read ------------------------------------------------------------------


def test_scene_with_200000_shapes_is_refused_before_it_is_built(cli: Cli, tmp_path: Path) -> None:
    count = 200_000
    shape = "{type: box, dimensions: [0.01, 0.01, 0.01]}"
    scene = tmp_path / "huge_scene.yaml"
    with scene.open("w") as stream:
        stream.write("world:\n  collision_objects:\n    - id: gravel\n      primitives:\n")
        stream.writelines(f"        - {shape}\n" for _ in range(count))
        stream.write("      primitive_poses:\n")
        stream.writelines(f"        - {{position: [{i * 1e-5:.5f}, 3, 0]}}\n" for i in range(count))
    began = time.perf_counter()
    result = cli("plan", "--robot", "panda", "--scene", scene, "--named", "ready", "-o", tmp_path / "out.mcap")
    elapsed = time.perf_counter() - began
    assert result.exit_code == 3, result.stderr
    assert f"{scene}: more than {MAX_YAML_EVENTS:,} YAML values" in result.stderr
    # Building the values would take about a minute; counting them takes a second or two.
    assert elapsed < 20.0
