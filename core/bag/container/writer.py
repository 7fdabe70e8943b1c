"""A ROS 2 bag written to MCAP, atomically: the writer's lifecycle, channels, metadata, attachments.

The container half of writing, as rosbag2 lays it out so that `ros2 bag`, Foxglove and
rosbags open the files: profile ros2, ros2msg schemas, CDR channels with their QoS in
channel metadata, zstd chunks with CRCs, message and chunk indexes, statistics. What goes
in the messages is the plan and execution writers' business.
"""

from __future__ import annotations

import os
import secrets
import stat
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import BinaryIO

from ...errors import InputError, UsageError
from ...version import moveplan_version
from ._mcap_writer import McapWriter
from ._qos import offered_qos_profiles

__all__ = ["BagStream", "atomic_file", "open_bag", "output_problem", "staged_file", "write_bag"]

_MEDIA_TYPES = {".urdf": "application/xml", ".srdf": "application/xml", ".yaml": "application/yaml"}


def write_bag(
    path: Path,
    topics: Mapping[str, tuple[str, bool]],
    schemas: Mapping[str, bytes],
    messages: Iterable[tuple[str, int, bytes]],
    metadata: Mapping[str, dict[str, str]],
    attachments: Mapping[str, bytes],
) -> None:
    """Write a ROS 2 bag to `path` atomically; return None.

    `topics` maps topic -> (message type, latched), in channel order; `schemas` maps
    message type -> schema text; `messages` are (topic, log time [ns], CDR), in log-time
    order; then metadata records and attachments, in order.

    Raises:
        UsageError: `path` cannot be an output file: a directory, a symbolic link, a device.
        InputError: `path` cannot be written.

    """
    with open_bag(path, topics, schemas) as bag:
        for topic, log_time_ns, data in messages:
            bag.add(topic, log_time_ns, data)
        for name, record in metadata.items():
            bag.add_metadata(name, record)
        for name, content in attachments.items():
            bag.add_attachment(name, content)


class BagStream:
    """A ROS 2 bag being written (`open_bag`): messages added as they come, then metadata and attachments."""

    def __init__(self, writer: McapWriter, channel_ids: Mapping[str, int]) -> None:
        self._writer = writer
        self._channel_ids = dict(channel_ids)

    def add(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Add one message (CDR) on a registered `topic` at `log_time_ns` [ns]; return None.

        Messages go into the file in the order they are added: add them in log-time order.
        """
        self._writer.add_message(self._channel_ids[topic], log_time_ns, data, log_time_ns)

    def add_metadata(self, name: str, record: dict[str, str]) -> None:
        """Add a metadata record `name`; return None."""
        self._writer.add_metadata(name, record)

    def add_attachment(self, name: str, content: bytes) -> None:
        """Add an attachment, its media type from the name's suffix; return None."""
        media_type = _MEDIA_TYPES.get(Path(name).suffix.lower(), "application/octet-stream")
        self._writer.add_attachment(0, 0, name, media_type, content)


@contextmanager
def open_bag(
    path: Path, topics: Mapping[str, tuple[str, bool]], schemas: Mapping[str, bytes]
) -> Iterator[BagStream]:
    """Yield a ROS 2 bag on a temporary file beside `path`, channels registered; finish and rename after the block.

    `topics` maps topic -> (message type, latched), in channel order; `schemas` maps message
    type -> schema text. Nothing is kept per message (the writer holds one chunk), so a
    file of any length is written in bounded memory. On any error the temporary file is
    removed and `path` is left as it was (`atomic_file`).

    Raises:
        UsageError: `path` cannot be an output file: a directory, a symbolic link, a device.
        InputError: `path` cannot be written.

    """
    with _atomic_writer(path) as writer:
        schema_ids: dict[str, int] = {}
        channel_ids: dict[str, int] = {}
        for topic, (msgtype, latched) in topics.items():
            if msgtype not in schema_ids:
                schema_ids[msgtype] = writer.register_schema(msgtype, "ros2msg", schemas[msgtype])
            qos = {"offered_qos_profiles": offered_qos_profiles(latched)}
            channel_ids[topic] = writer.register_channel(topic, "cdr", schema_ids[msgtype], qos)
        yield BagStream(writer, channel_ids)


def output_problem(path: Path) -> str | None:
    """Return why `path` must not be replaced by a new regular file (an output), None if it may.

    Refused: an empty name, a directory, a symbolic link (replacing it would drop the link, and
    writing through it would change a file elsewhere), and anything not a regular file (a
    device such as /dev/null, a FIFO, a socket). A path that does not exist yet is fine.
    """
    if str(path) in ("", "."):
        return "is empty (or '.'): not a file name"
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return None  # missing (fine), or unreachable: writing it reports why
    if stat.S_ISLNK(mode):
        return "is a symbolic link; name the file it points to, or another file"
    if stat.S_ISDIR(mode):
        return "is a directory; name a file"
    if not stat.S_ISREG(mode):
        return "is a device or special file, not a regular file"
    return None


@contextmanager
def atomic_file(path: Path) -> Iterator[BinaryIO]:
    """Yield a binary stream on a new temporary file beside `path`; when the block ends, rename it to `path`.

    The temporary file has a random name (`.NAME.RANDOM.tmp`), created exclusively, so a stale
    one left by a killed process never gets in the way. On any error or interruption
    (BaseException) it is removed and `path` is left as it was: untouched or complete.

    Raises:
        UsageError: `path` cannot be an output file (`output_problem`).
        InputError: `path` cannot be written (missing or read-only folder, full disk).

    """
    with _temporary_beside(path) as (_, stream):
        yield stream


@contextmanager
def staged_file(path: Path, data: bytes) -> Iterator[Path]:
    """Yield a temporary file beside `path` holding `data`; when the block ends well, rename it to `path`.

    For an output read back before it replaces `path` (tune-pid verifies its gains file); named,
    created and removed as atomic_file's, and raising what it raises.
    """
    with _temporary_beside(path) as (temporary, stream):
        stream.write(data)
        stream.close()
        yield temporary


@contextmanager
def _temporary_beside(path: Path) -> Iterator[tuple[Path, BinaryIO]]:
    """Yield atomic_file's temporary file and its stream; renamed to `path` when the block ends well, else removed."""
    problem = output_problem(path)
    if problem:
        raise UsageError(f"{path}: {problem}")
    try:
        temporary, stream = _create_beside(path)
    except OSError as exc:
        raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from None
    try:
        with stream:
            yield temporary, stream
        temporary.replace(path)
    except BaseException as exc:
        with suppress(OSError):
            temporary.unlink()
        if isinstance(exc, OSError):
            raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from exc
        raise


def _create_beside(path: Path) -> tuple[Path, BinaryIO]:
    """Return a new, exclusively created temporary file beside `path` and its open binary stream."""
    for _ in range(100):
        temporary = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")
        try:
            # os.open with mode 0o666, not tempfile (0o600): the output gets the user's umask permissions.
            descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666)
        except FileExistsError:
            continue
        return temporary, os.fdopen(descriptor, "wb")
    raise FileExistsError(f"no free temporary name beside {path}")


@contextmanager
def _atomic_writer(path: Path) -> Iterator[McapWriter]:
    """Yield a started MCAP writer on a temporary file beside `path`; finish, then rename (`atomic_file`)."""
    with atomic_file(path) as stream:
        writer = McapWriter(stream)
        writer.start("ros2", f"moveplan {moveplan_version()}")
        yield writer
        writer.finish()
