"""Checks of joint state samples as read: their order in time, and joints with no finite position.

A recording whose times go back far, or whose joint was never measured, gives no check
worth trusting: both are input errors naming the message and the joint. Both checks run
batch by batch as the messages stream in, so that no check needs the whole recording held.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..types import TimeSource

__all__ = ["REORDER_LIMIT_NS", "OrderWatch", "finite_error", "seconds_text"]

logger = logging.getLogger(__name__)

REORDER_LIMIT_NS = 50_000_000
"""How far [ns] a time may go back from one message to the next and still count as a
reordering (two publishers' messages crossing in transport: milliseconds) rather than a
clock that went back (a restarted simulation, a clock step: chrony and ntpd step the
clock only for offsets above 128 ms by default, and slew it below)."""


@dataclass
class OrderWatch:
    """Times that go back from message to message, watched batch by batch in the topic's order.

    A message is behind when its time is earlier than the latest time before it; its lag is
    by how much. Kept: how many are behind, the first of them, and the one furthest behind
    (the first such) with the message holding the latest time before it (its first holder).
    Messages are numbered as the topic's messages in the file, from 0.
    """

    latest: int = 0
    latest_index: int = -1
    behind: int = 0
    first_behind: int = -1
    worst_lag: int = 0
    worst: tuple[int, int, int, int] = (0, 0, 0, 0)  # (index, time, ahead index, ahead time)

    def add(self, times: NDArray[np.int64], indices: NDArray[np.int64]) -> None:
        """Take the next messages' times [ns], in the topic's order, with their message numbers."""
        if len(times) == 0:
            return
        start = times[0] if self.latest_index < 0 else self.latest
        reach = np.maximum.accumulate(np.concatenate(([start], times)))[1:]
        lag = reach - times
        late = np.flatnonzero(lag > 0)
        if len(late):
            self.behind += len(late)
            if self.first_behind < 0:
                self.first_behind = int(indices[late[0]])
            worst = int(late[np.argmax(lag[late])])
            if int(lag[worst]) > self.worst_lag:
                self.worst_lag = int(lag[worst])
                self.worst = (int(indices[worst]), int(times[worst]),
                              *self._holder(int(reach[worst]), times[:worst], indices))
        top = int(reach[-1])
        if self.latest_index < 0 or top > self.latest:
            self.latest_index = int(indices[int(np.argmax(times == top))])
            self.latest = top

    def advance(self, times: NDArray[np.int64], indices: NDArray[np.int64]) -> None:
        """Take the next messages' times [ns] when they are non-decreasing and none is behind."""
        top = int(times[-1])
        if self.latest_index < 0 or top > self.latest:
            self.latest_index = int(indices[int(np.searchsorted(times, top, side="left"))])
            self.latest = top

    def _holder(self, value: int, earlier: NDArray[np.int64], indices: NDArray[np.int64]) -> tuple[int, int]:
        """Return the first message before the current one holding `value`, and its time."""
        if self.latest_index >= 0 and self.latest == value:
            return self.latest_index, value
        return int(indices[int(np.argmax(earlier == value))]), value

    def report(self, time_source: TimeSource, where: str) -> None:
        """Warn of times that go back a little; raise InputError if one goes back far."""
        if self.behind == 0:
            return
        what = "header stamp" if time_source == "header" else "log time"
        index, time_ns, ahead, ahead_ns = self.worst
        if self.worst_lag > REORDER_LIMIT_NS:
            raise InputError(
                f"{where} message {index} has a {what} {self.worst_lag / 1e9:.3f} s earlier than "
                f"message {ahead} before it ({seconds_text(time_ns)} after "
                f"{seconds_text(ahead_ns)}): a clock that went back, or two publishers of these "
                "joints on one topic")
        logger.warning(
            "%s: %d messages have a %s earlier than a message before them, by at most "
            "%.3g ms (the first: message %d); samples sorted by %s", where, self.behind, what,
            self.worst_lag / 1e6, self.first_behind, what)


def finite_error(
    finite: NDArray[np.bool_], first_row: NDArray[np.float64], joints: tuple[str, ...], count: int,
    where: str,
) -> InputError | None:
    """Return the error for the first joint with no finite position in any message, or None.

    `finite` says per joint whether any message had a finite position; `first_row` is the
    first sample in time, whose value the message quotes.
    """
    missing = np.flatnonzero(~finite)
    if len(missing) == 0:
        return None
    column = int(missing[0])
    return InputError(f"{where} has no finite position of joint {joints[column]} in any of its "
                      f"{count} messages (message 0: {first_row[column]})")


def seconds_text(stamp_ns: int) -> str:
    """Return a time in [ns] as seconds with all its digits: "1700000000.123456789 s"."""
    sign = "-" if stamp_ns < 0 else ""
    seconds, nanoseconds = divmod(abs(stamp_ns), 1_000_000_000)
    return f"{sign}{seconds}.{nanoseconds:09d} s"
