"""rosbag2 sqlite3 files (.db3, Humble's default storage) read with Python's sqlite3.

The tables, as rosbag2_storage_sqlite3 writes them: topics(id, name, type,
serialization_format, offered_qos_profiles[, type_description_hash]) and messages(id,
topic_id, timestamp, data), the timestamp being the receive time [ns]; since schema
version 3 also schema(schema_version, ros_distro) and metadata, since version 4
message_definitions(topic_type, encoding, encoded_message_definition, ...). Older files
lack the schema table, and the oldest the QoS column.

Messages are read in the order they were inserted (by id), a few thousand at a time:
SQLite concatenates a batch's payloads and receive times (group_concat), which spares
Python a tuple and a bytes object per message, and the payloads are handed on as numpy
bytes like MCAP chunks. A damaged file (truncated, or not a bag) is an InputError naming it.

Reading never changes a file of the bag, nor adds one beside it: SQLite opens a file with
no pending write-ahead log or rollback journal as immutable (no lock, no -shm file); one
with them (a recorder that crashed, or is still writing) is copied with them to a
temporary folder, where SQLite replays the log into the copy: the data read is what a
recovered bag holds, the bag folder stays as it was.
"""

from __future__ import annotations

import logging
import shutil
import sqlite3
import tempfile
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...errors import CorruptData, InputError

__all__ = [
    "Db3Batch", "Db3Info", "Db3Topic", "check_pages", "db3_info", "db3_messages", "open_db3", "topic_counts",
]

logger = logging.getLogger(__name__)

# Message ids per query: a batch of a few MB, like an MCAP chunk.
_BATCH_IDS = 8192


@dataclass(frozen=True)
class Db3Topic:
    """A row of the topics table, with the message definition of its type if the file holds one."""

    id: int
    name: str
    type: str
    serialization_format: str
    offered_qos_profiles: str
    definition_encoding: str
    definition: bytes


@dataclass(frozen=True)
class Db3Info:
    """What a .db3 file says of itself: schema version (0: no schema table), ROS distro, topics."""

    schema_version: int
    ros_distro: str
    topics: tuple[Db3Topic, ...]


@dataclass(frozen=True)
class Db3Batch:
    """Payloads of consecutive messages: buf[starts[i] : starts[i] + lengths[i]], receive times [ns].

    `length` is the length of every payload when they are all alike, else 0.
    """

    buf: NDArray[np.uint8]
    starts: NDArray[np.int64]
    lengths: NDArray[np.int64]
    log_times: NDArray[np.int64]
    length: int


@contextmanager
def open_db3(path: Path) -> Iterator[sqlite3.Connection]:
    """Yield `path` opened for reading without changing it; an sqlite3 error inside the block becomes an InputError.

    The error names `path`, also when a copy is read (a file with a pending write-ahead log).
    """
    with ExitStack() as stack:
        try:
            connection = _connect(path, stack)
        except sqlite3.Error as exc:
            raise InputError(f"{path}: cannot open as a rosbag2 sqlite3 file: {exc}") from None
        try:
            yield connection
        except sqlite3.Error as exc:
            raise InputError(_damage(path, exc)) from None
        except CorruptData as exc:
            raise InputError(f"{path}: {exc}") from None
        finally:
            connection.close()


def _connect(path: Path, stack: ExitStack) -> sqlite3.Connection:
    """Return a connection reading `path` that writes nothing in its folder; a copy's folder goes on `stack`."""
    pending = [log for log in (Path(f"{path}-wal"), Path(f"{path}-journal")) if _has_bytes(log)]
    if not pending:
        # Read-only alone is not enough: a reader still writes its marks into a WAL database's -shm file.
        return sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro&immutable=1", uri=True)
    # immutable=1 would ignore the log and read the bag as it was before its last transactions.
    logger.info("%s: has a pending %s; reading a copy, so that the bag stays untouched", path,
                " and ".join(log.name for log in pending))
    try:
        folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="moveplan-db3-")))
        copy = folder / path.name
        shutil.copyfile(path, copy)
        for log in pending:
            shutil.copyfile(log, folder / (copy.name + log.name[len(path.name) :]))
    except OSError as exc:
        raise InputError(f"{path}: cannot copy it with its {pending[0].name} to {tempfile.gettempdir()} (set "
                         f"TMPDIR to a folder with space): {exc.strerror or exc}") from None
    return sqlite3.connect(copy)


def _has_bytes(path: Path) -> bool:
    try:
        return path.stat().st_size > 0
    except OSError:
        return False


def check_pages(connection: sqlite3.Connection, path: Path) -> None:
    """Raise InputError naming `path` unless SQLite's quick_check finds every page of the file sound.

    It reads every page: garbage in the pages of messages a count never visits is found too.
    """
    (result,) = connection.execute("PRAGMA quick_check(1)").fetchone()
    if result != "ok":
        found = "; ".join(line.strip() for line in str(result).splitlines() if not line.startswith("***"))
        raise InputError(f"{path}: corrupt sqlite3 file (SQLite's quick_check: {found})")


def _damage(path: Path, exc: sqlite3.Error) -> str:
    """Return the one-line message of an sqlite3 error met reading `path`."""
    text = str(exc)
    if text.startswith("no such table") or text.startswith("no such column"):
        return f"{path}: not a rosbag2 sqlite3 bag ({text})"
    if "locked" in text:
        return f"{path}: the sqlite3 file is locked ({text}): is a recorder still writing it?"
    return f"{path}: corrupt or truncated sqlite3 file ({text})"


def db3_info(connection: sqlite3.Connection, path: Path) -> Db3Info:
    """Return the schema version, distro and topics of an open .db3 file."""
    tables = {name for (name,) in connection.execute(
        "SELECT name FROM sqlite_master WHERE type = 'table'")}
    missing = {"topics", "messages"} - tables
    if missing:
        raise InputError(f"{path}: not a rosbag2 sqlite3 bag (no table {', '.join(sorted(missing))})")
    version, distro = 0, ""
    if "schema" in tables:
        row = connection.execute("SELECT schema_version, ros_distro FROM schema "
                                 "ORDER BY schema_version DESC LIMIT 1").fetchone()
        if row is not None:
            version, distro = _integer(row[0], "the schema table's schema_version"), str(row[1])
    definitions: dict[str, tuple[str, bytes]] = {}
    if "message_definitions" in tables:
        for topic_type, encoding, text in connection.execute(
                "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions"):
            definitions.setdefault(str(topic_type), (str(encoding), _bytes(text)))
    columns = {row[1] for row in connection.execute("PRAGMA table_info(topics)")}
    qos = "offered_qos_profiles" if "offered_qos_profiles" in columns else "''"
    topics = []
    for topic_id, name, kind, encoding, offered in connection.execute(
            f"SELECT id, name, type, serialization_format, {qos} FROM topics ORDER BY id"):
        definition_encoding, definition = definitions.get(str(kind), ("", b""))
        topics.append(Db3Topic(_integer(topic_id, f"the id of topic {_shown(name)}"), str(name), str(kind),
                               str(encoding), str(offered), definition_encoding, definition))
    return Db3Info(version, distro, tuple(topics))


def _integer(value: object, what: str) -> int:
    """Return `value`, a column rosbag2 declares INTEGER, as an int.

    Raises:
        CorruptData: It holds something else (SQLite stores any value in any column of a table
            declared without types, as a damaged or hand-made bag may be).

    """
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    raise CorruptData(f"{what} is {_shown(value)}, not an integer (rosbag2 writes one)")


def _bytes(value: object) -> bytes:
    return value if isinstance(value, bytes) else str(value).encode()


def topic_counts(connection: sqlite3.Connection, topic_ids: list[int]) -> tuple[dict[int, int], int, int]:
    """Return the message count per topic id, and the first and last receive times [ns] (0 without messages)."""
    if len(topic_ids) == 1:
        # A bag of one topic: count(*) of the whole table walks its smallest index, not the data.
        counts = {topic_ids[0]: int(connection.execute("SELECT count(*) FROM messages").fetchone()[0])}
    else:
        counts = dict.fromkeys(topic_ids, 0)
        for topic_id, count in connection.execute("SELECT topic_id, count(*) FROM messages GROUP BY topic_id"):
            if topic_id not in counts:
                raise CorruptData(_orphans(f"s ({count} of them)", topic_id))
            counts[topic_id] = int(count)
    first, last = connection.execute("SELECT min(timestamp), max(timestamp) FROM messages").fetchone()
    for value in (first, last):
        # Integers sort before reals and text in SQLite: a text time shows up as the largest.
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
            raise CorruptData(f"a message's timestamp is {_shown(value)}, not an integer number of nanoseconds")
    return counts, int(first or 0), int(last or 0)


def _orphans(row: object, topic_id: object) -> str:
    """Return the message of a row (or rows) whose topic_id the topics table does not have."""
    return (f"message row {row} names topic id {_shown(topic_id)}, which the topics table does not have "
            "(a damaged bag; rosbag2 would drop such rows unseen)")


def _shown(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def db3_messages(
    connection: sqlite3.Connection, path: Path, topic_ids: list[int],
    wants_log_times: Callable[[], bool] = lambda: True,
) -> Iterator[Db3Batch]:
    """Yield the messages of `topic_ids` in insertion order, a batch at a time.

    A batch read while `wants_log_times()` is False carries zeros for its receive times:
    SQLite spends a third of a batch's time writing them out as text.

    Raises:
        CorruptData: A row names a topic id the topics table lacks (rosbag2's reader would drop
            it unseen), or holds a payload that is no blob or a timestamp that is no integer.
    """
    if connection.execute("PRAGMA encoding").fetchone()[0] != "UTF-8":
        # group_concat reads payloads as text: in a UTF-16 file that would convert them.
        raise InputError(f"{path}: the sqlite3 file is not UTF-8 encoded, as rosbag2 writes it")
    first, last = connection.execute("SELECT min(id), max(id) FROM messages").fetchone()
    if first is None:
        return
    wanted = ", ".join(str(int(t)) for t in topic_ids)
    known = ", ".join(str(int(t)) for (t,) in connection.execute("SELECT id FROM topics")) or "NULL"
    # One aggregate pass per batch; rows come in id order, as the scan of the id range reads them.
    select = ("SELECT CAST(group_concat(data, '') AS BLOB), min(length(data)), max(length(data)), "
              "count(*), {} FROM messages WHERE id BETWEEN ? AND ? AND topic_id IN ({})")
    with_times = select.format("group_concat(timestamp, ',')", wanted)
    without_times = select.format("''", wanted)
    begin, last = _integer(first, "the smallest message row id"), _integer(last, "the largest message row id")
    while begin <= last:
        end = min(begin + _BATCH_IDS - 1, last)  # inclusive: ids may reach SQLite's largest integer
        data, shortest, longest, count, times = connection.execute(
            with_times if wants_log_times() else without_times, (begin, end)).fetchone()
        if count < end - begin + 1:
            # Other topics' rows, sparse ids, or rows of no topic: only a batch not all wanted is looked at.
            _check_topic_ids(connection, begin, end, known)
        if not count:
            # Ids need not be dense (a merged bag): skip an empty stretch in one step.
            (after,) = connection.execute("SELECT min(id) FROM messages WHERE id > ?", (end,)).fetchone()
            begin = int(after) if after is not None else last + 1
            continue
        try:
            log_times = (np.fromstring(times, dtype=np.int64, sep=",")  # text mode: not deprecated
                         if times else np.zeros(count, dtype=np.int64))
            lengths = _lengths(connection, begin, end, wanted, shortest, longest, count)
        except (ValueError, TypeError):
            log_times = lengths = np.zeros(0, dtype=np.int64)
        buf = np.frombuffer(data or b"", dtype=np.uint8)
        if len(log_times) != count or len(lengths) != count or int(lengths.sum()) != len(buf):
            _check_types(connection, begin, end, wanted)
            raise InputError(f"{path}: corrupt sqlite3 file (messages {begin} to {end} do not read "
                             "back whole)")
        starts = np.zeros(count, dtype=np.int64)
        np.cumsum(lengths[:-1], out=starts[1:])
        yield Db3Batch(buf, starts, lengths, log_times, int(shortest) if shortest == longest else 0)
        begin = end + 1


def _lengths(
    connection: sqlite3.Connection, begin: int, end: int, wanted: str, shortest: int, longest: int, count: int
) -> NDArray[np.int64]:
    """Return the payload lengths of a batch's wanted rows: all alike, or asked of SQLite one by one."""
    if shortest == longest:
        return np.full(count, int(shortest), dtype=np.int64)
    (text,) = connection.execute(
        f"SELECT group_concat(length(data), ',') FROM messages WHERE id BETWEEN ? AND ? "
        f"AND topic_id IN ({wanted})", (begin, end)).fetchone()
    return np.fromstring(text, dtype=np.int64, sep=",")


def _check_topic_ids(connection: sqlite3.Connection, begin: int, end: int, known: str) -> None:
    """Raise CorruptData naming the first row of ids [begin, end] whose topic_id the topics table lacks."""
    row = connection.execute(
        f"SELECT id, topic_id FROM messages WHERE id BETWEEN ? AND ? AND (topic_id NOT IN ({known}) "
        "OR topic_id IS NULL) ORDER BY id LIMIT 1", (begin, end)).fetchone()
    if row is not None:
        raise CorruptData(_orphans(row[0], row[1]))


def _check_types(connection: sqlite3.Connection, begin: int, end: int, wanted: str) -> None:
    """Raise CorruptData naming the first wanted row of ids [begin, end] whose data is no blob or time no integer."""
    row = connection.execute(
        f"SELECT id, typeof(data), typeof(timestamp) FROM messages WHERE id BETWEEN ? AND ? AND topic_id IN "
        f"({wanted}) AND (typeof(data) <> 'blob' OR typeof(timestamp) <> 'integer') ORDER BY id LIMIT 1",
        (begin, end)).fetchone()
    if row is None:
        return
    row_id, data_type, time_type = row
    problem = (f"its data is {data_type}, not a blob" if data_type != "blob"
               else f"its timestamp is {time_type}, not an integer number of nanoseconds")
    raise CorruptData(f"message row {row_id}: {problem} (rosbag2 writes a CDR blob and an integer time)")
