"""Hostile rosbag2 sqlite3 recordings and bag folders: one line naming the file and the problem, exit 3.

Rows rosbag2 never writes (a topic id of no topic, a NULL or text payload, a timestamp that is
no integer) are damage, reported as such; a bag folder's metadata.yaml may name only files
inside the folder, each once, and never itself.
"""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import pytest
from conftest import Cli
from test_db3 import DATA, HUMBLE_SCHEMA, JOINT_STATE, PLAN, QOS, RECORDINGS, humble_db3, mcap_messages

MESSAGES = mcap_messages(RECORDINGS / "tool_up_ok.mcap")


def one_line(result) -> str:  # noqa: ANN001 - click's Result
    """Return the error's one line on stderr (asserting it is the only line and no traceback)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    return lines[0]


def damaged(tmp_path: Path, sql: str, name: str = "damaged.db3") -> Path:
    """The recording as a Humble .db3, then changed by `sql`."""
    path = humble_db3(tmp_path / name, MESSAGES)
    connection = sqlite3.connect(path)
    connection.execute(sql)
    connection.commit()
    connection.close()
    return path


def null_payloads(tmp_path: Path) -> Path:
    """A .db3 whose messages table lets data be NULL, and every payload is."""
    path = tmp_path / "null.db3"
    connection = sqlite3.connect(path)
    connection.executescript(HUMBLE_SCHEMA.replace("data BLOB NOT NULL", "data BLOB"))
    connection.execute("INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) "
                       "VALUES (?, ?, ?, ?)", ("/joint_states", JOINT_STATE, "cdr", QOS))
    connection.executemany("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, 1, NULL)",
                           [(log_time,) for _, _, log_time, _ in MESSAGES])
    connection.commit()
    connection.close()
    return path


def check(cli: Cli, recording: Path, *args: object) -> tuple[int, str]:
    """Run check-tolerances of the sample plan against `recording`; return exit code and the one line."""
    result = cli("check-tolerances", PLAN, recording, *args)
    return result.exit_code, one_line(result)


@pytest.mark.parametrize(("sql", "problem"), [
    ("UPDATE messages SET topic_id = 99 WHERE id > 10", "message row 11 names topic id 99, which the topics table"),
    ("UPDATE messages SET timestamp = 'abc' WHERE id = 5", "message row 5: its timestamp is text, not an integer"),
    ("UPDATE messages SET timestamp = 9.9e300 WHERE id = 5", "message row 5: its timestamp is real, not an integer"),
    ("UPDATE messages SET data = 'hello'", "JointState message is too short or not plain CDR"),
])
def test_rows_rosbag2_never_writes_are_damage_named_by_row(cli: Cli, tmp_path: Path, sql: str,
                                                           problem: str) -> None:
    code, message = check(cli, damaged(tmp_path, sql))
    assert code == 3
    assert "damaged.db3" in message and problem in message


def test_null_payloads_are_damage_not_an_internal_error(cli: Cli, tmp_path: Path) -> None:
    code, message = check(cli, null_payloads(tmp_path))
    assert code == 3
    assert "null.db3" in message and "message row 1: its data is null, not a blob" in message


@pytest.mark.parametrize(("sql", "problem"), [
    ("UPDATE messages SET timestamp = 'abc' WHERE id = 5", "timestamp is 'abc', not an integer number of nanoseconds"),
    ("UPDATE messages SET timestamp = 9.9e300 WHERE id = 5", "timestamp is 9.9e+300, not an integer"),
])
def test_inspect_of_a_text_or_real_timestamp_is_bad_input(cli: Cli, tmp_path: Path, sql: str, problem: str) -> None:
    result = cli("inspect", damaged(tmp_path, sql))
    assert result.exit_code == 3
    message = one_line(result)
    assert "damaged.db3" in message and problem in message


def test_inspect_counts_rows_of_no_topic_as_damage(cli: Cli, tmp_path: Path) -> None:
    path = damaged(tmp_path, "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) "
                             "VALUES ('/tf', 'tf2_msgs/msg/TFMessage', 'cdr', '')")
    connection = sqlite3.connect(path)
    connection.execute("UPDATE messages SET topic_id = 7 WHERE id % 3 = 0")
    connection.commit()
    connection.close()
    result = cli("inspect", path)
    assert result.exit_code == 3
    assert "names topic id 7, which the topics table does not have" in one_line(result)


@pytest.mark.parametrize(("build", "command", "code", "problem"), [
    (lambda d: (d / "empty.db3").write_bytes(b"") or d / "empty.db3", "check-tolerances", 3,
     "not a rosbag2 sqlite3 file"),
    (lambda d: (d / "header.db3").write_bytes(b"SQLite format 3\x00") and d / "header.db3", "inspect", 3,
     "corrupt or truncated sqlite3 file"),
    (lambda d: humble_db3(d / "zero.db3", []), "check-tolerances", 3, "no topic /joint_states"),
])
def test_empty_or_truncated_db3_is_one_line(cli: Cli, tmp_path: Path, build, command: str, code: int,  # noqa: ANN001
                                            problem: str) -> None:
    path = build(tmp_path)
    result = cli(command, *([PLAN, path] if command == "check-tolerances" else [path]))
    assert result.exit_code == code
    message = one_line(result)
    assert path.name in message and problem in message


def test_db3_of_a_topic_with_no_messages_says_so(cli: Cli, tmp_path: Path) -> None:
    path = humble_db3(tmp_path / "silent.db3", MESSAGES)
    connection = sqlite3.connect(path)
    connection.execute("DELETE FROM messages")
    connection.commit()
    connection.close()
    code, message = check(cli, path)
    assert code == 3
    assert "silent.db3: no messages on /joint_states" in message


@pytest.fixture()
def bag(tmp_path: Path) -> Path:
    """The recording as a Humble bag folder of two splits."""
    folder = tmp_path / "robot_run"
    folder.mkdir()
    humble_db3(folder / "robot_run_0.db3", MESSAGES[:264])
    humble_db3(folder / "robot_run_1.db3", MESSAGES[264:])
    shutil.copy(DATA / "metadata.yaml", folder / "metadata.yaml")
    return folder


def relist(bag: Path, second: str) -> None:
    """Make metadata.yaml list `second` in place of the bag's second split."""
    metadata = bag / "metadata.yaml"
    metadata.write_text(metadata.read_text().replace("- robot_run_1.db3", f"- {second}"))


@pytest.mark.parametrize("command", ["check-tolerances", "inspect"])
@pytest.mark.parametrize(("second", "problem"), [
    ("../elsewhere.db3", "lists ../elsewhere.db3, outside the bag folder"),
    ("ABSOLUTE", "outside the bag folder"),
    ("metadata.yaml", "lists itself as a split file"),
    ("robot_run_0.db3", "lists robot_run_0.db3 twice"),
    ("''", "relative_file_paths: expected a list of file names"),
])
def test_metadata_naming_a_file_outside_the_folder_itself_or_twice_is_refused(
        cli: Cli, bag: Path, command: str, second: str, problem: str) -> None:
    shutil.copy(bag / "robot_run_1.db3", bag.parent / "elsewhere.db3")
    relist(bag, str(bag.parent / "elsewhere.db3") if second == "ABSOLUTE" else second)
    result = cli(command, *([PLAN, bag] if command == "check-tolerances" else [bag]))
    assert result.exit_code == 3
    message = one_line(result)
    assert "metadata.yaml" in message and problem in message


@pytest.mark.parametrize(("text", "problem"), [
    ("rosbag2_bagfile_information: [\n", "malformed YAML"),
    ("- a\n", "not a rosbag2 metadata.yaml"),
    ("", "not a rosbag2 metadata.yaml"),
])
def test_metadata_that_is_no_rosbag2_metadata_is_refused(cli: Cli, bag: Path, text: str, problem: str) -> None:
    (bag / "metadata.yaml").write_text(text)
    code, message = check(cli, bag)
    assert code == 3
    assert "metadata.yaml" in message and problem in message


def test_folder_holding_no_bag_is_refused(cli: Cli, tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("not a bag")
    code, message = check(cli, tmp_path)
    assert code == 3
    assert "folder holds no .mcap or .db3 file" in message


def test_bag_folder_with_a_link_into_itself_reads_as_the_recording(cli: Cli, bag: Path) -> None:
    (bag / "inner").symlink_to(bag)
    code, document = cli.json("check-tolerances", PLAN, bag)
    assert code == 0 and document["ok"] is True
