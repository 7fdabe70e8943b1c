"""An MCAP file without a usable summary, read from the start: its data section record by record.

A recording that was cut off (`ros2 bag record` killed, a full disk) has chunks, each followed
by the MessageIndex records of its channels, but no summary. Those message indexes are
enough to count a chunk's messages, and to find a topic's messages in it, without walking
its records one by one in Python: `data_records` hands each chunk over together with them.
A chunk is decompressed and walked only to learn the Schema and Channel records it may hold:
when it has no message indexes, or they name a channel not yet defined (whose definition
may also lie in an earlier chunk that was skipped: `Definitions` goes back for it).
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from ...errors import CorruptData, InputError
from ._mcap_records import (
    ATTACHMENT,
    CHANNEL,
    CHUNK,
    FOOTER,
    HEADER,
    MAGIC,
    MESSAGE,
    MESSAGE_FIXED,
    MESSAGE_INDEX,
    METADATA,
    RECORD_HEAD,
    SCHEMA,
    Codecs,
    attachment_name,
    channel_metadata,
    channel_record,
    chunk_records,
    header_record,
    metadata_name,
    schema_record,
    walk,
)
from .chunk_codecs import DEFAULT_MAX_CHUNK_BYTES, MAX_CHUNK_ENV, Damage, Skips

__all__ = ["CUT", "DataRecord", "Definitions", "Survey", "data_records", "survey"]

CUT = -1
"""The opcode `data_records` gives a record that runs past the end of the file."""

_ATTACHMENT_HEAD = 1 << 16


@dataclass(frozen=True)
class DataRecord:
    """A record of the data section at byte `position`, `length` bytes of content after its head.

    `content` is the record's content, except for a Chunk: it is left in the file (see
    Definitions.records), and for an Attachment: its first 64 KiB; `indexes` holds the (log_time, offset) rows of the
    MessageIndex records that follow it, per channel (None if none do).
    """

    opcode: int
    position: int
    content: bytes
    length: int = 0
    indexes: dict[int, NDArray[np.uint64]] | None = None


def data_records(stream: IO[bytes], size: int, limit: int = DEFAULT_MAX_CHUNK_BYTES) -> Iterator[DataRecord]:
    """Yield the records after the magic up to the footer; a cut record last, as opcode CUT.

    Raises:
        CorruptData: A record whose content is read (not a chunk, not an attachment) is
            longer than `limit` bytes.

    """
    position = len(MAGIC)
    while position < size:
        stream.seek(position)
        head = stream.read(RECORD_HEAD)
        if len(head) < RECORD_HEAD:
            yield DataRecord(CUT, position, b"")
            return
        opcode, length = struct.unpack("<BQ", head)
        if opcode == FOOTER:
            return
        end = position + RECORD_HEAD + length
        if end > size:
            yield DataRecord(CUT, position, b"")
            return
        if opcode == CHUNK:
            indexes, end = _message_indexes(stream, end, size)
            yield DataRecord(opcode, position, b"", length, indexes)
        elif opcode != MESSAGE_INDEX:  # one that follows no chunk indexes nothing
            if length > limit and opcode != ATTACHMENT:
                raise CorruptData(f"the record at byte {position} (opcode {opcode:#04x}) is {length} bytes long, "
                                  f"more than {MAX_CHUNK_ENV} allows ({limit})")
            # Of an attachment (a file of any size), only the head that names it is read.
            yield DataRecord(opcode, position, stream.read(min(length, _ATTACHMENT_HEAD)
                                                           if opcode == ATTACHMENT else length), length)
        position = end


def _message_indexes(
    stream: IO[bytes], position: int, size: int
) -> tuple[dict[int, NDArray[np.uint64]] | None, int]:
    """Return the MessageIndex records from `position` on, per channel, and where they end."""
    indexes: dict[int, NDArray[np.uint64]] = {}
    while position + RECORD_HEAD <= size:
        stream.seek(position)
        opcode, length = struct.unpack("<BQ", stream.read(RECORD_HEAD))
        if opcode != MESSAGE_INDEX or position + RECORD_HEAD + length > size or length < 6:
            break
        content = stream.read(length)
        channel_id, entries = struct.unpack_from("<HI", content)
        if entries % 16 or 6 + entries > length:
            raise CorruptData(f"the message index at byte {position} is malformed")
        rows = np.frombuffer(content, dtype="<u8", count=entries // 8, offset=6).reshape(-1, 2)
        indexes[channel_id] = rows
        position += RECORD_HEAD + length
    return (indexes or None), position


@dataclass
class Definitions:
    """The Schema and Channel records of a file read linearly, learned from chunks only as needed.

    `learn` takes each Schema or Channel record met, as (opcode, content); `skipped` are the
    positions of chunks not walked, searched if a channel or schema stays undefined. A
    damaged chunk of the file at `path` goes to `skips` (which refuses it unless allowed).
    """

    stream: IO[bytes]
    learn: Callable[[int, memoryview], None]
    codecs: Codecs
    path: Path = Path()
    skips: Skips = field(default_factory=Skips)
    channels: dict[int, int] = field(default_factory=dict)
    schemas: set[int] = field(default_factory=set)
    skipped: list[int] = field(default_factory=list)
    # Decompressed records, reused chunk after chunk (fresh megabytes cost page faults).
    out: bytearray = field(default_factory=bytearray)

    def take(self, opcode: int, content: memoryview) -> None:
        """Learn a top-level Schema or Channel record."""
        try:
            if opcode == SCHEMA:
                self.schemas.add(schema_record(content)[0])
            else:
                channel_id, schema_id, _, _ = channel_record(content)
                self.channels[channel_id] = schema_id
        except (struct.error, UnicodeDecodeError) as exc:
            raise CorruptData(f"a schema or channel record is malformed ({exc})") from None
        self.learn(opcode, content)

    def chunk(self, record: DataRecord) -> NDArray[np.uint8] | None:
        """Return a chunk's records decompressed if they had to be walked (and were), else None.

        Walked: a chunk without message indexes, or one naming an undefined channel. The
        skipped chunks before it are searched first when it needs a definition it lacks.
        The records returned are valid until the next call. A damaged chunk skipped gives None.
        """
        if record.indexes is not None and all(c in self.channels for c in record.indexes):
            self.skipped.append(record.position)
            return None
        buf = self.records(record)
        if buf is None:
            return None
        found = [(op, content) for op, content in walk(memoryview(buf.data)) if op in (SCHEMA, CHANNEL)]
        if not self._complete(found, record.indexes or {}):
            self._search_skipped()
        for opcode, content in found:
            self.take(opcode, content)
        return buf

    def records(self, record: DataRecord) -> NDArray[np.uint8] | None:
        """Return a chunk's records read and decompressed, valid until the next call; None if damaged and skipped."""
        return self._read(record, reuse=True)

    def _read(self, record: DataRecord, reuse: bool) -> NDArray[np.uint8] | None:
        """Return a chunk's records, in the reused buffer if `reuse`; None if damaged and skipped."""
        try:
            damage = self.codecs.too_long(record.position, record.length)
            if damage is not None:
                raise damage
            self.stream.seek(record.position)
            raw = self.stream.read(RECORD_HEAD + record.length)
            # The size a chunk declares, to size the buffer (chunk_records refuses a chunk too short to hold it).
            size = struct.unpack_from("<Q", raw, RECORD_HEAD + 16)[0] if len(raw) >= RECORD_HEAD + 24 else 0
            if reuse and len(self.out) < size <= self.codecs.limit:
                self.out = bytearray(size)
            return chunk_records(memoryview(raw), record.position, self.codecs, self.out if reuse else None)
        except Damage as damage:
            self.skips.take(self.path, damage)
            return None

    def _complete(self, found: list[tuple[int, memoryview]], indexed: dict[int, NDArray[np.uint64]]) -> bool:
        """Return True if the known definitions and `found` define every channel and schema needed."""
        channels, schemas = dict(self.channels), set(self.schemas) | {0}
        try:
            for opcode, content in found:
                if opcode == SCHEMA:
                    schemas.add(schema_record(content)[0])
                else:
                    channel_id, schema_id, _, _ = channel_record(content)
                    channels[channel_id] = schema_id
        except (struct.error, UnicodeDecodeError) as exc:
            raise CorruptData(f"a schema or channel record is malformed ({exc})") from None
        needed = set(indexed) | {c for c, s in channels.items() if c not in self.channels}
        return all(c in channels and channels[c] in schemas for c in needed)

    def _search_skipped(self) -> None:
        """Learn the definitions in the chunks skipped so far, in file order."""
        skipped, self.skipped = self.skipped, []
        for position in skipped:
            self.stream.seek(position)
            opcode, length = struct.unpack("<BQ", self.stream.read(RECORD_HEAD))
            # Not in the reused buffer: it holds the records of the chunk that needs these definitions.
            buf = self._read(DataRecord(opcode, position, b"", length), reuse=False)
            if buf is None:
                continue
            for opcode, content in walk(memoryview(buf.data)):
                if opcode in (SCHEMA, CHANNEL):
                    self.take(opcode, content)


@dataclass
class Survey:
    """What a linear pass over an MCAP file counts: header, channels, messages, records.

    `channels` maps a channel id to (topic, schema id, message encoding, metadata);
    `schemas` a schema id to its name. Times are log times [ns], (0, 0) without messages.
    """

    profile: str = ""
    library: str = ""
    schemas: dict[int, str] = field(default_factory=dict)
    channels: dict[int, tuple[str, int, str, dict[str, str]]] = field(default_factory=dict)
    counts: dict[int, int] = field(default_factory=dict)
    start_ns: int = 0
    end_ns: int = 0
    metadata: list[str] = field(default_factory=list)
    attachments: list[str] = field(default_factory=list)
    messages: int = 0

    def learn(self, opcode: int, content: memoryview) -> None:
        """Take in a Schema or Channel record."""
        if opcode == SCHEMA:
            schema_id, name, _, _ = schema_record(content)
            self.schemas[schema_id] = name
        else:
            channel_id, schema_id, topic, encoding = channel_record(content)
            self.channels[channel_id] = (topic, schema_id, encoding, channel_metadata(content))

    def add(self, channel_id: int, log_times: NDArray[np.integer] | list[int]) -> None:
        """Count messages of `channel_id` logged at `log_times` [ns]."""
        if len(log_times) == 0:
            return
        values = np.asarray(log_times, dtype=np.uint64)
        first, last = int(values.min()), int(values.max())
        if self.messages:
            first, last = min(self.start_ns, first), max(self.end_ns, last)
        self.start_ns, self.end_ns = first, last
        self.counts[channel_id] = self.counts.get(channel_id, 0) + len(log_times)
        self.messages += len(log_times)


def survey(path: Path, stream: IO[bytes], size: int, skips: Skips | None = None) -> Survey:
    """Return what an MCAP file holds, counted from the start without a summary.

    Chunks are counted from the MessageIndex records that follow them, and decompressed
    only to learn definitions or where they have no message indexes. A damaged chunk that
    `skips` allows to skip is counted from its message indexes all the same, else not at all.

    Raises:
        InputError: The file is truncated inside a record, or corrupt, or a message uses
            a channel it never defines.

    """
    found = Survey()
    definitions = Definitions(stream, found.learn, Codecs(), path, skips or Skips())
    try:
        for record in data_records(stream, size, definitions.codecs.limit):
            if record.opcode == CUT:
                raise InputError(f"{path}: file is truncated (the record at byte "
                                 f"{record.position} runs past its end)")
            _survey_record(record, found, definitions)
    except (CorruptData, struct.error, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: corrupt MCAP data: {exc}") from None
    undefined = sorted(set(found.counts) - set(found.channels))
    if undefined:
        raise InputError(f"{path}: a message uses undefined channel {undefined[0]}")
    return found


def _survey_record(record: DataRecord, found: Survey, definitions: Definitions) -> None:
    """Count one record of the data section into `found`."""
    content = memoryview(record.content)
    if record.opcode == HEADER:
        found.profile, found.library = header_record(content)
    elif record.opcode in (SCHEMA, CHANNEL):
        definitions.take(record.opcode, content)
    elif record.opcode == MESSAGE and len(content) >= MESSAGE_FIXED:
        channel_id, _, log_time = struct.unpack_from("<HIQ", content)
        found.add(channel_id, [log_time])
    elif record.opcode == METADATA:
        found.metadata.append(metadata_name(content))
    elif record.opcode == ATTACHMENT:
        found.attachments.append(attachment_name(content))
    elif record.opcode == CHUNK:
        walked = definitions.chunk(record)
        if record.indexes is not None:
            for channel_id, rows in record.indexes.items():
                found.add(channel_id, rows[:, 0])
        elif walked is not None:
            times: dict[int, list[int]] = {}
            for opcode, inner in walk(memoryview(walked.data)):
                if opcode == MESSAGE and len(inner) >= MESSAGE_FIXED:
                    channel_id, _, log_time = struct.unpack_from("<HIQ", inner)
                    times.setdefault(channel_id, []).append(log_time)
            for channel_id, logged in times.items():
                found.add(channel_id, logged)
