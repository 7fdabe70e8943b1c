"""One topic's messages from MCAP files in bulk: the container read without the mcap package.

The generic MCAP readers spend their time in per-message Python (mcap-ros2-support reads
~22 k messages/s, rosbags ~50 k/s). `read_topic` reads the summary's chunk indexes, then
per chunk one read, one decompression (zstd, lz4 or none) and the chunk's MessageIndex
offsets of the topic's channels, and hands a sink the message payloads as numpy bytes: a
(messages, bytes) view of the chunk where the records lie back to back with one length,
else offsets and lengths into it. A file without a usable summary (a recording that was
cut off, or written without one) is read by a linear scan, with a warning.

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
from collections.abc import Iterator
from dataclasses import dataclass, field
from io import BufferedReader
from pathlib import Path
from typing import IO, Any, Protocol

import numpy as np
import numpy.typing as npt
from numpy.lib.stride_tricks import as_strided, sliding_window_view
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["Channel", "CorruptData", "MessageSink", "byte_rows", "read_topic"]

logger = logging.getLogger(__name__)

_MAGIC = b"\x89MCAP0\r\n"
_FOOTER, _SCHEMA, _CHANNEL, _MESSAGE, _CHUNK, _MESSAGE_INDEX, _CHUNK_INDEX = 2, 3, 4, 5, 6, 7, 8
_STATISTICS = 11
_RECORD_HEAD = 9  # opcode u8 + length u64
_FOOTER_SIZE = _RECORD_HEAD + 20 + len(_MAGIC)
# A Message record: head, channel_id u16, sequence u32, log_time u64, publish_time u64, data.
_MESSAGE_FIXED = 22
_DATA_AT = _RECORD_HEAD + _MESSAGE_FIXED
# Messages gathered from an unchunked file before they are handed over as one batch.
_BATCH = 8192


class CorruptData(Exception):
    """A structural error inside a file, or a malformed message a sink met.

    `read_topic` turns it into an InputError naming the file.
    """


@dataclass(frozen=True)
class Channel:
    """A channel of the topic read, with its schema ("" and b"" for a channel without one)."""

    topic: str
    message_encoding: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes


class MessageSink(Protocol):
    """Takes the payloads (the data of Message records) of one topic, batch by batch."""

    def check(self, path: Path, channel: Channel) -> None:
        """Raise InputError unless the sink can read the messages of `channel` in `path`."""
        ...

    def reserve(self, count: int) -> None:
        """Expect about `count` more messages, as the file's statistics count them."""
        ...

    def add_rows(self, rows: NDArray[np.uint8], log_times: NDArray[np.int64]) -> bool:
        """Take payloads of one length, a row each; return False to take them through `add`."""
        ...

    def add(
        self, buf: NDArray[np.uint8], starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64],
    ) -> None:
        """Take the payloads buf[starts[i] : starts[i] + lengths[i]], log times in [ns]."""
        ...


def read_topic(source: Path, topic: str, sink: MessageSink) -> None:
    """Hand every message on `topic` to `sink`, file by file, in file order.

    Args:
        source: An MCAP file, or a rosbag2 folder whose *.mcap files are read in split order.
        topic: The topic to read.
        sink: Checks the topic's channels, then takes their payloads.

    Raises:
        InputError: A file is missing, not MCAP or corrupt; the topic is absent (the
            message lists the topics present) or has no messages; or `sink` refused a channel.

    """
    reader = _Reader(topic, sink)
    for file in _files(source):
        reader.read_file(file)
    if not reader.topics.get(topic):
        present = ", ".join(f"{t} ({m})" for t, m in sorted(reader.topics.items())) or "(none)"
        cut = f" ({reader.cut[0]})" if reader.cut else ""
        raise InputError(f"{source}: no topic {topic}{cut}; topics present: {present}")
    if reader.messages == 0:
        cut = f"; {reader.cut[0]}" if reader.cut else ""
        raise InputError(f"{source}: no messages on {topic}{cut}")


def byte_rows(buf: NDArray[np.uint8], starts: NDArray[np.int64], length: int) -> NDArray[np.uint8]:
    """Return the (m, length) bytes at `starts`: a strided view when evenly spaced, else a copy."""
    if len(starts) > 1:
        steps = np.diff(starts)
        stride = int(steps[0])
        if stride >= length and np.all(steps == stride):
            view: NDArray[np.uint8] = as_strided(buf[int(starts[0]) :], shape=(len(starts), length),
                                                 strides=(stride, 1), writeable=False)
            return view
    return sliding_window_view(buf, length)[starts]


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


@dataclass
class _Reader:
    """One `read_topic`: the current file's schemas and wanted channels, what was met so far."""

    topic: str
    sink: MessageSink
    path: Path = Path()
    wanted: set[int] = field(default_factory=set)
    schemas: dict[int, tuple[str, str, bytes]] = field(default_factory=dict)
    topics: dict[str, str] = field(default_factory=dict)
    codecs: _Codecs = field(default_factory=lambda: _Codecs())
    messages: int = 0
    cut: list[str] = field(default_factory=list)

    def read_file(self, path: Path) -> None:
        """Read one MCAP file: through its summary's indexes, else by a linear scan."""
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
                raise InputError(
                    f"{path}: not an MCAP file (it does not start with the MCAP magic)")
            # Channel and schema ids are per file.
            self.path, self.wanted, self.schemas = path, set(), {}
            try:
                summary = _summary(stream, size)
                if summary is not None and summary.chunks and summary.channels:
                    _read_indexed(stream, size, summary, self)
                else:
                    if summary is None:
                        logger.warning(
                            "%s: no summary index (an unfinished or cut-off recording?); reading "
                            "it by a linear scan, which is slower", path)
                    _read_linear(stream, size, self)
            except CorruptData as exc:
                raise InputError(f"{path}: corrupt MCAP data: {exc}") from None

    def select(
        self, schemas: dict[int, tuple[str, str, bytes]], channels: dict[int, tuple[int, str, str]]
    ) -> set[int]:
        """Return the ids of the topic's channels in a summary, checked by the sink."""
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
            raise CorruptData(f"a schema or channel record is malformed ({exc})") from None

    def _channel(self, channel_id: int, channel: tuple[int, str, str]) -> None:
        schema_id, topic, encoding = channel
        name, schema_encoding, text = self.schemas.get(schema_id, ("", "", b""))
        self.topics.setdefault(topic, name or "(no schema)")
        if topic == self.topic:
            self.sink.check(self.path, Channel(topic, encoding, name, schema_encoding, text))
            self.wanted.add(channel_id)

    def cut_at(self, position: int) -> None:
        """Note that the file ends inside the record at byte `position`."""
        self.cut.append(f"{self.path}: file is truncated at byte {position} (a record runs past "
                        "its end)")
        logger.warning("%s; using the messages before it", self.cut[-1])

    def add(
        self, buf: NDArray[np.uint8], starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64],
    ) -> None:
        """Hand the sink the payloads buf[starts[i] : starts[i] + lengths[i]]."""
        self.messages += len(starts)
        self.sink.add(buf, starts, lengths, log_times)


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
    except (CorruptData, struct.error, UnicodeDecodeError):
        return None  # an unreadable summary: the linear scan still reads the data
    return summary


def _walk(data: bytes | memoryview) -> Iterator[tuple[int, memoryview]]:
    """Yield (opcode, content) of the records in `data`, which must hold whole records."""
    view = memoryview(data)
    position, end = 0, len(view)
    while position < end:
        if position + _RECORD_HEAD > end:
            raise CorruptData(f"a record header at byte {position} is cut")
        opcode, length = struct.unpack_from("<BQ", view, position)
        start = position + _RECORD_HEAD
        if start + length > end:
            raise CorruptData(f"a record at byte {position} runs past its container")
        yield opcode, view[start : start + length]
        position = start + length


def _string(content: memoryview, offset: int) -> tuple[str, int]:
    (length,) = struct.unpack_from("<I", content, offset)
    end = offset + 4 + length
    if end > len(content):
        raise CorruptData("a string runs past its record")
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
) -> NDArray[np.uint8]:
    """Return the decompressed records of the Chunk record in `raw`, in `out` if it fits."""
    opcode, _ = struct.unpack_from("<BQ", raw)
    if opcode != _CHUNK:
        raise CorruptData(f"no chunk at byte {chunk_at}, where the chunk index points")
    (uncompressed_size,) = struct.unpack_from("<Q", raw, _RECORD_HEAD + 16)
    compression, offset = _string(raw, _RECORD_HEAD + 28)
    (length,) = struct.unpack_from("<Q", raw, offset)
    records = raw[offset + 8 : offset + 8 + length]
    if len(records) != length:
        raise CorruptData(f"the chunk at byte {chunk_at} is cut")
    try:
        data = codecs.decompress(compression, records, uncompressed_size, out)
    except (InputError, CorruptData):
        raise
    except Exception as exc:  # each codec raises its own kinds
        raise CorruptData(f"the chunk at byte {chunk_at} does not decompress ({exc})") from None
    if len(data) != uncompressed_size:
        raise CorruptData(f"the chunk at byte {chunk_at} decompresses to the wrong size")
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
                    raise CorruptData(f"a chunk does not decompress to its {size} bytes")
            return view
        if compression == "lz4":
            try:
                import lz4.frame
            except ImportError:
                raise InputError("the file has lz4-compressed chunks; install lz4") from None
            return bytes(lz4.frame.decompress(records))
        raise CorruptData(f"unknown chunk compression '{compression}'")


# --- reading ------------------------------------------------------------------------------


def _read_indexed(stream: BufferedReader, size: int, summary: _Summary, reader: _Reader) -> None:
    """Read the topic's messages chunk by chunk through the chunk and message indexes."""
    wanted = reader.select(summary.schemas, summary.channels)
    if not wanted:
        return
    reader.sink.reserve(sum(summary.channel_counts.get(c, 0) for c in wanted))
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
            raise CorruptData(f"the chunk at byte {chunk.start} runs past the end of the file")
        buf = _chunk_records(raw[: chunk.length], chunk.start, reader.codecs, out)
        ids = [c for c in chunk.message_index_offsets if c in wanted]
        if not ids:  # a chunk written without message indexes: walk its records
            _decode_walked(buf, wanted, reader)
            continue
        entries = [_message_index(raw, chunk.message_index_offsets[c] - chunk.start) for c in ids]
        index = entries[0]
        if len(entries) > 1:
            index = np.concatenate(entries)
            index = index[np.argsort(index[:, 1], kind="stable")]
        _decode_records(buf, index[:, 1].astype(np.int64), index[:, 0], reader, chunk.start)


def _message_index(raw: memoryview, at: int) -> NDArray[np.uint64]:
    """Return the (log_time, offset) rows of the MessageIndex record at byte `at` of `raw`."""
    opcode, length = struct.unpack_from("<BQ", raw, at)
    if opcode != _MESSAGE_INDEX:
        raise CorruptData("a chunk index points at a message index that is not there")
    (size,) = struct.unpack_from("<I", raw, at + _RECORD_HEAD + 2)
    start = at + _RECORD_HEAD + 6
    if size % 16 or start + size > len(raw):
        raise CorruptData("a message index is malformed")
    return np.frombuffer(raw, dtype="<u8", count=size // 8, offset=start).reshape(-1, 2)


def _decode_records(
    buf: NDArray[np.uint8], offsets: NDArray[np.int64], log_times: npt.ArrayLike,
    reader: _Reader, chunk_at: int,
) -> None:
    """Hand over the payloads of the Message records at `offsets` of the chunk's records `buf`."""
    if len(offsets) == 0:
        return
    if offsets.min() < 0 or offsets.max() + _DATA_AT > len(buf):
        raise CorruptData(f"a message index of the chunk at byte {chunk_at} points outside it")
    head = byte_rows(buf, offsets, _RECORD_HEAD)
    if np.any(head[:, 0] != _MESSAGE):
        raise CorruptData(f"a message index of the chunk at byte {chunk_at} points at no message")
    lengths = head[:, 1:].view("<u8")[:, 0].astype(np.int64)
    if lengths.min() < _MESSAGE_FIXED or (offsets + _RECORD_HEAD + lengths).max() > len(buf):
        raise CorruptData(f"a message of the chunk at byte {chunk_at} runs past it")
    times = np.asarray(log_times, dtype=np.uint64).astype(np.int64)
    size = int(lengths[0])
    if size == lengths.max() == lengths.min() and head.strides[0] == _RECORD_HEAD + size:
        # One topic, one length: the records lie back to back, a (m, size) view of the chunk.
        payloads = as_strided(buf[int(offsets[0]) + _DATA_AT :],
                              shape=(len(offsets), size - _MESSAGE_FIXED),
                              strides=(_RECORD_HEAD + size, 1), writeable=False)
        if reader.sink.add_rows(payloads, times):
            reader.messages += len(offsets)
            return
    reader.add(buf, offsets + _DATA_AT, lengths - _MESSAGE_FIXED, times)


def _decode_walked(buf: NDArray[np.uint8], wanted: set[int], reader: _Reader) -> None:
    """Hand over the wanted channels' messages found by walking the records in `buf`."""
    offsets, times = [], []
    for opcode, content, position in _walk_positions(buf):
        if opcode == _MESSAGE and len(content) >= _MESSAGE_FIXED:
            channel_id, _, log_time = struct.unpack_from("<HIQ", content)
            if channel_id in wanted:
                offsets.append(position)
                times.append(log_time)
        elif opcode in (_SCHEMA, _CHANNEL):
            reader.learn(opcode, content)
            wanted |= reader.wanted
    _decode_records(buf, np.array(offsets, dtype=np.int64), np.array(times, dtype=np.uint64),
                    reader, 0)


def _walk_positions(buf: NDArray[np.uint8]) -> Iterator[tuple[int, memoryview, int]]:
    position = 0
    for opcode, content in _walk(memoryview(buf.data)):
        yield opcode, content, position
        position += _RECORD_HEAD + len(content)


def _read_linear(stream: IO[bytes], size: int, reader: _Reader) -> None:
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
            reader.add(data, starts, lengths, np.array(batch_times, dtype=np.int64))
            batch.clear()
            batch_times.clear()

    while position < size:
        head = stream.read(_RECORD_HEAD)
        if len(head) < _RECORD_HEAD:
            reader.cut_at(position)
            break
        opcode, length = struct.unpack("<BQ", head)
        if opcode == _FOOTER:
            break
        if position + _RECORD_HEAD + length > size:
            reader.cut_at(position)
            break
        if opcode in (_SCHEMA, _CHANNEL):
            reader.learn(opcode, memoryview(stream.read(length)))
        elif opcode == _MESSAGE:
            content = stream.read(length)
            channel_id, _, log_time = struct.unpack_from("<HIQ", content)
            if channel_id in reader.wanted:
                batch.append(content[_MESSAGE_FIXED:])
                batch_times.append(log_time)
                if len(batch) >= _BATCH:
                    flush()
        elif opcode == _CHUNK:
            raw = memoryview(head + stream.read(length))
            buf = _chunk_records(raw, position, reader.codecs)
            flush()
            _decode_walked(buf, set(reader.wanted), reader)
        else:
            stream.seek(length, 1)
        position += _RECORD_HEAD + length
    flush()
