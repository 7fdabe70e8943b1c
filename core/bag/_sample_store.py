"""Decoded joint state samples kept in temporary files, read back a block at a time.

An hour at 1 kHz of a 6-joint arm is 170 MB per float array; a shift is several hours. The
samples are written out batch by batch as they are decoded (`SampleSpool`), checked on the
way (order in time, finite positions), and read back by row ranges (`JointStateStore`), so
a check holds a few blocks of the recording, never all of it. The files are anonymous
(tempfile.TemporaryFile: unlinked at once, gone when closed or when the process ends); the
system's page cache, not the process, holds what was read recently.

Samples come out sorted by time, as a stable sort of the rows in the order they were
decoded would put them. A time may go back at most REORDER_LIMIT_NS from one message to
the next (else the read is refused), so the sort is done in one pass holding back only the
rows within that limit of the latest time seen.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..types import JointStateSeries, SkippedData, TimeSource
from ._joint_state_checks import REORDER_LIMIT_NS, OrderWatch, finite_error

__all__ = ["JointStateStore", "SampleSpool"]

# Rows sorted at a time when times go back: a few MB per column.
_SORT_ROWS = 1 << 16


class _Column:
    """Rows of `width` values of `dtype` in an anonymous temporary file, appended and read back."""

    def __init__(self, dtype: type[np.generic], width: int = 0) -> None:
        try:
            self.file = tempfile.TemporaryFile(prefix="moveplan-samples-", buffering=0)
        except OSError as exc:
            raise _unwritable(exc) from None
        self.dtype = np.dtype(dtype)
        self.width = width
        self.rows = 0

    def append(self, values: NDArray[Any]) -> None:
        """Write `values` (m rows) after the rows written so far."""
        if len(values) == 0:
            return
        data = np.ascontiguousarray(values, dtype=self.dtype).data.cast("B")
        try:
            while data:
                written = self.file.write(data)
                data = data[written or 0 :]
        except OSError as exc:
            raise _unwritable(exc) from None
        self.rows += len(values)

    def read(self, begin: int, end: int) -> NDArray[Any]:
        """Return rows [begin, end) as a fresh array."""
        begin, end = max(begin, 0), min(end, self.rows)
        shape = (max(end - begin, 0), self.width) if self.width else (max(end - begin, 0),)
        out = np.empty(shape, dtype=self.dtype)
        if out.size == 0:
            return out
        view = out.data.cast("B")
        offset = begin * self.dtype.itemsize * max(self.width, 1)
        while view:
            count = os.preadv(self.file.fileno(), [view], offset)
            if count <= 0:
                raise OSError(f"a temporary sample file ends {len(view)} bytes early")
            view, offset = view[count:], offset + count
        return out

    def close(self) -> None:
        """Close (and so delete) the file."""
        self.file.close()


def _unwritable(exc: OSError) -> InputError:
    """Return the error for a temporary sample file that cannot be made or written (a full disk)."""
    return InputError(f"cannot keep the recording's samples in {tempfile.gettempdir()} (set TMPDIR to a "
                      f"folder with space): {exc.strerror or exc}")


@dataclass(frozen=True)
class JointStateStore:
    """Joint states of one topic in time order, kept on disk and read by row ranges.

    Attributes:
        names: Joint order of the position and velocity columns.
        count: Number of samples.
        start_ns: Time of the first sample in [ns] (header stamp or log time).
        time_source: "header" or "log", as for JointStateSeries.
        source: The file or folder read, for messages.
        skipped: The damaged parts of the recording its read skipped, as asked (--skip-damaged).

    """

    names: tuple[str, ...]
    count: int
    start_ns: int
    time_source: TimeSource
    source: str
    _times: _Column
    _positions: _Column
    _velocities: _Column | None
    skipped: tuple[SkippedData, ...] = ()

    @property
    def has_velocities(self) -> bool:
        """Return True if every sample carries velocities (and they were kept)."""
        return self._velocities is not None

    def read_times(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the times of samples [begin, end) in [s] from the first sample."""
        times = self._times.read(begin, end)
        times -= self.start_ns
        return times / 1e9

    def read_positions(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the positions of samples [begin, end), shape (end - begin, len(names))."""
        return self._positions.read(begin, end)

    def read_velocities(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the velocities of samples [begin, end); ValueError if none were kept."""
        if self._velocities is None:
            raise ValueError("the store holds no velocities")
        return self._velocities.read(begin, end)

    def series(self) -> JointStateSeries:
        """Return every sample in memory, as a read-only JointStateSeries."""
        arrays = [self.read_times(0, self.count), self.read_positions(0, self.count)]
        if self._velocities is not None:
            arrays.append(self.read_velocities(0, self.count))
        for array in arrays:
            array.setflags(write=False)
        velocities = arrays[2] if len(arrays) > 2 else None
        return JointStateSeries(self.names, arrays[0], arrays[1], velocities, self.start_ns,
                                self.time_source, self.source)

    def close(self) -> None:
        """Close and delete the store's files."""
        for column in (self._times, self._positions, self._velocities):
            if column is not None:
                column.close()

    def __enter__(self) -> JointStateStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class SampleSpool:
    """Decoded samples streamed batch by batch to temporary files, checked on the way.

    `append` takes the rows of one message layout; `end_batch` closes the batch of messages
    the reader handed over (rows of several layouts, stored layout by layout), which is
    then checked in the topic's order and written. Velocities are kept only if
    `velocities`; whether every batch had them is noted either way.
    """

    def __init__(self, velocities: bool = True, time_source: TimeSource = "header") -> None:
        self.keep_velocities = velocities
        self.time_source = time_source
        self.count = 0
        self.some_velocities = False
        self.all_velocities = True
        self.nonzero_stamp = False
        self.finite: NDArray[np.bool_] | None = None
        self._pending: list[tuple[NDArray[Any], NDArray[Any], NDArray[Any], NDArray[Any] | None,
                                  NDArray[np.int64]]] = []
        self._columns: dict[str, _Column] = {}
        self._batches: list[int] = []
        # Log times stand in for header stamps only while every stamp is zero.
        self._times: tuple[str, ...] = ("header", "log") if time_source == "header" else ("log",)
        self._watch = {name: OrderWatch() for name in self._times}
        self._sorted = dict.fromkeys(self._times, True)
        self._last: dict[str, int | None] = dict.fromkeys(self._times)

    @property
    def wants_log_times(self) -> bool:
        """Return True while the log times are kept: the time source, or the stand-in for zero stamps."""
        return "log" in self._times

    def append(
        self, times: NDArray[np.int64], log_times: NDArray[np.int64],
        positions: NDArray[np.float64], velocities: NDArray[np.float64] | None,
        indices: int | NDArray[np.int64],
    ) -> None:
        """Add rows: stamps and log times [ns], (m, n) positions and velocities or None.

        `indices`: which messages of the topic the rows are (an int: consecutive from there).
        """
        m = len(times)
        index = np.arange(indices, indices + m) if isinstance(indices, int) else np.asarray(indices)
        self.some_velocities |= velocities is not None
        self.all_velocities &= velocities is not None
        self._pending.append((times, log_times, positions, velocities, index))
        self.count += m

    def end_batch(self) -> None:
        """Check and write the rows added since the last batch (they may be views of a reused buffer)."""
        pending, self._pending = self._pending, []
        if not pending:
            return
        def joined(i: int) -> NDArray[Any]:
            parts = [cast(NDArray[Any], p[i]) for p in pending]
            return np.concatenate(parts) if len(parts) > 1 else parts[0]

        stamps, log_times, positions, index = (joined(i) for i in (0, 1, 2, 4))
        velocities = None
        if self.keep_velocities and self.all_velocities:
            velocities = np.concatenate([p[3] for p in pending]) if len(pending) > 1 else pending[0][3]
        if not self.nonzero_stamp and stamps.any():
            self.nonzero_stamp = True
            if "log" in self._times and self.time_source == "header":
                self._times = ("header",)
        order = np.argsort(index, kind="stable") if np.any(index[1:] < index[:-1]) else None
        times = {"header": stamps, "log": log_times}
        for name in self._times:
            self._watch_order(name, times[name], index, order)
        if self.finite is None or not self.finite.all():
            finite: NDArray[np.bool_] = np.isfinite(positions).any(axis=0)
            self.finite = finite if self.finite is None else self.finite | finite
        self._write(times, positions, velocities)
        self._batches.append(len(stamps))

    def _watch_order(
        self, name: str, times: NDArray[np.int64], index: NDArray[np.int64], order: NDArray[np.intp] | None
    ) -> None:
        """Note whether `times` keep their order as stored, and watch them in the topic's order."""
        last = self._last[name]
        ahead = last is not None and times[0] < last
        if ahead or np.any(times[1:] < times[:-1]):
            self._sorted[name] = False
        elif order is None:
            self._watch[name].advance(times, index)  # in order: nothing behind
            self._last[name] = int(times[-1])
            return
        self._last[name] = int(times[-1])
        if order is None:
            self._watch[name].add(times, index)
        else:
            self._watch[name].add(times[order], index[order])

    def _write(
        self, times: dict[str, NDArray[Any]], positions: NDArray[Any], velocities: NDArray[Any] | None
    ) -> None:
        if not self._columns:
            width = positions.shape[1]
            self._columns = {name: _Column(np.int64) for name in self._times}
            self._columns["positions"] = _Column(np.float64, width)
            if self.keep_velocities:
                self._columns["velocities"] = _Column(np.float64, width)
        if "log" in self._columns and "log" not in self._times:
            self._columns.pop("log").close()
        for name in self._times:
            self._columns[name].append(times[name])
        self._columns["positions"].append(positions)
        kept = self._columns.get("velocities")
        if kept is not None:
            if velocities is None:  # velocities are kept only if every message has them
                kept.close()
                del self._columns["velocities"]
            else:
                kept.append(velocities)

    def store(
        self, time_source: TimeSource, joints: tuple[str, ...], source: str, where: str
    ) -> JointStateStore:
        """Return the samples as a store sorted by `time_source`'s times ("header" or "log").

        Raises:
            InputError: A time goes back more than REORDER_LIMIT_NS from one message to the
                next, or a joint has no finite position in any message.

        """
        assert self.count and self.finite is not None and time_source in self._times
        columns = self._columns
        times = columns.pop(time_source)
        for name in self._times:
            if name != time_source:
                columns.pop(name).close()
        positions, velocities = columns.pop("positions"), columns.pop("velocities", None)
        if not self._sorted[time_source]:
            self._watch[time_source].report(time_source, where)
            times, positions, velocities = _sorted(times, positions, velocities, self._batches)
        error = finite_error(self.finite, positions.read(0, 1)[0], joints, self.count, where)
        start_ns = int(times.read(0, 1)[0])
        if error is not None:
            for column in (times, positions, velocities):
                if column is not None:
                    column.close()
            raise error
        return JointStateStore(joints, self.count, start_ns, time_source, source, times, positions,
                               velocities)


def _sorted(
    times: _Column, positions: _Column, velocities: _Column | None, batches: list[int]
) -> tuple[_Column, _Column, _Column | None]:
    """Return the columns sorted by time (stable), in one pass; the unsorted ones are closed.

    After each group of batches, the rows earlier than the latest time so far by more than
    REORDER_LIMIT_NS are final: no later message may fall further behind.
    """
    sources = [c for c in (times, positions, velocities) if c is not None]
    targets = [_Column(c.dtype.type, c.width) for c in sources]
    held: list[NDArray[Any]] = [c.read(0, 0) for c in sources]
    latest: int | None = None
    for begin, end in _groups(batches):
        rows = [np.concatenate((h, c.read(begin, end))) for h, c in zip(held, sources, strict=True)]
        top = int(rows[0][len(held[0]) :].max())
        latest = top if latest is None else max(latest, top)
        order = np.argsort(rows[0], kind="stable")
        rows = [r[order] for r in rows]
        cut = int(np.searchsorted(rows[0], latest - REORDER_LIMIT_NS, side="left"))
        for target, r in zip(targets, rows, strict=True):
            target.append(r[:cut])
        held = [r[cut:] for r in rows]
    for target, r in zip(targets, held, strict=True):
        target.append(r)
    for column in sources:
        column.close()
    return targets[0], targets[1], (targets[2] if len(targets) > 2 else None)


def _groups(batches: list[int]) -> Iterator[tuple[int, int]]:
    """Yield row ranges of whole consecutive batches, about _SORT_ROWS rows each."""
    begin = end = 0
    for rows in batches:
        end += rows
        if end - begin >= _SORT_ROWS:
            yield begin, end
            begin = end
    if end > begin:
        yield begin, end
