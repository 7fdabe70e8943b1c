"""Hostile recordings (issue 26): damaged CRCs, decompression bombs, absurd sizes, corrupt or live .db3 files, devices.

Each is refused with exit 3 and one line naming the file (and, for MCAP damage, the part's byte
offset and the check it fails), never a traceback, never gigabytes of memory: the tests build
each input small and assert the error that stops the read before the memory is spent.
`--skip-damaged` reads past damaged MCAP parts instead, saying what it skipped.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sqlite3
import struct
import zlib
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import zstandard
from conftest import SCHEMAS, Cli, run_process, write_bag
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.reader import make_reader
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Header,
    McapRecord,
    Message,
    MessageIndex,
    Schema,
    Statistics,
)
from mcap.writer import CompressionType, Writer
from test_checking import HOME, JOINTS, PICK, Plan, jtc, minimum_jerk
from test_db3 import humble_db3, mcap_messages
from test_hostile_recordings import PLAN, RECORDINGS, edited_plan, one_error_line

from moveplan.core.bag.jointstates import encode_joint_states, read_joint_states
from moveplan.core.bag.plan_file import PlanStepRecord
from moveplan.core.config.controllers import ExecutionConfig
from moveplan.core.control.check._alignment import PROFILE_SAMPLES, StepProfile
from moveplan.core.control.check._context import PLAN_PROFILE_SAMPLES, CheckContext
from moveplan.core.control.check.samples import source_of
from moveplan.core.pipeline.inspection import inspect_file
from moveplan.core.types import JointStateSeries

JOINT_STATE = "sensor_msgs/msg/JointState"
MAGIC = b"\x89MCAP0\r\n"
GiB = 1 << 30
OK = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
LOG_TIMES = OK.start_ns + np.round(OK.times_s * 1e9).astype(np.int64)
DB3_MESSAGES = mcap_messages(RECORDINGS / "tool_up_ok.mcap")
MESSAGES = [(int(t), p) for t, p in zip(LOG_TIMES, encode_joint_states(OK.names, LOG_TIMES, OK.positions),
                                        strict=True)]


def put(out: bytearray, record: McapRecord) -> int:
    """Append `record` to `out`; return where it starts."""
    builder = RecordBuilder()
    record.write(builder)
    at = len(out)
    out.extend(builder.end())
    return at


def raw_mcap(path: Path, messages: Sequence[tuple[int, bytes]] = MESSAGES, *, per_chunk: int = 64,
             edit: Callable[[int, Chunk], Chunk] | None = None,
             attachments: Sequence[tuple[str, bytes]] = ()) -> Path:
    """Write /joint_states (log time, payload) messages as an indexed MCAP file, record by record.

    Unlike mcap's Writer, every field can be made hostile: `edit(number, chunk)` returns the
    chunk to write in place of chunk `number` (zstd-compressed, its CRC computed), and the
    chunk index then declares what the edited chunk declares.
    """
    out = bytearray(MAGIC)
    put(out, Header("ros2", "hostile"))
    schema = Schema(1, SCHEMAS[JOINT_STATE], "ros2msg", JOINT_STATE)
    channel = Channel(1, "/joint_states", "cdr", {}, 1)
    attachment_indexes = []
    for name, data in attachments:
        at = put(out, Attachment(0, 0, name, "text/plain", data))
        attachment_indexes.append(AttachmentIndex(at, len(out) - at, 0, 0, len(data), name, "text/plain"))
    chunk_indexes = []
    for number, first in enumerate(range(0, len(messages), per_chunk)):
        part = messages[first : first + per_chunk]
        inner, rows = bytearray(), []
        for record in [schema, channel] if number == 0 else []:
            put(inner, record)
        for sequence, (log_time, data) in enumerate(part):
            rows.append((log_time, put(inner, Message(1, log_time, data, log_time, sequence))))
        chunk = Chunk(compression="zstd", data=zstandard.ZstdCompressor().compress(bytes(inner)),
                      message_start_time=part[0][0], message_end_time=part[-1][0],
                      uncompressed_crc=zlib.crc32(inner), uncompressed_size=len(inner))
        if edit is not None:
            chunk = edit(number, chunk)
        at = put(out, chunk)
        length = len(out) - at
        index_at = put(out, MessageIndex(1, rows))
        chunk_indexes.append(ChunkIndex(
            chunk_length=length, chunk_start_offset=at, compression=chunk.compression,
            compressed_size=len(chunk.data), message_end_time=chunk.message_end_time,
            message_index_length=len(out) - index_at, message_index_offsets={1: index_at},
            message_start_time=chunk.message_start_time, uncompressed_size=chunk.uncompressed_size))
    put(out, DataEnd(0))
    summary_start = len(out)
    for record in (schema, channel, *chunk_indexes, *attachment_indexes,
                   Statistics(len(attachments), 1, {1: len(messages)}, len(chunk_indexes), len(messages),
                              messages[-1][0], messages[0][0], 0, 1)):
        put(out, record)
    out.extend(struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, 0))
    out.extend(struct.pack("<I", zlib.crc32(out[summary_start:])))
    path.write_bytes(bytes(out + MAGIC))
    return path


def zstd_bomb(size: int) -> bytes:
    """A zstd frame that unpacks to `size` zero bytes, its header declaring them: 4 bytes per 128 KiB (RLE blocks)."""
    block = 1 << 17
    frame = bytearray(struct.pack("<IBB", 0xFD2FB528, 0xC0, 0x38))  # 8-byte content size; window 128 KiB
    frame += struct.pack("<Q", size)
    for at in range(0, size, block):
        n = min(block, size - at)
        header = (1 if at + n == size else 0) | (1 << 1) | (n << 3)
        frame += struct.pack("<I", header)[:3] + b"\x00"
    return bytes(frame)


def chunk_offsets(path: Path) -> list[int]:
    """Where each chunk of an indexed MCAP file starts."""
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return sorted(index.chunk_start_offset for index in summary.chunk_indexes)


def warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    """The warnings logged since the last call (the CLI prints them on stderr), then forgotten."""
    found = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    caplog.clear()
    return found


def check(cli: Cli, recording: Path, *args: object) -> Any:
    return cli("check-tolerances", PLAN, recording, *args)


# --- CRC mismatches -----------------------------------------------------------------------------


@pytest.fixture()
def hidden_violation(tmp_path: Path) -> tuple[Path, int]:
    """tool_up_ok with a violation recorded in an uncompressed chunk, whose bytes on disk were then put back.

    The chunk's CRC is the violation's: read as if sound, the file passes (the defect found).
    Returns the file and where the damaged chunk starts.
    """
    positions = OK.positions.copy()
    bumped = positions[200, 3] + 0.5  # wrist_1_joint far outside its 0.2 rad path tolerance
    positions[200, 3] = bumped
    payloads = encode_joint_states(OK.names, LOG_TIMES, positions)
    path = write_bag(tmp_path / "hidden.mcap", [("/joint_states", JOINT_STATE, int(t), p)
                                                for t, p in zip(LOG_TIMES, payloads, strict=True)],
                     compression=CompressionType.NONE)
    data = bytearray(path.read_bytes())
    at = data.find(struct.pack("<d", bumped))
    assert at > 0 and data.count(struct.pack("<d", bumped)) == 1
    data[at : at + 8] = struct.pack("<d", OK.positions[200, 3])
    chunk = max(start for start in chunk_offsets(path) if start < at)
    (tmp_path / "violation.mcap").write_bytes(path.read_bytes())
    path.write_bytes(bytes(data))
    return path, chunk


def test_crc_mismatch_that_hides_a_violation_is_bad_input_naming_file_and_chunk(
        cli: Cli, hidden_violation: tuple[Path, int]) -> None:
    path, chunk = hidden_violation
    assert check(cli, path.with_name("violation.mcap")).exit_code == 5  # what the chunk held
    for result in (check(cli, path), cli("inspect", path)):
        assert result.exit_code == 3, result.stderr
        line = one_error_line(result)
        assert "hidden.mcap" in line and f"the chunk at byte {chunk} fails its CRC check" in line
        assert "--skip-damaged" in line
    code, document = cli.json("check-tolerances", PLAN, path)
    assert code == 3 and f"chunk at byte {chunk}" in document["error"]["message"]


def test_crc_mismatch_with_skip_damaged_is_skipped_with_a_warning_and_listed(
        cli: Cli, hidden_violation: tuple[Path, int], caplog: pytest.LogCaptureFixture) -> None:
    path, chunk = hidden_violation
    result = check(cli, path, "--skip-damaged", "--json")
    assert result.exit_code == 0, result.stderr  # the violation lay in the chunk skipped: a gap now
    [skipped] = json.loads(result.stdout)["skipped"]
    assert skipped["file"] == str(path) and skipped["offset"] == chunk and skipped["part"] == "chunk"
    assert "fails its CRC check" in skipped["reason"]
    [skip] = [line for line in warnings(caplog) if "skipped the chunk" in line]
    assert str(path) in skip and f"at byte {chunk} (--skip-damaged): it fails its CRC check" in skip
    assert cli("inspect", path, "--skip-damaged").exit_code == 0
    assert any(f"skipped the chunk at byte {chunk}" in line for line in warnings(caplog))
    code, document = cli.json("inspect", path, "--skip-damaged")
    assert code == 0 and [(s["offset"], s["part"]) for s in document["skipped"]] == [(chunk, "chunk")]
    summary = inspect_file(path, skip_damaged=True).summary
    assert [(s.offset, s.part) for s in summary.skipped] == [(chunk, "chunk")]
    [topic] = summary.topics
    assert 0 < topic.count < len(OK.times_s)  # the skipped chunk's messages are not counted
    assert check(cli, path).exit_code == 3  # without the flag, still refused


def test_crc_mismatch_in_a_process_is_one_line_or_one_warning(hidden_violation: tuple[Path, int]) -> None:
    path, chunk = hidden_violation
    refused = run_process("check-tolerances", PLAN, path)
    assert refused.returncode == 3 and refused.stdout == "" and "Traceback" not in refused.stderr
    [line] = refused.stderr.splitlines()
    assert line.startswith(f"moveplan: error: {path}: corrupt MCAP data: the chunk at byte {chunk} fails its CRC")
    skipped = run_process("check-tolerances", PLAN, path, "--skip-damaged", "--json")
    assert skipped.returncode == 0 and json.loads(skipped.stdout)["skipped"][0]["offset"] == chunk
    assert f"{path}: skipped the chunk at byte {chunk} (--skip-damaged)" in skipped.stderr


def test_crc_of_zero_means_not_computed_and_is_no_error(cli: Cli, tmp_path: Path) -> None:
    path = raw_mcap(tmp_path / "nocrc.mcap", edit=lambda _, chunk: replace(chunk, uncompressed_crc=0))
    assert check(cli, path).exit_code == 0
    assert cli("inspect", path).exit_code == 0


def test_summary_crc_mismatch_is_bad_input_or_read_linearly_when_skipped(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = raw_mcap(tmp_path / "summary.mcap")
    data = bytearray(path.read_bytes())
    (summary_start,) = struct.unpack_from("<Q", data, len(data) - 37 + 9)
    data[-12:-8] = struct.pack("<I", struct.unpack_from("<I", data, len(data) - 12)[0] ^ 1)
    path.write_bytes(bytes(data))
    result = check(cli, path)
    assert result.exit_code == 3
    assert f"summary.mcap: corrupt MCAP data: the summary section at byte {summary_start} fails its CRC" in (
        one_error_line(result))
    caplog.clear()
    result = check(cli, path, "--skip-damaged")
    assert result.exit_code == 0, result.stderr
    assert [line for line in warnings(caplog) if "summary" in line] == [
        f"{path}: skipped the summary section at byte {summary_start} (--skip-damaged): it fails its CRC check: "
        f"its CRC-32 is {zlib.crc32(data[summary_start:-12]):#010x}, the footer records "
        f"{struct.unpack_from('<I', data, len(data) - 12)[0]:#010x}"]
    assert cli("inspect", path, "--skip-damaged").exit_code == 0


def test_data_section_crc_mismatch_is_bad_input_naming_the_data_end(cli: Cli, tmp_path: Path) -> None:
    path = tmp_path / "data_crc.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=4096, enable_data_crcs=True)
        writer.start("ros2", "hostile-writer")
        schema = writer.register_schema(JOINT_STATE, "ros2msg", SCHEMAS[JOINT_STATE])
        channel = writer.register_channel("/joint_states", "cdr", schema)
        for log_time, payload in MESSAGES:
            writer.add_message(channel, log_time, payload, log_time)
        writer.finish()
    assert check(cli, path).exit_code == 0  # the CRC mcap's writer computed is the one checked
    data = bytearray(path.read_bytes())
    data[data.find(b"hostile-writer")] ^= 0x20  # a header byte: no chunk's CRC covers it
    path.write_bytes(bytes(data))
    for result in (check(cli, path), cli("inspect", path)):
        assert result.exit_code == 3
        line = one_error_line(result)
        assert "data_crc.mcap" in line and "the data section at byte 0 fails its CRC check" in line
        assert "the DataEnd record at byte" in line
    assert check(cli, path, "--skip-damaged").exit_code == 0


def test_attachment_crc_mismatch_is_bad_input_for_inspect(
        cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = raw_mcap(tmp_path / "attached.mcap", attachments=[("notes.txt", b"calibrated on monday")])
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    [index] = summary.attachment_indexes
    at = index.offset
    data = bytearray(path.read_bytes())
    data[data.find(b"monday")] = ord("s")
    path.write_bytes(bytes(data))
    result = cli("inspect", path)
    assert result.exit_code == 3
    assert f"attached.mcap: corrupt MCAP data: the attachment 'notes.txt' at byte {at} fails its CRC check" in (
        one_error_line(result))
    caplog.clear()
    assert cli("inspect", path, "--skip-damaged").exit_code == 0
    assert any(f"skipped the attachment 'notes.txt' at byte {at}" in line for line in warnings(caplog))


def test_plan_with_a_damaged_chunk_is_refused_even_with_skip_damaged(cli: Cli, tmp_path: Path) -> None:
    plan = tmp_path / "plan.mcap"
    data = bytearray(PLAN.read_bytes())
    chunk = chunk_offsets(PLAN)[0]
    crc_at = chunk + 9 + 24  # record head, start and end times, uncompressed size
    data[crc_at : crc_at + 4] = struct.pack("<I", struct.unpack_from("<I", data, crc_at)[0] ^ 1)
    plan.write_bytes(bytes(data))
    for args in (["check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap", "--skip-damaged"],
                 ["inspect", plan, "--skip-damaged"]):
        result = cli(*args)
        assert result.exit_code == 3
        assert f"plan.mcap: corrupt MCAP data: the chunk at byte {chunk} fails its CRC check" in (
            one_error_line(result))


# --- decompression bombs and declared sizes -----------------------------------------------------


def test_zstd_bomb_stops_at_the_size_its_chunk_declares(cli: Cli, tmp_path: Path) -> None:
    bomb = zstd_bomb(3 * GiB)  # 96 KB on disk, its frame header claiming all 3 GiB
    path = raw_mcap(tmp_path / "zbomb.mcap", edit=lambda n, chunk: replace(chunk, data=bomb) if n == 2 else chunk)
    chunk = chunk_offsets(path)[2]
    for result in (check(cli, path), cli("inspect", path)):
        assert result.exit_code == 3
        line = one_error_line(result)
        assert "zbomb.mcap" in line and f"the chunk at byte {chunk} decompresses to more than the" in line


def test_lz4_bomb_stops_at_the_size_its_chunk_declares(cli: Cli, tmp_path: Path) -> None:
    lz4_frame = pytest.importorskip("lz4.frame")
    compressor = lz4_frame.LZ4FrameCompressor()
    zeros = bytes(64 << 20)
    bomb = compressor.begin() + b"".join(compressor.compress(zeros) for _ in range(16)) + compressor.flush()  # 1 GiB
    path = raw_mcap(tmp_path / "lbomb.mcap",
                    edit=lambda n, chunk: replace(chunk, compression="lz4", data=bomb) if n == 2 else chunk)
    chunk = chunk_offsets(path)[2]
    for result in (check(cli, path), cli("inspect", path)):
        assert result.exit_code == 3
        assert f"lbomb.mcap: corrupt MCAP data: the chunk at byte {chunk} decompresses to more than the" in (
            one_error_line(result))


def test_chunk_declaring_more_than_the_limit_is_refused_before_any_buffer(
        cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def huge(number: int, chunk: Chunk) -> Chunk:
        return replace(chunk, data=zstd_bomb(3 * GiB), uncompressed_size=3 * GiB, uncompressed_crc=0) if (
            number == 1) else chunk

    path = raw_mcap(tmp_path / "declared.mcap", edit=huge)
    chunk = chunk_offsets(path)[1]
    for result in (check(cli, path), cli("inspect", path)):
        assert result.exit_code == 3
        assert (f"the chunk at byte {chunk} declares 3221225472 bytes of records, more than "
                f"MOVEPLAN_MAX_CHUNK_BYTES allows ({GiB})") in one_error_line(result)
    # The limit is the user's: lowered below the sample's 16 KB chunks, they are refused too.
    monkeypatch.setenv("MOVEPLAN_MAX_CHUNK_BYTES", "8KiB")
    sound = raw_mcap(tmp_path / "sound.mcap")
    result = check(cli, sound)
    assert result.exit_code == 3 and "MOVEPLAN_MAX_CHUNK_BYTES allows (8192)" in one_error_line(result)
    monkeypatch.setenv("MOVEPLAN_MAX_CHUNK_BYTES", "lots")
    result = check(cli, sound)
    assert result.exit_code == 2 and "MOVEPLAN_MAX_CHUNK_BYTES='lots'" in one_error_line(result)


def with_summary_crc(data: bytearray) -> bytes:
    """The file `data` with its footer's summary CRC computed again, after an edit of its summary."""
    (summary_start,) = struct.unpack_from("<Q", data, len(data) - 28)
    data[-12:-8] = struct.pack("<I", zlib.crc32(data[summary_start:-12]))
    return bytes(data)


def message_offsets(records: bytes) -> list[int]:
    """Where each Message record of a chunk's records starts."""
    offsets, at = [], 0
    while at < len(records):
        opcode, length = struct.unpack_from("<BQ", records, at)
        if opcode == Opcode.MESSAGE:
            offsets.append(at)
        at += 9 + length
    return offsets


def long_message(number: int, chunk: Chunk) -> Chunk:
    """The chunk uncompressed, its 10th message claiming 2^60 bytes (its CRC computed again: only the length lies)."""
    records = bytearray(zstandard.ZstdDecompressor().decompress(chunk.data))
    at = message_offsets(bytes(records))[10]
    records[at + 1 : at + 9] = struct.pack("<Q", 1 << 60)
    return replace(chunk, compression="", data=bytes(records), uncompressed_crc=zlib.crc32(records))


def test_absurd_chunk_length_in_the_index_is_bad_input(cli: Cli, tmp_path: Path) -> None:
    path = raw_mcap(tmp_path / "absurd.mcap")
    data = bytearray(path.read_bytes())
    start = chunk_offsets(path)[3]
    at = data.rfind(struct.pack("<Q", start))  # the chunk index's chunk_start_offset, then its chunk_length
    data[at + 8 : at + 16] = struct.pack("<Q", 1 << 62)
    path.write_bytes(with_summary_crc(data))
    result = check(cli, path)
    assert result.exit_code == 3
    assert f"absurd.mcap: corrupt MCAP data: the chunk at byte {start} runs past the end of the file" in (
        one_error_line(result))


def test_absurd_message_length_and_offset_are_bad_input(cli: Cli, tmp_path: Path) -> None:
    path = raw_mcap(tmp_path / "long.mcap", edit=lambda number, chunk: long_message(number, chunk) if number == 1
                    else chunk)
    result = check(cli, path)
    assert result.exit_code == 3
    assert f"long.mcap: corrupt MCAP data: a message of the chunk at byte {chunk_offsets(path)[1]} runs past it" in (
        one_error_line(result))
    path = raw_mcap(tmp_path / "offset.mcap")
    data = bytearray(path.read_bytes())
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    index = min(summary.chunk_indexes, key=lambda i: i.chunk_start_offset)
    row = index.message_index_offsets[1] + 9 + 2 + 4 + 16 * 5  # the 6th (log time, offset) row
    data[row + 8 : row + 16] = struct.pack("<Q", 1 << 62)
    path.write_bytes(bytes(data))
    result = check(cli, path)
    assert result.exit_code == 3
    assert "offset.mcap: corrupt MCAP data: a message index of the chunk at byte" in one_error_line(result)


def test_absurd_message_count_allocates_nothing(cli: Cli, tmp_path: Path) -> None:
    path = raw_mcap(tmp_path / "counts.mcap")
    data = bytearray(path.read_bytes())
    (summary_start,) = struct.unpack_from("<Q", data, len(data) - 28)
    count = struct.pack("<Q", len(MESSAGES))  # Statistics' message_count and the channel's count
    data[summary_start:] = data[summary_start:].replace(count, struct.pack("<Q", (1 << 63) - 1))
    path.write_bytes(with_summary_crc(data))
    assert check(cli, path).exit_code == 0  # the count is a number shown, never a size allocated
    code, document = cli.json("inspect", path)
    assert code == 0 and document["topics"][0]["count"] == (1 << 63) - 1


# --- plans of absurd duration -------------------------------------------------------------------


def test_plan_longer_than_a_day_is_bad_input_naming_the_plan(cli: Cli, tmp_path: Path) -> None:
    def int32_seconds(message: Any) -> None:
        message.points[-1].time_from_start.sec = 2**31 - 1

    plan = edited_plan(tmp_path / "forever.mcap", int32_seconds)
    for args in (["check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap"], ["inspect", plan],
                 ["check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap", "--start", "all"]):
        result = cli(*args)
        assert result.exit_code == 3
        line = one_error_line(result)
        assert "forever.mcap: step 'up' ends 2.14748e+09 s after the plan's start" in line and "86400 s" in line


def test_plan_of_hours_is_checked_in_memory_bounded_by_the_recording(cli: Cli, tmp_path: Path) -> None:
    def stretched(message: Any) -> None:  # 10,000 s: 10 M samples at 1 ms
        for point in message.points:
            t = (point.time_from_start.sec + point.time_from_start.nanosec * 1e-9) * 2e4
            point.time_from_start.sec, point.time_from_start.nanosec = int(t), int(t % 1 * 1e9)

    plan = edited_plan(tmp_path / "hours.mcap", stretched)
    code, document = cli.json("check-tolerances", plan, RECORDINGS / "tool_up_ok.mcap")
    assert code == 3 and "tool_up_ok.mcap: the recording ends" in document["error"]["message"]


def test_profiles_of_a_long_plan_share_a_bounded_grid() -> None:
    steps = tuple(PlanStepRecord(f"s{i}", 1000.0 * i, minimum_jerk(HOME, PICK, 1000.0) if i % 2 == 0
                                 else minimum_jerk(PICK, HOME, 1000.0)) for i in range(40))
    times = np.arange(0.0, 2.0, 0.004)
    series = JointStateSeries(JOINTS, times, np.tile(HOME, (len(times), 1)), None, 0, "header", "rest.mcap")
    context = CheckContext.build(Plan(steps), source_of(series), jtc(), ExecutionConfig(), ())
    total = sum(len(profile.times) for profile in context.profiles)
    assert total <= PLAN_PROFILE_SAMPLES + 2 * len(steps)  # 40 steps at 1 ms would be 40 x 1 M points
    longest = StepProfile.build("long", minimum_jerk(HOME, PICK, 2000.0), np.zeros(6, dtype=bool), 0.02)
    assert len(longest.times) == PROFILE_SAMPLES


# --- rosbag2 sqlite3 files ----------------------------------------------------------------------


def garbage_page(path: Path) -> None:
    """Overwrite the page holding a message's data mid-table: a count never visits it."""
    data = bytearray(path.read_bytes())
    page = data.find(DB3_MESSAGES[300][3]) // 4096
    assert page > 1
    data[page * 4096 : (page + 1) * 4096] = b"\xa5" * 4096
    path.write_bytes(bytes(data))


def sql(statement: str) -> Callable[[Path], None]:
    def run(path: Path) -> None:
        connection = sqlite3.connect(path)
        connection.execute(statement)
        connection.commit()
        connection.close()
    return run


@pytest.mark.parametrize(("damage", "commands", "problem"), [
    (lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]), ("inspect", "check-tolerances"),
     "corrupt or truncated sqlite3 file"),
    (garbage_page, ("inspect", "check-tolerances"), "corrupt"),
    (sql("DROP TABLE topics"), ("inspect", "check-tolerances"), "not a rosbag2 sqlite3 bag (no table topics)"),
    (sql("UPDATE messages SET data = substr(data, 1, 20) WHERE id = 100"), ("check-tolerances",),
     "JointState message"),
    (sql("UPDATE messages SET data = CAST(X'00010000' || zeroblob(8) || X'FFFFFFFF' || zeroblob(300) AS BLOB) "
         "WHERE id = 100"),
     ("check-tolerances",), "JointState message"),
], ids=["truncated", "garbage_page", "missing_table", "cut_cdr", "undecodable_cdr"])
def test_corrupt_db3_is_bad_input_naming_it(cli: Cli, tmp_path: Path, damage: Callable[[Path], None],
                                            commands: tuple[str, ...], problem: str) -> None:
    path = humble_db3(tmp_path / "corrupt.db3", DB3_MESSAGES)
    damage(path)
    for command in commands:
        result = cli(command, *([PLAN, path] if command == "check-tolerances" else [path]))
        assert result.exit_code == 3, (command, result.stderr)
        line = one_error_line(result)
        assert "corrupt.db3" in line and problem in line


def folder_state(folder: Path) -> dict[str, tuple[int, str]]:
    """Every file of a folder: modification time [ns] and content hash."""
    return {p.name: (p.stat().st_mtime_ns, hashlib.sha256(p.read_bytes()).hexdigest())
            for p in sorted(folder.iterdir())}


@pytest.fixture()
def live_bag(tmp_path: Path) -> Path:
    """A bag folder as a recorder in WAL mode leaves it when it dies: its last 227 messages only in the -wal file."""
    messages = mcap_messages(RECORDINGS / "tool_up_ok.mcap")
    source = humble_db3(tmp_path / "source.db3", messages[:300])
    writer = sqlite3.connect(source)
    writer.execute("PRAGMA journal_mode=WAL")
    writer.execute("PRAGMA wal_autocheckpoint=0")
    writer.executemany("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, 1, ?)",
                       [(log_time, data) for _, _, log_time, data in messages[300:]])
    writer.commit()
    folder = tmp_path / "crashed"
    folder.mkdir()
    shutil.copy(source, folder / "crashed_0.db3")
    shutil.copy(f"{source}-wal", folder / "crashed_0.db3-wal")  # copied while open: the crash
    writer.close()
    return folder


def test_db3_with_a_write_ahead_log_is_read_whole_and_left_untouched(cli: Cli, live_bag: Path) -> None:
    before = folder_state(live_bag)
    code, document = cli.json("inspect", live_bag / "crashed_0.db3")
    assert code == 0 and document["topics"][0]["count"] == len(OK.times_s)  # the log's rows too
    assert check(cli, live_bag).exit_code == 0
    assert check(cli, live_bag / "crashed_0.db3").exit_code == 0
    assert folder_state(live_bag) == before  # no -shm made, nothing checkpointed, no mtime moved


def test_db3_in_wal_mode_without_a_log_is_read_without_making_a_shm_file(cli: Cli, tmp_path: Path) -> None:
    folder = tmp_path / "closed"
    folder.mkdir()
    path = humble_db3(folder / "closed_0.db3", mcap_messages(RECORDINGS / "tool_up_ok.mcap"))
    sql("PRAGMA journal_mode=WAL")(path)  # the header says WAL; closing cleanly removed the log
    before = folder_state(folder)
    assert cli("inspect", path).exit_code == 0 and check(cli, path).exit_code == 0
    assert folder_state(folder) == before


# --- devices and pipes --------------------------------------------------------------------------


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom", "fifo"])
@pytest.mark.parametrize("where", ["recording", "inspect", "plan"])
def test_device_or_pipe_given_as_a_bag_is_refused_at_once(cli: Cli, tmp_path: Path, device: str, where: str) -> None:
    path = Path(device)
    if device == "fifo":
        path = tmp_path / "live.mcap"
        os.mkfifo(path)  # no writer: opening it would block forever
    args = {"recording": ["check-tolerances", PLAN, path], "inspect": ["inspect", path],
            "plan": ["check-tolerances", path, RECORDINGS / "tool_up_ok.mcap"]}[where]
    result = cli(*args)
    assert result.exit_code == 3
    line = one_error_line(result)
    kind = "a pipe" if device == "fifo" else "a character device"
    assert f"{path}: not a regular file ({kind})" in line
