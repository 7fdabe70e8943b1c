"""A ROS 2 bag written to MCAP, atomically: the mcap Writer's lifecycle, channels, metadata, attachments.

The container half of writing, as rosbag2 lays it out so that `ros2 bag`, Foxglove and
rosbags open the files: profile ros2, ros2msg schemas, CDR channels with their QoS in
channel metadata, zstd chunks with CRCs, message and chunk indexes, statistics. What goes
in the messages is the plan and execution writers' business.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from importlib.metadata import version
from pathlib import Path

from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

from ..errors import InputError
from .qos import offered_qos_profiles

__all__ = ["write_bag"]

_MEDIA_TYPES = {".urdf": "application/xml", ".srdf": "application/xml", ".yaml": "application/yaml"}


def write_bag(
    path: Path,
    topics: Mapping[str, tuple[str, bool]],
    schemas: Mapping[str, bytes],
    messages: list[tuple[str, int, bytes]],
    metadata: Mapping[str, dict[str, str]],
    attachments: Mapping[str, bytes],
) -> None:
    """Write a ROS 2 bag to `path` atomically; return None.

    `topics` maps topic -> (message type, latched), in channel order; `schemas` maps
    message type -> schema text; `messages` are (topic, log time [ns], CDR), in log-time
    order; then metadata records and attachments, in order.

    Raises:
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
        add_message = writer.add_message
        for topic, log_time_ns, data in messages:
            add_message(channel_ids[topic], log_time_ns, data, log_time_ns)
        for name, record in metadata.items():
            writer.add_metadata(name, record)
        for name, content in attachments.items():
            media_type = _MEDIA_TYPES.get(Path(name).suffix.lower(), "application/octet-stream")
            writer.add_attachment(0, 0, name, media_type, content)


@contextmanager
def _atomic_writer(path: Path) -> Iterator[Writer]:
    """Yield a started mcap Writer on a temporary file beside `path`; finish, then rename.

    On any error the temporary file is removed: `path` is either untouched or complete.
    """
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    library = f"moveplan {version('moveplan')}; {LIBRARY_IDENTIFIER}"
    try:
        # open(mode "x"), not tempfile: the output gets the user's umask permissions.
        with temporary.open("xb") as stream:
            writer = Writer(stream, compression=CompressionType.ZSTD, enable_data_crcs=True)
            writer.start(profile="ros2", library=library)
            yield writer
            writer.finish()  # type: ignore[no-untyped-call]  # mcap leaves it unannotated
        temporary.replace(path)
    except BaseException as exc:
        temporary.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from exc
        raise
