"""The reference CDR: mcap_ros2's schema-driven encoder, reached through its public Writer.

moveplan's encoders (core/bag/cdr/generic.py and the `*_cdr` twins) are checked against
it byte for byte. The messages go through an uncompressed in-memory MCAP file and are
read back in the order they were written.
"""

from __future__ import annotations

import io
from collections.abc import Iterable
from importlib.resources import files
from typing import Any

from mcap.reader import make_reader
from mcap.writer import CompressionType
from mcap_ros2.writer import Writer


def schema(msgtype: str, distro: str) -> str:
    """The shipped ros2msg schema text of `msgtype` ("pkg/msg/Type") for `distro`."""
    return files("moveplan.core.bag.cdr.msgs").joinpath(distro, msgtype.replace("/", "__") + ".msg").read_text()


def reference_cdr(msgtype: str, distro: str, messages: Iterable[Any], text: str | None = None) -> list[bytes]:
    """CDR of each of `messages` as mcap_ros2 encodes it, from `text` or else the shipped schema."""
    buffer = io.BytesIO()
    writer = Writer(buffer, compression=CompressionType.NONE)
    registered = writer.register_msgdef(msgtype, schema(msgtype, distro) if text is None else text)
    for index, message in enumerate(messages):
        writer.write_message("/reference", registered, message, log_time=index)
    writer.finish()
    buffer.seek(0)
    return [message.data for _, _, message in make_reader(buffer).iter_messages(log_time_order=True)]


def generic(msgtype: str, distro: str, message: Any) -> bytes:
    """CDR of one `message` as mcap_ros2 encodes it with the shipped schema of `distro`."""
    return reference_cdr(msgtype, distro, [message])[0]
