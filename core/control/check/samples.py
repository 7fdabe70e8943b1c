"""The recorded samples a check reads, a block at a time: in memory, or from a store on disk.

A recording of a shift holds tens of millions of samples; a check needs them one window
at a time (an execution's steps), plus a few scans over all of them (where the robot
departs, gaps, the sample period). `Samples` reads them through a `SampleSource`: a
JointStateSeries in memory, or core.bag's JointStateStore, which reads row ranges from
temporary files. Times are found by a coarse index in memory (every MARK_ROWS-th time)
and a search in one block, so nothing the size of the recording is held.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..._median import median
from ...errors import InputError, known
from ...trajectory import shortest_angular_distance
from ...types import JointStateSeries

__all__ = ["SCAN_ROWS", "SampleSource", "Samples", "source_of"]

MARK_ROWS = 1024
"""One time in this many is kept in memory to find times without reading them all."""

SCAN_ROWS = 1 << 16
"""Samples read at a time by a scan over the recording (3 MB of positions for 6 joints)."""

_DISTANCE_BLOCK = 16384
_PERIOD_INTERVALS = 100_000
# Blocks of MARK_ROWS times kept for searches: the checks search near where they searched last.
_CACHED_BLOCKS = 64


class SampleSource(Protocol):
    """Recorded joint states read by row ranges (core.bag's JointStateStore is one)."""

    @property
    def names(self) -> tuple[str, ...]:
        """Joint order of the position and velocity columns."""

    @property
    def count(self) -> int:
        """Number of samples."""

    @property
    def start_ns(self) -> int:
        """Time of the first sample in [ns]."""

    @property
    def source(self) -> str:
        """The file or folder read, for messages."""

    @property
    def has_velocities(self) -> bool:
        """True if the samples carry velocities."""

    def read_times(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return times [s] from the first sample of samples [begin, end), non-decreasing."""

    def read_positions(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return positions of samples [begin, end) in the source's column order."""

    def read_velocities(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return velocities of samples [begin, end) in the source's column order."""


@dataclass(frozen=True)
class _SeriesSource:
    """A JointStateSeries read as a SampleSource: slices of its arrays."""

    series: JointStateSeries

    @property
    def names(self) -> tuple[str, ...]:
        return self.series.names

    @property
    def count(self) -> int:
        return len(self.series.times_s)

    @property
    def start_ns(self) -> int:
        return self.series.start_ns

    @property
    def source(self) -> str:
        return self.series.source

    @property
    def has_velocities(self) -> bool:
        return self.series.velocities is not None

    def read_times(self, begin: int, end: int) -> NDArray[np.float64]:
        return self.series.times_s[begin:end]

    def read_positions(self, begin: int, end: int) -> NDArray[np.float64]:
        return self.series.positions[begin:end]

    def read_velocities(self, begin: int, end: int) -> NDArray[np.float64]:
        assert self.series.velocities is not None
        return self.series.velocities[begin:end]


def source_of(recording: JointStateSeries | SampleSource) -> SampleSource:
    """Return `recording` as a SampleSource (a JointStateSeries is read through its arrays)."""
    return _SeriesSource(recording) if isinstance(recording, JointStateSeries) else recording


@dataclass(frozen=True)
class Samples:
    """The recorded samples, read in a controller's joint order.

    Attributes:
        source: Where the samples are read from.
        count: Number of samples.
        columns: The recording's column of each controller joint.
        continuous: Per controller joint, whether its distances wrap around.
        period_s: The median time between samples in [s] (0 without two distinct times).
        first_time: Time of the first sample in [s] (0 by definition of the times).
        last_time: Time of the last sample in [s].

    """

    source: SampleSource
    count: int
    columns: NDArray[np.intp]
    continuous: NDArray[np.bool_]
    period_s: float
    first_time: float
    last_time: float
    _marks: NDArray[np.float64]
    _blocks: OrderedDict[int, NDArray[np.float64]] = field(default_factory=OrderedDict, compare=False,
                                                          repr=False)

    @staticmethod
    def build(
        source: SampleSource, joints: Sequence[str], continuous_joints: Iterable[str]
    ) -> Samples:
        """Return `source` read in the order of `joints`; InputError if one is missing."""
        missing = [j for j in joints if j not in source.names]
        if missing:
            raise InputError(
                f"{source.source or 'the recording'}: no joint {', '.join(missing)} in the "
                f"recording; joints present: {known(source.names)}")
        columns = np.array([source.names.index(j) for j in joints], dtype=np.intp)
        names = set(continuous_joints)
        continuous = np.array([j in names for j in joints])
        marks, period, first, last = _time_index(source)
        return Samples(source, source.count, columns, continuous, period, first, last, marks)

    @property
    def has_velocities(self) -> bool:
        """Return True if the samples carry velocities."""
        return self.source.has_velocities

    def times(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the times of samples [begin, end) in [s]."""
        return self.source.read_times(begin, end)

    def time(self, index: int) -> float:
        """Return the time of sample `index` in [s]."""
        if not 0 <= index < self.count:
            raise IndexError(f"sample {index} of {self.count}")
        return float(self._block(index // MARK_ROWS)[index % MARK_ROWS])

    def search(self, value: float, side: Literal["left", "right"] = "left") -> int:
        """Return where `value` [s] would go among the sample times, as np.searchsorted."""
        mark = int(np.searchsorted(self._marks, value, side=side))
        if mark == 0:
            return 0
        block = mark - 1
        return block * MARK_ROWS + int(np.searchsorted(self._block(block), value, side=side))

    def _block(self, number: int) -> NDArray[np.float64]:
        """Return the times of samples [number * MARK_ROWS, (number + 1) * MARK_ROWS), cached."""
        times = self._blocks.get(number)
        if times is None:
            begin = number * MARK_ROWS
            times = self.times(begin, min(begin + MARK_ROWS, self.count))
            self._blocks[number] = times
            if len(self._blocks) > _CACHED_BLOCKS:
                self._blocks.popitem(last=False)
        else:
            self._blocks.move_to_end(number)
        return times

    def search_many(self, values: npt.ArrayLike, side: Literal["left", "right"] = "left") -> NDArray[np.intp]:
        """Return `search` of each of `values`."""
        return np.array([self.search(float(v), side) for v in np.ravel(values)], dtype=np.intp)

    def rows(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the positions of samples [begin, end) in controller order."""
        return self.source.read_positions(begin, end)[:, self.columns]

    def spans(self, begins: Sequence[int], ends: Sequence[int]) -> NDArray[np.float64]:
        """Return the positions of samples [begins[i], ends[i]) end to end, in controller order."""
        return self._stacked(self.source.read_positions, begins, ends)

    def velocity_spans(self, begins: Sequence[int], ends: Sequence[int]) -> NDArray[np.float64]:
        """Return the velocities of samples [begins[i], ends[i]) end to end, in controller order."""
        return self._stacked(self.source.read_velocities, begins, ends)

    def _stacked(
        self, read: Callable[[int, int], NDArray[np.float64]], begins: Sequence[int], ends: Sequence[int]
    ) -> NDArray[np.float64]:
        block = np.concatenate([read(b, e) for b, e in zip(begins, ends, strict=True)])
        if np.array_equal(self.columns, np.arange(block.shape[1])):
            return block
        return block[:, self.columns]

    def distance(self, begin: int, end: int, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return per sample in [begin, end) the largest joint distance to `point` in [rad]."""
        return self._distance(self.source.read_positions(begin, end), point)

    def distances(
        self, begin: int, end: int, point: NDArray[np.float64]
    ) -> Iterator[tuple[int, NDArray[np.float64]]]:
        """Yield (first index, distances to `point` [rad]) of samples [begin, end), block by block."""
        for at in range(begin, end, SCAN_ROWS):
            stop = min(at + SCAN_ROWS, end)
            yield at, self._distance(self.source.read_positions(at, stop), point)

    def _distance(self, positions: NDArray[np.float64], point: NDArray[np.float64]) -> NDArray[np.float64]:
        result = np.zeros(len(positions))
        # Block by block: a block's columns stay in cache, where long columns would be read
        # from memory once per joint. A non-finite sample is far from any point.
        with np.errstate(invalid="ignore"):
            for at in range(0, len(positions), _DISTANCE_BLOCK):
                block = positions[at : at + _DISTANCE_BLOCK]
                out = result[at : at + len(block)]
                for j, column in enumerate(self.columns):
                    values = block[:, column]
                    if self.continuous[j]:
                        gap = np.abs(shortest_angular_distance(point[j], values))
                    else:
                        gap = np.abs(values - point[j])
                    np.maximum(out, gap, out=out)
        return result

    def time_blocks(self) -> Iterator[tuple[int, NDArray[np.float64]]]:
        """Yield (first index, times [s]) of every sample, block by block."""
        for at in range(0, self.count, SCAN_ROWS):
            yield at, self.times(at, min(at + SCAN_ROWS, self.count))


def _time_index(source: SampleSource) -> tuple[NDArray[np.float64], float, float, float]:
    """Return the coarse time index, the median sample period [s], and the first and last times [s].

    The median is taken over up to _PERIOD_INTERVALS spread intervals, (i - 1, i) for every
    `every`-th sample i, as np.median would take it.
    """
    count = source.count
    every = max(1, count // _PERIOD_INTERVALS)
    marks, steps = [], []
    previous = np.nan
    first = last = 0.0
    for at in range(0, count, SCAN_ROWS):
        times = source.read_times(at, min(at + SCAN_ROWS, count))
        if at == 0:
            first = float(times[0])
        last = float(times[-1])
        marks.append(times[(-at) % MARK_ROWS :: MARK_ROWS].copy())  # not a view holding the block
        # Intervals (i - 1, i) ending in this block, the one across its start included.
        ends = np.arange(at + (-at) % every, at + len(times), every)
        ends = ends[ends >= every]
        before = np.concatenate(([previous], times))
        steps.append(before[ends - at + 1] - before[ends - at])
        previous = times[-1]
    step = np.concatenate(steps) if steps else np.zeros(0)
    step = step[step > 0.0]
    period = float(median(step)) if len(step) else 0.0
    mark_times = np.concatenate(marks) if marks else np.zeros(0)
    return mark_times, period, first, last
