"""Joint states read from MCAP files, checked against rosbags' decoding of the same files."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
from conftest import write_bag
from mcap.writer import CompressionType, Writer
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from moveplan.core.bag.jointstates import (
    JOINT_STATE_TYPE,
    JointStateSeries,
    encode_joint_states,
    read_joint_states,
)
from moveplan.core.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
MSGS = ROOT / "core" / "bag" / "cdr" / "msgs" / "jazzy"
SCHEMAS = {
    JOINT_STATE_TYPE: (MSGS / "sensor_msgs__msg__JointState.msg").read_bytes(),
    "std_msgs/msg/String": (MSGS / "std_msgs__msg__String.msg").read_bytes(),
}
JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
EPOCH_NS = 1_700_000_000_123_456_789
STORE = get_typestore(Stores.ROS2_JAZZY)


def motion(count: int, rate_hz: float = 200.0, joints: int = 6, seed: int = 0):
    """Stamps [ns], positions and velocities of a smooth motion with a little noise."""
    t = np.arange(count) / rate_hz
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, np.pi, joints)
    positions = np.sin(t[:, None] + phases) + rng.normal(0, 1e-4, (count, joints))
    velocities = np.cos(t[:, None] + phases)
    return EPOCH_NS + np.round(t * 1e9).astype(np.int64), positions, velocities


def joint_state_bag(path: Path, count: int = 600, names=JOINTS, **options) -> tuple[Path, tuple]:
    stamps, positions, velocities = motion(count, joints=len(names))
    payloads = encode_joint_states(names, stamps, positions, velocities)
    messages = [("/joint_states", JOINT_STATE_TYPE, int(s) + 50_000, p)
                for s, p in zip(stamps, payloads, strict=True)]
    return write_bag(path, messages, **options), (stamps, positions, velocities)


def rosbags_joint_states(path: Path, topic: str = "/joint_states"):
    """(log time, message) of every message on `topic`, decoded by rosbags."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return [(t, reader.deserialize(raw, c.msgtype))
                for c, t, raw in reader.messages(connections=connections)]


def rosbags_payload(names, stamp_ns: int, position, velocity=(), effort=(), frame_id="",
                    little_endian: bool = True) -> bytes:
    """A JointState serialized by rosbags: an encoder independent of ours."""
    types = STORE.types
    message = types[JOINT_STATE_TYPE](
        header=types["std_msgs/msg/Header"](
            stamp=types["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9,
                                                       nanosec=stamp_ns % 10**9),
            frame_id=frame_id),
        name=list(names),
        position=np.asarray(position, dtype=np.float64),
        velocity=np.asarray(velocity, dtype=np.float64),
        effort=np.asarray(effort, dtype=np.float64),
    )
    return bytes(STORE.serialize_cdr(message, JOINT_STATE_TYPE, little_endian=little_endian))


# --- reading, against rosbags ---------------------------------------------------------------


@pytest.mark.parametrize("compression", [CompressionType.ZSTD, CompressionType.LZ4,
                                         CompressionType.NONE])
def test_columns_match_rosbags_decoding(tmp_path: Path, compression: CompressionType) -> None:
    path, _ = joint_state_bag(tmp_path / "js.mcap", compression=compression)
    series = read_joint_states(path)
    decoded = rosbags_joint_states(path)
    assert series.names == tuple(decoded[0][1].name) == JOINTS
    np.testing.assert_array_equal(series.positions, [m.position for _, m in decoded])
    np.testing.assert_array_equal(series.velocities, [m.velocity for _, m in decoded])
    stamps = np.array([m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _, m in decoded])
    assert series.start_ns == stamps[0]
    np.testing.assert_allclose(series.times_s, (stamps - stamps[0]) / 1e9, atol=1e-12)
    assert series.time_source == "header" and not series.positions.flags.writeable


def test_encoder_is_byte_identical_to_rosbags() -> None:
    stamps, positions, velocities = motion(3)
    ours = encode_joint_states(JOINTS, stamps, positions, velocities, frame_id="base")
    for stamp, row, vel, data in zip(stamps, positions, velocities, ours, strict=True):
        assert data == rosbags_payload(JOINTS, int(stamp), row, vel, frame_id="base")


def test_joints_in_another_order_with_an_extra_joint(tmp_path: Path) -> None:
    names = ("elbow_joint", "gripper_joint", "shoulder_pan_joint", "wrist_3_joint",
             "shoulder_lift_joint", "wrist_1_joint", "wrist_2_joint")
    path, (_, positions, velocities) = joint_state_bag(tmp_path / "js.mcap", names=names)
    series = read_joint_states(path, joints=JOINTS)
    order = [names.index(j) for j in JOINTS]
    assert series.names == JOINTS
    np.testing.assert_array_equal(series.positions, positions[:, order])
    np.testing.assert_array_equal(series.velocities, velocities[:, order])


def test_velocities_are_left_unread_when_not_wanted(tmp_path: Path) -> None:
    path, (_, positions, _) = joint_state_bag(tmp_path / "js.mcap")
    series = read_joint_states(path, joints=JOINTS, velocities=False)
    assert series.velocities is None
    np.testing.assert_array_equal(series.positions, positions)


def test_missing_joint_names_it_and_the_joints_present(tmp_path: Path) -> None:
    path, _ = joint_state_bag(tmp_path / "js.mcap", names=JOINTS[:5])
    with pytest.raises(InputError, match="no joint wrist_3_joint") as error:
        read_joint_states(path, joints=JOINTS)
    assert "elbow_joint" in str(error.value) and str(path) in str(error.value)


def test_log_time_source(tmp_path: Path) -> None:
    path, (stamps, _, _) = joint_state_bag(tmp_path / "js.mcap")
    series = read_joint_states(path, time_source="log")
    assert series.time_source == "log" and series.start_ns == stamps[0] + 50_000
    np.testing.assert_allclose(series.times_s, (stamps - stamps[0]) / 1e9, atol=1e-12)


def test_zero_header_stamps_fall_back_to_log_time(tmp_path: Path, caplog) -> None:
    _, positions, _ = motion(50)
    payloads = encode_joint_states(JOINTS, np.zeros(50, np.int64), positions)
    messages = [("/joint_states", JOINT_STATE_TYPE, EPOCH_NS + i * 10**7, p)
                for i, p in enumerate(payloads)]
    path = write_bag(tmp_path / "js.mcap", messages)
    with caplog.at_level(logging.WARNING):
        series = read_joint_states(path)
    assert series.time_source == "log" and "header stamp" in caplog.text
    np.testing.assert_allclose(np.diff(series.times_s), 0.01, atol=1e-12)
    assert series.velocities is None


def test_publishers_with_different_layouts_on_one_topic(tmp_path: Path, caplog) -> None:
    # An arm broadcaster (with a frame_id) and a gripper publisher share /joint_states, plus
    # arm messages from a third node listing the joints in another order, big-endian.
    stamps, positions, velocities = motion(300)
    messages = []
    for i, (stamp, row, vel) in enumerate(zip(stamps.tolist(), positions, velocities, strict=True)):
        if i % 3 == 2:
            payload = rosbags_payload(JOINTS[::-1], stamp, row[::-1], vel[::-1],
                                      little_endian=False)
        else:
            payload = rosbags_payload(JOINTS, stamp, row, vel, effort=np.zeros(6), frame_id="arm")
        messages.append(("/joint_states", JOINT_STATE_TYPE, stamp, payload))
        gripper = rosbags_payload(["finger_joint"], stamp + 1, [0.01 * i], frame_id="g")
        messages.append(("/joint_states", JOINT_STATE_TYPE, stamp + 1, gripper))
    path = write_bag(tmp_path / "js.mcap", messages, chunk_size=8192)
    with caplog.at_level(logging.WARNING):
        series = read_joint_states(path, joints=JOINTS)
    np.testing.assert_array_equal(series.positions, positions)
    np.testing.assert_array_equal(series.velocities, velocities)
    assert "skipped 300 of 600" in caplog.text
    gripper = read_joint_states(path, joints=["finger_joint"])
    np.testing.assert_allclose(gripper.positions[:, 0], 0.01 * np.arange(300))
    assert gripper.velocities is None


def test_other_topics_in_the_same_chunks_and_two_channels(tmp_path: Path) -> None:
    stamps, positions, velocities = motion(400)
    payloads = encode_joint_states(JOINTS, stamps, positions, velocities)
    text = bytes(STORE.serialize_cdr(STORE.types["std_msgs/msg/String"](data="x" * 7),
                                     "std_msgs/msg/String"))
    messages = []
    for i, (stamp, payload) in enumerate(zip(stamps.tolist(), payloads, strict=True)):
        messages.append(("/joint_states", JOINT_STATE_TYPE, stamp, payload))
        if i % 3 == 0:
            messages.append(("/chatter", "std_msgs/msg/String", stamp, text))
    path = write_bag(tmp_path / "js.mcap", messages, chunk_size=16384)
    series = read_joint_states(path)
    np.testing.assert_array_equal(series.positions, positions)
    np.testing.assert_array_equal(series.velocities, velocities)
    # The same topic on two channels (bags merged from two recordings), in one file.
    with (tmp_path / "two.mcap").open("wb") as stream:
        writer = Writer(stream, chunk_size=16384)
        writer.start("ros2", "test")
        schema = writer.register_schema(JOINT_STATE_TYPE, "ros2msg", SCHEMAS[JOINT_STATE_TYPE])
        channels = [writer.register_channel("/joint_states", "cdr", schema) for _ in range(2)]
        for i, (stamp, payload) in enumerate(zip(stamps.tolist(), payloads, strict=True)):
            writer.add_message(channels[i % 2], stamp, payload, stamp)
        writer.finish()
    np.testing.assert_array_equal(read_joint_states(tmp_path / "two.mcap").positions, positions)


def test_series_is_sorted_by_time(tmp_path: Path) -> None:
    stamps, positions, _ = motion(100)
    # Neighbours swapped, as two publishers' messages cross in transport (a jump back is refused).
    order = np.arange(100).reshape(50, 2)[:, ::-1].reshape(-1)
    payloads = encode_joint_states(JOINTS, stamps[order], positions[order])
    path = write_bag(tmp_path / "js.mcap", [("/joint_states", JOINT_STATE_TYPE, EPOCH_NS, p)
                                          for p in payloads])
    series = read_joint_states(path)
    np.testing.assert_array_equal(series.positions, positions)


def test_unchunked_file_is_read(tmp_path: Path, caplog) -> None:
    path, (_, positions, _) = joint_state_bag(tmp_path / "js.mcap", use_chunking=False)
    with caplog.at_level(logging.WARNING):
        series = read_joint_states(path)
    np.testing.assert_array_equal(series.positions, positions)
    assert caplog.text == ""


def test_rosbag2_folder_reads_its_splits_in_order(tmp_path: Path) -> None:
    stamps, positions, _ = motion(30)
    payloads = encode_joint_states(JOINTS, stamps, positions)
    folder = tmp_path / "rosbag2_run"
    folder.mkdir()
    # Splits 0..10: name order would put _10 before _2.
    for split in range(11):
        part = range(split * 3, min(30, split * 3 + 3))
        write_bag(folder / f"rosbag2_run_{split}.mcap",
                  [("/joint_states", JOINT_STATE_TYPE, EPOCH_NS, payloads[i]) for i in part])
    series = read_joint_states(folder)
    np.testing.assert_array_equal(series.positions, positions)


# --- damaged and wrong files ----------------------------------------------------------------


def test_cut_off_recording_is_read_by_linear_scan_with_a_warning(tmp_path: Path, caplog) -> None:
    path, (_, positions, _) = joint_state_bag(tmp_path / "js.mcap", count=2000, chunk_size=8192)
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    with caplog.at_level(logging.WARNING):
        series = read_joint_states(cut)
    assert "linear scan" in caplog.text and "truncated at byte" in caplog.text
    count = len(series.times_s)
    assert 0 < count < 2000
    np.testing.assert_array_equal(series.positions, positions[:count])


def test_file_cut_before_any_message_is_an_input_error(tmp_path: Path) -> None:
    path, _ = joint_state_bag(tmp_path / "js.mcap")
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[:40])
    with pytest.raises(InputError, match=r"cut\.mcap.*truncated"):
        read_joint_states(cut)


def test_not_an_mcap_file(tmp_path: Path) -> None:
    path = tmp_path / "notes.mcap"
    path.write_text("hello")
    with pytest.raises(InputError, match=r"notes\.mcap: not an MCAP file"):
        read_joint_states(path)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="file not found"):
        read_joint_states(tmp_path / "none.mcap")


def test_missing_topic_lists_the_topics_present(tmp_path: Path) -> None:
    path, _ = joint_state_bag(tmp_path / "js.mcap")
    with pytest.raises(InputError, match=r"no topic /robot/joint_states.*"
                                         r"/joint_states \(sensor_msgs/msg/JointState\)"):
        read_joint_states(path, topic="/robot/joint_states")


def test_topic_of_another_type(tmp_path: Path) -> None:
    text = bytes(STORE.serialize_cdr(STORE.types["std_msgs/msg/String"](data="hi"),
                                     "std_msgs/msg/String"))
    path = write_bag(tmp_path / "s.mcap",
                     [("/joint_states", "std_msgs/msg/String", EPOCH_NS, text)])
    with pytest.raises(InputError, match="has type std_msgs/msg/String, expected sensor_msgs"):
        read_joint_states(path)


def test_corrupt_chunk_is_an_input_error(tmp_path: Path) -> None:
    path, _ = joint_state_bag(tmp_path / "js.mcap", chunk_size=1 << 20)
    data = bytearray(path.read_bytes())
    middle = len(data) // 3
    data[middle : middle + 64] = bytes(64)
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match=r"js\.mcap"):
        read_joint_states(path)


def test_series_arrays_are_read_only_and_checked() -> None:
    series = JointStateSeries(("a",), [0.0, 1.0], [[0.0], [1.0]], None, 0)
    with pytest.raises(ValueError):
        series.positions[0, 0] = 2.0
    with pytest.raises(ValueError, match="positions"):
        JointStateSeries(("a", "b"), [0.0, 1.0], [[0.0], [1.0]], None, 0)
