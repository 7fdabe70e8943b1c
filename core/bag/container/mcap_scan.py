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

from ...errors import InputError
from ._files import check_regular

__all__ = ["DAMAGE", "ClampedReads", "Contents", "Kept", "open_mcap", "scan"]

_MAGIC = b"\x89MCAP0\r\n"
DAMAGE = (McapError, EOFError, ValueError, struct.error, RuntimeError, zstandard.ZstdError, OverflowError)
"""What mcap and the decompressors raise on a damaged file (lz4 raises RuntimeError; a record inside a
chunk whose length is 2**63 or more, read from the chunk's bytes, raises OverflowError)."""

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


class ClampedReads:
    """A file as the mcap package reads it: no read asks for more bytes than the file has left.

    mcap reads a record's content, strings and padding with stream.read(length), the length as
    the file states it; a BufferedReader allocates `length` bytes before it reads (4 GiB for a
    damaged u32 or record length, an OverflowError for a u64). Clamped to what is left, a read
    returns the same bytes and a damaged length costs nothing.
    """

    def __init__(self, stream: IO[bytes], size: int) -> None:
        self._stream, self._size = stream, size

    def read(self, length: int | None = -1) -> bytes:
        """Return up to `length` bytes (all that is left if negative), never asking for more than is left."""
        left = max(self._size - self._stream.tell(), 0)
        return self._stream.read(left if length is None or length < 0 else min(length, left))

    def seek(self, offset: int, whence: int = os.SEEK_SET) -> int:
        """Move to `offset` as the file's seek does."""
        return self._stream.seek(offset, whence)

    def tell(self) -> int:
        """Return the position in the file."""
        return self._stream.tell()


def _records(path: Path, stream: IO[bytes]) -> Iterator[McapRecord]:
    """Yield every record of an MCAP file in file order, chunks opened and CRCs checked."""
    size = stream.seek(0, os.SEEK_END)
    stream.seek(0)
    # No record is longer than the file: a length beyond it is damage, never a read of that size.
    # mcap's annotation asks for IO[bytes]; it only reads, seeks and tells.
    records = StreamReader(ClampedReads(stream, size), validate_crcs=True,  # type: ignore[arg-type]
                           record_size_limit=size).records
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
            elif isinstance(exc, OverflowError):
                message = "corrupt MCAP data: a record declares a length of 2**63 bytes or more"
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
