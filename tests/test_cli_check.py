"""`moveplan check-tolerances`: recordings judged against a plan with the controller's rules."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, Cli, write_bag

from moveplan.core.jointstates import encode_joint_states, read_joint_states

RECORDINGS = SAMPLES / "recordings"
PLAN = RECORDINGS / "tool_up_plan.mcap"


def test_recording_that_follows_the_plan_passes(cli: Cli) -> None:
    code, document = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap")
    assert code == 0
    assert document["ok"] and document["result"]["name"] == "SUCCESSFUL"
    assert all(margin > 0 for margin in document["margins"].values())


def test_bumped_recording_violates_the_path_tolerance_at_the_bump(cli: Cli) -> None:
    code, document = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_path_violation.mcap")
    assert code == 5
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    violation = document["violations"][0]
    assert violation["joint"] == "wrist_1_joint" and violation["time_s"] == pytest.approx(0.5, abs=0.01)
    assert violation["tolerance"] == 0.2


def test_sluggish_robot_misses_the_goal_within_goal_time(cli: Cli) -> None:
    code, document = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_goal_missed.mcap", "--controllers",
                              RECORDINGS / "ur10e_goal_time_controllers.yaml", "--start", "0")
    assert code == 5
    assert document["result"]["name"] == "GOAL_TOLERANCE_VIOLATED"
    assert {v["check"] for v in document["violations"]} >= {"goal_time", "goal"}


def test_check_of_an_executed_file_agrees_with_execute(cli: Cli) -> None:
    _, executed = cli.json("execute", PLAN, "--fake", "--disturb", "t=0.5,joint=wrist_1_joint,delta=0.25")
    _, checked = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_path_violation.mcap", "--start", "0")
    assert checked["result"]["name"] == executed["result"]["name"]
    assert checked["violations"][0]["error"] == pytest.approx(executed["violations"][0]["error"], abs=1e-9)


def test_start_all_finds_every_cycle_and_names_the_failing_one(cli: Cli, tmp_path: Path) -> None:
    # A robot repeating the joint-goals cycle (home -> two goals -> home) four times, bumped in cycle 2.
    plan = tmp_path / "cycle.mcap"
    assert cli("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", plan).exit_code == 0
    executed = tmp_path / "executed.mcap"
    assert cli("execute", plan, "--fake", "-o", executed).exit_code == 0
    one = read_joint_states(executed)
    period = float(np.median(np.diff(one.times_s)))
    pause = np.repeat(one.positions[-1:], int(1.0 / period), axis=0)  # one second at rest between cycles
    cycle = np.concatenate([one.positions, pause])
    positions = np.concatenate([cycle] * 4)
    bump = 2 * len(cycle) + len(one.positions) // 3
    positions[bump : bump + 5, 2] += 0.3
    stamps = (np.arange(len(positions)) * period * 1e9).astype(np.int64) + 1_700_000_000_000_000_000
    payloads = encode_joint_states(one.names, stamps, positions)
    recording = write_bag(tmp_path / "shift.mcap", [("/joint_states", "sensor_msgs/msg/JointState", int(s), p)
                                                    for s, p in zip(stamps, payloads, strict=True)])
    code, document = cli.json("check-tolerances", plan, recording, "--start", "all")
    assert code == 5
    assert [c["index"] for c in document["cycles"]] == [0, 1, 2, 3]
    assert document["failing_cycles"] == [2]
    assert document["cycles"][2]["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    assert all(c["ok"] for c in document["cycles"] if c["index"] != 2)


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--topic", "/nope"], 3, "/joint_states"),
        (["--start", "soon"], 2, "--start"),
        (["--time-source", "wall"], 2, "header or log"),
    ],
)
def test_bad_check_input_exits_with_code_and_one_line(cli: Cli, args: list[str], code: int, message: str) -> None:
    result = cli("check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap", *args)
    assert result.exit_code == code, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr


def test_truncated_recording_is_read_as_far_as_it_goes_with_a_warning(cli: Cli, tmp_path: Path) -> None:
    cut = tmp_path / "cut.mcap"
    cut.write_bytes((RECORDINGS / "tool_up_ok.mcap").read_bytes()[:60_000])
    result = cli("check-tolerances", PLAN, cut, "--start", "0")
    assert result.exit_code in (3, 5), result.stderr
    assert "cut.mcap" in result.stderr and "Traceback" not in result.stderr
