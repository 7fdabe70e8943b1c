"""MCAP chunks made safe to read: decompression bounded by the size a chunk declares, CRCs, damage skipped or refused.

A chunk's records are decompressed into at most the size the chunk declares, itself at
most `max_chunk_bytes()` (1 GiB, or MOVEPLAN_MAX_CHUNK_BYTES): a small chunk that would
unpack to gigabytes (a zstd or lz4 bomb) stops at its limit, before the memory is spent.
A CRC of 0 means the writer computed none (MCAP specification). A failed check raises
Damage, a CorruptData naming the part and its offset; a read asked to skip damaged parts
(`Skips(allowed=True)`, --skip-damaged) notes it with a warning and reads on.
"""

from __future__ import annotations

import logging
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...errors import CorruptData, InputError, UsageError
from ...types import SkippedData

try:  # zlib-ng's CRC-32 runs at ~15x zlib's: checking every chunk then costs the fast reader next to nothing
    from zlib_ng.zlib_ng import crc32
except ImportError:  # pragma: no cover - zlib-ng is a dependency; zlib computes the same CRC
    from zlib import crc32

__all__ = [
    "DATA_SECTION", "DEFAULT_MAX_CHUNK_BYTES", "MAX_CHUNK_ENV", "Codecs", "Damage", "Skips", "crc32", "max_chunk_bytes",
]

logger = logging.getLogger(__name__)

MAX_CHUNK_ENV = "MOVEPLAN_MAX_CHUNK_BYTES"
"""The environment variable that sets the largest chunk a read accepts, in bytes (suffixes K, M, G: KiB, MiB, GiB)."""

DEFAULT_MAX_CHUNK_BYTES = 1 << 30
"""The largest decompressed chunk a read accepts without MOVEPLAN_MAX_CHUNK_BYTES: 1 GiB (writers use 1-4 MiB)."""

DATA_SECTION = "data section"
"""The part a Damage names when the CRC over the whole data section (the DataEnd record's) fails."""

_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def max_chunk_bytes() -> int:
    """Return the largest decompressed chunk a read accepts, in bytes: MOVEPLAN_MAX_CHUNK_BYTES, else 1 GiB.

    Raises:
        UsageError: The variable is set to something that is not a positive size.

    """
    text = os.environ.get(MAX_CHUNK_ENV, "").strip()
    if not text:
        return DEFAULT_MAX_CHUNK_BYTES
    match = re.fullmatch(r"(\d+)\s*([KMGT]?)(?:i?B)?", text, re.IGNORECASE)
    if match is None or int(match.group(1)) == 0:
        raise UsageError(f"{MAX_CHUNK_ENV}={text!r}: expected a positive number of bytes, such as 2147483648 or 2GiB")
    return int(match.group(1)) * _UNITS[match.group(2).upper()]


class Damage(CorruptData):
    """A part of an MCAP file that fails a check (CRC, size, decompression): `part` at byte `offset`, `reason`."""

    def __init__(self, part: str, offset: int, reason: str) -> None:
        self.part, self.offset, self.reason = part, offset, reason
        super().__init__(f"{self.described} (--skip-damaged reads the file without it)")

    @property
    def described(self) -> str:
        """Return what failed, without the hint: "the chunk at byte 4242 fails its CRC check: ..."."""
        return f"the {self.part} at byte {self.offset} {self.reason}"


@dataclass
class Skips:
    """The damaged parts met by one read: refused (the Damage raised on) unless `allowed`, then noted and skipped."""

    allowed: bool = False
    found: list[SkippedData] = field(default_factory=list)

    def take(self, path: Path, damage: Damage) -> None:
        """Note `damage` in `path` as skipped, with a warning; raise it unless skipping is allowed.

        The data section's CRC covers the whole file: it fails whenever a chunk does, so it is
        noted only in a file where nothing else was skipped (damage outside the chunks read).
        """
        if not self.allowed:
            raise damage
        here = [s for s in self.found if s.file == str(path)]
        if any(s.offset == damage.offset and s.part == damage.part for s in here):
            return  # met again by a second pass over the file (inspect verifies, then counts)
        if damage.part == DATA_SECTION and here:
            return
        self.found.append(SkippedData(str(path), damage.offset, damage.part, damage.reason))
        if damage.part == DATA_SECTION:
            logger.warning("%s: the data section %s; reading on, as --skip-damaged asks", path, damage.reason)
        else:
            logger.warning("%s: skipped the %s at byte %d (--skip-damaged): it %s", path, damage.part,
                           damage.offset, damage.reason)


class Codecs:
    """Decompressors, made once per read: a zstd context costs more to make than to use.

    `limit` is the largest decompressed chunk accepted [bytes]; `raw_limit` the largest chunk
    record read from the file (compression may grow incompressible data by a little).
    """

    def __init__(self, limit: int | None = None) -> None:
        self._zstd: Any = None
        self.limit = max_chunk_bytes() if limit is None else limit
        self.raw_limit = self.limit + self.limit // 8 + (1 << 16)

    def too_long(self, at: int, length: int) -> Damage | None:
        """Return the Damage of the chunk record at byte `at`, `length` bytes long, if too long to read, else None."""
        if length <= self.raw_limit:
            return None
        return Damage("chunk", at, f"is {length} bytes long, more than {MAX_CHUNK_ENV} allows ({self.raw_limit} with "
                                   "compression)")

    def too_large(self, at: int, size: int) -> Damage | None:
        """Return the Damage of the chunk at byte `at` if the records size it declares is over the limit, else None."""
        if size <= self.limit:
            return None
        return Damage("chunk", at, f"declares {size} bytes of records, more than {MAX_CHUNK_ENV} allows ({self.limit})")

    def decompress(
        self, compression: str, records: memoryview, size: int, out: bytearray | None
    ) -> bytes | memoryview:
        """Return one chunk's records decompressed, never more than `size` bytes, into `out` where the codec allows.

        Decompressing into a reused buffer spares a fresh megabyte of memory, and its page
        faults, per chunk.

        Raises:
            CorruptData: The records decompress to more than `size` bytes, or do not decompress.
            InputError: The chunk is lz4-compressed and lz4 is not installed.

        """
        if compression == "":
            return records
        if compression == "zstd":
            return self._zstd_records(records, size, out)
        if compression == "lz4":
            return _lz4_records(records, size)
        raise CorruptData(f"unknown chunk compression '{compression}'")

    def _zstd_records(self, records: memoryview, size: int, out: bytearray | None) -> memoryview:
        if self._zstd is None:
            import zstandard

            self._zstd = zstandard.ZstdDecompressor()
        # Never ZstdDecompressor.decompress: it allocates whatever size the frame header claims.
        view = memoryview(out if out is not None and len(out) >= size else bytearray(size))[:size]
        filled = 0
        with self._zstd.stream_reader(records) as reader:
            while filled < size:
                count = reader.readinto(view[filled:])
                if not count:
                    break
                filled += count
            if filled == size and reader.read(1):
                raise CorruptData(f"decompresses to more than the {size} bytes it declares")
        return view[:filled]


def _lz4_records(records: memoryview, size: int) -> bytes:
    """Return an lz4 chunk's records, never more than `size` bytes (frame after frame, as lz4.frame.decompress)."""
    try:
        import lz4.frame
    except ImportError:
        raise InputError("the file has lz4-compressed chunks; install lz4") from None
    parts: list[bytes] = []
    filled, rest = 0, bytes(records)
    while rest:
        decompressor = lz4.frame.LZ4FrameDecompressor()
        # One byte more than is left to fill: getting it means the frame holds more than declared.
        part = decompressor.decompress(rest, max_length=size - filled + 1)
        filled += len(part)
        if filled > size:
            raise CorruptData(f"decompresses to more than the {size} bytes it declares")
        parts.append(part)
        if not decompressor.eof:
            raise CorruptData("does not decompress (its lz4 frame is cut)")
        rest = decompressor.unused_data
    return b"".join(parts)
