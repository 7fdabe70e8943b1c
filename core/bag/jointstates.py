"""Joint states from any bag: sensor_msgs/msg/JointState messages as numpy columns.

Fast enough for hour-long 1 kHz recordings: core.bag.container.topic_reader hands over a topic's
payloads chunk by chunk (MCAP) or batch by batch (rosbag2 sqlite3), and the rows whose
bytes up to the position array equal a template row's (same frame_id, same names, same
array sizes) are decoded together with numpy. Rows laid out differently get their own
template, or are decoded one by one. Decoded rows go to temporary files batch by batch
(core.bag._sample_store): `open_joint_states` hands back a store read by row ranges, whose
memory does not grow with the recording; `read_joint_states` loads it all.
The CDR layout itself is core.bag.cdr.joint_state's, which also encodes payloads
(`encode_joint_states`, re-exported here with JOINT_STATE_TYPE and JointStateSeries).
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import CorruptData, InputError, known
from ..types import JointStateSeries, TimeSource
from ._joint_state_checks import seconds_text
from ._sample_store import JointStateStore, SampleSpool
from .cdr import (
    JOINT_STATE_TYPE,
    JointStateLayout,
    check_definition,
    encode_joint_states,
    parse_layout,
)
from .container import Channel, byte_rows, read_topic

__all__ = [
    "JOINT_STATE_TYPE", "JointStateSeries", "JointStateStore", "encode_joint_states", "open_joint_states",
    "read_joint_states",
]

logger = logging.getLogger(__name__)

# Templates tried per batch before the remaining rows are decoded one by one: enough for
# a few publishers sharing a topic (arm and gripper), bounded for pathological files.
_MAX_LAYOUTS = 8


def read_joint_states(
    path: str | Path,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    time_source: TimeSource = "header",
    velocities: bool = True,
) -> JointStateSeries:
    """Return the joint states recorded on `topic`, columns in the order of `joints`, in memory.

    As `open_joint_states`, with every sample loaded: for short recordings and tests.
    """
    with open_joint_states(path, topic, joints, time_source, velocities) as store:
        return store.series()


def open_joint_states(
    path: str | Path,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    time_source: TimeSource = "header",
    velocities: bool = True,
    skip_damaged: bool = False,
) -> JointStateStore:
    """Return the joint states recorded on `topic` as a store read by row ranges (close it after use).

    Messages may list joints in any order and carry extra joints. Messages that lack one
    of `joints` (another publisher on the same topic, a gripper) are skipped, with a
    warning when some are. Samples are sorted by time: a time up to 50 ms earlier than one
    before it (two publishers' messages crossing) with a warning, further back is an error.

    Args:
        path: An MCAP or rosbag2 sqlite3 (.db3) file, or a rosbag2 bag folder whose split
            files are read in order.
        topic: The sensor_msgs/msg/JointState topic.
        joints: Joints to keep, in column order; None = those of the first message.
        time_source: "header" for header.stamp (falls back to log time, with a warning,
            when every stamp is zero), "log" for the bag's log time (receive time).
        velocities: False to leave the recorded velocities unread (store.has_velocities is
            False): an hour at 1 kHz holds 170 MB of them.
        skip_damaged: Skip the MCAP chunks (and summary or data sections) that fail their CRC
            or size checks, with a warning, instead of refusing the file; store.skipped lists them.

    Raises:
        InputError: The file is missing, of no bag kind, truncated or corrupt (damaged, unless
            skipped); the topic is absent (the message lists the topics present) or not
            JointState; or no message carries all of `joints` (the message lists the joints present); a
            message names a joint twice; a time goes back more than 50 ms; or a wanted
            joint has no finite position in any message.

    """
    if time_source not in ("header", "log"):
        raise ValueError(f"time_source must be 'header' or 'log', got {time_source!r}")
    source = Path(path)
    decoder = _Decoder(source, topic, tuple(joints) if joints is not None else None, velocities,
                       time_source)
    skipped = read_topic(source, topic, decoder, skip_damaged)
    return replace(decoder.store(time_source), skipped=skipped)


class _Decoder:
    """Collects decoded columns across chunks and files: the MessageSink of read_topic."""

    def __init__(
        self, source: Path, topic: str, joints: tuple[str, ...] | None, velocities: bool = True,
        time_source: TimeSource = "header",
    ) -> None:
        self.source, self.topic, self.joints = source, topic, joints
        self.columns = SampleSpool(velocities, time_source)
        # The layout of the last rows decoded together, and a row laid out so.
        self.template: tuple[NDArray[np.uint8], JointStateLayout] | None = None
        self.joint_columns: dict[tuple[str, ...], NDArray[np.intp] | None] = {}
        self.seen_joints: set[str] = set()
        self.skipped = 0
        self.messages = 0

    def check(self, path: Path, channel: Channel) -> None:
        """Raise InputError unless `channel` carries CDR JointState messages."""
        name, topic = channel.schema_name, channel.topic
        if name != JOINT_STATE_TYPE:
            raise InputError(f"{path}: topic {topic} has type {name or '(no schema)'}, "
                             f"expected {JOINT_STATE_TYPE}")
        if channel.message_encoding != "cdr":
            raise InputError(f"{path}: topic {topic} is encoded as "
                             f"'{channel.message_encoding}', expected cdr")
        if channel.schema_encoding == "ros2msg":
            check_definition(path, topic, channel.schema_data)

    def reserve(self, count: int) -> None:
        """Expect about `count` more messages: nothing to do, the samples go to disk as they come."""

    def wants_log_times(self) -> bool:
        """Return True while log times may be used: as the time source, or while every stamp is zero."""
        return self.columns.wants_log_times

    def add_rows(self, rows: NDArray[np.uint8], log_times: NDArray[np.int64]) -> bool:
        """Decode payloads of equal length, one per row; return False if they differ in layout."""
        # Rows laid out as the previous batch's take its layout without parsing one again.
        template = self.template
        if (template is None or template[1].length != rows.shape[1]
                or not _matches(rows, *template).all()):
            layout = self._layout(rows[0], 0, rows.shape[1])
            if not layout.little or not _matches(rows, rows[0], layout).all():
                return False
            template = self.template = (np.array(rows[0]), layout)
        first = self.messages
        self.messages += len(rows)
        self._add_rows(rows, template[1], log_times, first)
        self.columns.end_batch()
        return True

    def add(
        self, buf: NDArray[np.uint8], starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64],
    ) -> None:
        """Decode the payloads buf[starts[i] : starts[i] + lengths[i]]."""
        first = self.messages
        self.messages += len(starts)
        remaining = np.arange(len(starts))
        for _ in range(_MAX_LAYOUTS):
            if len(remaining) == 0:
                self.columns.end_batch()
                return
            template = self._layout(buf, int(starts[remaining[0]]), int(lengths[remaining[0]]))
            if not template.little:
                break
            same = remaining[lengths[remaining] == template.length]
            rows = byte_rows(buf, starts[same], template.length)
            match = _matches(rows, rows[0], template)
            kept = same[match]
            indices = first if len(kept) == len(starts) else first + kept
            self._add_rows(rows if match.all() else rows[match], template, log_times[kept], indices)
            matched = np.zeros(len(starts), dtype=bool)
            matched[same[match]] = True
            remaining = remaining[~matched[remaining]]
        self._add_each(buf, starts[remaining], lengths[remaining], log_times[remaining],
                       first + remaining)
        self.columns.end_batch()

    def _layout(self, buf: NDArray[np.uint8], start: int, length: int) -> JointStateLayout:
        try:
            return parse_layout(bytes(buf[start : start + length]))
        except (struct.error, UnicodeDecodeError):
            raise CorruptData("a JointState message is malformed") from None
        except ValueError as exc:
            raise CorruptData(str(exc)) from None

    def _columns(
        self, names: tuple[str, ...], size: int, index: int, stamp_ns: int
    ) -> NDArray[np.intp] | None:
        """Return the columns of the wanted joints in a message with `names`, or None.

        `index` and `stamp_ns` say which message it is (the first laid out so), for errors.
        """
        if names not in self.joint_columns:
            if len(set(names)) < len(names):
                twice = next(name for i, name in enumerate(names) if name in names[:i])
                raise InputError(
                    f"{self.source}: {self.topic} message {index} (stamp {seconds_text(stamp_ns)}) "
                    f"names joint {twice} twice: a JointState must name each joint once")
            self.seen_joints.update(names)
            if self.joints is None and size == len(names) and names:
                self.joints = tuple(dict.fromkeys(names))
            found = {name: i for i, name in reversed(list(enumerate(names)))}
            usable = self.joints is not None and all(j in found for j in self.joints)
            self.joint_columns[names] = (
                np.array([found[j] for j in self.joints or ()], dtype=np.intp) if usable else None
            )
        columns = self.joint_columns[names]
        # JointState arrays must match the names; a message without positions is unusable.
        return columns if columns is not None and size == len(names) else None

    def _add_rows(
        self, rows: NDArray[np.uint8], layout: JointStateLayout, log_times: NDArray[np.int64],
        indices: int | NDArray[np.int64],
    ) -> None:
        """Decode rows laid out as `layout`: messages `indices` of the topic (int: from there on)."""
        first = indices if isinstance(indices, int) else int(indices[0])
        columns = self._columns(layout.names, layout.position_size, first, layout.stamp_ns)
        if columns is None:
            self.skipped += len(rows)
            return
        n = layout.position_size
        seconds = rows[:, 4:8].view("<i4")[:, 0].astype(np.int64)
        times = seconds * 1_000_000_000 + rows[:, 8:12].view("<u4")[:, 0]
        velocities = None
        if layout.velocity_size == n:
            velocities = _floats(rows, layout.velocity_at, n, columns)
        self.columns.append(times, log_times, _floats(rows, layout.position_at, n, columns),
                            velocities, indices)

    def _add_each(
        self, buf: NDArray[np.uint8], starts: NDArray[np.int64], lengths: NDArray[np.int64],
        log_times: NDArray[np.int64], indices: NDArray[np.int64],
    ) -> None:
        """Decode payloads one by one: big-endian ones, or layouts beyond the templates tried."""
        times, kept_log_times, positions, velocities, kept = [], [], [], [], []
        for start, length, log_time, index in zip(starts.tolist(), lengths.tolist(),
                                                  log_times.tolist(), indices.tolist(), strict=True):
            layout = self._layout(buf, start, length)
            columns = self._columns(layout.names, layout.position_size, index, layout.stamp_ns)
            if columns is None:
                self.skipped += 1
                continue
            kept.append(index)
            data = bytes(buf[start : start + length])
            kind = ("<" if layout.little else ">") + "f8"
            n = layout.position_size
            times.append(layout.stamp_ns)
            kept_log_times.append(log_time)
            positions.append(np.frombuffer(data, kind, n, layout.position_at)[columns])
            if layout.velocity_size == n:
                velocities.append(np.frombuffer(data, kind, n, layout.velocity_at)[columns])
        if times:
            complete = len(velocities) == len(positions)
            self.columns.append(np.array(times, dtype=np.int64),
                                np.array(kept_log_times, dtype=np.int64),
                                np.array(positions, dtype=np.float64),
                                np.array(velocities, dtype=np.float64) if complete else None,
                                np.array(kept, dtype=np.int64))

    def store(self, time_source: TimeSource) -> JointStateStore:
        """Return the collected samples as a store, sorted by time."""
        source = self.source
        if self.columns.count == 0:
            wanted = self.joints or ()
            missing = [j for j in wanted if not any(j in names for names in self.joint_columns)]
            if missing or not wanted:
                raise InputError(
                    f"{source}: {self.topic} has no joint {', '.join(missing) or '(any)'}; joints "
                    f"present: {known(self.seen_joints)}")
            raise InputError(f"{source}: no message on {self.topic} carries all of "
                             f"{', '.join(wanted)} with positions; joints present: "
                             f"{known(self.seen_joints)}")
        if self.skipped:
            logger.warning("%s: skipped %d of %d messages on %s that lack one of the joints %s",
                           source, self.skipped, self.messages, self.topic,
                           ", ".join(self.joints or ()))
        if time_source == "header" and not self.columns.nonzero_stamp:
            logger.warning("%s: every header stamp on %s is zero; using log times", source,
                           self.topic)
            time_source = "log"
        if not self.columns.all_velocities and self.columns.some_velocities:
            logger.warning("%s: only some messages on %s carry velocities; ignoring velocities",
                           source, self.topic)
        return self.columns.store(time_source, tuple(self.joints or ()), str(source),
                                  f"{source}: {self.topic}")


def _matches(rows: np.ndarray, template: np.ndarray, layout: JointStateLayout) -> NDArray[np.bool_]:
    """Return per row whether it is laid out as `template`: same bytes except stamp and values.

    Compared 8 bytes at a time (frame_id, names and the position count), then the
    encapsulation and the other arrays' sizes.
    """
    end = layout.position_at
    words = (end - 12) // 8
    key = slice(12, 12 + 8 * words)
    equal = rows[:, key].view("<u8") == template[key].view("<u8")
    # Usually every row is alike: one test of the whole block beats a test per row.
    same: NDArray[np.bool_] = np.ones(len(rows), dtype=bool) if equal.all() else equal.all(axis=1)
    for at, size in ((end - 8, "<u8"), (0, "<u2"), (layout.velocity_count_at, "<u4"),
                     (layout.effort_count_at, "<u4")):
        width = np.dtype(size).itemsize
        same &= rows[:, at : at + width].view(size)[:, 0] == template[at : at + width].view(size)[0]
    return same


def _floats(rows: np.ndarray, at: int, n: int, columns: NDArray[np.intp]) -> NDArray[np.float64]:
    """Return the float64 array of n values at byte `at` of each row, `columns` of it.

    Joints in the recorded order come back as a view of the rows, copied once where kept.
    """
    values = rows[:, at : at + 8 * n].view("<f8")
    if len(columns) == n and np.array_equal(columns, np.arange(n)):
        return values
    return values[:, columns]
