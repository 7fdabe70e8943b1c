"""MoveIt's MotionPlanRequest YAML read into a MotionPlanRequest: no robot is needed to read one."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from conftest import ROOT

from moveplan.core.config.goals import JointGoal, PoseGoal
from moveplan.core.config.moveit_request import PositionGoal, load_motion_plan_request, planner_name
from moveplan.core.errors import ConfigError

REQUEST = ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda" / "request0001.yaml"
WRITTEN_REQUEST = ROOT / "tests" / "data" / "moveit_written" / "panda_request.yaml"
START = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
GOAL = [0.4534448383669427, 1.7628, 0.1941262264518609, -0.8667848896139277, -0.3798524112731043,
        2.606927984171601, -0.1898611792470702]


def write(path: Path, content: dict[str, Any]) -> Path:
    path.write_text(yaml.safe_dump(content, sort_keys=False))
    return path


def request_with(**changes: Any) -> dict[str, Any]:
    content = yaml.safe_load(REQUEST.read_text())
    content.update(changes)
    return content


def written_request() -> dict[str, Any]:
    """Return the request MoveGroupInterface sends after setPositionTarget."""
    content: dict[str, Any] = yaml.safe_load(WRITTEN_REQUEST.read_text())
    return content


def test_mbm_request_gives_group_start_goal_planner_and_moveit_scaling() -> None:
    request = load_motion_plan_request(REQUEST)
    assert request.group_name == "panda_arm"
    assert request.start == dict(zip([f"panda_joint{i}" for i in range(1, 8)], START, strict=True)) | {
        "panda_finger_joint1": 0.065, "panda_finger_joint2": 0.065}
    assert request.goal is not None and request.goal.name == "request0001"
    goal = dict(zip([f"panda_joint{i}" for i in range(1, 8)], GOAL, strict=True))
    assert request.goal.goal == JointGoal.by_name(goal)
    assert request.goal.goal.describe() == {"joints": goal}
    assert (request.motion.planner, request.motion.planning_time) == ("BKPIECE1", 60.0)
    # MoveIt reads a scaling factor of 0 as 1.0.
    assert (request.motion.velocity_scaling, request.motion.acceleration_scaling) == (1.0, 1.0)
    assert request.raw == REQUEST.read_bytes()


@pytest.mark.parametrize(("planner_id", "planner"), [
    ("RRTConnectkConfigDefault", "RRTConnect"), ("geometric::RRTstar", "RRTstar"), ("RRTkConfigDefault", "RRT"),
    ("LBKPIECEkConfigDefault", "LBKPIECE1"), ("KPIECE", "KPIECE1"), ("BKPIECE1", "BKPIECE1"),
    ("PRMstarkConfigDefault", "PRMstar"), ("", None),
])
def test_planner_id_maps_to_the_longest_ompl_planner_prefix(planner_id: str, planner: str | None) -> None:
    assert planner_name(planner_id, "r.yaml: planner_id") == planner


@pytest.mark.parametrize("planner_id", ["RRTXstatickConfigDefault", "SBLkConfigDefault", "Chomp"])
def test_planner_id_of_no_available_planner_is_an_error(planner_id: str) -> None:
    with pytest.raises(ConfigError, match=f"r.yaml: planner_id: '{planner_id}'.*RRTConnect"):
        planner_name(planner_id, "r.yaml: planner_id")


@pytest.mark.parametrize(("value", "expected"), [(0.3, 0.3), (1, 1.0), (0, 1.0), (1.5, 1.0), (-0.2, 1.0)])
def test_scaling_outside_zero_one_means_full_limits_as_in_moveit(tmp_path: Path, value: float, expected: float) -> None:
    path = write(tmp_path / "r.yaml", request_with(max_velocity_scaling_factor=value))
    assert load_motion_plan_request(path).motion.velocity_scaling == expected


def test_request_without_scaling_leaves_it_to_the_defaults(tmp_path: Path) -> None:
    content = request_with(allowed_planning_time=0, planner_id="")
    del content["max_velocity_scaling_factor"]
    request = load_motion_plan_request(write(tmp_path / "r.yaml", content))
    assert (request.motion.velocity_scaling, request.motion.acceleration_scaling) == (None, 1.0)
    assert (request.motion.planner, request.motion.planning_time) == (None, None)


def test_first_goal_alternative_is_used_with_a_warning(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    first = {"joint_constraints": [{"joint_name": "panda_joint1", "position": 0.5}]}
    second = {"joint_constraints": [{"joint_name": "panda_joint1", "position": -0.5}]}
    with caplog.at_level(logging.WARNING):
        request = load_motion_plan_request(write(tmp_path / "r.yaml", request_with(goal_constraints=[first, second])))
    assert request.goal is not None and request.goal.goal == JointGoal.by_name({"panda_joint1": 0.5})
    assert "2 alternatives" in caplog.text


def test_position_and_orientation_constraints_become_a_pose_goal_of_their_link(tmp_path: Path) -> None:
    half = float(np.sqrt(0.5))
    goal = {
        "position_constraints": [{
            "header": {"frame_id": "panda_link0"}, "link_name": "panda_hand",
            "target_point_offset": {"x": 0, "y": 0, "z": 0.1},
            "constraint_region": {"primitives": [{"type": "sphere", "dimensions": [0.001]}],
                                  "primitive_poses": [{"position": {"x": 0.5, "y": 0.0, "z": 0.4}}]}}],
        "orientation_constraints": [{
            "header": {"frame_id": "panda_link0"}, "link_name": "panda_hand",
            "orientation": {"x": half, "y": 0.0, "z": 0.0, "w": half}, "absolute_x_axis_tolerance": 0.01}],
    }
    request = load_motion_plan_request(write(tmp_path / "r.yaml", request_with(goal_constraints=[goal])))
    assert request.goal is not None
    pose = request.goal.goal
    assert isinstance(pose, PoseGoal)
    assert (pose.frame, pose.link, pose.rpy) == ("panda_link0", "panda_hand", None)
    np.testing.assert_allclose(pose.quat, [half, 0, 0, half])
    # The hand's z axis points along -y: its origin sits 0.1 m back from the target point.
    np.testing.assert_allclose(pose.xyz, [0.5, 0.1, 0.4], atol=1e-12)


def test_position_goal_with_a_target_point_offset_is_refused(tmp_path: Path) -> None:
    content = written_request()
    content["goal_constraints"][0]["position_constraints"][0]["target_point_offset"] = {"z": 0.1}
    with pytest.raises(ConfigError, match=r"position_constraints\[0\].target_point_offset: not supported in a goal "
                                          "without an orientation constraint"):
        load_motion_plan_request(write(tmp_path / "request.yaml", content))


def test_orientation_constraint_alone_is_refused(tmp_path: Path) -> None:
    content = written_request()
    goal = content["goal_constraints"][0]
    goal["orientation_constraints"] = [{"link_name": "panda_hand", "orientation": {"w": 1.0}}]
    goal["position_constraints"] = []
    with pytest.raises(ConfigError, match=r"goal_constraints\[0\]: a goal needs joint constraints, or one position "
                                          r"constraint and at most one orientation constraint \(got 0 and 1\)"):
        load_motion_plan_request(write(tmp_path / "request.yaml", content))


def test_position_constraint_alone_reads_as_a_position_goal_of_its_link_in_its_frame() -> None:
    request = load_motion_plan_request(WRITTEN_REQUEST)
    assert request.goal is not None
    goal = request.goal.goal
    assert isinstance(goal, PositionGoal)
    assert (goal.link, goal.frame, goal.xyz, goal.rpy, goal.quat) == ("panda_hand", "world", (0.45, 0.25, 0.55),
                                                                      None, None)
    assert goal.describe()["pose"]["orientation"] == "free"
