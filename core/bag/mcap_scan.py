"""An MCAP file read record by record with the mcap package: opened, checked, and scanned once.

The container half of reading plan files and summaries of any bag. A file that stops on
a record boundary without a footer (its writer never finished) is read as far as it goes;
one that stops inside a record is truncated; a damaged one is corrupt. Each is an
InputError naming the file.
"""

from __future__ import annotations

import os
import struct
from collections import Counter
from collections.abc import Collection, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import zstandard
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.records import Attachment, Channel, Header, McapRecord, Message, Metadata, Schema
from mcap.stream_reader import MAGIC_SIZE, StreamReader

from ..errors import InputError
from .bag_files import check_regular

__all__ = ["DAMAGE", "Contents", "Kept", "open_mcap", "scan"]

_MAGIC = b"\x89MCAP0\r\n"
DAMAGE = (McapError, EOFError, ValueError, struct.error, RuntimeError, zstandard.ZstdError)
"""What mcap and the decompressors raise on a damaged file (lz4 raises RuntimeError)."""

Kept = tuple[Channel, Schema | None, Message]
"""A kept message with its channel and the channel's schema (None if it has none)."""


@dataclass(frozen=True)
class Contents:
    """What a linear pass over an MCAP file found; `kept` holds the kept topics' messages."""

    header: Header | None
    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    counts: Counter[int]
    start_ns: int
    end_ns: int
    metadata: tuple[Metadata, ...]
    attachments: tuple[Attachment, ...]
    kept: tuple[Kept, ...]


@contextmanager
def open_mcap(path: Path) -> Iterator[IO[bytes]]:
    """Yield `path` opened for reading, after checking that it starts like an MCAP file.

    Raises:
        InputError: The file is missing, a folder, a device or pipe, unreadable or not MCAP.

    """
    check_regular(path)
    try:
        stream = path.open("rb")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the .mcap file inside it") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    with stream:
        if stream.read(MAGIC_SIZE) != _MAGIC:
            raise InputError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")
        yield stream


def scan(path: Path, stream: IO[bytes], keep_topics: Collection[str]) -> Contents:
    """Return the contents of an MCAP file read record by record, keeping `keep_topics`' messages.

    Raises:
        InputError: The file is truncated or corrupt, or a message uses an undefined channel.

    """
    header = None
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    counts: Counter[int] = Counter()
    times: list[int] = []
    metadata: list[Metadata] = []
    attachments: list[Attachment] = []
    kept: list[Kept] = []
    for record in _records(path, stream):
        if isinstance(record, Header):
            header = record
        elif isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            channels[record.id] = record
        elif isinstance(record, Message):
            channel = channels.get(record.channel_id)
            if channel is None:
                raise InputError(f"{path}: a message uses undefined channel {record.channel_id}")
            counts[record.channel_id] += 1
            times.append(record.log_time)
            if channel.topic in keep_topics:
                kept.append((channel, schemas.get(channel.schema_id), record))
        elif isinstance(record, Metadata):
            metadata.append(record)
        elif isinstance(record, Attachment):
            attachments.append(record)
    return Contents(
        header=header,
        schemas=schemas,
        channels=channels,
        counts=counts,
        start_ns=min(times, default=0),
        end_ns=max(times, default=0),
        metadata=tuple(metadata),
        attachments=tuple(attachments),
        kept=tuple(sorted(kept, key=lambda item: item[2].log_time)),
    )


def _records(path: Path, stream: IO[bytes]) -> Iterator[McapRecord]:
    """Yield every record of an MCAP file in file order, chunks opened and CRCs checked."""
    stream.seek(0)
    records = StreamReader(stream, validate_crcs=True).records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except DAMAGE as exc:
            cut = _cut_record(stream)
            if cut is None and isinstance(exc, EndOfFile):
                return
            if cut is not None:
                message = f"file is truncated (the record at byte {cut} runs past its end)"
            else:
                message = f"corrupt MCAP data: {type(exc).__name__}: {exc}".removesuffix(": ")
            raise InputError(f"{path}: {message}") from exc
        yield record


def _cut_record(stream: IO[bytes]) -> int | None:
    """Return the offset of the first record that runs past the end of the file, or None."""
    size = stream.seek(0, os.SEEK_END)
    offset = MAGIC_SIZE
    while offset < size:
        stream.seek(offset)
        head = stream.read(9)
        if len(head) < 9:
            return offset
        opcode, length = struct.unpack("<BQ", head)
        end = offset + 9 + length + (MAGIC_SIZE if opcode == Opcode.FOOTER else 0)
        if end > size:
            return offset
        offset = end
    return None
