"""moveplan's MCAP writer writes the bytes the mcap library's Writer writes, set up as moveplan sets it up."""

from __future__ import annotations

import io
from functools import partial
from typing import Any
from unittest.mock import patch

import mcap.writer
import zstandard
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader

from moveplan.core.bag.container._mcap_writer import ZSTD_LEVEL, McapWriter

_NAMES = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=12)
_OPERATIONS = st.lists(st.one_of(
    st.tuples(st.just("message"), st.integers(0, 2), st.integers(0, 2**40), st.binary(max_size=600)),
    st.tuples(st.just("metadata"), _NAMES, st.dictionaries(_NAMES, _NAMES, max_size=3)),
    st.tuples(st.just("attachment"), _NAMES, st.binary(max_size=300)),
), max_size=40)


def _written(writer: Any, stream: io.BytesIO, operations: list[tuple[Any, ...]]) -> bytes:
    """Return what `writer` wrote of three schemas and channels and `operations`, as moveplan's bag writer calls it."""
    writer.start(profile="ros2", library="moveplan test")
    channels = []
    for k in range(3):
        schema = writer.register_schema(f"pkg/msg/Type{k}", "ros2msg", f"float64 x{k}\n".encode())
        channels.append(writer.register_channel(f"/topic{k}", "cdr", schema, {"offered_qos_profiles": f"- depth: {k}"}))
    for operation in operations:
        if operation[0] == "message":
            _, channel, time_ns, data = operation
            writer.add_message(channels[channel], time_ns, data, time_ns)
        elif operation[0] == "metadata":
            writer.add_metadata(operation[1], operation[2])
        else:
            writer.add_attachment(0, 0, operation[1], "application/octet-stream", operation[2])
    writer.finish()
    return stream.getvalue()


@settings(max_examples=150, deadline=None)
@given(_OPERATIONS, st.sampled_from([64, 1000, 1024 * 1024]))
def test_any_bag_is_written_byte_for_byte_as_the_mcap_library_writes_it(
    operations: list[tuple[Any, ...]], chunk_bytes: int
) -> None:
    # mcap's Writer as core/bag/container/writer.py used it: zstd chunks, data CRCs, every index and summary;
    # its chunks compressed at the level of mcap's C++ writer, which ros2 bag record writes with.
    theirs = io.BytesIO()
    library = mcap.writer.Writer(theirs, chunk_size=chunk_bytes, compression=mcap.writer.CompressionType.ZSTD,
                                 enable_data_crcs=True)
    with patch.object(mcap.writer.zstandard, "compress", partial(zstandard.compress, level=ZSTD_LEVEL)):
        reference = _written(library, theirs, operations)
    ours = io.BytesIO()
    assert _written(McapWriter(ours, chunk_bytes), ours, operations) == reference


def test_messages_read_back_in_order_through_the_mcap_library_with_every_crc_checked() -> None:
    stream = io.BytesIO()
    operations = [("message", k % 3, 10 * k, bytes([k]) * k) for k in range(200)]
    _written(McapWriter(stream, chunk_bytes=2000), stream, operations)
    stream.seek(0)
    reader = make_reader(stream, validate_crcs=True)
    read = [(channel.topic, message.log_time, message.data) for _, channel, message in reader.iter_messages()]
    assert read == [(f"/topic{k % 3}", 10 * k, bytes([k]) * k) for k in range(200)]
    summary = reader.get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count == 200 and len(summary.chunk_indexes) > 10
