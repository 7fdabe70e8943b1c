"""Decoded joint state samples, gathered batch by batch into arrays sized once for the whole file."""

from __future__ import annotations

import mmap

import numpy as np
from numpy.typing import NDArray

from .joint_state_checks import Indices

__all__ = ["SampleColumns"]


class SampleColumns:
    """Decoded samples, appended per batch into arrays sized from the file's statistics.

    Filling preallocated arrays keeps the peak near one copy of the result (an hour at
    1 kHz is 170 MB per float array); batches beyond the reserved size are kept apart and
    concatenated at the end. Velocities are kept only if `velocities`; whether every
    batch had them is noted either way.
    """

    def __init__(self, velocities: bool = True) -> None:
        self.keep_velocities = velocities
        self.capacity = 0
        self.count = 0
        self._filled = 0
        self._arrays: list[np.ndarray] | None = None
        self._velocities: NDArray[np.float64] | None = None
        self._extra: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]] = []
        self._indices: Indices = []
        self.some_velocities = False
        self.all_velocities = True

    def reserve(self, count: int) -> None:
        """Expect `count` more samples (an upper bound)."""
        if self._arrays is None:
            self.capacity += count

    def append(
        self, times: NDArray[np.int64], log_times: NDArray[np.int64],
        positions: NDArray[np.float64], velocities: NDArray[np.float64] | None,
        indices: int | NDArray[np.int64],
    ) -> None:
        """Add a batch: stamps and log times [ns], (m, n) positions and velocities or None.

        `indices`: which messages of the topic the rows are (an int: consecutive from there).
        """
        m, n = positions.shape
        self.count += m
        self._indices.append((m, indices))
        self.some_velocities |= velocities is not None
        self.all_velocities &= velocities is not None
        if not self.keep_velocities:
            velocities = None
        if self._arrays is None and self.capacity >= m:
            self._arrays = [_touched((self.capacity,), np.int64),
                            _touched((self.capacity,), np.int64),
                            _touched((self.capacity, n), np.float64)]
        if self._arrays is None or self._filled + m > self.capacity or self._extra:
            # Copies: values may be views of a chunk buffer that is about to be reused.
            kept = None if velocities is None else np.array(velocities)
            self._extra.append((np.array(times), np.array(log_times), np.array(positions), kept))
            return
        rows = slice(self._filled, self._filled + m)
        for array, values in zip(self._arrays, (times, log_times, positions), strict=True):
            array[rows] = values
        if velocities is not None and self.all_velocities:
            if self._velocities is None:
                self._velocities = _touched((self.capacity, n), np.float64)
            self._velocities[rows] = velocities
        self._filled += m

    def take(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, Indices]:
        """Return times, log times, positions, velocities (None unless every batch had them), indices."""
        parts = list(self._extra)
        if self._arrays is not None:
            filled = self._filled
            velocities = self._velocities[:filled] if self._velocities is not None else None
            times, log_times, positions = (array[:filled] for array in self._arrays)
            parts.insert(0, (times, log_times, positions, velocities))
        indices, self._indices = self._indices, []
        self._arrays, self._velocities, self._extra = None, None, []
        if len(parts) == 1:
            times, log_times, positions, velocities = parts[0]
        else:
            times, log_times, positions = (np.concatenate([p[i] for p in parts]) for i in range(3))
            velocities = None
            if self.all_velocities and self.keep_velocities:
                velocities = np.concatenate([p[3] for p in parts if p[3] is not None])
        return (times, log_times, positions, velocities if self.all_velocities else None,
                indices)


def _touched(shape: tuple[int, ...], dtype: type[np.generic]) -> np.ndarray:
    """Return a zeroed array whose pages are already mapped.

    Pages first touched one batch at a time, between the decompressor's allocations,
    cost ten times more than one sweep over them; where the system maps them all in one
    call (Linux MAP_POPULATE), that costs about half a sweep.
    """
    size = int(np.prod(shape)) * np.dtype(dtype).itemsize
    populate = getattr(mmap, "MAP_POPULATE", 0)
    if populate and size:
        memory = mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS | populate)
        return np.frombuffer(memory, dtype=dtype).reshape(shape)
    # A bytearray is zero-filled, which touches every page.
    return np.frombuffer(bytearray(size), dtype=dtype).reshape(shape)
