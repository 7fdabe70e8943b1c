"""Hostile recordings and plans: NaN samples and points, joints named twice, stamps going back, another robot's plan.

Each is refused with one line naming file, topic, joint and message (or step, point and time),
exit 3 (bad input) or 5 (a violation), never a traceback, never an output file written or replaced.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import SAMPLES, Cli, write_bag
from mcap.reader import make_reader
from mcap.writer import Writer
from mcap_ros2._dynamic import generate_dynamic, serialize_dynamic

from moveplan.core.bag.jointstates import encode_joint_states, read_joint_states

RECORDINGS = SAMPLES / "recordings"
PLAN = RECORDINGS / "tool_up_plan.mcap"
JOINT_STATE = "sensor_msgs/msg/JointState"
OLD = b"an earlier output, to be kept"


def recording(path: Path, positions: np.ndarray | None = None, stamps: np.ndarray | None = None,
              names: tuple[str, ...] | None = None) -> Path:
    """Write tool_up_ok.mcap again, with its positions, stamps or joint names replaced."""
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    if stamps is None:
        stamps = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    log_times = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    payloads = encode_joint_states(names or recorded.names, stamps,
                                   recorded.positions if positions is None else positions)
    return write_bag(path, [("/joint_states", JOINT_STATE, int(t), p)
                            for t, p in zip(log_times, payloads, strict=True)])


def recorded_positions() -> np.ndarray:
    return read_joint_states(RECORDINGS / "tool_up_ok.mcap").positions.copy()


def edited_plan(path: Path, edit: Callable[[Any], None], source: Path = PLAN) -> Path:
    """Copy a plan file, each /planned_trajectory message changed by `edit` (decoded, in place)."""
    with source.open("rb") as stream, path.open("wb") as out:
        reader = make_reader(stream)
        writer = Writer(out)
        writer.start(reader.get_header().profile, reader.get_header().library)
        summary = reader.get_summary()
        assert summary is not None
        for schema in summary.schemas.values():
            writer.register_schema(schema.name, schema.encoding, schema.data)
        for channel in summary.channels.values():
            writer.register_channel(channel.topic, channel.message_encoding, channel.schema_id,
                                    channel.metadata)
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            data = message.data
            if channel.topic == "/planned_trajectory":
                text = schema.data.decode()
                decoded = generate_dynamic(schema.name, text)[schema.name](data)
                edit(decoded)
                data = serialize_dynamic(schema.name, text)[schema.name](decoded)
            writer.add_message(channel.id, message.log_time, data, message.publish_time,
                               message.sequence)
        for attachment in reader.iter_attachments():
            writer.add_attachment(attachment.create_time, attachment.log_time, attachment.name,
                                  attachment.media_type, attachment.data)
        for metadata in reader.iter_metadata():
            writer.add_metadata(metadata.name, metadata.metadata)
        writer.finish()
    return path


def one_error_line(result: Any) -> str:
    """Return the one line a failed command wrote to stderr, checked to be the only one."""
    assert "Traceback" not in result.stderr and result.stdout == ""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("moveplan: error: "), result.stderr
    return lines[0]


# --- 1. NaN positions in a recording ----------------------------------------------------------


def test_recording_with_one_nan_sample_violates_the_path_tolerance_there(cli: Cli, tmp_path: Path) -> None:
    positions = recorded_positions()
    positions[len(positions) // 2, 3] = math.nan  # one glitch on wrist_1_joint, mid-motion
    glitch = recording(tmp_path / "glitch.mcap", positions)
    result = cli("check-tolerances", PLAN, glitch)
    assert result.exit_code == 5, result.stderr
    first = result.stdout.splitlines()[0] + " " + result.stdout.splitlines()[1]
    assert "PATH_TOLERANCE_VIOLATED" in first and "wrist_1_joint actual nan (not a number)" in first
    code, document = cli.json("check-tolerances", PLAN, glitch)
    assert code == 5
    [violation] = document["violations"]
    assert violation["joint"] == "wrist_1_joint" and violation["check"] == "path"
    assert violation["actual"] is None and violation["time_s"] == pytest.approx(0.526, abs=0.01)


def test_recording_with_nan_in_every_sample_of_a_joint_is_bad_input(cli: Cli, tmp_path: Path) -> None:
    positions = recorded_positions()
    positions[:, 3] = math.nan  # hardware that never reported wrist_1_joint (mock_components unset)
    unset = recording(tmp_path / "unset.mcap", positions)
    result = cli("check-tolerances", PLAN, unset)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "unset.mcap" in line and "/joint_states" in line and "wrist_1_joint" in line
    assert "no finite position" in line


def test_recording_all_nan_is_bad_input_in_json_too(cli: Cli, tmp_path: Path) -> None:
    unset = recording(tmp_path / "unset.mcap", np.full_like(recorded_positions(), math.nan))
    code, document = cli.json("check-tolerances", PLAN, unset)
    assert code == 3 and document["error"]["kind"] == "InputError"
    assert "shoulder_pan_joint" in document["error"]["message"]


# --- 2. plans JTC would refuse ----------------------------------------------------------------


def nan_point(message: Any) -> None:
    message.points[2].positions[1] = math.nan


def repeated_time(message: Any) -> None:
    message.points[4].time_from_start.sec = message.points[3].time_from_start.sec
    message.points[4].time_from_start.nanosec = message.points[3].time_from_start.nanosec


def test_execute_refuses_a_plan_with_a_nan_point_and_writes_nothing(cli: Cli, tmp_path: Path) -> None:
    plan = edited_plan(tmp_path / "nan_plan.mcap", nan_point)
    output = tmp_path / "executed.mcap"
    output.write_bytes(OLD)
    result = cli("execute", plan, "--fake", "-o", output)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "nan_plan.mcap" in line and "step 'up'" in line and "/planned_trajectory" in line
    assert "positions of joint shoulder_lift_joint at point #2" in line and "nan" in line
    assert output.read_bytes() == OLD
    fresh = tmp_path / "fresh.mcap"
    assert cli("execute", plan, "--fake", "-o", fresh).exit_code == 3 and not fresh.exists()


def test_execute_refuses_a_plan_whose_times_do_not_increase(cli: Cli, tmp_path: Path) -> None:
    plan = edited_plan(tmp_path / "stalled.mcap", repeated_time)
    output = tmp_path / "executed.mcap"
    output.write_bytes(OLD)
    result = cli("execute", plan, "--fake", "-o", output)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "stalled.mcap" in line and "step 'up'" in line and "strictly increasing" in line
    assert output.read_bytes() == OLD


def test_inspect_of_a_plan_with_a_nan_point_says_it_is_invalid(cli: Cli, tmp_path: Path) -> None:
    plan = edited_plan(tmp_path / "nan_plan.mcap", nan_point)
    result = cli("inspect", plan)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "nan_plan.mcap" in line and "point #2" in line and "shoulder_lift_joint" in line


def test_check_tolerances_refuses_a_plan_with_a_nan_point(cli: Cli, tmp_path: Path) -> None:
    plan = edited_plan(tmp_path / "nan_plan.mcap", nan_point)
    result = cli("check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap")
    assert result.exit_code == 3
    assert "point #2" in one_error_line(result)


# --- 3. JointState messages: a joint named twice, stamps going back ---------------------------


def test_joint_state_naming_a_joint_twice_is_bad_input_naming_message_and_joint(
        cli: Cli, tmp_path: Path) -> None:
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    log_times = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    good = encode_joint_states(recorded.names, log_times, recorded.positions)
    names = (*recorded.names[:5], "elbow_joint")  # wrist_3_joint's slot says elbow_joint again
    bad = encode_joint_states(names, log_times[7:8], recorded.positions[7:8])
    payloads = [*good[:7], *bad, *good[8:]]
    twice = write_bag(tmp_path / "twice.mcap", [("/joint_states", JOINT_STATE, int(t), p)
                                                for t, p in zip(log_times, payloads, strict=True)])
    result = cli("check-tolerances", PLAN, twice)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "twice.mcap" in line and "/joint_states message 7" in line
    assert "names joint elbow_joint twice" in line


def test_header_stamp_going_back_a_second_is_bad_input_naming_the_message(cli: Cli, tmp_path: Path) -> None:
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    stamps = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    stamps[300:] -= 1_000_000_000  # the clock stepped back 1 s (a simulation restarted)
    jumped = recording(tmp_path / "jumped.mcap", stamps=stamps)
    result = cli("check-tolerances", PLAN, jumped)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "jumped.mcap" in line and "/joint_states message 300" in line
    assert "header stamp" in line and "before it" in line


def test_header_stamps_reordered_by_a_millisecond_are_sorted_with_a_warning(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    stamps = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    positions = recorded.positions.copy()
    # Two messages crossed in transport: received (and recorded) in the wrong order.
    stamps[[100, 101]] = stamps[[101, 100]]
    positions[[100, 101]] = positions[[101, 100]]
    crossed = recording(tmp_path / "crossed.mcap", positions, stamps)
    result = cli("check-tolerances", PLAN, crossed)
    assert result.exit_code == 0, result.stderr
    [warning] = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert "crossed.mcap" in warning and "message 101" in warning and "sorted by header stamp" in warning
    code, document = cli.json("check-tolerances", PLAN, crossed)
    assert code == 0 and document["ok"]


# --- 4. --start-from a plan of another robot -------------------------------------------------


@pytest.fixture(scope="module")
def panda_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    plan = tmp_path_factory.mktemp("panda") / "panda.mcap"
    assert Cli()("plan", "--robot", "panda", "--named", "ready", "-o", plan).exit_code == 0
    return plan


def test_start_from_a_plan_of_another_robot_is_refused_naming_both(
        cli: Cli, tmp_path: Path, panda_plan: Path) -> None:
    output = tmp_path / "ur10e.mcap"
    output.write_bytes(OLD)
    result = cli("plan", "--robot", "ur10e", "--start-from", panda_plan, "--named", "home", "-o", output)
    assert result.exit_code == 3
    line = one_error_line(result)
    assert "panda.mcap" in line and "robot 'panda'" in line and "robot 'ur10e'" in line
    assert "panda_joint1" in line and "shoulder_pan_joint" in line
    assert output.read_bytes() == OLD
    code, document = cli.json("plan", "--robot", "ur10e", "--start-from", panda_plan, "--named", "home",
                              "-o", tmp_path / "fresh.mcap")
    assert code == 3 and "robot 'panda'" in document["error"]["message"]
    assert not (tmp_path / "fresh.mcap").exists()


def test_start_from_a_plan_with_a_nan_end_is_refused(cli: Cli, tmp_path: Path) -> None:
    def nan_end(message: Any) -> None:
        message.points[-1].positions[0] = math.nan

    plan = edited_plan(tmp_path / "nan_end.mcap", nan_end)
    output = tmp_path / "next.mcap"
    result = cli("plan", "--robot", "ur10e", "--start-from", plan, "--named", "home", "-o", output)
    assert result.exit_code == 3
    assert "shoulder_pan_joint" in one_error_line(result) and not output.exists()


def test_json_of_a_refused_recording_is_one_document(cli: Cli, tmp_path: Path) -> None:
    positions = recorded_positions()
    positions[:, 0] = math.inf
    result = cli("check-tolerances", PLAN, recording(tmp_path / "inf.mcap", positions), "--json")
    assert result.exit_code == 3
    assert json.loads(result.stdout)["error"]["exit_code"] == 3


def test_messages_of_two_layouts_in_stamp_order_are_not_reported_as_reordered(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # Alternate messages carry a frame_id: read as two layouts, grouped per layout in a batch.
    recorded = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    stamps = recorded.start_ns + np.round(recorded.times_s * 1e9).astype(np.int64)
    plain = encode_joint_states(recorded.names, stamps, recorded.positions)
    framed = encode_joint_states(recorded.names, stamps, recorded.positions, frame_id="base_link")
    payloads = [framed[i] if i % 2 else plain[i] for i in range(len(stamps))]
    mixed = write_bag(tmp_path / "mixed.mcap", [("/joint_states", JOINT_STATE, int(t), p)
                                                for t, p in zip(stamps, payloads, strict=True)])
    series = read_joint_states(mixed)
    np.testing.assert_array_equal(series.positions, recorded.positions)
    assert not [r for r in caplog.records if r.levelname == "WARNING"]
    stamps[[100, 101]] = stamps[[101, 100]]
    payloads = [encode_joint_states(recorded.names, stamps[i : i + 1], recorded.positions[i : i + 1],
                                    frame_id="base_link" if i % 2 else "")[0] for i in range(len(stamps))]
    write_bag(mixed, [("/joint_states", JOINT_STATE, int(t), p)
                      for t, p in zip(stamps, payloads, strict=True)])
    read_joint_states(mixed)
    [warning] = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert "message 101" in warning


def moving_end(message: Any) -> None:
    """Leave the last point with a velocity, as a goal JTC's allow_nonzero_velocity_at_trajectory_end refuses."""
    velocities = list(message.points[-1].velocities)
    velocities[1] = 0.25
    message.points[-1].velocities = velocities


def test_execute_and_check_refuse_a_plan_whose_last_point_still_moves(cli: Cli, tmp_path: Path) -> None:
    """test_trajectory_actions.cpp test_allow_nonzero_velocity_at_trajectory_end_false: the goal is rejected."""
    plan = edited_plan(tmp_path / "moving.mcap", moving_end)
    output = tmp_path / "executed.mcap"
    result = cli("execute", plan, "--fake", "-o", output)
    assert result.exit_code == 3 and not output.exists()
    line = one_error_line(result)
    assert "moving.mcap" in line and "step 'up'" in line
    assert "Velocity of last trajectory point of joint shoulder_lift_joint is not zero: 0.250000000000000" in line
    result = cli("check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap")
    assert result.exit_code == 3 and "is not zero" in one_error_line(result)
