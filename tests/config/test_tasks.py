"""Task files parse once into typed goals and starts; the goals describe themselves as the plan JSON shows them."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import UR10E, Cli

from moveplan.core.config.goals import JointGoal, NamedGoal, PoseGoal, ShiftGoal, StartFrom
from moveplan.core.config.tasks import load_task
from moveplan.core.errors import ConfigError

TASK = """\
robot: ../configs/ur10e
scene: scene.yaml
start: {named: home}
defaults: {velocity_scaling: 0.5}
steps:
  - {name: all, joints: [0, -1.2, -1.8, 0, 1.57, 0]}
  - {name: some, joints: {elbow_joint: 1.2, shoulder_lift_joint: -1}}
  - {name: home, named: home}
  - {name: approach, pose: {frame: object, xyz: [0, 0, 0.15], rpy: [3.14159, 0, 0]}}
  - {name: turned, pose: {link: tool0, quat: [0, 0, 0, 1]}}
  - {name: up, shift: {yaw: 0.3, z: 0.1}, linear: true}
  - {name: along_base, shift: {x: 0.1, frame: base}}
"""


def write_task(folder: Path, text: str) -> Path:
    path = folder / "task.yaml"
    path.write_text(text)
    return path


def test_each_step_kind_parses_into_its_goal_type(tmp_path: Path) -> None:
    task = load_task(write_task(tmp_path, TASK))
    goals = {step.name: step.goal for step in task.steps}
    assert goals["all"] == JointGoal((0.0, -1.2, -1.8, 0.0, 1.57, 0.0))
    assert goals["some"] == JointGoal.by_name({"elbow_joint": 1.2, "shoulder_lift_joint": -1.0})
    assert goals["home"] == NamedGoal("home")
    assert goals["approach"] == PoseGoal(xyz=(0.0, 0.0, 0.15), rpy=(3.14159, 0.0, 0.0), frame="object")
    assert goals["turned"] == PoseGoal(quat=(0.0, 0.0, 0.0, 1.0), link="tool0")
    assert goals["up"] == ShiftGoal(z=0.1, yaw=0.3)
    assert goals["along_base"] == ShiftGoal(x=0.1, frame="base")
    assert [step.linear for step in task.steps] == [False] * 5 + [True, False]
    assert task.start == NamedGoal("home")
    assert task.robot == tmp_path / "../configs/ur10e"


def test_goals_describe_themselves_as_the_plan_json_reports_them(tmp_path: Path) -> None:
    goals = {step.name: step.goal.describe() for step in load_task(write_task(tmp_path, TASK)).steps}
    assert goals["all"] == {"joints": [0.0, -1.2, -1.8, 0.0, 1.57, 0.0]}
    assert goals["some"] == {"joints": {"elbow_joint": 1.2, "shoulder_lift_joint": -1.0}}
    assert goals["home"] == {"named": "home"}
    assert goals["approach"] == {"pose": {"frame": "object", "link": None, "xyz": [0.0, 0.0, 0.15],
                                          "rpy": [3.14159, 0.0, 0.0], "quat": None}}
    assert goals["up"] == {"shift": {"z": 0.1, "yaw": 0.3, "frame": "tool"}}
    assert goals["along_base"] == {"shift": {"x": 0.1, "frame": "base"}}


def test_start_from_a_plan_file_resolves_against_the_task_folder(tmp_path: Path) -> None:
    task = load_task(write_task(tmp_path, "robot: r\nstart: {from: previous.mcap}\nsteps: [{named: home}]\n"))
    assert task.start == StartFrom(tmp_path / "previous.mcap")


def test_task_without_start_starts_at_the_initial_positions(tmp_path: Path) -> None:
    assert load_task(write_task(tmp_path, "robot: r\nsteps: [{named: home}]\n")).start is None


@pytest.mark.parametrize(("step", "message"), [
    ("{joints: [0, 1], linear: true}", r"steps\[0\]: linear applies to pose and shift goals, not joints"),
    ("{named: home, linear: true}", "not named"),
    ("{named: home, joints: [0]}", "give exactly one goal of: joints, named, pose, shift"),
    ("{pose: {rpy: [0, 0, 0], quat: [0, 0, 0, 1]}}", r"steps\[0\].pose: give rpy or quat, not both"),
    ("{pose: {quat: [0, 0, 0, 0]}}", "zero norm"),
    ("{shift: {frame: base}}", "give at least one of x, y, z, roll, pitch, yaw"),
    ("{shift: {up: 1}}", "unknown key 'up'"),
    ("{joints: 3}", "expected a list of values or a mapping"),
    ("{named: home, tolerances: {goal_tolerance: {elbow_joint: 0.1}}}",
     r"steps\[0\].tolerances.goal_tolerance: expected a list of \{name, position, velocity, acceleration\}"),
    ("{named: home, tolerances: {goal_tolerance: [{name: elbow_joint, position: .nan}]}}",
     r"steps\[0\].tolerances.goal_tolerance\[0\].position"),
    ("{named: home, tolerances: {goal_time: 1}}", r"steps\[0\].tolerances: unknown key 'goal_time'"),
])
def test_malformed_goal_is_a_config_error_naming_the_step(tmp_path: Path, step: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        load_task(write_task(tmp_path, f"robot: r\nsteps:\n  - {step}\n"))


def test_a_steps_goal_tolerances_are_read_as_a_follow_joint_trajectory_goal_gives_them(tmp_path: Path) -> None:
    task = load_task(write_task(tmp_path, "robot: r\nsteps:\n  - named: home\n    tolerances:\n"
                                          "      path_tolerance: [{name: elbow_joint, position: 0.05, velocity: -1}]\n"
                                          "      goal_time_tolerance: 0.5\n"))
    tolerances = task.steps[0].tolerances
    assert tolerances is not None and tolerances.goal_time_s == 0.5 and tolerances.goal == ()
    assert (tolerances.path[0].name, tolerances.path[0].position, tolerances.path[0].velocity) == \
        ("elbow_joint", 0.05, -1.0)


def test_task_robot_by_bare_name_plans_with_the_shipped_config(tmp_path: Path) -> None:
    task = write_task(tmp_path, "robot: ur10e\nsteps: [{name: bend, joints: {elbow_joint: -1.0}}]\n")
    result = Cli()("plan", task, "-o", tmp_path / "out.mcap", "--quiet")
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "out.mcap").is_file()


def test_task_robot_beside_the_task_file_comes_before_a_shipped_config(tmp_path: Path) -> None:
    (tmp_path / "ur10e").mkdir()
    assert load_task(write_task(tmp_path, "robot: ur10e\nsteps: [{named: home}]\n")).robot == tmp_path / "ur10e"
    shipped = load_task(write_task(tmp_path, "robot: panda\nsteps: [{named: home}]\n")).robot
    # The installed copy of configs/panda (the clone's own folder only in an editable install).
    assert shipped is not None and shipped.name == "panda" and shipped.parent.name == "configs"
    assert (shipped / "moveplan.yaml").read_bytes() == (UR10E.parent / "panda" / "moveplan.yaml").read_bytes()


def test_task_robot_by_unknown_bare_name_is_one_line_naming_it_and_the_shipped_configs(tmp_path: Path) -> None:
    task = write_task(tmp_path, "robot: ur10\nsteps: [{named: home}]\n")
    result = Cli()("plan", task, "-o", tmp_path / "out.mcap")
    assert result.exit_code == 3
    assert result.stderr.count("\n") == 1
    assert "ur10: robot config not found" in result.stderr
    assert "shipped config: excavator, panda, ur10e" in result.stderr
    assert not (tmp_path / "out.mcap").exists()
