"""rosbag2 sqlite3 bags (.db3, Humble's default storage) checked and inspected like MCAP recordings."""

from __future__ import annotations

import json
import shutil
import sqlite3
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, Cli
from mcap.reader import make_reader
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from moveplan.core.bag.container.summary import summarize
from moveplan.core.bag.jointstates import encode_joint_states, read_joint_states
from moveplan.core.errors import InputError

RECORDINGS = SAMPLES / "recordings"
PLAN = RECORDINGS / "tool_up_plan.mcap"
DATA = Path(__file__).resolve().parents[1] / "data" / "db3"
JOINT_STATE = "sensor_msgs/msg/JointState"
# Humble's rosbag2_storage_sqlite3 (schema version 3): SqliteStorage::initialize.
HUMBLE_SCHEMA = """
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);
CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,metadata TEXT NOT NULL);
CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,
  serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
INSERT INTO schema (schema_version, ros_distro) VALUES (3, 'humble');
"""
QOS = json.loads('"' + (DATA / "metadata.yaml").read_text().split('offered_qos_profiles: "')[1].split('"\n')[0] + '"')


def mcap_messages(path: Path, topics: Iterable[str] = ("/joint_states",)) -> list[tuple[str, str, int, bytes]]:
    """(topic, type, log time [ns], payload) of an MCAP file's messages on `topics`, in file order."""
    with path.open("rb") as stream:
        return [(channel.topic, schema.name, message.log_time, message.data)
                for schema, channel, message in make_reader(stream).iter_messages(topics=list(topics))]


def humble_db3(path: Path, messages: Iterable[tuple[str, str, int, bytes]]) -> Path:
    """Write `messages` to `path` as Humble's sqlite3 storage does: one row each, in arrival order."""
    connection = sqlite3.connect(path)
    connection.executescript(HUMBLE_SCHEMA)
    topics: dict[str, int] = {}
    for topic, msgtype, log_time, data in messages:
        if topic not in topics:
            topics[topic] = connection.execute(
                "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES (?, ?, ?, ?)",
                (topic, msgtype, "cdr", QOS)).lastrowid
        connection.execute("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)",
                           (log_time, topics[topic], data))
    connection.commit()
    connection.close()
    return path


@pytest.fixture()
def humble_bag(tmp_path: Path) -> Path:
    """tool_up_ok.mcap's /joint_states as the bag folder Humble's `ros2 bag record` writes, split in two."""
    folder = tmp_path / "robot_run"
    folder.mkdir()
    messages = mcap_messages(RECORDINGS / "tool_up_ok.mcap")
    humble_db3(folder / "robot_run_0.db3", messages[:264])
    humble_db3(folder / "robot_run_1.db3", messages[264:])
    shutil.copy(DATA / "metadata.yaml", folder / "metadata.yaml")
    return folder


def rosbags_db3(folder: Path, source: Path) -> Path:
    """Convert an MCAP recording's /joint_states with rosbags' own writer (sqlite3 storage, version 8)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    with Writer(folder, version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
        connection = writer.add_connection("/joint_states", JOINT_STATE, typestore=store)
        for _, _, log_time, data in mcap_messages(source):
            writer.write(connection, log_time, data)
    return folder


def test_humble_split_bag_folder_checks_exactly_as_the_mcap_recording(cli: Cli, humble_bag: Path) -> None:
    code, from_db3 = cli.json("check-tolerances", PLAN, humble_bag)
    _, from_mcap = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap")
    assert code == 0 and from_db3["ok"] is True
    assert from_db3 == from_mcap


def test_db3_file_written_by_rosbags_reports_the_same_violation(cli: Cli, tmp_path: Path) -> None:
    folder = rosbags_db3(tmp_path / "bumped", RECORDINGS / "tool_up_path_violation.mcap")
    code, from_db3 = cli.json("check-tolerances", PLAN, folder / "bumped.db3")
    _, from_mcap = cli.json("check-tolerances", PLAN, RECORDINGS / "tool_up_path_violation.mcap")
    assert code == 5 and from_db3["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    assert from_db3["violations"] == from_mcap["violations"]


@pytest.mark.parametrize("time_source", ["header", "log"])
def test_joint_states_of_a_db3_bag_equal_the_mcap_ones(humble_bag: Path, time_source: str) -> None:
    from_db3 = read_joint_states(humble_bag, time_source=time_source)
    from_mcap = read_joint_states(RECORDINGS / "tool_up_ok.mcap", time_source=time_source)
    assert from_db3.names == from_mcap.names and from_db3.start_ns == from_mcap.start_ns
    np.testing.assert_array_equal(from_db3.times_s, from_mcap.times_s)
    np.testing.assert_array_equal(from_db3.positions, from_mcap.positions)
    np.testing.assert_array_equal(from_db3.velocities, from_mcap.velocities)


def test_publishers_of_different_layouts_in_one_batch_are_decoded_apart(tmp_path: Path) -> None:
    # An arm (six joints) and a gripper (one, a longer name) share /joint_states: payloads differ in length.
    stamps = 1_700_000_000_000_000_000 + np.arange(400) * 5_000_000
    arm = np.linspace(0, 1, 400 * 6).reshape(400, 6)
    joints = [f"joint_{i}" for i in range(6)]
    arm_payloads = encode_joint_states(joints, stamps, arm)
    gripper_payloads = encode_joint_states(["gripper_finger_joint"], stamps, np.zeros((400, 1)))
    messages = [m for i in range(400) for m in (("/joint_states", JOINT_STATE, int(stamps[i]), arm_payloads[i]),
                                                 ("/joint_states", JOINT_STATE, int(stamps[i]), gripper_payloads[i]))]
    series = read_joint_states(humble_db3(tmp_path / "two.db3", messages), joints=joints)
    np.testing.assert_array_equal(series.positions, arm)


def test_inspect_lists_topics_counts_and_qos_of_a_bag_folder(cli: Cli, humble_bag: Path) -> None:
    code, document = cli.json("inspect", humble_bag)
    assert code == 0
    assert document["topics"] == [{"topic": "/joint_states", "type": JOINT_STATE, "encoding": "cdr",
                                   "count": 527, "durability": "volatile"}]
    assert "sqlite3" in document["library"] and "humble" in document["library"]
    assert document["duration_s"] == pytest.approx(summarize(RECORDINGS / "tool_up_ok.mcap").duration_s, abs=0.1)
    text = cli("inspect", humble_bag / "robot_run_1.db3")
    assert text.exit_code == 0 and "/joint_states" in text.stdout


def test_folder_without_metadata_reads_its_splits_in_number_order(tmp_path: Path) -> None:
    messages = mcap_messages(RECORDINGS / "tool_up_ok.mcap")
    folder = tmp_path / "unfinished"
    folder.mkdir()
    for split, part in enumerate(np.array_split(np.arange(len(messages)), 11)):  # _10 sorts before _2 by name
        humble_db3(folder / f"unfinished_{split}.db3", [messages[i] for i in part])
    series = read_joint_states(folder)
    np.testing.assert_array_equal(series.positions, read_joint_states(RECORDINGS / "tool_up_ok.mcap").positions)


@pytest.mark.parametrize("command", ["check-tolerances", "inspect"])
@pytest.mark.parametrize("damage", ["truncated", "overwritten"])
def test_damaged_db3_exits_3_with_one_line_naming_it(cli: Cli, tmp_path: Path, command: str, damage: str) -> None:
    path = humble_db3(tmp_path / "damaged.db3", mcap_messages(RECORDINGS / "tool_up_ok.mcap"))
    data = bytearray(path.read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    else:
        data[4096 : len(data) - 4096] = b"\xa5" * (len(data) - 8192)
    path.write_bytes(bytes(data))
    args = [PLAN, path] if command == "check-tolerances" else [path]
    result = cli(command, *args)
    assert result.exit_code == 3, result.stderr
    assert "damaged.db3" in result.stderr and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_sqlite_file_that_is_no_bag_and_text_named_db3_are_refused(tmp_path: Path) -> None:
    other = tmp_path / "other.db3"
    sqlite3.connect(other).execute("CREATE TABLE notes(text TEXT)").connection.commit()
    with pytest.raises(InputError, match=r"other\.db3: not a rosbag2 sqlite3 bag \(no table messages, topics\)"):
        read_joint_states(other)
    text = tmp_path / "notes.db3"
    text.write_text("robot: ur10e\n")
    with pytest.raises(InputError, match=r"notes\.db3: not a rosbag2 sqlite3 file"):
        summarize(text)


def test_compressed_bag_is_refused_saying_how_to_read_it(cli: Cli, humble_bag: Path) -> None:
    metadata = humble_bag / "metadata.yaml"
    text = metadata.read_text().replace('compression_format: ""', "compression_format: zstd")
    metadata.write_text(text.replace('compression_mode: ""', "compression_mode: FILE"))
    result = cli("check-tolerances", PLAN, humble_bag)
    assert result.exit_code == 3
    assert "metadata.yaml" in result.stderr and "compressed" in result.stderr and "decompress" in result.stderr


def test_metadata_naming_a_missing_split_is_bad_input(cli: Cli, humble_bag: Path) -> None:
    (humble_bag / "robot_run_1.db3").unlink()
    result = cli("inspect", humble_bag)
    assert result.exit_code == 3
    assert "robot_run_1.db3" in result.stderr and "Traceback" not in result.stderr


def test_missing_topic_lists_the_topics_of_the_db3(cli: Cli, humble_bag: Path) -> None:
    result = cli("check-tolerances", PLAN, humble_bag, "--topic", "/robot/joint_states")
    assert result.exit_code == 3
    assert "no topic /robot/joint_states" in result.stderr
    assert "/joint_states (sensor_msgs/msg/JointState)" in result.stderr


@pytest.mark.parametrize("time_source", ["header", "log"])
def test_many_batches_with_sparse_ids_read_in_id_order(tmp_path: Path, time_source: str) -> None:
    count = 20_000  # several batches of ids
    stamps = 1_700_000_000_000_000_000 + np.arange(count) * 1_000_000
    positions = np.random.default_rng(2).normal(size=(count, 6))
    payloads = encode_joint_states([f"joint_{i}" for i in range(6)], stamps, positions)
    path = humble_db3(tmp_path / "merged.db3", [("/joint_states", JOINT_STATE, int(s) + 7, p)
                                                for s, p in zip(stamps, payloads, strict=True)])
    connection = sqlite3.connect(path)
    # A merged bag: the second half renumbered far away, the last message at SQLite's largest id.
    connection.execute("UPDATE messages SET id = id + 4611686018427387904 WHERE id > 10000")
    connection.execute("UPDATE messages SET id = 9223372036854775807 WHERE id = (SELECT max(id) FROM messages)")
    connection.commit()
    connection.close()
    series = read_joint_states(path, time_source=time_source)
    np.testing.assert_array_equal(series.positions, positions)
    assert series.start_ns == stamps[0] + (7 if time_source == "log" else 0)
    np.testing.assert_allclose(series.times_s, np.arange(count) * 1e-3, atol=1e-12)
