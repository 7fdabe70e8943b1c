"""One topic's messages from MCAP or rosbag2 sqlite3 files in bulk, handed to a sink chunk by chunk.

The generic MCAP readers spend their time in per-message Python (mcap-ros2-support reads
~22 k messages/s, rosbags ~50 k/s). `read_topic` reads the summary's chunk indexes, then
per chunk one read, one decompression (zstd, lz4 or none) and the chunk's MessageIndex
offsets of the topic's channels, and hands a sink the message payloads as numpy bytes: a
(messages, bytes) view of the chunk where the records lie back to back with one length,
else offsets and lengths into it. A file without a usable summary (a recording that was
cut off, or written without one) is read by a linear scan (core.bag.container._mcap_linear), with a
warning: chunk by chunk through the MessageIndex records that follow each chunk. A .db3
file is read a batch of messages at a time (core.bag.container._db3). Only the current chunk or batch
is held: memory does not grow with the recording.

The records are core.bag.container._mcap_records' to parse, without the mcap package. Each chunk
read is checked whole (core.bag.container.chunk_codecs): decompressed no further than the size it
declares, itself bounded, and its CRC compared where the writer computed one; the summary
and data section CRCs too, where present. A damaged part is bad input, or with
`skip_damaged` skipped with a warning, and listed in what `read_topic` returns.
"""

from __future__ import annotations

import logging
import struct
from dataclasses import dataclass, field
from io import BufferedReader
from pathlib import Path
from typing import IO, Protocol

import numpy as np
import numpy.typing as npt
from numpy.lib.stride_tricks import as_strided, sliding_window_view
from numpy.typing import NDArray

from ...errors import CorruptData, InputError
from ...types import SkippedData
from ._db3 import db3_info, db3_messages, open_db3
from ._files import MCAP_MAGIC, bag_files
from ._mcap_linear import CUT, DataRecord, Definitions, data_records
from ._mcap_records import (
    CHANNEL,
    CHUNK,
    DATA_AT,
    MESSAGE,
    MESSAGE_FIXED,
    RECORD_HEAD,
    SCHEMA,
    ChunkIndex,
    Codecs,
    Summary,
    channel_record,
    chunk_records,
    message_index,
    read_summary,
    schema_record,
    walk_positions,
)
from .chunk_codecs import Damage, Skips
from .mcap_verify import data_section_damage

__all__ = ["Channel", "MessageSink", "byte_rows", "read_topic"]

logger = logging.getLogger(__name__)

# Messages gathered from an unchunked file before they are handed over as one batch.
_BATCH = 8192


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

    def wants_log_times(self) -> bool:
        """Return False if the log times of the next payloads are not needed (zeros will do)."""
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


def read_topic(source: Path, topic: str, sink: MessageSink, skip_damaged: bool = False) -> tuple[SkippedData, ...]:
    """Hand every message on `topic` to `sink`, file by file, in file order; return the damaged parts skipped.

    Args:
        source: An MCAP or rosbag2 sqlite3 (.db3) file, or a rosbag2 bag folder whose
            split files are read in order (core.bag.container._files).
        topic: The topic to read.
        sink: Checks the topic's channels, then takes their payloads.
        skip_damaged: Skip an MCAP chunk that fails its CRC or size checks, the summary
            section or data section CRC, with a warning, instead of refusing the file.

    Raises:
        InputError: A file is missing, neither MCAP nor sqlite3, or corrupt (a damaged part
            names its offset and the check that failed); the topic is absent (the message
            lists the topics present) or has no messages; or `sink` refused a channel.

    """
    reader = _Reader(topic, sink, skips=Skips(skip_damaged))
    for file in bag_files(source):
        if file.storage == "sqlite3":
            reader.read_db3(file.path)
        else:
            reader.read_file(file.path)
    if not reader.topics.get(topic):
        present = ", ".join(f"{t} ({m})" for t, m in sorted(reader.topics.items())) or "(none)"
        cut = f" ({reader.cut[0]})" if reader.cut else ""
        raise InputError(f"{source}: no topic {topic}{cut}; topics present: {present}")
    if reader.messages == 0:
        cut = f"; {reader.cut[0]}" if reader.cut else ""
        lost = f"; {len(reader.skips.found)} damaged parts skipped" if reader.skips.found else ""
        raise InputError(f"{source}: no messages on {topic}{cut}{lost}")
    return tuple(reader.skips.found)


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


@dataclass
class _Reader:
    """One `read_topic`: the current file's schemas and wanted channels, what was met so far."""

    topic: str
    sink: MessageSink
    path: Path = Path()
    wanted: set[int] = field(default_factory=set)
    schemas: dict[int, tuple[str, str, bytes]] = field(default_factory=dict)
    topics: dict[str, str] = field(default_factory=dict)
    codecs: Codecs = field(default_factory=lambda: Codecs())
    messages: int = 0
    cut: list[str] = field(default_factory=list)
    skips: Skips = field(default_factory=Skips)

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
            if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
                raise InputError(
                    f"{path}: not an MCAP file (it does not start with the MCAP magic)")
            # Channel and schema ids are per file.
            self.path, self.wanted, self.schemas = path, set(), {}
            try:
                summary = self._summary(stream, size)
                if summary is not None and summary.chunks and summary.channels:
                    _read_indexed(stream, size, summary, self)
                else:
                    _read_linear(stream, size, self)
                # Last: a damaged chunk read is named by its own offset, not by the whole section's CRC.
                damage = data_section_damage(stream, size)
                if damage is not None:
                    self.skips.take(path, damage)
            except CorruptData as exc:
                raise InputError(f"{path}: corrupt MCAP data: {exc}") from None

    def _summary(self, stream: BufferedReader, size: int) -> Summary | None:
        """Return the file's summary section; None if it has none (with a warning), or one damaged and skipped."""
        try:
            summary = read_summary(stream, size, self.codecs.limit)
        except Damage as damage:
            self.skips.take(self.path, damage)  # its warning says why the file is read by a linear scan
            return None
        if summary is None:
            logger.warning("%s: no summary index (an unfinished or cut-off recording?); reading it by a linear scan",
                           self.path)
        return summary

    def read_db3(self, path: Path) -> None:
        """Read one rosbag2 sqlite3 file, a batch of messages at a time."""
        self.path = path
        with open_db3(path) as connection:
            ids = []
            for topic in db3_info(connection, path).topics:
                self.topics.setdefault(topic.name, topic.type)
                if topic.name == self.topic:
                    self.sink.check(path, Channel(topic.name, topic.serialization_format, topic.type,
                                                  topic.definition_encoding, topic.definition))
                    ids.append(topic.id)
            if not ids:
                return
            try:
                for batch in db3_messages(connection, path, ids, self.sink.wants_log_times):
                    count = len(batch.starts)
                    if batch.length and self.sink.add_rows(batch.buf.reshape(count, batch.length),
                                                           batch.log_times):
                        self.messages += count
                    else:
                        self.add(batch.buf, batch.starts, batch.lengths, batch.log_times)
            except CorruptData as exc:
                raise InputError(f"{path}: corrupt message data: {exc}") from None

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
            if opcode == SCHEMA:
                schema_id, name, encoding, text = schema_record(content)
                self.schemas[schema_id] = (name, encoding, text)
            else:
                channel_id, schema_id, topic, encoding = channel_record(content)
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


# --- reading ------------------------------------------------------------------------------


def _read_indexed(stream: BufferedReader, size: int, summary: Summary, reader: _Reader) -> None:
    """Read the topic's messages chunk by chunk through the chunk and message indexes."""
    wanted = reader.select(summary.schemas, summary.channels)
    if not wanted:
        return
    reader.sink.reserve(sum(summary.channel_counts.get(c, 0) for c in wanted))
    chunks = _sized(reader, size, [c for c in sorted(summary.chunks, key=lambda c: c.start)
                                   if not c.message_index_offsets or wanted & c.message_index_offsets.keys()])
    # One buffer for the file bytes, one for the decompressed records, reused chunk after
    # chunk: fresh megabytes per chunk cost more in page faults than the decompression.
    # (A reading thread does not pay on two cores: it waits for the GIL as long as it saves.)
    raw_buffer = bytearray(max((c.length + c.message_index_length for c in chunks), default=0))
    out = bytearray(max((c.uncompressed_size for c in chunks), default=0))
    for chunk in chunks:
        raw = memoryview(raw_buffer)[: chunk.length + chunk.message_index_length]
        stream.seek(chunk.start)
        if stream.readinto(raw) < len(raw):
            raise CorruptData(f"the chunk at byte {chunk.start} runs past the end of the file")
        try:
            buf = chunk_records(raw[: chunk.length], chunk.start, reader.codecs, out)
        except Damage as damage:
            reader.skips.take(reader.path, damage)
            continue
        ids = [c for c in chunk.message_index_offsets if c in wanted]
        if not ids:  # a chunk written without message indexes: walk its records
            _decode_walked(buf, wanted, reader)
            continue
        entries = [message_index(raw, chunk.message_index_offsets[c] - chunk.start) for c in ids]
        index = entries[0]
        if len(entries) > 1:
            index = np.concatenate(entries)
            index = index[np.argsort(index[:, 1], kind="stable")]
        _decode_records(buf, index[:, 1].astype(np.int64), index[:, 0], reader, chunk.start)


def _sized(reader: _Reader, size: int, chunks: list[ChunkIndex]) -> list[ChunkIndex]:
    """Return the chunks whose sizes, as their indexes declare them, fit the file and the limits.

    Checked before any buffer is made for them: a declared size is a number anyone can write.
    A chunk over a limit is damage (refused, or skipped); one past the file's end, corruption.
    """
    fitting = []
    for chunk in chunks:
        if chunk.start + chunk.length + chunk.message_index_length > size:
            raise CorruptData(f"the chunk at byte {chunk.start} runs past the end of the file")
        damage = (reader.codecs.too_long(chunk.start, max(chunk.length, chunk.message_index_length))
                  or reader.codecs.too_large(chunk.start, chunk.uncompressed_size))
        if damage is not None:
            reader.skips.take(reader.path, damage)
        else:
            fitting.append(chunk)
    return fitting


def _decode_records(
    buf: NDArray[np.uint8], offsets: NDArray[np.int64], log_times: npt.ArrayLike,
    reader: _Reader, chunk_at: int,
) -> None:
    """Hand over the payloads of the Message records at `offsets` of the chunk's records `buf`."""
    if len(offsets) == 0:
        return
    if offsets.min() < 0 or offsets.max() + DATA_AT > len(buf):
        raise CorruptData(f"a message index of the chunk at byte {chunk_at} points outside it")
    head = byte_rows(buf, offsets, RECORD_HEAD)
    if np.any(head[:, 0] != MESSAGE):
        raise CorruptData(f"a message index of the chunk at byte {chunk_at} points at no message")
    lengths = head[:, 1:].view("<u8")[:, 0].astype(np.int64)
    if lengths.min() < MESSAGE_FIXED or (offsets + RECORD_HEAD + lengths).max() > len(buf):
        raise CorruptData(f"a message of the chunk at byte {chunk_at} runs past it")
    times = np.asarray(log_times, dtype=np.uint64).astype(np.int64)
    size = int(lengths[0])
    if size == lengths.max() == lengths.min() and head.strides[0] == RECORD_HEAD + size:
        # One topic, one length: the records lie back to back, a (m, size) view of the chunk.
        payloads = as_strided(buf[int(offsets[0]) + DATA_AT :],
                              shape=(len(offsets), size - MESSAGE_FIXED),
                              strides=(RECORD_HEAD + size, 1), writeable=False)
        if reader.sink.add_rows(payloads, times):
            reader.messages += len(offsets)
            return
    reader.add(buf, offsets + DATA_AT, lengths - MESSAGE_FIXED, times)


def _decode_walked(buf: NDArray[np.uint8], wanted: set[int], reader: _Reader) -> None:
    """Hand over the wanted channels' messages found by walking the records in `buf`."""
    offsets, times = [], []
    for opcode, content, position in walk_positions(buf):
        if opcode == MESSAGE and len(content) >= MESSAGE_FIXED:
            channel_id, _, log_time = struct.unpack_from("<HIQ", content)
            if channel_id in wanted:
                offsets.append(position)
                times.append(log_time)
        elif opcode in (SCHEMA, CHANNEL):
            reader.learn(opcode, content)
            wanted |= reader.wanted
    _decode_records(buf, np.array(offsets, dtype=np.int64), np.array(times, dtype=np.uint64),
                    reader, 0)


def _read_linear(stream: IO[bytes], size: int, reader: _Reader) -> None:
    """Read the topic's messages from the start, chunk by chunk; stop at a cut record."""
    definitions = Definitions(stream, reader.learn, reader.codecs, reader.path, reader.skips)
    batch: list[bytes] = []
    batch_times: list[int] = []

    def flush() -> None:
        if batch:
            data = np.frombuffer(b"".join(batch), dtype=np.uint8)
            lengths = np.array([len(b) for b in batch], dtype=np.int64)
            starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
            # Log times are u64: the same int64 view as the indexed path's (_decode_records), never an overflow.
            reader.add(data, starts, lengths, np.array(batch_times, dtype=np.uint64).astype(np.int64))
            batch.clear()
            batch_times.clear()

    for record in data_records(stream, size, reader.codecs.limit):
        if record.opcode == CUT:
            reader.cut_at(record.position)
            break
        if record.opcode in (SCHEMA, CHANNEL):
            definitions.take(record.opcode, memoryview(record.content))
        elif record.opcode == MESSAGE and len(record.content) >= MESSAGE_FIXED:
            channel_id, _, log_time = struct.unpack_from("<HIQ", record.content)
            if channel_id in reader.wanted:
                batch.append(record.content[MESSAGE_FIXED:])
                batch_times.append(log_time)
                if len(batch) >= _BATCH:
                    flush()
        elif record.opcode == CHUNK:
            flush()
            _read_chunk(record, definitions, reader)
    flush()


def _read_chunk(record: DataRecord, definitions: Definitions, reader: _Reader) -> None:
    """Hand over the wanted messages of a chunk met in a linear scan, through its message indexes."""
    walked = definitions.chunk(record)
    indexes = record.indexes
    if indexes is None:
        if walked is not None:  # None: damaged, and skipped
            _decode_walked(walked, set(reader.wanted), reader)
        return
    ids = [c for c in indexes if c in reader.wanted]
    if not ids:
        return
    buf = walked if walked is not None else definitions.records(record)
    if buf is None:
        return
    index = indexes[ids[0]]
    if len(ids) > 1:
        index = np.concatenate([indexes[c] for c in ids])
        index = index[np.argsort(index[:, 1], kind="stable")]
    _decode_records(buf, index[:, 1].astype(np.int64), index[:, 0], reader, record.position)
