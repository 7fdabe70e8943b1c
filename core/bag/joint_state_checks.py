"""Checks of joint state samples as read: their order in time, and joints with no finite position.

A recording whose times go back far, or whose joint was never measured, gives no check
worth trusting: both are input errors naming the message and the joint.
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..types import TimeSource

__all__ = ["Indices", "check_finite", "check_order", "seconds_text"]

logger = logging.getLogger(__name__)

# How far [ns] a time may go back from one message to the next and still count as a
# reordering (two publishers' messages crossing in transport: milliseconds) rather than a
# clock that went back (a restarted simulation, a clock step: chrony and ntpd step the
# clock only for offsets above 128 ms by default, and slew it below).
_REORDER_LIMIT_NS = 50_000_000

Indices = list[tuple[int, int | NDArray[np.int64]]]
"""Which messages of the topic the stored rows are, per batch: (rows, first index or indices)."""


def check_order(times: NDArray[np.int64], indices: Indices, time_source: TimeSource, where: str) -> None:
    """Warn of times that go back a little in the topic's order; raise if one goes back far.

    Rows are stored per layout within a batch, so their order is restored first: only
    times that go back from message to message count.
    """
    index = _indices(indices, len(times))
    if np.any(index[1:] < index[:-1]):
        order = np.argsort(index, kind="stable")
        times, index = times[order], index[order]
    lag = np.maximum.accumulate(times) - times
    behind = np.flatnonzero(lag > 0)
    if len(behind) == 0:
        return
    what = "header stamp" if time_source == "header" else "log time"
    worst = int(behind[np.argmax(lag[behind])])
    if lag[worst] > _REORDER_LIMIT_NS:
        ahead = int(np.argmax(times[:worst]))
        raise InputError(
            f"{where} message {index[worst]} has a {what} "
            f"{lag[worst] / 1e9:.3f} s earlier than message {index[ahead]} before it "
            f"({seconds_text(int(times[worst]))} after {seconds_text(int(times[ahead]))}): a clock "
            f"that went back, or two publishers of these joints on one topic")
    first = int(behind[0])
    logger.warning(
        "%s: %d messages have a %s earlier than a message before them, by at most "
        "%.3g ms (the first: message %d); samples sorted by %s", where, len(behind), what,
        lag[worst] / 1e6, index[first], what)


def check_finite(positions: NDArray[np.float64], joints: tuple[str, ...], where: str) -> None:
    """Raise InputError if a joint has no finite position in any message."""
    if len(positions) == 0 or np.isfinite(positions[0]).all():
        return  # every joint has a finite sample: the usual case costs one row
    for column in np.flatnonzero(~np.isfinite(positions[0])).tolist():
        if not np.isfinite(positions[:, column]).any():
            joint = joints[column]
            raise InputError(
                f"{where} has no finite position of joint {joint} in "
                f"any of its {len(positions)} messages (message 0: {positions[0, column]})")


def _indices(pieces: Indices, count: int) -> NDArray[np.int64]:
    """Return the topic message index of each of `count` stored rows."""
    index = np.empty(count, dtype=np.int64)
    at = 0
    for rows, where in pieces:
        index[at : at + rows] = np.arange(where, where + rows) if isinstance(where, int) else where
        at += rows
    return index


def seconds_text(stamp_ns: int) -> str:
    """Return a time in [ns] as seconds with all its digits: "1700000000.123456789 s"."""
    sign = "-" if stamp_ns < 0 else ""
    seconds, nanoseconds = divmod(abs(stamp_ns), 1_000_000_000)
    return f"{sign}{seconds}.{nanoseconds:09d} s"
