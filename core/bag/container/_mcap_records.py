"""MCAP records read without the mcap package: the summary section, record walks, chunks decompressed.

The few record kinds bulk topic reading needs (MCAP specification, records Header to
Statistics), parsed from bytes with struct and numpy; only zstandard (and lz4, imported
when a file uses it) besides. A structural error raises CorruptData, which the topic
reader turns into an InputError naming the file.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import IO

import numpy as np
from numpy.typing import NDArray

from ...errors import CorruptData, InputError
from .chunk_codecs import MAX_CHUNK_ENV, Codecs, Damage, crc32

__all__ = [
    "ATTACHMENT",
    "CHANNEL",
    "CHUNK",
    "CHUNK_FIXED",
    "DATA_AT",
    "FOOTER",
    "HEADER",
    "MAGIC",
    "MESSAGE",
    "MESSAGE_INDEX",
    "METADATA",
    "MESSAGE_FIXED",
    "RECORD_HEAD",
    "SCHEMA",
    "ChunkIndex",
    "Codecs",
    "Summary",
    "attachment_name",
    "channel_metadata",
    "channel_record",
    "chunk_records",
    "header_record",
    "message_index",
    "metadata_name",
    "read_summary",
    "schema_record",
    "walk",
    "walk_positions",
]

MAGIC = b"\x89MCAP0\r\n"
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, MESSAGE_INDEX, CHUNK_INDEX = 1, 2, 3, 4, 5, 6, 7, 8
ATTACHMENT, STATISTICS, METADATA = 9, 11, 12
RECORD_HEAD = 9  # opcode u8 + length u64
# A Chunk record's content before its records: start and end times, uncompressed size u64, CRC u32,
# compression (a string: u32 length, here empty) and the records' length u64.
CHUNK_FIXED = 8 + 8 + 8 + 4 + 4 + 8
FOOTER_SIZE = RECORD_HEAD + 20 + len(MAGIC)
# A Message record: head, channel_id u16, sequence u32, log_time u64, publish_time u64, data.
MESSAGE_FIXED = 22
DATA_AT = RECORD_HEAD + MESSAGE_FIXED


@dataclass(frozen=True)
class ChunkIndex:
    """A ChunkIndex record: where a chunk lies, its message indexes per channel, its size decompressed."""

    start: int
    length: int
    message_index_offsets: dict[int, int]
    message_index_length: int
    uncompressed_size: int


@dataclass
class Summary:
    """What a file's summary section holds: schemas and channels by id, chunk indexes, counts per channel."""

    schemas: dict[int, tuple[str, str, bytes]] = field(default_factory=dict)
    channels: dict[int, tuple[int, str, str]] = field(default_factory=dict)
    chunks: list[ChunkIndex] = field(default_factory=list)
    channel_counts: dict[int, int] = field(default_factory=dict)


def read_summary(stream: IO[bytes], size: int, limit: int) -> Summary | None:
    """Return the schemas, channels and chunk indexes of the summary section, or None without a readable one.

    Raises:
        Damage: The summary section is longer than `limit` bytes, or fails the footer's CRC check.

    """
    if size < len(MAGIC) + FOOTER_SIZE:
        return None
    stream.seek(size - FOOTER_SIZE)
    tail = stream.read(FOOTER_SIZE)
    if tail[-len(MAGIC) :] != MAGIC or tail[0] != FOOTER:
        return None
    summary_start, _, summary_crc = struct.unpack_from("<QQI", tail, RECORD_HEAD)
    if not len(MAGIC) <= summary_start <= size - FOOTER_SIZE:
        return None
    length = size - FOOTER_SIZE - summary_start
    if length > limit:
        raise Damage("summary section", summary_start, f"is {length} bytes long, more than {MAX_CHUNK_ENV} "
                                                       f"allows ({limit})")
    stream.seek(summary_start)
    data = stream.read(length)
    if summary_crc:
        # Over the summary and the footer up to its summary_crc field (MCAP specification).
        computed = crc32(tail[: RECORD_HEAD + 16], crc32(data))
        if computed != summary_crc:
            raise Damage("summary section", summary_start, f"fails its CRC check: its CRC-32 is {computed:#010x}, "
                                                           f"the footer records {summary_crc:#010x}")
    summary = Summary()
    try:
        for opcode, content in walk(data):
            if opcode == SCHEMA:
                schema_id, name, encoding, text = schema_record(content)
                summary.schemas[schema_id] = (name, encoding, text)
            elif opcode == CHANNEL:
                channel_id, schema_id, channel_topic, encoding = channel_record(content)
                summary.channels[channel_id] = (schema_id, channel_topic, encoding)
            elif opcode == CHUNK_INDEX:
                summary.chunks.append(_chunk_index(content))
            elif opcode == STATISTICS:
                # message_count .. message_end_time take 42 bytes; then a map<u16, u64>.
                (map_size,) = struct.unpack_from("<I", content, 42)
                counts = struct.iter_unpack("<HQ", content[46 : 46 + map_size])
                summary.channel_counts = dict(counts)
    except (CorruptData, struct.error, UnicodeDecodeError):
        return None  # an unreadable summary: the linear scan still reads the data
    return summary


def walk(data: bytes | memoryview) -> Iterator[tuple[int, memoryview]]:
    """Yield (opcode, content) of the records in `data`, which must hold whole records."""
    view = memoryview(data)
    position, end = 0, len(view)
    while position < end:
        if position + RECORD_HEAD > end:
            raise CorruptData(f"a record header at byte {position} is cut")
        opcode, length = struct.unpack_from("<BQ", view, position)
        start = position + RECORD_HEAD
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


def schema_record(content: memoryview) -> tuple[int, str, str, bytes]:
    """Return id, name, encoding and data of the Schema record `content`."""
    (schema_id,) = struct.unpack_from("<H", content)
    name, offset = _string(content, 2)
    encoding, offset = _string(content, offset)
    (length,) = struct.unpack_from("<I", content, offset)
    return schema_id, name, encoding, bytes(content[offset + 4 : offset + 4 + length])


def channel_record(content: memoryview) -> tuple[int, int, str, str]:
    """Return id, schema id, topic and message encoding of the Channel record `content`."""
    channel_id, schema_id = struct.unpack_from("<HH", content)
    topic, offset = _string(content, 4)
    encoding, _ = _string(content, offset)
    return channel_id, schema_id, topic, encoding


def channel_metadata(content: memoryview) -> dict[str, str]:
    """Return the metadata map of the Channel record `content`."""
    _, offset = _string(content, 4)
    _, offset = _string(content, offset)
    (size,) = struct.unpack_from("<I", content, offset)
    end, offset = offset + 4 + size, offset + 4
    if end > len(content):
        raise CorruptData("a channel's metadata runs past its record")
    metadata = {}
    while offset < end:
        key, offset = _string(content, offset)
        value, offset = _string(content, offset)
        metadata[key] = value
    return metadata


def header_record(content: memoryview) -> tuple[str, str]:
    """Return profile and library of the Header record `content`."""
    profile, offset = _string(content, 0)
    library, _ = _string(content, offset)
    return profile, library


def metadata_name(content: memoryview) -> str:
    """Return the name of the Metadata record `content`."""
    return _string(content, 0)[0]


def attachment_name(content: memoryview) -> str:
    """Return the name of the Attachment record `content` (after its log and create times)."""
    return _string(content, 16)[0]


def _chunk_index(content: memoryview) -> ChunkIndex:
    start, length, map_size = struct.unpack_from("<QQI", content, 16)
    entries = struct.iter_unpack("<HQ", content[36 : 36 + map_size])
    (index_length,) = struct.unpack_from("<Q", content, 36 + map_size)
    _, offset = _string(content, 44 + map_size)
    (uncompressed_size,) = struct.unpack_from("<Q", content, offset + 8)
    return ChunkIndex(start, length, dict(entries), index_length, uncompressed_size)


def chunk_records(
    raw: memoryview, chunk_at: int, codecs: Codecs, out: bytearray | None = None
) -> NDArray[np.uint8]:
    """Return the decompressed records of the Chunk record in `raw`, in `out` if it fits, checked whole.

    Raises:
        Damage: The chunk declares more records than `codecs.limit`, holds fewer bytes than it
            says, does not decompress to the size it declares, or fails its CRC check.
        CorruptData: There is no chunk at all where `raw` begins.

    """
    if len(raw) < RECORD_HEAD or raw[0] != CHUNK:
        raise CorruptData(f"no chunk at byte {chunk_at}, where the chunk index points")
    if len(raw) < RECORD_HEAD + CHUNK_FIXED:
        raise Damage("chunk", chunk_at, f"holds {len(raw) - RECORD_HEAD} bytes, fewer than the {CHUNK_FIXED} of a "
                                        "chunk's header")
    uncompressed_size, uncompressed_crc = struct.unpack_from("<QI", raw, RECORD_HEAD + 16)
    damage = codecs.too_large(chunk_at, uncompressed_size)
    if damage is not None:
        raise damage
    try:
        compression, offset = _string(raw, RECORD_HEAD + 28)
        (length,) = struct.unpack_from("<Q", raw, offset)
    except (CorruptData, struct.error, UnicodeDecodeError):
        raise Damage("chunk", chunk_at, "has a malformed header: its compression name runs past it") from None
    records = raw[offset + 8 : offset + 8 + length]
    if len(records) != length:
        raise Damage("chunk", chunk_at, f"holds {len(records)} bytes of records where it declares {length}")
    try:
        data = codecs.decompress(compression, records, uncompressed_size, out)
    except Damage:
        raise
    except CorruptData as exc:
        raise Damage("chunk", chunk_at, str(exc)) from None
    except InputError:
        raise
    except Exception as exc:  # each codec raises its own kinds
        raise Damage("chunk", chunk_at, f"does not decompress ({type(exc).__name__}: {exc})") from None
    if len(data) != uncompressed_size:
        raise Damage("chunk", chunk_at, f"decompresses to {len(data)} bytes, not the {uncompressed_size} it declares")
    if uncompressed_crc:
        computed = crc32(data)
        if computed != uncompressed_crc:
            raise Damage("chunk", chunk_at, f"fails its CRC check: its records' CRC-32 is {computed:#010x}, the "
                                            f"chunk records {uncompressed_crc:#010x}")
    return np.frombuffer(data, dtype=np.uint8)


def message_index(raw: memoryview, at: int) -> NDArray[np.uint64]:
    """Return the (log_time, offset) rows of the MessageIndex record at byte `at` of `raw`."""
    opcode, length = struct.unpack_from("<BQ", raw, at)
    if opcode != MESSAGE_INDEX:
        raise CorruptData("a chunk index points at a message index that is not there")
    (size,) = struct.unpack_from("<I", raw, at + RECORD_HEAD + 2)
    start = at + RECORD_HEAD + 6
    if size % 16 or start + size > len(raw):
        raise CorruptData("a message index is malformed")
    return np.frombuffer(raw, dtype="<u8", count=size // 8, offset=start).reshape(-1, 2)


def walk_positions(buf: NDArray[np.uint8]) -> Iterator[tuple[int, memoryview, int]]:
    """Yield (opcode, content, offset of the record) of the whole records in `buf`."""
    position = 0
    for opcode, content in walk(memoryview(buf.data)):
        yield opcode, content, position
        position += RECORD_HEAD + len(content)
