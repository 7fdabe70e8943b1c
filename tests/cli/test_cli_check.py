"""`moveplan check-tolerances`: recordings judged against a plan with the controller's rules."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, Cli, write_bag

from moveplan.core.bag.jointstates import JointStateSeries, encode_joint_states, read_joint_states

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


# --- executions cut off by the recording ---------------------------------------------------


@pytest.fixture(scope="module")
def cycle(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, JointStateSeries]:
    """The joint-goals cycle (home -> two goals -> home) planned, and one fake execution of it."""
    folder = tmp_path_factory.mktemp("cycle")
    cli = Cli()
    plan = folder / "cycle.mcap"
    assert cli("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", plan).exit_code == 0
    executed = folder / "executed.mcap"
    assert cli("execute", plan, "--fake", "-o", executed).exit_code == 0
    return plan, read_joint_states(executed)


def shift_recording(one: JointStateSeries, path: Path, cycles: int, begin: float = 0.0, end: float = 1.0,
                    bump: float | None = None) -> Path:
    """Write `cycles` executions with 1 s at rest after each, from `begin` to `end` (fractions of
    an execution) into the first and last; `bump` (a fraction) kicks the last one's elbow."""
    period = float(np.median(np.diff(one.times_s)))
    count = len(one.positions)
    cycle = np.concatenate([one.positions, np.repeat(one.positions[-1:], int(1.0 / period), axis=0)])
    positions = np.concatenate([cycle] * cycles)
    last = (cycles - 1) * len(cycle)
    if bump is not None:
        at = last + int(bump * count)
        positions[at : at + 5, 2] += 0.3
    positions = positions[int(begin * count) : last + int(end * count)]
    stamps = (np.arange(len(positions)) * period * 1e9).astype(np.int64) + 1_700_000_000_000_000_000
    payloads = encode_joint_states(one.names, stamps, positions)
    return write_bag(path, [("/joint_states", "sensor_msgs/msg/JointState", int(s), p)
                            for s, p in zip(stamps, payloads, strict=True)])


def test_start_all_counts_a_last_cycle_cut_by_the_recording_as_incomplete(
        cli: Cli, cycle: tuple[Path, JointStateSeries], tmp_path: Path) -> None:
    plan, one = cycle
    recording = shift_recording(one, tmp_path / "shift.mcap", cycles=3, end=0.5)
    code, document = cli.json("check-tolerances", plan, recording, "--start", "all")
    assert code == 0
    assert document["ok"] is True and document["error"] is None
    assert document["failing_cycles"] == [] and document["incomplete_cycles"] == [2]
    assert [c["ok"] for c in document["cycles"]] == [True, True, None]
    assert document["cycles"][2]["result"]["name"] == "INCOMPLETE"
    assert document["cycles"][2]["result"]["code"] == -100
    assert "1 incomplete" in document["result"]["message"]
    text = cli("check-tolerances", plan, recording, "--start", "all")
    assert text.exit_code == 0
    words = " ".join(text.stdout.split())  # rich wraps lines at the terminal's width
    assert "3 executions found; failing: none; incomplete: 1 (cycle 2, cut off by the recording)" in words


def test_start_all_counts_a_first_cycle_already_running_as_incomplete(
        cli: Cli, cycle: tuple[Path, JointStateSeries], tmp_path: Path) -> None:
    plan, one = cycle
    recording = shift_recording(one, tmp_path / "shift.mcap", cycles=3, begin=0.4)
    code, document = cli.json("check-tolerances", plan, recording, "--start", "all")
    assert code == 0, document
    assert document["incomplete_cycles"] == [0] and document["failing_cycles"] == []
    assert [c["ok"] for c in document["cycles"]] == [None, True, True]
    assert "already running" in document["cycles"][0]["result"]["message"]


def test_start_all_fails_a_cut_cycle_that_violated_before_the_cut(
        cli: Cli, cycle: tuple[Path, JointStateSeries], tmp_path: Path) -> None:
    plan, one = cycle
    recording = shift_recording(one, tmp_path / "shift.mcap", cycles=3, end=0.5, bump=1 / 3)
    code, document = cli.json("check-tolerances", plan, recording, "--start", "all")
    assert code == 5
    assert document["failing_cycles"] == [2] and document["incomplete_cycles"] == []
    assert document["cycles"][2]["ok"] is False
    assert document["cycles"][2]["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    text = cli("check-tolerances", plan, recording, "--start", "all")
    assert text.exit_code == 5 and "failing: 2; incomplete: 0" in " ".join(text.stdout.split())


@pytest.mark.parametrize("start", ["auto", "0", "all"])
def test_check_with_no_complete_execution_is_bad_input(
        cli: Cli, cycle: tuple[Path, JointStateSeries], tmp_path: Path, start: str) -> None:
    plan, one = cycle
    recording = shift_recording(one, tmp_path / "cut.mcap", cycles=1, end=0.5)
    code, document = cli.json("check-tolerances", plan, recording, "--start", start)
    assert code == 3
    assert document["ok"] is False and document["result"]["name"] == "INCOMPLETE"
    assert document["violations"] == []
    error = document["error"]
    assert error["exit_code"] == 3 and error["kind"] == "InputError"
    assert "cut.mcap" in error["message"] and "recording ends" in error["message"]
    text = cli("check-tolerances", plan, recording, "--start", start)
    assert text.exit_code == 3
    assert "moveplan: error:" in text.stderr and "cut.mcap" in text.stderr and "Traceback" not in text.stderr


def test_single_check_cut_after_a_violation_fails(
        cli: Cli, cycle: tuple[Path, JointStateSeries], tmp_path: Path) -> None:
    plan, one = cycle
    recording = shift_recording(one, tmp_path / "cut.mcap", cycles=1, end=0.5, bump=1 / 3)
    code, document = cli.json("check-tolerances", plan, recording)
    assert code == 5
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED" and document["error"] is None


def test_recording_with_an_infinite_position_prints_strict_json_with_null(cli: Cli, tmp_path: Path) -> None:
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    positions = recorded.positions.copy()
    positions[len(positions) // 2, 3] = np.inf  # a sensor glitch on wrist_1_joint
    stamps = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    payloads = encode_joint_states(recorded.names, stamps, positions)
    glitch = write_bag(tmp_path / "glitch.mcap", [("/joint_states", "sensor_msgs/msg/JointState", int(s), p)
                                                  for s, p in zip(stamps, payloads, strict=True)])

    def reject(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    result = cli("check-tolerances", PLAN, glitch, "--json")
    assert result.exit_code == 5, result.stderr
    document = json.loads(result.stdout, parse_constant=reject)
    [violation] = document["violations"]
    assert violation["joint"] == "wrist_1_joint" and violation["actual"] is None and violation["error"] is None
    text = cli("check-tolerances", PLAN, glitch)
    assert text.exit_code == 5 and "inf/nan" in text.stdout and "Traceback" not in text.stderr
