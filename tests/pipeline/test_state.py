"""`moveplan state`, and each step's end state in `plan --json` and `inspect --json`."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, SAMPLES, UR10E, Cli
from rosbags.highlevel import AnyReader

WORKSHOP_SCENE = SAMPLES / "ur10e_workshop_scene.yaml"
ARM = ROOT / "tests" / "data" / "limits_start" / "arm.urdf"  # j3 prismatic, j4 continuous


def one_line(result: Any) -> str:
    """Return the error's one line on stderr (asserting it is one line)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    return lines[0]


def tool0_in_base_link(values: list[float]) -> np.ndarray:
    """Return base_link_T_tool0 by pinocchio from the shipped URDF, independently of moveplan's model."""
    model = pin.buildModelFromUrdf(str(UR10E / "ur10e.urdf"))
    data = model.createData()
    q = pin.neutral(model)
    for name, value in zip(JOINTS, values, strict=True):
        q[model.idx_qs[model.getJointId(name)]] = value
    pin.framesForwardKinematics(model, data, q)
    base = data.oMf[model.getFrameId("base_link")]
    return np.array((base.inverse() * data.oMf[model.getFrameId("tool0")]).homogeneous)


JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]


def pose_matrix(pose: dict[str, Any]) -> np.ndarray:
    """Return the 4x4 transform a JSON pose's position and quaternion give."""
    x, y, z, w = pose["quaternion"]
    transform = np.eye(4)
    transform[:3, :3] = pin.Quaternion(w, x, y, z).toRotationMatrix()
    transform[:3, 3] = pose["position"]
    return transform


@pytest.fixture(scope="module")
def pick_plan(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """The pick-and-place sample planned (it embeds the workshop scene), with its plan JSON."""
    out = tmp_path_factory.mktemp("state") / "pick.mcap"
    code, document = Cli().json("plan", SAMPLES / "ur10e_pick_and_place.yaml", "-o", out)
    assert code == 0
    return out, document


def last_points(path: Path) -> list[list[float]]:
    """Return each step's last trajectory point, read back with rosbags."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if c.topic == "/planned_trajectory"]
        return [list(reader.deserialize(raw, c.msgtype).points[-1].positions)
                for c, _, raw in reader.messages(connections=connections)]


# The workshop's first step: get_current_joint_values(), then lookup_transform('base_link', 'tool0').


def test_workshop_first_step_gives_start_joints_and_tool0_in_base_link(cli: Cli) -> None:
    code, document = cli.json("state", "--robot", "ur10e", "--link", "tool0", "--frame", "base_link")
    assert code == 0
    initial = [0.0, -1.57, 0.0, -1.57, 0.0, 0.0]  # configs/ur10e/initial_positions.yaml
    assert list(document["joints"]) == JOINTS
    np.testing.assert_allclose(list(document["joints"].values()), initial, atol=1e-12)
    pose = document["pose"]
    assert (pose["link"], pose["frame"]) == ("tool0", "base_link")
    np.testing.assert_allclose(pose_matrix(pose), tool0_in_base_link(initial), atol=1e-9)
    roll, pitch, yaw = pose["rpy"]
    np.testing.assert_allclose(pin.rpy.rpyToMatrix(roll, pitch, yaw), pose_matrix(pose)[:3, :3], atol=1e-9)
    assert pose["quaternion"][3] >= 0.0


def test_text_output_is_a_joint_table_in_rad_and_deg_then_the_pose(cli: Cli) -> None:
    result = cli("state", "--robot", "ur10e", "--link", "tool0", "--frame", "base_link")
    assert result.exit_code == 0
    text = result.stdout
    assert "value [rad]" in text and "value [deg]" in text
    assert "-1.570000" in text and "-89.9544" in text  # shoulder_lift_joint
    assert "tool0 in base_link" in text
    assert "position [m]" in text and "rpy [rad]" in text and "quaternion [x, y, z, w]" in text


def test_default_link_and_frame_are_the_tip_and_the_planning_frame(cli: Cli) -> None:
    code, document = cli.json("state", "--robot", "ur10e")
    assert code == 0
    assert (document["pose"]["link"], document["pose"]["frame"]) == ("tool0", "base_link")
    assert document["robot"] == "ur10e" and document["group"] == "manipulator"


def test_joints_in_degrees_and_named_states_set_the_state(cli: Cli) -> None:
    code, document = cli.json("state", "--robot", UR10E, "--joints", "elbow_joint=-90deg,wrist_1_joint=pi/2")
    assert code == 0
    assert document["joints"]["elbow_joint"] == pytest.approx(-math.pi / 2)
    assert document["joints"]["wrist_1_joint"] == pytest.approx(math.pi / 2)
    assert document["joints"]["shoulder_lift_joint"] == pytest.approx(-1.57)  # the others: the start state
    code, document = cli.json("state", "--robot", UR10E, "--named", "home")
    assert code == 0
    np.testing.assert_allclose(list(document["joints"].values()), [0, -math.pi / 2, -math.pi / 2, 0, 0, 0],
                               atol=1e-6)


def test_pose_in_a_scene_frame(cli: Cli) -> None:
    # target_1 sits at (0.6, 0.2, 0.4) in base_link, turned by pi about x.
    code, document = cli.json("state", "--robot", UR10E, "--scene", WORKSHOP_SCENE, "--link", "target_1",
                              "--frame", "base_link")
    assert code == 0
    np.testing.assert_allclose(document["pose"]["position"], [0.6, 0.2, 0.4], atol=1e-12)
    np.testing.assert_allclose(np.abs(document["pose"]["quaternion"]), [1, 0, 0, 0], atol=1e-6)


# --from a plan file: no --robot (the plan carries its config), and its embedded scene's frames.


def test_from_plan_is_its_last_point_read_back_with_rosbags(cli: Cli, pick_plan: tuple[Path, dict[str, Any]]) -> None:
    path, _ = pick_plan
    code, document = cli.json("state", "--from", path)
    assert code == 0
    np.testing.assert_allclose(list(document["joints"].values()), last_points(path)[-1], atol=1e-12)
    assert document["source"].endswith("end of the plan")


def test_step_end_agrees_with_plan_json_and_inspect_json(cli: Cli, pick_plan: tuple[Path, dict[str, Any]]) -> None:
    path, plan_document = pick_plan
    code, inspected = cli.json("inspect", path)
    assert code == 0
    points = last_points(path)
    for k, (planned, step) in enumerate(zip(plan_document["steps"], inspected["plan"]["steps"], strict=True)):
        code, state = cli.json("state", "--from", path, "--step", planned["name"])
        assert code == 0
        for end in (planned["end_state"], step["end_state"]):
            np.testing.assert_allclose(list(end["joints"].values()), points[k], atol=1e-12)
            assert (end["pose"]["link"], end["pose"]["frame"]) == ("tool0", "base_link")
            np.testing.assert_allclose(pose_matrix(end["pose"]), pose_matrix(state["pose"]), atol=1e-9)
        np.testing.assert_allclose(pose_matrix(state["pose"]), tool0_in_base_link(points[k]), atol=1e-9)


def test_approach_ends_15_cm_above_the_object_pointing_down(cli: Cli, pick_plan: tuple[Path, dict[str, Any]]) -> None:
    path, _ = pick_plan
    code, document = cli.json("state", "--from", path, "--step", "approach", "--frame", "object")
    assert code == 0
    np.testing.assert_allclose(document["pose"]["position"], [0, 0, 0.15], atol=1e-5)
    np.testing.assert_allclose(pose_matrix(document["pose"])[:3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-5)


def test_at_counts_from_the_plan_start_or_from_the_step_start(
    cli: Cli, pick_plan: tuple[Path, dict[str, Any]]
) -> None:
    path, plan_document = pick_plan
    approach = plan_document["steps"][0]["duration_s"]
    code, whole = cli.json("state", "--from", path, "--at", str(approach + 0.2))
    assert code == 0
    code, within = cli.json("state", "--from", path, "--step", "reach", "--at", "0.2")
    assert code == 0
    # The plan JSON rounds durations to the microsecond.
    np.testing.assert_allclose(list(whole["joints"].values()), list(within["joints"].values()), atol=1e-5)
    assert "(step 'reach')" in whole["source"] and "into step 'reach'" in within["source"]
    code, start = cli.json("state", "--from", path, "--at", "0")
    assert code == 0
    np.testing.assert_allclose(list(start["joints"].values()), [0, -math.pi / 2, -math.pi / 2, 0, 0, 0], atol=1e-9)


def test_plan_and_inspect_text_give_one_end_pose_per_step(cli: Cli, pick_plan: tuple[Path, dict[str, Any]]) -> None:
    path, _ = pick_plan
    result = cli("inspect", path)
    assert result.exit_code == 0
    assert "end of each step: tool0 in base_link" in result.stdout
    assert "[0.6000, -0.4000, 0.2500]" in result.stdout  # approach: 15 cm above the object at z = 0.1


# Bad input: one line, the documented exit code.


@pytest.mark.parametrize(("args", "code", "message"), [
    (["--robot", "ur10e", "--frame", "tol0"], 3,
     "frame 'tol0' not found in robot 'ur10e' (--frame); known: base, base_link, flange"),
    (["--robot", "ur10e", "--scene", WORKSHOP_SCENE, "--link", "targt_1"], 3, "known: base, base_link"),
    (["--robot", "ur10e", "--at", "1"], 2, "--at goes with --from PLAN.mcap"),
    (["--robot", "ur10e", "--step", "reach"], 2, "--step goes with --from PLAN.mcap"),
    ([], 2, "no robot: give --robot, or --from a plan file"),
    (["--robot", "ur10e", "--joints", "0,0,0", "--named", "home"], 2, "give one of --joints, --named and --from"),
    (["--robot", "ur10e", "--joints", "elbow_joint=3.5"], 2,
     "--joints: joint 'elbow_joint' at 3.5 is outside its limits [-3.14159, 3.14159]"),
    (["--robot", "ur10e", "--joints", "elbow_joint=90"], 2, "90 rad is more than a full turn (2*pi)"),
    (["--robot", "ur10e", "--joints", "0,1,2"], 2, "joint goal has 3 values; group 'manipulator' has 6 joints"),
    (["--robot", "ur10e", "--named", "nope"], 3, "named state 'nope' not found"),
    (["--robot", "ur10e", "--group", "arm"], 3, "group 'arm' not found"),
    (["--robot", ARM, "--joints", "j3=2deg"], 2, "--joints j3: 'j3' is a prismatic joint, in [m]"),
    (["--robot", ARM, "--joints", "j4=7"], 2, "--joints j4: 7 rad is more than a full turn (2*pi): angles are"),
])
def test_bad_state_request_is_one_line_and_its_exit_code(cli: Cli, args: list[Any], code: int, message: str) -> None:
    result = cli("state", *args)
    assert result.exit_code == code, result.stderr
    assert message in one_line(result)


def test_bad_plan_requests_are_one_line(cli: Cli, pick_plan: tuple[Path, dict[str, Any]], tmp_path: Path) -> None:
    path, plan_document = pick_plan
    end = sum(step["duration_s"] for step in plan_document["steps"])
    cases = [
        (["--at", str(end + 1)], 2, "--at: "),
        (["--step", "reach", "--at", "5"], 2, "is after the end of step 'reach'"),
        (["--step", "grab"], 3, "step 'grab' not found in"),
        (["--joints", "0,0,0,0,0,0"], 2, "give one of --joints, --named and --from"),
        (["--robot", "panda"], 3, "a plan of robot 'ur10e', not of robot 'panda'"),
        (["--frame", "nowhere"], 3, "known: base, base_link, flange, forearm_link, object, shoulder_link, target_1"),
        (["--urdf", "other.urdf"], 2, "--urdf completes --robot: give --robot too"),
    ]
    for args, code, message in cases:
        result = cli("state", "--from", path, *args)
        assert result.exit_code == code, (args, result.stderr)
        assert message in one_line(result), args
    missing = cli("state", "--from", tmp_path / "missing.mcap")
    assert missing.exit_code == 3 and "missing.mcap" in one_line(missing)


def test_error_as_json_is_one_document(cli: Cli) -> None:
    code, document = cli.json("state", "--robot", "ur10e", "--frame", "tol0")
    assert code == 3
    assert document["ok"] is False and document["error"]["kind"] == "FrameNotFound"


def test_prismatic_joint_is_shown_in_metres(cli: Cli) -> None:
    result = cli("state", "--robot", ARM, "--joints", "j3=0.05,j4=90deg")
    assert result.exit_code == 0, result.stderr
    assert "0.050000 m" in result.stdout and "90.0000" in result.stdout


def test_end_states_of_a_file_without_or_with_a_damaged_record_are_computed_from_its_config(
    pick_plan: tuple[Path, dict[str, Any]], caplog: pytest.LogCaptureFixture
) -> None:
    """Files from before end states were recorded (samples/recordings) and damaged records give the same states."""
    from dataclasses import replace

    from moveplan.core.bag.plan_file import END_STATES_KEY
    from moveplan.core.pipeline._plan_files import read_valid_plan
    from moveplan.core.pipeline.inspection import end_states

    path, document = pick_plan
    plan = read_valid_plan(path)
    recorded = end_states(plan, path)
    assert [s.as_dict() for s in recorded] == [step["end_state"] for step in document["steps"]]
    for metadata in ({k: v for k, v in plan.metadata.items() if k != END_STATES_KEY},
                     {**plan.metadata, END_STATES_KEY: '[{"joints": {}}]'}):
        computed = end_states(replace(plan, metadata=metadata), path)
        for mine, theirs in zip(computed, recorded, strict=True):
            assert mine.joints == pytest.approx(theirs.joints)
            assert mine.pose.position == pytest.approx(theirs.pose.position, abs=1e-9)
    assert "recorded end states are unreadable" in caplog.text
    old = SAMPLES / "recordings" / "tool_up_plan.mcap"
    assert END_STATES_KEY not in read_valid_plan(old).metadata
    assert len(end_states(read_valid_plan(old), old)) == len(read_valid_plan(old).steps)
