"""`moveplan execute --fake`: a plan replayed through the simulated controller, verdicts and exit codes."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT, SAMPLES, UR10E, Cli

from moveplan.core.control.results import Violation
from moveplan.core.pipeline import execution as pipeline
from moveplan.core.pipeline.execution import ExecuteRequest, PlanExecution

SHIPPED_PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"  # shipped: these tests need no planner


@pytest.fixture(scope="module")
def plan_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("execute") / "plan.mcap"
    result = Cli()("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", out)
    assert result.exit_code == 0, result.stderr
    return out


def test_mirror_execution_succeeds_with_margins_and_exit_0(cli: Cli, plan_file: Path) -> None:
    code, document = cli.json("execute", plan_file, "--fake")
    assert code == 0
    assert document["ok"] is True
    assert document["result"] == {"code": 0, "name": "SUCCESSFUL", "message": document["result"]["message"]}
    assert document["violations"] == []
    assert set(document["margins"]) == {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                                        "wrist_2_joint", "wrist_3_joint"}
    assert all(margin > 0 for margin in document["margins"].values())
    assert [s["name"] for s in document["steps"]] == ["first", "second", "home"]
    assert document["duration_s"] > 10


def test_without_fake_says_only_fake_execution_exists_and_exits_2(cli: Cli, plan_file: Path) -> None:
    result = cli("execute", plan_file)
    assert result.exit_code == 2
    assert "only fake execution exists" in result.stderr


def test_disturbance_beyond_path_tolerance_is_reported_with_joint_time_and_numbers(cli: Cli, plan_file: Path) -> None:
    code, document = cli.json("execute", plan_file, "--fake", "--disturb", "t=1.0,joint=elbow_joint,delta=0.3")
    assert code == 5
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED" and document["result"]["code"] == -4
    violation = document["violations"][0]
    assert violation["check"] == "path" and violation["joint"] == "elbow_joint" and violation["step"] == "first"
    assert violation["time_s"] == pytest.approx(1.0, abs=0.01)
    assert violation["tolerance"] == 0.2 and abs(violation["error"]) == pytest.approx(0.3, abs=1e-6)
    assert document["margins"]["elbow_joint"] < 0


def test_robot_away_from_the_plan_start_fails_moveits_start_check(cli: Cli, plan_file: Path) -> None:
    code, document = cli.json("execute", plan_file, "--fake", "--start-joints", "elbow_joint=-1.6")
    assert code == 5
    assert document["result"]["name"] == "START_STATE_INVALID"
    assert document["violations"][0]["check"] == "start_tolerance"
    assert document["violations"][0]["joint"] == "elbow_joint"


def test_slow_lag_plant_violates_the_path_tolerance(cli: Cli, plan_file: Path) -> None:
    code, document = cli.json("execute", plan_file, "--fake", "--plant", "lag", "--plant-param", "tau=1.5")
    assert code == 5
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"


def test_tight_tolerances_from_controllers_override_fail_a_lagging_robot(cli: Cli, plan_file: Path,
                                                                         tmp_path: Path) -> None:
    tight = tmp_path / "ros2_controllers.yaml"
    text = (UR10E / "ros2_controllers.yaml").read_text().replace("trajectory: 0.2", "trajectory: 0.001")
    tight.write_text(text)
    assert cli("execute", plan_file, "--fake", "--plant", "lag", "--plant-param", "tau=0.05").exit_code == 0
    code, document = cli.json("execute", plan_file, "--fake", "--plant", "lag", "--plant-param", "tau=0.05",
                              "--controllers", tight)
    assert code == 5
    assert document["violations"][0]["tolerance"] == 0.001


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--plant", "spring"], "mirror"),
        (["--plant", "lag", "--plant-param", "tua=0.1"], "tau"),
        (["--plant", "pid"], "[velocity] or [effort]"),
        (["--disturb", "t=1,joint=elbow_joint"], "t=SECONDS"),
        (["--plant-param", "tau"], "key=value"),
    ],
)
def test_bad_execute_flags_exit_2(cli: Cli, plan_file: Path, args: list[str], message: str) -> None:
    result = cli("execute", plan_file, "--fake", *args)
    assert result.exit_code == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr


def test_disturbing_an_unknown_joint_is_a_usage_error_listing_joints(cli: Cli, plan_file: Path) -> None:
    result = cli("execute", plan_file, "--fake", "--disturb", "t=1,joint=elbw,delta=0.1")
    assert result.exit_code == 2, result.stderr
    assert "elbow_joint" in result.stderr


def test_execute_on_a_file_that_is_not_a_plan_exits_3(cli: Cli, tmp_path: Path) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n" + b"\x00" * 20)
    result = cli("execute", bad, "--fake")
    assert result.exit_code == 3
    assert "bad.mcap" in result.stderr


def test_pid_plant_passes_with_tuned_gains_and_fails_with_mistuned_ones(cli: Cli, plan_file: Path) -> None:
    tuned, tuned_doc = cli.json("execute", plan_file, "--fake", "--plant", "pid",
                                "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml")
    assert tuned == 0, tuned_doc["result"]
    mistuned, mistuned_doc = cli.json("execute", plan_file, "--fake", "--plant", "pid",
                                      "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml")
    assert mistuned == 5
    assert mistuned_doc["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    assert mistuned_doc["violations"][0]["check"] == "path"


# --- numbers that are not finite ---------------------------------------------------------------


def strict_json(text: str) -> Any:
    """Parse `text` as JSON proper: NaN, Infinity and -Infinity are not JSON."""
    def reject(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=reject)


@pytest.fixture()
def exploding_controllers(tmp_path: Path) -> Path:
    """An effort-driven PID so stiff that, on a near-weightless joint, the first correction overflows."""
    text = (SAMPLES / "ur10e_velocity_controllers.yaml").read_text()
    text = text.replace("      - velocity\n    state_interfaces", "      - effort\n    state_interfaces")
    text = text.replace("p: 20.0, i: 0.0, d: 0.5, i_clamp: 0.0, ff_velocity_scale: 1.0",
                        "p: 1.0e+300, i: 0.0, d: 0.0, i_clamp: 0.0, ff_velocity_scale: 0.0")
    path = tmp_path / "exploding_controllers.yaml"
    path.write_text(text)
    return path


def test_diverging_plant_prints_strict_json_with_null_for_infinite_errors(
        cli: Cli, exploding_controllers: Path) -> None:
    args = ("execute", SHIPPED_PLAN, "--fake", "--plant", "pid", "--plant-param", "inertia=1e-300",
            "--controllers", exploding_controllers)
    result = cli(*args, "--json")
    assert result.exit_code == 5, result.stderr
    document = strict_json(result.stdout)
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED" and "inf" in document["result"]["message"]
    assert document["violations"] and all(v["actual"] is None and v["error"] is None for v in document["violations"])
    assert all(v["tolerance"] == 0.2 for v in document["violations"])
    text = cli(*args)
    assert text.exit_code == 5 and "Traceback" not in text.stderr
    assert "inf/nan" in text.stdout


def test_execution_with_nan_prints_strict_json_with_null(cli: Cli, monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipeline.execute

    def diverged(request: ExecuteRequest) -> PlanExecution:
        outcome = real(request)
        step = outcome.steps[0]
        nan = float("nan")
        report = replace(step.report, ok=False, margins={"elbow_joint": nan, "wrist_1_joint": float("-inf")},
                         violations=(Violation("path", "elbow_joint", 0.1, 1.0, nan, nan, 0.2),))
        return replace(outcome, ok=False, steps=(replace(step, report=report),))

    monkeypatch.setattr(pipeline, "execute", diverged)
    result = cli("execute", SHIPPED_PLAN, "--fake", "--json")
    assert result.exit_code == 5, result.stderr
    document = strict_json(result.stdout)
    assert document["margins"] == {"elbow_joint": None, "wrist_1_joint": None}
    assert document["violations"][0]["actual"] is None and document["violations"][0]["error"] is None
    assert document["violations"][0]["reference"] == 1.0
    text = cli("execute", SHIPPED_PLAN, "--fake")
    assert text.exit_code == 5 and "Traceback" not in text.stderr
    assert "inf/nan" in text.stdout


def test_ros2_controllers_names_the_release_simulated(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("execute", SHIPPED_PLAN, "--fake", "--ros2-controllers", "4.35.0")
    assert code == 0 and document["ok"] is True  # a MoveIt plan starts at 0 s: no blend, same verdict
    result = cli("execute", SHIPPED_PLAN, "--fake", "--ros2-controllers", "newest", "-o", tmp_path / "run.mcap")
    assert result.exit_code == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "--ros2-controllers 'newest': expected a distro (humble, jazzy, kilted, rolling)" in result.stderr
    assert not (tmp_path / "run.mcap").exists()


def test_a_controller_that_checks_nothing_says_so_and_each_step_has_its_verdict(cli: Cli, tmp_path: Path) -> None:
    """A tolerance of 0 is JTC's "not checked": a run through a 1 s lag passes, and the report says why."""
    import yaml

    controllers = yaml.safe_load((SAMPLES / "ur10e_mistuned_controllers.yaml").read_text())
    for value in controllers.values():
        constraints = value.get("ros__parameters", {}).get("constraints") if isinstance(value, dict) else None
        if isinstance(constraints, dict):
            for joint, entry in constraints.items():
                if isinstance(entry, dict):
                    constraints[joint] = {"trajectory": 0.0, "goal": 0.0}
    path = tmp_path / "unchecked.yaml"
    path.write_text(yaml.safe_dump(controllers))
    args = ("execute", SHIPPED_PLAN, "--fake", "--controllers", path)
    code, document = cli.json(*args)
    assert code == 0
    joints = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
              "wrist_3_joint"}
    assert set(document["unchecked"]["path"]) == set(document["unchecked"]["goal"]) == joints
    assert document["margins"] == {}
    text = cli(*args).stdout
    assert "not checked (nothing is checked): path of every joint; goal of every joint: its tolerance is 0" in text
    assert "up: result SUCCESSFUL" in text


def test_tolerances_a_task_step_sends_with_its_goal_are_honoured_by_execute_and_check(
        cli: Cli, tmp_path: Path) -> None:
    """A step's `tolerances` (control_msgs/FollowJointTrajectory's fields) replace the controller's for that goal."""
    task = tmp_path / "task.yaml"
    task.write_text(
        "robot: ur10e\nstart: {named: home}\n"
        "steps:\n"
        "  - name: tight\n"
        "    joints: [0.6, -1.3, -1.6, 0.0, 1.3, 0.0]\n"
        "    tolerances:\n"
        "      goal_tolerance: [{name: shoulder_pan_joint, position: 1.0e-6}]\n"
        "      goal_time_tolerance: 1.0e-3\n"
        "  - {name: loose, joints: [0.3, -1.4, -1.5, 0.0, 1.2, 0.0]}\n")
    plan = tmp_path / "plan.mcap"
    assert cli("plan", task, "--seed", 0, "-o", plan).exit_code == 0
    from rosbags.highlevel import AnyReader  # the tolerances travel in the plan's metadata

    with AnyReader([plan]):
        pass
    lag = ("--plant", "lag", "--plant-param", "tau=0.05")
    code, document = cli.json("execute", plan, "--fake", *lag, "-o", tmp_path / "run.mcap")
    assert code == 5 and document["result"]["name"] == "GOAL_TOLERANCE_VIOLATED", document
    assert [s["ok"] for s in document["steps"]] == [False]  # the first failing step ends the execution
    assert {v["step"] for v in document["violations"]} == {"tight"}
    code, checked = cli.json("check-tolerances", plan, tmp_path / "run.mcap", "--start", "0")
    assert code == 5 and checked["result"]["name"] == "GOAL_TOLERANCE_VIOLATED", checked
    # Erased (-1), the goal tolerance of that joint is not checked: the same run passes.
    task.write_text(task.read_text().replace("position: 1.0e-6", "position: -1").replace(
        "goal_time_tolerance: 1.0e-3", "goal_time_tolerance: 0"))
    assert cli("plan", task, "--seed", 0, "-o", plan).exit_code == 0
    code, document = cli.json("execute", plan, "--fake", *lag)
    assert code == 0, document


def test_a_partial_goal_holds_the_joints_it_leaves_out_where_the_controller_allows_it(cli: Cli, tmp_path: Path) -> None:
    """test_trajectory_controller.cpp test_partial_joint_list(_not_allowed): JTC's fill_partial_goal holds them."""
    from moveplan.core.bag.jointstates import read_joint_states

    arm = (ROOT / "configs" / "panda" / "ros2_controllers.yaml").read_text()
    assert "      - panda_joint7\n    allow_nonzero_velocity_at_trajectory_end: true\n" in arm
    partial, strict = tmp_path / "partial.yaml", tmp_path / "strict.yaml"
    allow = "    allow_nonzero_velocity_at_trajectory_end: true\n"
    partial.write_text(arm.replace("      - panda_joint7\n", "      - panda_joint7\n      - panda_finger_joint1\n")
                       .replace(allow, allow + "    allow_partial_joints_goal: true\n"))
    strict.write_text(partial.read_text().replace("    allow_partial_joints_goal: true\n", ""))
    plan, run = tmp_path / "arm.mcap", tmp_path / "run.mcap"
    assert cli("plan", "--robot", "panda", "--joints", "panda_joint1=0.5,panda_joint4=-2.0", "-o", plan).exit_code == 0
    code, document = cli.json("execute", plan, "--fake", "--controllers", partial, "-o", run)
    assert code == 0 and document["result"]["name"] == "SUCCESSFUL", document
    recorded = read_joint_states(run)
    finger = recorded.positions[:, recorded.names.index("panda_finger_joint1")]
    assert finger.min() == finger.max() == 0.0  # held where the fake hardware starts it (initial_positions)
    code, checked = cli.json("check-tolerances", plan, run, "--controllers", partial)
    assert code == 0 and checked["result"]["name"] == "SUCCESSFUL", checked
    for command in (("execute", plan, "--fake"), ("check-tolerances", plan, run)):
        refused = cli(*command, "--controllers", strict)
        assert refused.exit_code == 3 and refused.stderr.strip() == (
            f"moveplan: error: {plan}: step 'goal': Joints on incoming trajectory don't match the controller joints: "
            "controller 'panda_arm_controller' also has panda_finger_joint1 (partial goals are not allowed)")
