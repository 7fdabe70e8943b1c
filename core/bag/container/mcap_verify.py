"""An MCAP file checked whole: every chunk's size and CRC, every attachment's CRC, the data and summary sections' CRCs.

What `inspect` and the plan reader do before they trust a file (a topic read checks the
chunks it reads as it goes, core.bag.container.topic_reader). Every chunk is decompressed, bounded by
the size it declares, into one buffer reused chunk after chunk; an attachment is read a
block at a time. A CRC of 0 is one the writer did not compute: nothing to check.
"""

from __future__ import annotations

import struct
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from ...errors import CorruptData, InputError
from ._mcap_linear import CUT, DataRecord, data_records
from ._mcap_records import (
    ATTACHMENT,
    CHUNK,
    FOOTER,
    FOOTER_SIZE,
    MAGIC,
    RECORD_HEAD,
    attachment_name,
    chunk_records,
    read_summary,
)
from .chunk_codecs import DATA_SECTION, Codecs, Damage, Skips, crc32

__all__ = ["Verified", "data_section_damage", "verify_mcap"]

_DATA_END = 0x0F
_DATA_END_SIZE = RECORD_HEAD + 4
_BLOCK = 8 << 20


@dataclass(frozen=True)
class Verified:
    """What `verify_mcap` found: messages per channel id in the chunks it skipped, and whether the summary is sound."""

    lost: dict[int, int]
    summary_sound: bool


def verify_mcap(path: Path, stream: IO[bytes], size: int, skips: Skips) -> Verified:
    """Check every size and CRC an MCAP file records, its `size` bytes read once; return what was skipped.

    A damaged part is refused, or with `skips.allowed` noted (with a warning) and passed over:
    a chunk's messages are then counted as lost from its message indexes. A file that ends
    inside a record is left to the reads that follow, which say where it is cut.

    Raises:
        InputError: A part is damaged (the message names the file, the part's offset and the
            check that failed) and skipping is not allowed, or the file is corrupt.

    """
    codecs = Codecs()
    lost: Counter[int] = Counter()
    sound = True
    try:
        try:
            read_summary(stream, size, codecs.limit)
        except Damage as summary_damage:
            skips.take(path, summary_damage)
            sound = False
        raw, out = bytearray(), bytearray()
        for record in data_records(stream, size, codecs.limit):
            if record.opcode == CUT:
                break
            if record.opcode == ATTACHMENT:
                damage = _attachment_damage(stream, record)
            elif record.opcode == CHUNK:
                damage = codecs.too_long(record.position, record.length)
                if damage is None:
                    total = RECORD_HEAD + record.length
                    if len(raw) < total:
                        raw = bytearray(total)
                    stream.seek(record.position)
                    stream.readinto(memoryview(raw)[:total])  # type: ignore[attr-defined]  # IO omits it; files have it
                    # To size the buffer; chunk_records refuses a chunk too short to declare a size.
                    declared = struct.unpack_from("<Q", raw, RECORD_HEAD + 16)[0] if total >= RECORD_HEAD + 24 else 0
                    if len(out) < declared <= codecs.limit:
                        out = bytearray(declared)
                    try:
                        chunk_records(memoryview(raw)[:total], record.position, codecs, out)
                    except Damage as found:
                        damage = found
                if damage is not None:
                    for channel_id, rows in (record.indexes or {}).items():
                        lost[channel_id] += len(rows)
            else:
                continue
            if damage is not None:
                skips.take(path, damage)
        # After the chunks: a damaged chunk is named by its own offset, not by the whole section's CRC.
        damage = data_section_damage(stream, size)
        if damage is not None:
            skips.take(path, damage)
    except (CorruptData, struct.error, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: corrupt MCAP data: {exc}") from None
    return Verified(dict(lost), sound)


def data_section_damage(stream: IO[bytes], size: int) -> Damage | None:
    """Return the Damage of a data section that fails the CRC its DataEnd record holds, else None.

    The DataEnd record is found through the footer, where the summary section (or the
    footer) begins; a file without a footer, or a CRC of 0, has nothing to check. The whole
    data section is read for it, a block at a time.
    """
    if size < len(MAGIC) + FOOTER_SIZE + _DATA_END_SIZE:
        return None
    stream.seek(size - FOOTER_SIZE)
    tail = stream.read(FOOTER_SIZE)
    if tail[0] != FOOTER or tail[-len(MAGIC) :] != MAGIC:
        return None
    (summary_start,) = struct.unpack_from("<Q", tail, RECORD_HEAD)
    end = summary_start or size - FOOTER_SIZE
    at = end - _DATA_END_SIZE
    if not len(MAGIC) <= at <= size - FOOTER_SIZE - _DATA_END_SIZE:
        return None
    stream.seek(at)
    opcode, length, recorded = struct.unpack("<BQI", stream.read(_DATA_END_SIZE))
    if opcode != _DATA_END or length != 4 or not recorded:
        return None
    computed = _crc_of(stream, 0, at)
    if computed == recorded:
        return None
    return Damage(DATA_SECTION, 0, f"fails its CRC check: its CRC-32 is {computed:#010x}, the DataEnd record "
                                     f"at byte {at} holds {recorded:#010x}")


def _attachment_damage(stream: IO[bytes], record: DataRecord) -> Damage | None:
    """Return the Damage of an attachment that fails its CRC check, else None."""
    if record.length < 4:
        raise CorruptData(f"the attachment at byte {record.position} is too short to hold its CRC")
    name = attachment_name(memoryview(record.content))
    start = record.position + RECORD_HEAD
    computed = _crc_of(stream, start, start + record.length - 4)
    (recorded,) = struct.unpack("<I", stream.read(4))
    if not recorded or computed == recorded:
        return None
    return Damage(f"attachment '{name}'", record.position, f"fails its CRC check: its CRC-32 is {computed:#010x}, "
                                                          f"the attachment records {recorded:#010x}")


def _crc_of(stream: IO[bytes], begin: int, end: int) -> int:
    """Return the CRC-32 of bytes [begin, end) of `stream`, read a block at a time; the stream is left at `end`."""
    stream.seek(begin)
    value, left = 0, end - begin
    while left > 0:
        block = stream.read(min(_BLOCK, left))
        if not block:
            break
        value = crc32(block, value)
        left -= len(block)
    return value
