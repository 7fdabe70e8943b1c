"""`moveplan plan`: joint and named goals on the UR10e, what the written trajectory guarantees, bad input."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, TABLE_SCENE, UR10E, Cli, dense_peaks, run_process
from rosbags.highlevel import AnyReader

from moveplan.core.bag import read_plan
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.trajectory import sample

GOAL = [0.5, -1.2, -1.8, 0.0, 1.57, 0.0]
HOME = [0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0]


@pytest.fixture(scope="module")
def table_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("plan") / "out.mcap"
    result = Cli()("plan", "--robot", UR10E, "--scene", TABLE_SCENE, "--start-named", "home",
                   "--joints", ",".join(map(str, GOAL)), "--velocity-scaling", "0.5",
                   "--acceleration-scaling", "0.4", "-o", out)
    assert result.exit_code == 0, result.stderr
    return out


def test_joint_goal_plan_reads_back_with_rosbags(table_plan: Path) -> None:
    with AnyReader([table_plan]) as reader:
        topics = {c.topic: c.msgtype for c in reader.connections}
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in
                    reader.messages(connections=[c for c in reader.connections if c.topic == "/planned_trajectory"])]
    assert topics["/planned_trajectory"] == "trajectory_msgs/msg/JointTrajectory"
    latched = {"/robot_description", "/tf_static", "/planning_scene_markers", "/display_planned_path"}
    assert latched | {"/tf"} <= set(topics)
    assert len(messages) == 1
    assert list(messages[0].joint_names)[2] == "elbow_joint"
    np.testing.assert_allclose(messages[0].points[-1].positions, GOAL, atol=1e-12)


def test_trajectory_starts_at_start_and_ends_at_goal_at_rest(table_plan: Path) -> None:
    trajectory = read_plan(table_plan).steps[0].trajectory
    assert trajectory.times_s[0] == 0.0
    assert np.all(np.diff(trajectory.times_s) > 0)
    np.testing.assert_allclose(trajectory.positions[0], HOME, atol=1e-12)
    np.testing.assert_allclose(trajectory.positions[-1], GOAL, atol=1e-12)
    assert np.all(trajectory.velocities[-1] == 0.0) and np.all(trajectory.accelerations[-1] == 0.0)
    assert np.all(trajectory.velocities[0] == 0.0)


def test_interpolated_trajectory_stays_within_scaled_limits_everywhere(table_plan: Path, ur10e: Robot) -> None:
    trajectory = read_plan(table_plan).steps[0].trajectory
    peak_v, peak_a = dense_peaks(trajectory)
    assert np.all(peak_v <= ur10e.max_velocity * 0.5 + 1e-9)
    assert np.all(peak_a <= ur10e.max_acceleration * 0.4 + 1e-9)
    # Time-optimal: some joint uses most of its scaled velocity or acceleration.
    assert max(np.max(peak_v / (ur10e.max_velocity * 0.5)), np.max(peak_a / (ur10e.max_acceleration * 0.4))) > 0.9


def test_trajectory_is_collision_free_when_checked_densely(table_plan: Path, ur10e: Robot) -> None:
    trajectory = read_plan(table_plan).steps[0].trajectory
    checker = CollisionChecker(ur10e, load_scene(TABLE_SCENE, ur10e).objects)
    times = np.linspace(0.0, trajectory.duration_s, 4000)
    positions, _, _ = sample(trajectory, times)
    assert checker.free_batch(ur10e.configurations(positions, ur10e.neutral())).all()


def test_same_seed_gives_byte_identical_plan_files(tmp_path: Path) -> None:
    outputs = []
    for name in ("a.mcap", "b.mcap"):
        result = run_process("plan", "--robot", UR10E, "--scene", TABLE_SCENE, "--start-named", "home",
                             "--joints", ",".join(map(str, GOAL)), "--seed", "7", "-o", tmp_path / name)
        assert result.returncode == 0, result.stderr
        assert result.stderr == ""  # nothing from the libraries leaks onto the terminal
        outputs.append((tmp_path / name).read_bytes())
    assert outputs[0] == outputs[1]


def test_without_start_flag_plan_starts_at_initial_positions(cli: Cli, tmp_path: Path, ur10e: Robot) -> None:
    result = cli("plan", "--robot", UR10E, "--named", "home", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr
    start = read_plan(tmp_path / "p.mcap").steps[0].trajectory.positions[0]
    expected = [ur10e.config.initial_positions[j] for j in ur10e.joint_names]
    np.testing.assert_allclose(start, expected, atol=1e-12)


def test_partial_joint_goal_keeps_other_joints_and_accepts_pi_expressions(cli: Cli, tmp_path: Path) -> None:
    result = cli("plan", "--robot", UR10E, "--start-joints", "0,-pi/2,-pi/2,0,0,0", "--joints",
                 "elbow_joint=-pi/3,wrist_1_joint=0.2", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr
    end = read_plan(tmp_path / "p.mcap").steps[0].trajectory.positions[-1]
    np.testing.assert_allclose(end, [0, -np.pi / 2, -np.pi / 3, 0.2, 0, 0], atol=1e-12)


def test_any_ompl_planner_by_name(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("plan", "--robot", UR10E, "--start-named", "home", "--named", "ready",
                              "--planner", "PRM", "--planning-time", "0.5", "-o", tmp_path / "p.mcap")
    assert code == 0
    assert document["steps"][0]["planner"] == "PRM"


def test_task_file_chains_steps_with_per_step_scaling(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", tmp_path / "p.mcap")
    assert code == 0
    assert [s["name"] for s in document["steps"]] == ["first", "second", "home"]
    assert set(document["steps"][0]) >= {"name", "status", "goal", "planner", "planning_time_s", "duration_s"}
    plan = read_plan(tmp_path / "p.mcap")
    for before, after in zip(plan.steps[:-1], plan.steps[1:], strict=True):
        np.testing.assert_allclose(after.trajectory.positions[0], before.trajectory.positions[-1], atol=1e-12)
        assert after.start_s == pytest.approx(before.start_s + before.trajectory.duration_s, abs=1e-9)
    np.testing.assert_allclose(plan.steps[-1].trajectory.positions[-1], HOME, atol=1e-12)


def test_start_from_previous_plan_continues_where_it_ended(cli: Cli, tmp_path: Path, table_plan: Path) -> None:
    result = cli("plan", "--robot", UR10E, "--start-from", table_plan, "--named", "home", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr
    start = read_plan(tmp_path / "p.mcap").steps[0].trajectory.positions[0]
    np.testing.assert_allclose(start, GOAL, atol=1e-12)


def test_plan_json_has_the_documented_keys(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("plan", "--robot", UR10E, "--named", "ready", "-o", tmp_path / "p.mcap")
    assert code == 0
    assert document["ok"] is True and document["error"] is None
    assert document["robot"] == "ur10e" and document["group"] == "manipulator"
    assert document["output"].endswith("p.mcap")
    (step,) = document["steps"]
    assert (step["name"], step["goal"], step["status"]) == ("ready", {"named": "ready"}, "ok")


BAD_FLAGS = [
    (["--joints", "0,0,0,0,0,zero"], 2, "expected a number"),
    (["--joints", "nan,0,0,0,0,0"], 2, "expected a number"),
    (["--joints", "inf,0,0,0,0,0"], 2, "expected a number"),
    (["--joints", "0,0,0"], 2, "has 6 joints"),
    (["--named", "home", "--velocity-scaling", "0"], 2, "[0.001, 1]"),
    (["--named", "home", "--acceleration-scaling", "1.5"], 2, "[0.001, 1]"),
    (["--named", "home", "--planner", "Foo"], 2, "RRTConnect"),
    (["--joints", "elbw_joint=1"], 3, "elbow_joint"),
    (["--named", "nope"], 3, "known: home"),
    (["--group", "arm", "--named", "home"], 3, "known: manipulator"),
    (["--named", "home", "--scene", "/nonexistent/scene.yaml"], 3, "scene.yaml: file not found"),
    (["--joints", "elbow_joint=4"], 4, "elbow_joint"),
    (["--scene", TABLE_SCENE, "--start-joints", "0,0.3,0,0,0,0", "--named", "home"], 4, "upper_arm_link touches table"),
    (["--scene", TABLE_SCENE, "--start-named", "home", "--joints", "0,0.3,0,0,0,0"], 4, "goal state is in collision"),
    (["--named", "home", "--joints", "0,0,0,0,0,0"], 2, "give one start flag and one goal flag, got --joints, --named"),
    (["--named", "home", "--frame", "tool0"], 2, "--frame goes with --pose"),
    (["--named", "home", "--linear"], 2, "--linear goes with --pose or --shift"),
    (["--named", "home", "--planning-time", "0"], 2, "--planning-time: expected a positive number of seconds"),
    (["--named", "home", "--planning-time", "soon"], 2, "--planning-time: expected a number"),
    (["--pose", "0.5,0,0.5", "--linear", "--min-fraction", "2"], 2, "--min-fraction: expected a number in [0, 1]"),
    (["--pose", "0.5,0,0.5,1"], 2, "--pose: expected 'x,y,z'"),
    (["--shift", "up=1"], 2, "--shift: expected axis=value pairs"),
]


@pytest.mark.parametrize(("args", "code", "message"), BAD_FLAGS)
def test_bad_input_exits_with_documented_code_and_one_line(
    cli: Cli, tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", UR10E, *args, "-o", out)
    assert result.exit_code == code, result.stderr
    assert message in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_a_failing_task_step_is_named_in_the_one_line_error(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(f"robot: {UR10E}\nstart: {{named: home}}\nsteps:\n  - {{name: up, named: ready}}\n"
                    "  - {name: back, joints: {elbow_joint: 4}}\n")
    code, document = cli.json("plan", task, "-o", tmp_path / "o.mcap")
    assert code == 4 and document["error"]["kind"] == "GoalOutsideLimits"
    assert document["error"]["message"].startswith("step 'back': goal for joint 'elbow_joint'")


def test_json_of_a_plan_failing_at_its_second_step_lists_the_step_planned_before(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(f"robot: {UR10E}\nstart: {{named: home}}\nsteps:\n  - {{name: reach, joints: {GOAL}}}\n"
                    "  - {name: far, pose: {xyz: [5, 0, 0], rpy: [3.14159, 0, 0]}}\n"
                    "  - {name: home, named: home}\n")
    code, document = cli.json("plan", task, "-o", tmp_path / "o.mcap")
    assert code == 4
    assert document["ok"] is False and document["output"] is None
    assert (document["robot"], document["group"]) == ("ur10e", "manipulator")
    assert document["error"]["kind"] == "GoalUnreachable" and document["error"]["message"].startswith("step 'far'")
    reach, far = document["steps"]
    assert (reach["name"], reach["status"], reach["goal"]) == ("reach", "ok", {"joints": GOAL})
    assert reach["duration_s"] > 0 and reach["end_state"]["joints"]["elbow_joint"] == pytest.approx(GOAL[2])
    assert far == {"name": "far", "status": "error"}
    assert list(tmp_path.iterdir()) == [task]


def test_goal_outside_limits_names_joint_value_and_limit(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("plan", "--robot", UR10E, "--joints", "elbow_joint=4", "-o", tmp_path / "o.mcap")
    assert code == 4
    assert document["error"]["kind"] == "GoalOutsideLimits"
    assert "elbow_joint" in document["error"]["message"] and "3.14159" in document["error"]["message"]


def _broken_config(tmp_path: Path, file: str, text: str) -> Path:
    folder = tmp_path / "ur10e"
    shutil.copytree(UR10E, folder)
    (folder / file).write_text(text)
    return folder


@pytest.mark.parametrize(
    ("file", "text", "message"),
    [
        ("moveplan.yaml", "name: ur10e\nurdf: [unclosed\n", "moveplan.yaml: line"),
        ("ur10e.urdf", "<robot name='x'><link name='a'>", "ur10e.urdf: malformed XML"),
        ("joint_limits.yaml", "joint_limits:\n  elbow_joint: {has_velocity_limits: true, max_velocity: -1}\n",
         "joint_limits.elbow_joint.max_velocity: expected a positive number, got -1"),
        ("joint_limits.yaml", "joint_limits:\n  elbow_joint: {max_velocty: 1}\n", "unknown key 'max_velocty'"),
    ],
)
def test_malformed_config_file_exits_3_naming_file_and_problem(
    cli: Cli, tmp_path: Path, file: str, text: str, message: str
) -> None:
    robot = _broken_config(tmp_path, file, text)
    out = tmp_path / "out.mcap"
    result = cli("plan", "--robot", robot, "--named", "home", "-o", out)
    assert result.exit_code == 3, result.stderr
    assert message in result.stderr
    assert not out.exists()


def test_missing_robot_config_exits_3(cli: Cli, tmp_path: Path) -> None:
    result = cli("plan", "--robot", tmp_path / "nowhere", "--named", "home", "-o", tmp_path / "o.mcap")
    assert result.exit_code == 3
    assert "robot config not found" in result.stderr


def test_a_step_ends_reported_at_the_link_its_goal_moved(cli: Cli, tmp_path: Path) -> None:
    # The summary and `inspect` show where the --link went, not the group's tip.
    out = tmp_path / "hand.mcap"
    code, document = cli.json("plan", "--robot", "panda", "--start-named", "ready", "--pose", "0.4,0.1,0.4,pi,0,0",
                              "--link", "panda_hand", "-o", out)
    assert code == 0, document
    pose = document["steps"][0]["end_state"]["pose"]
    assert pose["link"] == "panda_hand" and pose["position"] == pytest.approx([0.4, 0.1, 0.4], abs=1e-4)
    assert "end of each step: panda_hand in panda_link0" in cli("inspect", out).stdout
