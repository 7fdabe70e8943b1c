"""A minimal little-endian CDR (XCDR1) writer: what every moveplan message encoder writes through.

ROS 2 (rmw_fastrtps, rosbag2) serializes messages as plain CDR: a 4-byte encapsulation
header 00 01 00 00 (CDR, little endian), then the fields in definition order, each
primitive aligned to its own size relative to the start of the payload after the header.
Sequences and strings carry a uint32 length; strings are UTF-8 with a trailing NUL that
the length counts. The schema-driven encoder (core.bag.cdr.generic) writes field by field;
the hand-written twins (core.bag.cdr.bulk) pack float arrays in bulk from numpy, and
`patched_copies` repeats a written template with new values, which is what makes them
fast: a generic encoder spends a Python call per field.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["CdrWriter", "patched_copies", "time_array"]

_ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR_LE, no options
_UINT32 = struct.Struct("<I")
_TIME = struct.Struct("<II")


class CdrWriter:
    """Append CDR fields one after another; `data()` returns the message so far.

    Methods that write values a template may vary return the index in `data()` where
    those values start, for `patched_copies`.
    """

    __slots__ = ("_buffer",)

    def __init__(self) -> None:
        """Start a message with its encapsulation header."""
        self._buffer = bytearray(_ENCAPSULATION)

    def __len__(self) -> int:
        """Return the number of bytes written, header included."""
        return len(self._buffer)

    def data(self) -> bytes:
        """Return the encoded message: encapsulation header plus payload."""
        return bytes(self._buffer)

    def _align(self, size: int) -> None:
        # Alignment counts from the payload, which starts after the 4-byte header.
        padding = (len(_ENCAPSULATION) - len(self._buffer)) % size
        if padding:
            self._buffer += bytes(padding)

    def raw(self, data: bytes) -> None:
        """Append already encoded bytes as they are; return None."""
        self._buffer += data

    def boolean(self, value: bool) -> None:
        """Write a bool as one byte, 1 or 0; return None."""
        self._buffer.append(1 if value else 0)

    def uint32(self, value: int) -> None:
        """Write a uint32 (also a sequence length); return None."""
        self._align(4)
        self._buffer += _UINT32.pack(value)

    def time(self, stamp_ns: int) -> int:
        """Write a builtin_interfaces Time or Duration of `stamp_ns` [ns] >= 0; return its index."""
        self._align(4)
        start = len(self._buffer)
        # sec packed as uint32: a negative time raises here (and in time_array), where the
        # schema-driven encoder, following the schemas' int32 sec, would write it.
        self._buffer += _TIME.pack(*divmod(stamp_ns, 1_000_000_000))
        return start

    def string(self, text: str) -> None:
        """Write a string: uint32 length including the NUL, UTF-8 bytes, NUL; return None."""
        data = text.encode() + b"\0"
        self.uint32(len(data))
        self._buffer += data

    def strings(self, texts: Sequence[str]) -> None:
        """Write a string sequence: uint32 count, then each string; return None."""
        self.uint32(len(texts))
        for text in texts:
            self.string(text)

    def scalars(self, code: str, size: int, values: Sequence[Any]) -> None:
        """Write `values` as the struct type `code` ("d", "I", "b" ...) of `size` bytes; return None.

        Each element is aligned to its size: aligning the first aligns the rest, and no
        values write nothing, not even padding.
        """
        if values:
            if size > 1:
                self._align(size)
            self._buffer += struct.pack(f"<{len(values)}{code}", *values)

    def float64_array(self, values: NDArray[np.float64]) -> int:
        """Write the elements of `values` (C order) as float64, no length; return their index."""
        # Alignment comes before the first element, so an empty array pads nothing,
        # exactly as an encoder that aligns each element does.
        if values.size:
            self._align(8)
        start = len(self._buffer)
        self._buffer += values.astype("<f8", copy=False).tobytes()
        return start

    def float64_sequence(self, values: NDArray[np.float64]) -> int:
        """Write a float64 sequence: uint32 length, then 1-D `values`; return their index."""
        self.uint32(len(values))
        return self.float64_array(values)


def time_array(stamps_ns: Iterable[int] | NDArray[np.integer]) -> NDArray[np.uint32]:
    """Return builtin_interfaces Time or Duration {sec, nanosec} rows for `stamps_ns` >= 0.

    Raises OverflowError for a negative time or one past uint32 seconds, as CdrWriter.time.
    """
    # Vectorized: an executed file has a stamp per control cycle, 1,000 per second.
    if isinstance(stamps_ns, np.ndarray):
        stamps = stamps_ns.astype(np.int64, copy=False).reshape(-1)
    else:
        stamps = np.fromiter(stamps_ns, dtype=np.int64)
    sec, nanosec = np.divmod(stamps, 1_000_000_000)
    if np.any(stamps < 0) or np.any(sec > np.iinfo(np.uint32).max):
        raise OverflowError("a time must be >= 0 s with at most uint32 seconds")
    return np.stack((sec, nanosec), axis=-1).astype("<u4")


def patched_copies(
    template: bytes, count: int, patches: Iterable[tuple[int, NDArray[np.generic]]]
) -> NDArray[np.uint8]:
    """Return `count` copies of `template` as rows of bytes, patched copy by copy.

    Each patch is (index in `template`, 2-D values with `count` rows, little-endian dtype):
    in copy i, the bytes of row i replace the template's from that index on.
    """
    rows = np.tile(np.frombuffer(template, dtype=np.uint8), (count, 1))
    for start, values in patches:
        data = np.ascontiguousarray(values).view(np.uint8)  # (count, bytes per row)
        rows[:, start : start + data.shape[1]] = data
    return rows
