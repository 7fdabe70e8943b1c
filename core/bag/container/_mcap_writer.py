"""MCAP written without the mcap package's per-record Python: the bytes its Writer makes, as moveplan sets it up.

mcap's Writer (zstd chunks of 1 MiB, every index, schemas and channels repeated in the summary,
statistics, summary offsets, CRCs of chunks, attachments, summary and data section) builds each
record field by field through a BytesIO, several Python calls per field: a plan file's ~120
messages took it 1.3 ms, an executed file's thousands proportionally more. Here a message is two
byte strings appended to the chunk. The records and their order are the mcap Writer's to the
byte, its chunks compressed at ZSTD_LEVEL (tests/bag/test_mcap_writer.py writes the same bags
with both; benchmarks/mcap_write.py times them): its metadata and attachments go out as they
come, before the open chunk.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from dataclasses import dataclass
from typing import BinaryIO

import zstandard

from ._mcap_records import (
    ATTACHMENT,
    CHANNEL,
    CHUNK,
    CHUNK_INDEX,
    FOOTER,
    HEADER,
    MAGIC,
    MESSAGE,
    MESSAGE_INDEX,
    METADATA,
    SCHEMA,
    STATISTICS,
)
from .chunk_codecs import crc32

__all__ = ["CHUNK_BYTES", "McapWriter", "ZSTD_LEVEL"]

CHUNK_BYTES = 1024 * 1024
"""A chunk is closed once its records pass this many bytes, as mcap's Writer does by default."""
ZSTD_LEVEL = 1
"""Chunks are compressed as mcap's C++ writer compresses them by default, which ros2 bag record uses
(CompressionLevel::Default, zstd level 1; mcap/writer.inl): 40% faster than the Python Writer's level 3,
files ~3% larger."""

_ATTACHMENT_INDEX, _METADATA_INDEX, _SUMMARY_OFFSET, _DATA_END = 0x0A, 0x0D, 0x0E, 0x0F
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")  # opcode, length, channel, sequence, log time, publish time
_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")


def _record(opcode: int, *fields: bytes) -> bytes:
    """Return an MCAP record: opcode, the fields' length, the fields."""
    body = b"".join(fields)
    return struct.pack("<BQ", opcode, len(body)) + body


def _string(text: str) -> bytes:
    """Return MCAP's string: its UTF-8 length (u32), then its bytes."""
    encoded = text.encode()
    return _U32.pack(len(encoded)) + encoded


def _pairs(values: Mapping[str, str]) -> bytes:
    """Return MCAP's map<string, string>: its byte length (u32), then key and value strings."""
    body = b"".join(_string(key) + _string(value) for key, value in values.items())
    return _U32.pack(len(body)) + body


@dataclass
class _ChunkIndex:
    start_ns: int
    end_ns: int
    offset: int
    length: int
    index_offsets: dict[int, int]
    index_length: int
    compressed: int
    uncompressed: int


class McapWriter:
    """Writes an MCAP file to a binary stream: start, schemas and channels, messages, metadata, attachments, finish."""

    def __init__(self, stream: BinaryIO, chunk_bytes: int = CHUNK_BYTES) -> None:
        """Write to `stream` (left open), closing a chunk once it holds more than `chunk_bytes`."""
        self._stream, self._chunk_bytes = stream, chunk_bytes
        self._offset = self._crc = 0
        self._schemas: list[bytes] = []
        self._channels: list[bytes] = []
        self._chunk: list[bytes] = []
        self._chunk_size = 0
        self._message_index: dict[int, list[tuple[int, int]]] = {}
        self._chunk_indexes: list[_ChunkIndex] = []
        self._attachment_indexes: list[bytes] = []
        self._metadata_indexes: list[bytes] = []
        self._counts: dict[int, int] = {}
        self._messages = self._start_ns = self._end_ns = 0
        self._compressor = zstandard.ZstdCompressor(level=ZSTD_LEVEL)

    def start(self, profile: str, library: str) -> None:
        """Write the magic and the header record; return None."""
        self._emit(MAGIC + _record(HEADER, _string(profile), _string(library)))

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        """Return the id of a new schema, written into the open chunk."""
        schema_id = len(self._schemas) + 1
        record = _record(SCHEMA, _U16.pack(schema_id), _string(name), _string(encoding), _U32.pack(len(data)), data)
        self._schemas.append(record)
        self._to_chunk(record)
        return schema_id

    def register_channel(self, topic: str, encoding: str, schema_id: int, metadata: Mapping[str, str]) -> int:
        """Return the id of a new channel, written into the open chunk."""
        channel_id = len(self._channels) + 1
        record = _record(CHANNEL, _U16.pack(channel_id), _U16.pack(schema_id), _string(topic), _string(encoding),
                         _pairs(metadata))
        self._channels.append(record)
        self._to_chunk(record)
        return channel_id

    def add_message(self, channel_id: int, log_time_ns: int, data: bytes, publish_time_ns: int) -> None:
        """Add a message to the open chunk (sequence 0); return None."""
        # Only what the chunk needs is kept per message: times and counts are summed when it closes.
        entries = self._message_index.get(channel_id)
        if entries is None:
            entries = self._message_index[channel_id] = []
        entries.append((log_time_ns, self._chunk_size))
        self._chunk.append(_MESSAGE_HEAD.pack(MESSAGE, 22 + len(data), channel_id, 0, log_time_ns, publish_time_ns))
        self._chunk.append(data)
        self._chunk_size += _MESSAGE_HEAD.size + len(data)
        if self._chunk_size > self._chunk_bytes:
            self._close_chunk()

    def add_metadata(self, name: str, values: Mapping[str, str]) -> None:
        """Write a metadata record now (before the open chunk, as mcap's Writer does); return None."""
        record = _record(METADATA, _string(name), _pairs(values))
        self._metadata_indexes.append(_record(_METADATA_INDEX, _U64.pack(self._offset), _U64.pack(len(record)),
                                              _string(name)))
        self._emit(record)

    def add_attachment(self, create_time_ns: int, log_time_ns: int, name: str, media_type: str, data: bytes) -> None:
        """Write an attachment record now, with its CRC; return None."""
        body = b"".join((_U64.pack(log_time_ns), _U64.pack(create_time_ns), _string(name), _string(media_type),
                         _U64.pack(len(data)), data))
        record = _record(ATTACHMENT, body, _U32.pack(crc32(body)))
        self._attachment_indexes.append(_record(
            _ATTACHMENT_INDEX, _U64.pack(self._offset), _U64.pack(len(record)), _U64.pack(log_time_ns),
            _U64.pack(create_time_ns), _U64.pack(len(data)), _string(name), _string(media_type)))
        self._emit(record)

    def finish(self) -> None:
        """Close the open chunk, write the data end, the summary, the footer and the magic; return None."""
        self._close_chunk()
        self._emit(_record(_DATA_END, _U32.pack(self._crc)))
        start = self._offset
        statistics = _record(
            STATISTICS, struct.pack("<QHIIIIQQ", self._messages, len(self._schemas), len(self._channels),
                                    len(self._attachment_indexes), len(self._metadata_indexes),
                                    len(self._chunk_indexes), self._start_ns, self._end_ns),
            _U32.pack(10 * len(self._counts)), *(struct.pack("<HQ", c, n) for c, n in self._counts.items()))
        groups = ((SCHEMA, self._schemas), (CHANNEL, self._channels), (STATISTICS, [statistics]),
                  (CHUNK_INDEX, [self._chunk_index(index) for index in self._chunk_indexes]),
                  (_ATTACHMENT_INDEX, self._attachment_indexes), (_METADATA_INDEX, self._metadata_indexes))
        summary, offsets, at = [], [], start
        for opcode, records in groups:
            length = sum(map(len, records))
            summary += records
            offsets.append(_record(_SUMMARY_OFFSET, struct.pack("<BQQ", opcode, at, length)))
            at += length
        data = b"".join(summary + offsets)
        footer_head = struct.pack("<BQQQ", FOOTER, 20, start if data else 0, at)
        crc = crc32(footer_head, crc32(data))
        self._stream.write(data + footer_head + _U32.pack(crc) + MAGIC)

    @staticmethod
    def _chunk_index(index: _ChunkIndex) -> bytes:
        """Return a chunk's index record."""
        offsets = b"".join(struct.pack("<HQ", c, at) for c, at in index.index_offsets.items())
        return _record(CHUNK_INDEX, struct.pack("<QQQQ", index.start_ns, index.end_ns, index.offset, index.length),
                       _U32.pack(len(offsets)), offsets, _U64.pack(index.index_length), _string("zstd"),
                       _U64.pack(index.compressed), _U64.pack(index.uncompressed))

    def _to_chunk(self, record: bytes) -> None:
        """Add a schema or channel record to the open chunk, closing it if full."""
        self._chunk.append(record)
        self._chunk_size += len(record)
        if self._chunk_size > self._chunk_bytes:
            self._close_chunk()

    def _close_chunk(self) -> None:
        """Write the open chunk, compressed, and its message indexes, if it holds a message; return None."""
        if not self._message_index:
            return  # schemas and channels wait for the first message's chunk, as in mcap's Writer
        times = [time for entries in self._message_index.values() for time, _ in entries]
        chunk_start, chunk_end = min(times), max(times)
        if self._messages == 0:
            self._start_ns, self._end_ns = chunk_start, chunk_end
        self._start_ns, self._end_ns = min(self._start_ns, chunk_start), max(self._end_ns, chunk_end)
        self._messages += len(times)
        for channel_id, entries in self._message_index.items():
            self._counts[channel_id] = self._counts.get(channel_id, 0) + len(entries)
        content = b"".join(self._chunk)
        compressed = self._compressor.compress(content)
        chunk = _record(CHUNK, struct.pack("<QQQI", chunk_start, chunk_end, len(content),
                                           crc32(content)), _string("zstd"), _U64.pack(len(compressed)),
                        compressed)
        chunk_at = self._offset
        self._emit(chunk)
        indexes, offsets, at = [], {}, self._offset
        for channel_id, entries in self._message_index.items():
            offsets[channel_id] = at
            record = _record(MESSAGE_INDEX, _U16.pack(channel_id), _U32.pack(16 * len(entries)),
                             struct.pack(f"<{2 * len(entries)}Q", *(v for entry in entries for v in entry)))
            indexes.append(record)
            at += len(record)
        written = b"".join(indexes)
        self._emit(written)
        self._chunk_indexes.append(_ChunkIndex(chunk_start, chunk_end, chunk_at, len(chunk), offsets,
                                               len(written), len(compressed), len(content)))
        self._chunk, self._message_index, self._chunk_size = [], {}, 0

    def _emit(self, data: bytes) -> None:
        """Write `data` to the data section, keeping its offset and CRC."""
        self._stream.write(data)
        self._crc = crc32(data, self._crc)
        self._offset += len(data)
