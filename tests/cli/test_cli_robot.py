"""`moveplan robot`: what a user learns about a config, and where each limit came from."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import UR10E, Cli


def test_robot_json_lists_groups_joints_sources_named_states_frames_and_tolerances(cli: Cli) -> None:
    code, document = cli.json("robot", UR10E)
    assert code == 0
    assert document["name"] == "ur10e"
    assert document["groups"]["manipulator"] == {
        "joints": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
                   "wrist_3_joint"],
        "base": "base_link", "tip": "tool0",
    }
    elbow = document["joints"]["elbow_joint"]
    assert elbow["upper"] == pytest.approx(3.14159, abs=1e-5)
    assert elbow["source"] == {"position": "ur10e.urdf", "velocity": "joint_limits.yaml",
                               "acceleration": "joint_limits.yaml"}
    assert document["named_states"]["manipulator"]["home"] == pytest.approx([0, -1.5708, -1.5708, 0, 0, 0], abs=1e-4)
    assert {"base", "base_link", "tool0", "flange"} <= set(document["frames"])
    constraints = document["controllers"]["joint_trajectory_controller"]["constraints"]
    assert constraints["stopped_velocity_tolerance"] == 0.2
    assert constraints["elbow_joint"] == {"trajectory": 0.2, "goal": 0.1}


def test_robot_table_shows_every_joint(cli: Cli) -> None:
    result = cli("robot", UR10E)
    assert result.exit_code == 0
    assert "wrist_3_joint" in result.stdout and "home" in result.stdout


def test_robot_on_missing_folder_exits_3_with_one_line(cli: Cli, tmp_path: Path) -> None:
    result = cli("robot", tmp_path)
    assert result.exit_code == 3
    assert result.stderr.count("\n") == 1 and "moveplan.yaml" in result.stderr


def test_a_bare_name_finds_the_shipped_config(cli: Cli) -> None:
    code, document = cli.json("robot", "ur10e")
    assert code == 0 and document["name"] == "ur10e"


def test_unknown_bare_name_lists_the_shipped_configs(cli: Cli) -> None:
    result = cli("robot", "nope")
    assert result.exit_code == 3 and "ur10e" in result.stderr
