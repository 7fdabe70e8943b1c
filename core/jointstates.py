"""Joint states from any MCAP file: sensor_msgs/msg/JointState messages as numpy columns.

Owns the JointState CDR layout in both directions (`encode_joint_states` builds payloads
for writers and tests) and a reader fast enough for hour-long 1 kHz recordings. The
generic MCAP readers spend their time in per-message Python (mcap-ros2-support reads
~22 k messages/s, rosbags ~50 k/s); this reader reads the summary's chunk indexes, then per
chunk one read, one decompression (zstd, lz4 or none) and the chunk's MessageIndex
offsets of the topic's channel, and decodes the rows whose bytes up to the position array
equal a template row's (same frame_id, same names, same array sizes) with numpy.
Rows laid out differently get their own template, or are decoded one by one. A file
without a usable summary (a recording that was cut off, or written without one) is read
by a linear scan, with a warning.

Only zstandard (and lz4, imported when a file uses it) and numpy: the mcap package stays
in core.recording, and this module reads the few record kinds it needs itself (MCAP
specification, records Header to Statistics). Chunk CRCs are not checked, as rosbag2
writes none (CRC 0) by default; decompression and the record structure still catch
damaged chunks.
"""

from __future__ import annotations

import logging
import re
import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from io import BufferedReader
from pathlib import Path
from typing import IO, Any, Literal

import numpy as np
import numpy.typing as npt
from numpy.lib.stride_tricks import as_strided, sliding_window_view
from numpy.typing import NDArray

from moveplan.core.errors import InputError, known

__all__ = ["JOINT_STATE_TYPE", "JointStateSeries", "encode_joint_states", "read_joint_states"]

logger = logging.getLogger(__name__)

JOINT_STATE_TYPE = "sensor_msgs/msg/JointState"

_MAGIC = b"\x89MCAP0\r\n"
_FOOTER, _SCHEMA, _CHANNEL, _MESSAGE, _CHUNK, _MESSAGE_INDEX, _CHUNK_INDEX = 2, 3, 4, 5, 6, 7, 8
_STATISTICS = 11
_RECORD_HEAD = 9  # opcode u8 + length u64
_FOOTER_SIZE = _RECORD_HEAD + 20 + len(_MAGIC)
# A Message record: head, channel_id u16, sequence u32, log_time u64, publish_time u64, data.
_MESSAGE_FIXED = 22
_DATA_AT = _RECORD_HEAD + _MESSAGE_FIXED
# Templates tried per batch before the remaining rows are decoded one by one: enough for
# a few publishers sharing a topic (arm and gripper), bounded for pathological files.
_MAX_LAYOUTS = 8
# Messages gathered from an unchunked file before they are decoded as one batch.
_BATCH = 8192
_EXPECTED_FIELDS = [
    ("header", ("std_msgs/Header", "std_msgs/msg/Header", "Header")),
    ("name", ("string[]",)),
    ("position", ("float64[]",)),
    ("velocity", ("float64[]",)),
    ("effort", ("float64[]",)),
]

TimeSource = Literal["header", "log"]


@dataclass(frozen=True)
class JointStateSeries:
    """Joint positions (and velocities) recorded on one topic, in a chosen joint order.

    Arrays are read-only. Read-only float64 arrays given to the constructor are kept as
    they are (an hour at 1 kHz is 170 MB per array); any other input is copied.

    Attributes:
        names: Joint order of the columns.
        times_s: Sample times in [s] from the first sample, non-decreasing, shape (N,).
        positions: In [rad] or [m], shape (N, n).
        velocities: In [rad]/[s] or [m]/[s], shape (N, n); None when the messages carry none.
        start_ns: Time of the first sample in [ns] (header stamp or log time), so
            `start_ns + times_s * 1e9` are the recorded times.
        time_source: "header" (the messages' header.stamp) or "log" (MCAP log time).
        source: The file or folder read, for messages.

    """

    names: tuple[str, ...]
    times_s: NDArray[np.float64]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64] | None
    start_ns: int
    time_source: TimeSource = "header"
    source: str = ""

    def __post_init__(self) -> None:
        """Check shapes and order, and freeze the arrays."""
        object.__setattr__(self, "names", tuple(self.names))
        times = _frozen(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        shape = (len(times), len(self.names))
        object.__setattr__(self, "positions", _frozen(self.positions, shape, "positions"))
        if self.velocities is not None:
            object.__setattr__(self, "velocities", _frozen(self.velocities, shape, "velocities"))
        if np.any(np.diff(times) < 0.0):
            raise ValueError("times_s must be non-decreasing")


def _frozen(value: npt.ArrayLike, shape: tuple[int | None, ...], name: str) -> NDArray[np.float64]:
    """Return `value` as a read-only float64 array of `shape`, copied unless already frozen."""
    if isinstance(value, np.ndarray) and value.dtype == np.float64 and not value.flags.writeable:
        array = value
    else:
        array = np.array(value, dtype=np.float64)
        array.setflags(write=False)
    if array.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(array.shape, shape, strict=True)
    ):
        raise ValueError(f"{name}: expected shape {shape}, got {array.shape}")
    return array


def read_joint_states(
    path: str | Path,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    time_source: TimeSource = "header",
) -> JointStateSeries:
    """Return the joint states recorded on `topic`, columns in the order of `joints`.

    Messages may list joints in any order and carry extra joints. Messages that lack one
    of `joints` (another publisher on the same topic, a gripper) are skipped, with a
    warning when some are. Samples are sorted by time.

    Args:
        path: An MCAP file, or a rosbag2 folder whose *.mcap files are read in split order.
        topic: The sensor_msgs/msg/JointState topic.
        joints: Joints to keep, in column order; None = those of the first message.
        time_source: "header" for header.stamp (falls back to log time, with a warning,
            when every stamp is zero), "log" for the MCAP log time (receive time).

    Raises:
        InputError: The file is missing, not MCAP, truncated or corrupt; the topic is
            absent (the message lists the topics present) or not JointState; or no
            message carries all of `joints` (the message lists the joints present).

    """
    if time_source not in ("header", "log"):
        raise ValueError(f"time_source must be 'header' or 'log', got {time_source!r}")
    source = Path(path)
    decoder = _Decoder(source, topic, tuple(joints) if joints is not None else None)
    for file in _files(source):
        _read_file(file, decoder)
    return decoder.series(time_source)


def encode_joint_states(
    names: Sequence[str],
    stamps_ns: npt.ArrayLike,
    positions: npt.ArrayLike,
    velocities: npt.ArrayLike | None = None,
    efforts: npt.ArrayLike | None = None,
    frame_id: str = "",
) -> list[bytes]:
    """Return one little-endian CDR sensor_msgs/msg/JointState payload per row of `positions`.

    Built with numpy: one template row (frame_id, names, array sizes) repeated, with
    stamps and values written into their columns, so a million messages take about a second.

    Args:
        names: Joint names, n.
        stamps_ns: header.stamp per message in [ns], shape (M,).
        positions: In [rad] or [m], shape (M, n).
        velocities: Shape (M, n), or None for empty arrays.
        efforts: Shape (M, n), or None for empty arrays.
        frame_id: header.frame_id of every message.

    """
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    count, n = len(stamps), len(names)
    columns = [None if v is None else np.asarray(v, dtype="<f8").reshape(count, n)
               for v in (positions, velocities, efforts)]
    head = bytearray(b"\x00\x01\x00\x00" + bytes(8))
    _put_string(head, frame_id)
    _align(head, 4)
    head += struct.pack("<I", n)
    for name in names:
        _align(head, 4)
        _put_string(head, name)
    offsets = []
    for values in columns:
        _align(head, 4)
        size = 0 if values is None else n
        head += struct.pack("<I", size)
        if size:
            _align(head, 8)
        offsets.append(len(head))
        head += bytes(8 * size)
    rows = np.empty((count, len(head)), dtype=np.uint8)
    rows[:] = np.frombuffer(bytes(head), dtype=np.uint8)
    seconds, nanoseconds = np.divmod(stamps, 1_000_000_000)
    rows[:, 4:8] = seconds.astype("<i4").view(np.uint8).reshape(count, 4)
    rows[:, 8:12] = nanoseconds.astype("<u4").view(np.uint8).reshape(count, 4)
    for offset, values in zip(offsets, columns, strict=True):
        if values is not None and n:
            rows[:, offset : offset + 8 * n] = np.ascontiguousarray(values).view(np.uint8)
    data, size = rows.tobytes(), rows.shape[1]
    return [data[i * size : (i + 1) * size] for i in range(count)]


def _put_string(buffer: bytearray, text: str) -> None:
    raw = text.encode() + b"\x00"
    buffer += struct.pack("<I", len(raw)) + raw


def _align(buffer: bytearray, alignment: int) -> None:
    # CDR aligns relative to the end of the 4-byte encapsulation header.
    buffer += bytes(-(len(buffer) - 4) % alignment)


# --- files and records ------------------------------------------------------------------


def _files(source: Path) -> list[Path]:
    """Return the MCAP files to read: `source` itself, or a rosbag2 folder's splits in order."""
    if source.is_dir():
        files = sorted(source.glob("*.mcap"), key=_split_order)
        if not files:
            raise InputError(f"{source}: folder holds no .mcap file")
        return files
    if not source.exists():
        raise InputError(f"{source}: file not found")
    return [source]


def _split_order(path: Path) -> tuple[str, int]:
    """Return a sort key putting rosbag2 splits name_0, name_1, ..., name_10 in order."""
    match = re.fullmatch(r"(.*?)(\d+)", path.stem)
    return (match.group(1), int(match.group(2))) if match else (path.stem, -1)


@dataclass(frozen=True)
class _ChunkIndex:
    start: int
    length: int
    message_index_offsets: dict[int, int]
    message_index_length: int
    uncompressed_size: int


@dataclass
class _Summary:
    schemas: dict[int, tuple[str, str, bytes]] = field(default_factory=dict)
    channels: dict[int, tuple[int, str, str]] = field(default_factory=dict)
    chunks: list[_ChunkIndex] = field(default_factory=list)
    channel_counts: dict[int, int] = field(default_factory=dict)


class _Damaged(Exception):
    """A structural error inside a file; becomes an InputError naming the file."""


def _read_file(path: Path, decoder: _Decoder) -> None:
    try:
        stream = path.open("rb")
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the .mcap file inside it") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    with stream:
        size = stream.seek(0, 2)
        stream.seek(0)
        if stream.read(len(_MAGIC)) != _MAGIC:
            raise InputError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")
        decoder.begin_file(path)
        try:
            summary = _summary(stream, size)
            if summary is not None and summary.chunks and summary.channels:
                _read_indexed(stream, size, summary, decoder)
            else:
                if summary is None:
                    logger.warning(
                        "%s: no summary index (an unfinished or cut-off recording?); reading it "
                        "by a linear scan, which is slower", path)
                _read_linear(stream, size, decoder)
        except _Damaged as exc:
            raise InputError(f"{path}: corrupt MCAP data: {exc}") from None


def _summary(stream: IO[bytes], size: int) -> _Summary | None:
    """Return the schemas, channels and chunk indexes of the summary section, or None."""
    if size < len(_MAGIC) + _FOOTER_SIZE:
        return None
    stream.seek(size - _FOOTER_SIZE)
    tail = stream.read(_FOOTER_SIZE)
    if tail[-len(_MAGIC) :] != _MAGIC or tail[0] != _FOOTER:
        return None
    summary_start = struct.unpack_from("<Q", tail, _RECORD_HEAD)[0]
    if not len(_MAGIC) <= summary_start <= size - _FOOTER_SIZE:
        return None
    stream.seek(summary_start)
    data = stream.read(size - _FOOTER_SIZE - summary_start)
    summary = _Summary()
    try:
        for opcode, content in _walk(data):
            if opcode == _SCHEMA:
                schema_id, name, encoding, text = _schema(content)
                summary.schemas[schema_id] = (name, encoding, text)
            elif opcode == _CHANNEL:
                channel_id, schema_id, channel_topic, encoding = _channel(content)
                summary.channels[channel_id] = (schema_id, channel_topic, encoding)
            elif opcode == _CHUNK_INDEX:
                summary.chunks.append(_chunk_index(content))
            elif opcode == _STATISTICS:
                # message_count .. message_end_time take 42 bytes; then a map<u16, u64>.
                (map_size,) = struct.unpack_from("<I", content, 42)
                counts = struct.iter_unpack("<HQ", content[46 : 46 + map_size])
                summary.channel_counts = dict(counts)
    except (_Damaged, struct.error, UnicodeDecodeError):
        return None  # an unreadable summary: the linear scan still reads the data
    return summary


def _walk(data: bytes | memoryview) -> Iterator[tuple[int, memoryview]]:
    """Yield (opcode, content) of the records in `data`, which must hold whole records."""
    view = memoryview(data)
    position, end = 0, len(view)
    while position < end:
        if position + _RECORD_HEAD > end:
            raise _Damaged(f"a record header at byte {position} is cut")
        opcode, length = struct.unpack_from("<BQ", view, position)
        start = position + _RECORD_HEAD
        if start + length > end:
            raise _Damaged(f"a record at byte {position} runs past its container")
        yield opcode, view[start : start + length]
        position = start + length


def _string(content: memoryview, offset: int) -> tuple[str, int]:
    (length,) = struct.unpack_from("<I", content, offset)
    end = offset + 4 + length
    if end > len(content):
        raise _Damaged("a string runs past its record")
    return bytes(content[offset + 4 : end]).decode(), end


def _schema(content: memoryview) -> tuple[int, str, str, bytes]:
    (schema_id,) = struct.unpack_from("<H", content)
    name, offset = _string(content, 2)
    encoding, offset = _string(content, offset)
    (length,) = struct.unpack_from("<I", content, offset)
    return schema_id, name, encoding, bytes(content[offset + 4 : offset + 4 + length])


def _channel(content: memoryview) -> tuple[int, int, str, str]:
    channel_id, schema_id = struct.unpack_from("<HH", content)
    topic, offset = _string(content, 4)
    encoding, _ = _string(content, offset)
    return channel_id, schema_id, topic, encoding


def _chunk_index(content: memoryview) -> _ChunkIndex:
    start, length, map_size = struct.unpack_from("<QQI", content, 16)
    entries = struct.iter_unpack("<HQ", content[36 : 36 + map_size])
    (index_length,) = struct.unpack_from("<Q", content, 36 + map_size)
    _, offset = _string(content, 44 + map_size)
    (uncompressed_size,) = struct.unpack_from("<Q", content, offset + 8)
    return _ChunkIndex(start, length, dict(entries), index_length, uncompressed_size)


def _chunk_records(
    raw: memoryview, chunk_at: int, codecs: _Codecs, out: bytearray | None = None
) -> np.ndarray:
    """Return the decompressed records of the Chunk record in `raw`, in `out` if it fits."""
    opcode, _ = struct.unpack_from("<BQ", raw)
    if opcode != _CHUNK:
        raise _Damaged(f"no chunk at byte {chunk_at}, where the chunk index points")
    (uncompressed_size,) = struct.unpack_from("<Q", raw, _RECORD_HEAD + 16)
    compression, offset = _string(raw, _RECORD_HEAD + 28)
    (length,) = struct.unpack_from("<Q", raw, offset)
    records = raw[offset + 8 : offset + 8 + length]
    if len(records) != length:
        raise _Damaged(f"the chunk at byte {chunk_at} is cut")
    try:
        data = codecs.decompress(compression, records, uncompressed_size, out)
    except (InputError, _Damaged):
        raise
    except Exception as exc:  # each codec raises its own kinds
        raise _Damaged(f"the chunk at byte {chunk_at} does not decompress ({exc})") from None
    if len(data) != uncompressed_size:
        raise _Damaged(f"the chunk at byte {chunk_at} decompresses to the wrong size")
    return np.frombuffer(data, dtype=np.uint8)


class _Codecs:
    """Decompressors, made once per read: a zstd context costs more to make than to use."""

    def __init__(self) -> None:
        self._zstd: Any = None

    def decompress(
        self, compression: str, records: memoryview, size: int, out: bytearray | None
    ) -> bytes | memoryview:
        """Return one chunk's records decompressed, into `out` where the codec allows it.

        Decompressing into a reused buffer spares a fresh megabyte of memory, and its
        page faults, per chunk.
        """
        if compression == "":
            return records
        if compression == "zstd":
            if self._zstd is None:
                import zstandard

                self._zstd = zstandard.ZstdDecompressor()
            if out is None or len(out) < size:
                return self._zstd.decompress(records, max_output_size=size)  # type: ignore[no-any-return]
            view = memoryview(out)[:size]
            filled = 0
            with self._zstd.stream_reader(records) as reader:
                while filled < size:
                    count = reader.readinto(view[filled:])
                    if not count:
                        break
                    filled += count
                if filled < size or reader.read(1):
                    raise _Damaged(f"a chunk does not decompress to its {size} bytes")
            return view
        if compression == "lz4":
            try:
                import lz4.frame
            except ImportError:
                raise InputError("the file has lz4-compressed chunks; install lz4") from None
            return bytes(lz4.frame.decompress(records))
        raise _Damaged(f"unknown chunk compression '{compression}'")


# --- reading ------------------------------------------------------------------------------


def _read_indexed(
    stream: BufferedReader, size: int, summary: _Summary, decoder: _Decoder
) -> None:
    """Read the topic's messages chunk by chunk through the chunk and message indexes."""
    wanted = decoder.select(summary.schemas, summary.channels)
    if not wanted:
        return
    decoder.columns.reserve(sum(summary.channel_counts.get(c, 0) for c in wanted))
    chunks = [c for c in sorted(summary.chunks, key=lambda c: c.start)
              if not c.message_index_offsets or wanted & c.message_index_offsets.keys()]
    # One buffer for the file bytes, one for the decompressed records, reused chunk after
    # chunk: fresh megabytes per chunk cost more in page faults than the decompression.
    # (A reading thread does not pay on two cores: it waits for the GIL as long as it saves.)
    raw_buffer = bytearray(max((c.length + c.message_index_length for c in chunks), default=0))
    out = bytearray(max((c.uncompressed_size for c in chunks), default=0))
    for chunk in chunks:
        raw = memoryview(raw_buffer)[: chunk.length + chunk.message_index_length]
        stream.seek(chunk.start)
        if stream.readinto(raw) < len(raw) or chunk.start + len(raw) > size:
            raise _Damaged(f"the chunk at byte {chunk.start} runs past the end of the file")
        buf = _chunk_records(raw[: chunk.length], chunk.start, decoder.codecs, out)
        ids = [c for c in chunk.message_index_offsets if c in wanted]
        if not ids:  # a chunk written without message indexes: walk its records
            _decode_walked(buf, wanted, decoder)
            continue
        entries = [_message_index(raw, chunk.message_index_offsets[c] - chunk.start) for c in ids]
        index = entries[0]
        if len(entries) > 1:
            index = np.concatenate(entries)
            index = index[np.argsort(index[:, 1], kind="stable")]
        _decode_records(buf, index[:, 1].astype(np.int64), index[:, 0], decoder, chunk.start)


def _message_index(raw: memoryview, at: int) -> NDArray[np.uint64]:
    """Return the (log_time, offset) rows of the MessageIndex record at byte `at` of `raw`."""
    opcode, length = struct.unpack_from("<BQ", raw, at)
    if opcode != _MESSAGE_INDEX:
        raise _Damaged("a chunk index points at a message index that is not there")
    (size,) = struct.unpack_from("<I", raw, at + _RECORD_HEAD + 2)
    start = at + _RECORD_HEAD + 6
    if size % 16 or start + size > len(raw):
        raise _Damaged("a message index is malformed")
    return np.frombuffer(raw, dtype="<u8", count=size // 8, offset=start).reshape(-1, 2)


def _decode_records(
    buf: np.ndarray, offsets: NDArray[np.int64], log_times: npt.ArrayLike, decoder: _Decoder,
    chunk_at: int,
) -> None:
    """Decode the Message records that start at `offsets` of the chunk's records `buf`."""
    if len(offsets) == 0:
        return
    if offsets.min() < 0 or offsets.max() + _DATA_AT > len(buf):
        raise _Damaged(f"a message index of the chunk at byte {chunk_at} points outside it")
    head = _rows(buf, offsets, _RECORD_HEAD)
    if np.any(head[:, 0] != _MESSAGE):
        raise _Damaged(f"a message index of the chunk at byte {chunk_at} points at no message")
    lengths = head[:, 1:].view("<u8")[:, 0].astype(np.int64)
    if lengths.min() < _MESSAGE_FIXED or (offsets + _RECORD_HEAD + lengths).max() > len(buf):
        raise _Damaged(f"a message of the chunk at byte {chunk_at} runs past it")
    times = np.asarray(log_times, dtype=np.uint64).astype(np.int64)
    size = int(lengths[0])
    if size == lengths.max() == lengths.min() and head.strides[0] == _RECORD_HEAD + size:
        # One topic, one layout: the records lie back to back, a (m, size) view of the chunk.
        payloads = as_strided(buf[int(offsets[0]) + _DATA_AT :],
                              shape=(len(offsets), size - _MESSAGE_FIXED),
                              strides=(_RECORD_HEAD + size, 1), writeable=False)
        if decoder.add_uniform(payloads, times):
            return
    decoder.add(buf, offsets + _DATA_AT, lengths - _MESSAGE_FIXED, times)


def _decode_walked(buf: np.ndarray, wanted: set[int], decoder: _Decoder) -> None:
    """Decode the wanted channels' messages found by walking the records in `buf`."""
    offsets, times = [], []
    for opcode, content, position in _walk_positions(buf):
        if opcode == _MESSAGE and len(content) >= _MESSAGE_FIXED:
            channel_id, _, log_time = struct.unpack_from("<HIQ", content)
            if channel_id in wanted:
                offsets.append(position)
                times.append(log_time)
        elif opcode in (_SCHEMA, _CHANNEL):
            decoder.learn(opcode, content)
            wanted |= decoder.wanted
    _decode_records(buf, np.array(offsets, dtype=np.int64), np.array(times, dtype=np.uint64),
                    decoder, 0)


def _walk_positions(buf: np.ndarray) -> Iterator[tuple[int, memoryview, int]]:
    position = 0
    for opcode, content in _walk(memoryview(buf.data)):
        yield opcode, content, position
        position += _RECORD_HEAD + len(content)


def _read_linear(stream: IO[bytes], size: int, decoder: _Decoder) -> None:
    """Read the topic's messages record by record from the start; stop at a cut record."""
    position = len(_MAGIC)
    stream.seek(position)
    batch: list[bytes] = []
    batch_times: list[int] = []

    def flush() -> None:
        if batch:
            data = np.frombuffer(b"".join(batch), dtype=np.uint8)
            lengths = np.array([len(b) for b in batch], dtype=np.int64)
            starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
            decoder.add(data, starts, lengths, np.array(batch_times, dtype=np.int64))
            batch.clear()
            batch_times.clear()

    while position < size:
        head = stream.read(_RECORD_HEAD)
        if len(head) < _RECORD_HEAD:
            decoder.cut_at(position)
            break
        opcode, length = struct.unpack("<BQ", head)
        if opcode == _FOOTER:
            break
        if position + _RECORD_HEAD + length > size:
            decoder.cut_at(position)
            break
        if opcode in (_SCHEMA, _CHANNEL):
            decoder.learn(opcode, memoryview(stream.read(length)))
        elif opcode == _MESSAGE:
            content = stream.read(length)
            channel_id, _, log_time = struct.unpack_from("<HIQ", content)
            if channel_id in decoder.wanted:
                batch.append(content[_MESSAGE_FIXED:])
                batch_times.append(log_time)
                if len(batch) >= _BATCH:
                    flush()
        elif opcode == _CHUNK:
            raw = memoryview(head + stream.read(length))
            buf = _chunk_records(raw, position, decoder.codecs)
            flush()
            _decode_walked(buf, set(decoder.wanted), decoder)
        else:
            stream.seek(length, 1)
        position += _RECORD_HEAD + length
    flush()


# --- decoding -------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Layout:
    """Where the fields of one JointState payload lie, in bytes from the payload's start."""

    little: bool
    stamp_ns: int
    names: tuple[str, ...]
    length: int
    position_at: int
    position_count_at: int
    position_size: int
    velocity_count_at: int
    velocity_at: int
    velocity_size: int
    effort_count_at: int


def _parse(data: bytes) -> _Layout:
    """Return the layout of one CDR JointState payload; _Damaged if it is malformed."""
    if len(data) < 16 or data[0] != 0:
        raise _Damaged("a JointState message is too short or not plain CDR")
    if data[1] not in (0, 1):
        raise _Damaged(f"unsupported CDR encapsulation 0x{data[:2].hex()}")
    order = "<" if data[1] == 1 else ">"

    def u32(at: int) -> int:
        return int(struct.unpack_from(order + "I", data, at)[0])

    def aligned(at: int, alignment: int) -> int:
        return at + (-(at - 4) % alignment)

    sec, nanosec = struct.unpack_from(order + "iI", data, 4)
    position = 16 + u32(12)
    count = u32(aligned(position, 4))
    position = aligned(position, 4) + 4
    if count * 4 > len(data) - position:
        raise _Damaged("a JointState message lists more names than it holds")
    names = []
    for _ in range(count):
        position = aligned(position, 4)
        size = u32(position)
        name = data[position + 4 : position + 4 + size].rstrip(b"\x00")
        names.append(name.decode(errors="replace"))
        position += 4 + size
    arrays = []
    for _ in range(3):
        count_at = aligned(position, 4)
        size = u32(count_at)
        position = count_at + 4
        if size:
            position = aligned(position, 8)
        arrays.append((count_at, position, size))
        position += 8 * size
    if position > len(data):
        raise _Damaged("a JointState message is shorter than its arrays")
    (p_count, p_at, p_size), (v_count, v_at, v_size), (e_count, _, _) = arrays
    return _Layout(order == "<", int(sec) * 1_000_000_000 + int(nanosec), tuple(names),
                   len(data), p_at, p_count, p_size, v_count, v_at, v_size, e_count)


@dataclass
class _Decoder:
    """Collects decoded columns across chunks and files; knows which channels to read."""

    source: Path
    topic: str
    joints: tuple[str, ...] | None
    path: Path = Path()
    wanted: set[int] = field(default_factory=set)
    schemas: dict[int, tuple[str, str, bytes]] = field(default_factory=dict)
    channels: dict[int, tuple[int, str, str]] = field(default_factory=dict)
    topics: dict[str, str] = field(default_factory=dict)
    columns: _Columns = field(default_factory=lambda: _Columns())
    codecs: _Codecs = field(default_factory=_Codecs)
    joint_columns: dict[tuple[str, ...], NDArray[np.intp] | None] = field(default_factory=dict)
    seen_joints: set[str] = field(default_factory=set)
    skipped: int = 0
    messages: int = 0
    cut: list[str] = field(default_factory=list)

    def begin_file(self, path: Path) -> None:
        """Start a file: channel ids are per file."""
        self.path = path
        self.wanted, self.schemas, self.channels = set(), {}, {}

    def select(
        self, schemas: dict[int, tuple[str, str, bytes]], channels: dict[int, tuple[int, str, str]]
    ) -> set[int]:
        """Return the ids of the topic's channels, checking their type and encoding."""
        self.schemas.update(schemas)
        for channel_id, channel in channels.items():
            self._channel(channel_id, channel)
        return set(self.wanted)

    def learn(self, opcode: int, content: memoryview) -> None:
        """Take in a Schema or Channel record met in the data section."""
        try:
            if opcode == _SCHEMA:
                schema_id, name, encoding, text = _schema(content)
                self.schemas[schema_id] = (name, encoding, text)
            else:
                channel_id, schema_id, topic, encoding = _channel(content)
                self._channel(channel_id, (schema_id, topic, encoding))
        except (struct.error, UnicodeDecodeError) as exc:
            raise _Damaged(f"a schema or channel record is malformed ({exc})") from None

    def _channel(self, channel_id: int, channel: tuple[int, str, str]) -> None:
        schema_id, topic, encoding = channel
        self.channels[channel_id] = channel
        name, schema_encoding, text = self.schemas.get(schema_id, ("", "", b""))
        self.topics.setdefault(topic, name or "(no schema)")
        if topic != self.topic:
            return
        if name != JOINT_STATE_TYPE:
            raise InputError(f"{self.path}: topic {topic} has type {name or '(no schema)'}, "
                             f"expected {JOINT_STATE_TYPE}")
        if encoding != "cdr":
            raise InputError(f"{self.path}: topic {topic} is encoded as '{encoding}', expected cdr")
        if schema_encoding == "ros2msg":
            _check_definition(self.path, topic, text)
        self.wanted.add(channel_id)

    def cut_at(self, position: int) -> None:
        """Note that the file ends inside the record at byte `position`."""
        self.cut.append(f"{self.path}: file is truncated at byte {position} (a record runs past "
                        "its end)")
        logger.warning("%s; using the messages before it", self.cut[-1])

    def add_uniform(self, rows: np.ndarray, log_times: NDArray[np.int64]) -> bool:
        """Decode payloads of equal length, one per row; return False if they differ in layout."""
        template = self._layout(rows[0], 0, rows.shape[1])
        if not template.little or not _matches(rows, rows[0], template).all():
            return False
        self.messages += len(rows)
        self._add_rows(rows, template, log_times)
        return True

    def add(
        self, buf: np.ndarray, starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64],
    ) -> None:
        """Decode the payloads buf[starts[i] : starts[i] + lengths[i]]."""
        self.messages += len(starts)
        remaining = np.arange(len(starts))
        for _ in range(_MAX_LAYOUTS):
            if len(remaining) == 0:
                return
            template = self._layout(buf, int(starts[remaining[0]]), int(lengths[remaining[0]]))
            if not template.little:
                break
            same = remaining[lengths[remaining] == template.length]
            rows = _rows(buf, starts[same], template.length)
            match = _matches(rows, rows[0], template)
            self._add_rows(rows if match.all() else rows[match], template, log_times[same[match]])
            matched = np.zeros(len(starts), dtype=bool)
            matched[same[match]] = True
            remaining = remaining[~matched[remaining]]
        self._add_each(buf, starts[remaining], lengths[remaining], log_times[remaining])

    def _layout(self, buf: np.ndarray, start: int, length: int) -> _Layout:
        try:
            return _parse(bytes(buf[start : start + length]))
        except (struct.error, UnicodeDecodeError):
            raise _Damaged("a JointState message is malformed") from None

    def _columns(self, names: tuple[str, ...], size: int) -> NDArray[np.intp] | None:
        """Return the columns of the wanted joints in a message with `names`, or None."""
        if names not in self.joint_columns:
            self.seen_joints.update(names)
            if self.joints is None and size == len(names) and names:
                self.joints = tuple(dict.fromkeys(names))
            found = {name: i for i, name in reversed(list(enumerate(names)))}
            usable = self.joints is not None and all(j in found for j in self.joints)
            self.joint_columns[names] = (
                np.array([found[j] for j in self.joints or ()], dtype=np.intp) if usable else None
            )
        columns = self.joint_columns[names]
        # JointState arrays must match the names; a message without positions is unusable.
        return columns if columns is not None and size == len(names) else None

    def _add_rows(self, rows: np.ndarray, layout: _Layout, log_times: NDArray[np.int64]) -> None:
        columns = self._columns(layout.names, layout.position_size)
        if columns is None:
            self.skipped += len(rows)
            return
        n = layout.position_size
        seconds = rows[:, 4:8].view("<i4")[:, 0].astype(np.int64)
        times = seconds * 1_000_000_000 + rows[:, 8:12].view("<u4")[:, 0]
        velocities = None
        if layout.velocity_size == n:
            velocities = _floats(rows, layout.velocity_at, n, columns)
        self.columns.append(times, log_times, _floats(rows, layout.position_at, n, columns),
                            velocities)

    def _add_each(
        self, buf: np.ndarray, starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64],
    ) -> None:
        """Decode payloads one by one: big-endian ones, or layouts beyond the templates tried."""
        times, kept_log_times, positions, velocities = [], [], [], []
        for start, length, log_time in zip(starts.tolist(), lengths.tolist(), log_times.tolist(),
                                           strict=True):
            layout = self._layout(buf, start, length)
            columns = self._columns(layout.names, layout.position_size)
            if columns is None:
                self.skipped += 1
                continue
            data = bytes(buf[start : start + length])
            kind = ("<" if layout.little else ">") + "f8"
            n = layout.position_size
            times.append(layout.stamp_ns)
            kept_log_times.append(log_time)
            positions.append(np.frombuffer(data, kind, n, layout.position_at)[columns])
            if layout.velocity_size == n:
                velocities.append(np.frombuffer(data, kind, n, layout.velocity_at)[columns])
        if times:
            complete = len(velocities) == len(positions)
            self.columns.append(np.array(times, dtype=np.int64),
                                np.array(kept_log_times, dtype=np.int64),
                                np.array(positions, dtype=np.float64),
                                np.array(velocities, dtype=np.float64) if complete else None)

    def series(self, time_source: TimeSource) -> JointStateSeries:
        """Return the collected samples as a series, sorted by time."""
        source = self.source
        if not self.topics.get(self.topic):
            present = ", ".join(f"{t} ({m})" for t, m in sorted(self.topics.items())) or "(none)"
            cut = f" ({self.cut[0]})" if self.cut else ""
            raise InputError(f"{source}: no topic {self.topic}{cut}; topics present: {present}")
        if self.columns.count == 0:
            if self.messages == 0:
                cut = f"; {self.cut[0]}" if self.cut else ""
                raise InputError(f"{source}: no messages on {self.topic}{cut}")
            wanted = self.joints or ()
            missing = [j for j in wanted if not any(j in names for names in self.joint_columns)]
            if missing or not wanted:
                raise InputError(
                    f"{source}: {self.topic} has no joint {', '.join(missing) or '(any)'}; joints "
                    f"present: {known(self.seen_joints)}")
            raise InputError(f"{source}: no message on {self.topic} carries all of "
                             f"{', '.join(wanted)} with positions; joints present: "
                             f"{known(self.seen_joints)}")
        if self.skipped:
            logger.warning("%s: skipped %d of %d messages on %s that lack one of the joints %s",
                           source, self.skipped, self.messages, self.topic,
                           ", ".join(self.joints or ()))
        times, log_times, positions, velocities = self.columns.take()
        if time_source == "log" or not times.any():
            if time_source == "header":
                logger.warning("%s: every header stamp on %s is zero; using log times", source,
                               self.topic)
                time_source = "log"
            times = log_times
        del log_times
        if velocities is None and self.columns.some_velocities:
            logger.warning("%s: only some messages on %s carry velocities; ignoring velocities",
                           source, self.topic)
        if np.any(np.diff(times) < 0):
            order = np.argsort(times, kind="stable")
            times, positions = times[order], positions[order]
            velocities = velocities[order] if velocities is not None else None
        start_ns = int(times[0])
        times_s = (times - start_ns) / 1e9
        for array in (times_s, positions, velocities):
            if array is not None:
                array.setflags(write=False)
        return JointStateSeries(tuple(self.joints or ()), times_s, positions, velocities, start_ns,
                                time_source, str(source))


class _Columns:
    """Decoded samples, appended per batch into arrays sized from the file's statistics.

    Filling preallocated arrays keeps the peak near one copy of the result (an hour at
    1 kHz is 170 MB per float array); batches beyond the reserved size are kept apart and
    concatenated at the end.
    """

    def __init__(self) -> None:
        self.capacity = 0
        self.count = 0
        self._filled = 0
        self._arrays: list[np.ndarray] | None = None
        self._velocities: NDArray[np.float64] | None = None
        self._extra: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]] = []
        self.some_velocities = False
        self.all_velocities = True

    def reserve(self, count: int) -> None:
        """Expect `count` more samples (an upper bound)."""
        if self._arrays is None:
            self.capacity += count

    def append(
        self, times: NDArray[np.int64], log_times: NDArray[np.int64],
        positions: NDArray[np.float64], velocities: NDArray[np.float64] | None,
    ) -> None:
        """Add a batch: stamps and log times [ns], (m, n) positions and velocities or None."""
        m, n = positions.shape
        self.count += m
        self.some_velocities |= velocities is not None
        self.all_velocities &= velocities is not None
        if self._arrays is None and self.capacity >= m:
            self._arrays = [_touched((self.capacity,), np.int64),
                            _touched((self.capacity,), np.int64),
                            _touched((self.capacity, n), np.float64)]
        if self._arrays is None or self._filled + m > self.capacity or self._extra:
            # Copies: values may be views of a chunk buffer that is about to be reused.
            kept = None if velocities is None else np.array(velocities)
            self._extra.append((np.array(times), np.array(log_times), np.array(positions), kept))
            return
        rows = slice(self._filled, self._filled + m)
        for array, values in zip(self._arrays, (times, log_times, positions), strict=True):
            array[rows] = values
        if velocities is not None and self.all_velocities:
            if self._velocities is None:
                self._velocities = _touched((self.capacity, n), np.float64)
            self._velocities[rows] = velocities
        self._filled += m

    def take(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """Return times, log times, positions and velocities (None unless every batch had them)."""
        parts = list(self._extra)
        if self._arrays is not None:
            filled = self._filled
            velocities = self._velocities[:filled] if self._velocities is not None else None
            times, log_times, positions = (array[:filled] for array in self._arrays)
            parts.insert(0, (times, log_times, positions, velocities))
        self._arrays, self._velocities, self._extra = None, None, []
        if len(parts) == 1:
            times, log_times, positions, velocities = parts[0]
        else:
            times, log_times, positions = (np.concatenate([p[i] for p in parts]) for i in range(3))
            velocities = None
            if self.all_velocities:
                velocities = np.concatenate([p[3] for p in parts if p[3] is not None])
        return times, log_times, positions, velocities if self.all_velocities else None


def _touched(shape: tuple[int, ...], dtype: type[np.generic]) -> np.ndarray:
    """Return a zeroed array whose pages are already mapped.

    Pages first touched one batch at a time, between the decompressor's allocations,
    cost ten times more than one sweep over them.
    """
    count = int(np.prod(shape))
    array = np.frombuffer(bytearray(count * np.dtype(dtype).itemsize), dtype=dtype).reshape(shape)
    array.fill(0)
    return array


def _rows(buf: np.ndarray, starts: NDArray[np.int64], length: int) -> np.ndarray:
    """Return the (m, length) bytes at `starts`: a strided view when evenly spaced, else a copy."""
    if len(starts) > 1:
        steps = np.diff(starts)
        stride = int(steps[0])
        if stride >= length and np.all(steps == stride):
            view = as_strided(buf[int(starts[0]) :], shape=(len(starts), length),
                              strides=(stride, 1), writeable=False)
            return view
    return sliding_window_view(buf, length)[starts]


def _matches(rows: np.ndarray, template: np.ndarray, layout: _Layout) -> NDArray[np.bool_]:
    """Return per row whether it is laid out as `template`: same bytes except stamp and values.

    Compared 8 bytes at a time (frame_id, names and the position count), then the
    encapsulation and the other arrays' sizes.
    """
    end = layout.position_at
    words = (end - 12) // 8
    key = slice(12, 12 + 8 * words)
    same: NDArray[np.bool_] = (rows[:, key].view("<u8") == template[key].view("<u8")).all(axis=1)
    for at, size in ((end - 8, "<u8"), (0, "<u2"), (layout.velocity_count_at, "<u4"),
                     (layout.effort_count_at, "<u4")):
        width = np.dtype(size).itemsize
        same &= rows[:, at : at + width].view(size)[:, 0] == template[at : at + width].view(size)[0]
    return same


def _floats(rows: np.ndarray, at: int, n: int, columns: NDArray[np.intp]) -> NDArray[np.float64]:
    """Return the float64 array of n values at byte `at` of each row, `columns` of it.

    Joints in the recorded order come back as a view of the rows, copied once where kept.
    """
    values = rows[:, at : at + 8 * n].view("<f8")
    if len(columns) == n and np.array_equal(columns, np.arange(n)):
        return values
    return values[:, columns]


def _check_definition(path: Path, topic: str, text: bytes) -> None:
    """Raise InputError unless the schema's top-level fields are JointState's, in order."""
    top = text.decode(errors="replace").split("\n" + "=" * 80)[0]
    fields = []
    for line in top.splitlines():
        line = line.split("#", 1)[0].strip()
        if line and "=" not in line:
            parts = line.split()
            fields.append((parts[-1] if len(parts) > 1 else "", parts[0]))
    ok = len(fields) == len(_EXPECTED_FIELDS) and all(
        name == want and kind in kinds
        for (name, kind), (want, kinds) in zip(fields, _EXPECTED_FIELDS, strict=True)
    )
    if not ok:
        found = ", ".join(f"{kind} {name}" for name, kind in fields) or "(none)"
        raise InputError(f"{path}: the schema of {topic} is named {JOINT_STATE_TYPE} but its "
                         f"fields are not JointState's (header, name, position, velocity, "
                         f"effort): {found}")

