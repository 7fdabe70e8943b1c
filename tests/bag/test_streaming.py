"""Recordings read and checked in bounded memory: samples on disk, read back block by block.

The verdicts must not depend on how the samples are cut into blocks, nor on whether they
are read from memory or from the store; an unfinished MCAP file is read through the
message indexes that follow its chunks, and gives what the indexed file gives.
"""

from __future__ import annotations

import json
import logging
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import MSGS, ROOT, write_bag
from mcap.writer import CompressionType, Writer

from moveplan.core.bag.cdr.joint_state import JOINT_STATE_TYPE, encode_joint_states
from moveplan.core.bag.container.summary import summarize
from moveplan.core.bag.jointstates import open_joint_states, read_joint_states
from moveplan.core.bag.plan_file import PlanStepRecord
from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.control.check import _alignment as alignment
from moveplan.core.control.check import samples as check_samples
from moveplan.core.control.check.recording import check_recording
from moveplan.core.control.check.samples import Samples, source_of
from moveplan.core.pipeline.report import check_document
from moveplan.core.trajectory import sample
from moveplan.core.types import JointStateSeries, JointTrajectory

JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
PICK = HOME + np.array([1.0, 0.5, -0.8, 1.2, -1.0, 1.5])
EPOCH_NS = 1_700_000_000_000_000_000
SCHEMA = (MSGS / "sensor_msgs__msg__JointState.msg").read_bytes()


@dataclass(frozen=True)
class Plan:
    steps: tuple[PlanStepRecord, ...]


def minimum_jerk(start: np.ndarray, goal: np.ndarray, duration: float) -> JointTrajectory:
    t = np.linspace(0.0, duration, int(round(duration / 0.1)) + 1)
    s = (t / duration)[:, None]
    delta = goal - start
    return JointTrajectory(JOINTS, t, start + (10 * s**3 - 15 * s**4 + 6 * s**5) * delta,
                           (30 * s**2 - 60 * s**3 + 30 * s**4) / duration * delta,
                           (60 * s - 180 * s**2 + 120 * s**3) / duration**2 * delta)


CYCLE = Plan((PlanStepRecord("out", 0.0, minimum_jerk(HOME, PICK, 2.0)),
              PlanStepRecord("back", 2.0, minimum_jerk(PICK, HOME, 2.0))))
CONTROLLER = ControllerConfig(
    name="joint_trajectory_controller", joints=JOINTS, update_rate_hz=500.0,
    command_interfaces=("velocity",), state_interfaces=("position", "velocity"), goal_time_s=0.5,
    stopped_velocity_tolerance=0.2, trajectory_tolerance=dict.fromkeys(JOINTS, 0.2),
    goal_tolerance=dict.fromkeys(JOINTS, 0.1), gains={})


def shift(path: Path, cycles: int = 6, rate: float = 500.0) -> tuple[Path, np.ndarray, np.ndarray]:
    """Write a robot repeating CYCLE every 5.5 s (cycle 3 bumped, the last cut off, a gap), as MCAP.

    Returns the file, and the stamps [ns] and positions written.
    """
    times = np.arange(int((cycles * 5.5 - 3.0) * rate)) / rate
    positions = np.tile(HOME, (len(times), 1))
    velocities = np.zeros_like(positions)
    for k in range(cycles):
        start = 0.7 + 5.5 * k
        for offset, step in ((0.0, CYCLE.steps[0]), (2.3, CYCLE.steps[1])):
            mask = (times >= start + offset + 0.004) & (times < start + offset + 2.3 + 0.004)
            p, v, _ = sample(step.trajectory, times[mask] - start - offset - 0.004)
            positions[mask], velocities[mask] = p, v
    bump = (times > 0.7 + 5.5 * 3 + 1.0) & (times < 0.7 + 5.5 * 3 + 1.02)
    positions[bump, 2] += 0.3
    keep = (times < 11.0) | (times > 11.4)  # a gap of 0.4 s, the robot at rest
    stamps = EPOCH_NS + np.round(times[keep] * 1e9).astype(np.int64)
    payloads = encode_joint_states(JOINTS, stamps, positions[keep], velocities[keep])
    write_bag(path, [("/joint_states", JOINT_STATE_TYPE, int(s), p) for s, p in zip(stamps, payloads, strict=True)],
              chunk_size=16384)
    return path, stamps, positions[keep]


def documents(recorded: object) -> dict[str, str]:
    """The check documents of `recorded` for --start all, auto and a time, as JSON."""
    return {str(start): json.dumps(check_document(check_recording(CYCLE, recorded, CONTROLLER, ExecutionConfig(),
                                                                  (), start=start), Path("rec")), sort_keys=True)
            for start in ("all", "auto", 5.0)}


@pytest.fixture(scope="module")
def shift_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return shift(tmp_path_factory.mktemp("shift") / "shift.mcap")[0]


def test_check_from_the_store_equals_the_check_in_memory(shift_file: Path) -> None:
    with open_joint_states(shift_file) as store:
        from_store = documents(store)
        in_memory = documents(store.series())
    assert from_store == in_memory
    report = json.loads(from_store["all"])
    assert report["failing_cycles"] == [3] and report["incomplete_cycles"] == [5]
    assert report["gaps"] and report["gaps"][0]["length_s"] == pytest.approx(0.404, abs=1e-6)


def test_verdicts_do_not_depend_on_how_the_samples_are_cut_into_blocks(
    shift_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with open_joint_states(shift_file) as store:
        whole = documents(store)
        # Blocks of a few samples: every scan, search and carried state crosses many block edges.
        monkeypatch.setattr(check_samples, "SCAN_ROWS", 37)
        monkeypatch.setattr(alignment, "SCAN_ROWS", 37)
        monkeypatch.setattr(check_samples, "MARK_ROWS", 5)
        assert documents(store) == whole


def test_search_finds_what_numpy_finds_among_repeated_times(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(check_samples, "MARK_ROWS", 4)
    times = np.repeat(np.arange(50) * 0.01, np.random.default_rng(0).integers(1, 4, 50))
    series = JointStateSeries(("a",), times, np.zeros((len(times), 1)), None, 0)
    samples = Samples.build(source_of(series), ("a",), ())
    probes = np.concatenate((times, times + 0.004, [-1.0, 10.0]))
    for side in ("left", "right"):
        np.testing.assert_array_equal(samples.search_many(probes, side), np.searchsorted(times, probes, side))
    assert [samples.time(i) for i in range(len(times))] == times.tolist()


def test_times_that_go_back_a_little_are_sorted_across_sort_groups(tmp_path: Path, caplog) -> None:
    # More messages than one sort group holds; neighbours swapped every 997 messages (1 ms back).
    count = 150_000
    stamps = EPOCH_NS + np.arange(count) * 1_000_000
    order = np.arange(count)
    swapped = np.arange(500, count - 1, 997)
    order[swapped], order[swapped + 1] = swapped + 1, swapped
    positions = np.random.default_rng(1).normal(size=(count, 6))
    payloads = encode_joint_states(JOINTS, stamps[order], positions[order])
    path = write_bag(tmp_path / "crossed.mcap", [("/joint_states", JOINT_STATE_TYPE, EPOCH_NS, p) for p in payloads],
                     chunk_size=1 << 20)
    with caplog.at_level(logging.WARNING), open_joint_states(path) as store:
        assert store.count == count and store.start_ns == EPOCH_NS
        np.testing.assert_array_equal(store.read_positions(0, count), positions)
        np.testing.assert_array_equal(store.read_times(70_000, 70_010), np.arange(70_000, 70_010) * 1e-3)
    assert f"{len(swapped)} messages have a header stamp earlier" in caplog.text


def channel_in_a_skipped_chunk(path: Path) -> Path:
    """An MCAP file whose /joint_states channel is defined in a chunk holding only other messages.

    Chunk 1 defines /clock and holds its messages; chunk 2 defines /joint_states but holds only
    /clock messages; /joint_states messages start in chunk 3.
    """
    stamps = EPOCH_NS + np.arange(40) * 10_000_000
    payloads = encode_joint_states(JOINTS, stamps, np.arange(40 * 6.0).reshape(40, 6))
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=200, compression=CompressionType.NONE)
        writer.start("ros2", "test")
        clock = writer.register_channel("/clock", "cdr", writer.register_schema("std_msgs/msg/String", "ros2msg",
                                                                                 b"string data\n"))
        for i in range(3):
            writer.add_message(clock, i, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00" * 8, i)
        joint_states = writer.register_channel("/joint_states", "cdr",
                                               writer.register_schema(JOINT_STATE_TYPE, "ros2msg", SCHEMA))
        for i in range(3, 6):
            writer.add_message(clock, i, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00" * 8, i)
        for stamp, payload in zip(stamps.tolist(), payloads, strict=True):
            writer.add_message(joint_states, stamp, payload, stamp)
        writer.finish()
    return path


def summary_start(path: Path) -> int:
    data = path.read_bytes()
    return int.from_bytes(data[-8 - 20 : -8 - 12], "little")


def test_unfinished_recording_reads_like_the_indexed_one(tmp_path: Path, caplog) -> None:
    indexed = channel_in_a_skipped_chunk(tmp_path / "indexed.mcap")
    unfinished = tmp_path / "unfinished.mcap"
    unfinished.write_bytes(indexed.read_bytes()[: summary_start(indexed)])
    with caplog.at_level(logging.WARNING):
        cut = read_joint_states(unfinished)
    assert "linear scan" in caplog.text
    whole = read_joint_states(indexed)
    np.testing.assert_array_equal(cut.positions, whole.positions)
    np.testing.assert_array_equal(cut.times_s, whole.times_s)
    assert summarize(unfinished) == summarize(indexed)


def test_unfinished_shift_is_summarized_and_checked_like_the_indexed_one(shift_file: Path, tmp_path: Path) -> None:
    unfinished = tmp_path / "unfinished.mcap"
    unfinished.write_bytes(shift_file.read_bytes()[: summary_start(shift_file)])
    assert summarize(unfinished) == summarize(shift_file)
    with open_joint_states(unfinished) as cut, open_joint_states(shift_file) as whole:
        assert documents(cut) == documents(whole)


@pytest.mark.slow
def test_a_million_messages_are_checked_in_well_under_300_mb() -> None:
    """The peak resident memory of a check of 1 M messages, in a process of its own."""
    script = ROOT / "benchmarks" / "check_speed.py"
    made = subprocess.run([sys.executable, str(script), "--messages", "1000000", "--no-rosbags"],
                          capture_output=True, text=True, timeout=900, check=True)
    peak = float(made.stdout.split("peak RSS ")[1].split(" MB")[0])
    assert peak < 300, made.stdout
