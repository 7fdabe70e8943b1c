"""What `moveplan inspect` shows of any MCAP file: profile, topics with types and counts, time range.

Taken from the summary section's statistics when they are complete, else counted in one
linear pass (an unfinished or damaged file).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import IO

from mcap.reader import SeekingReader
from mcap.records import Channel, Header, Schema

from .mcap_scan import DAMAGE, open_mcap, scan
from .qos import durability

__all__ = ["BagSummary", "TopicSummary", "summarize"]


@dataclass(frozen=True)
class TopicSummary:
    """One channel: topic, type, message encoding, count, offered durability ("" if unknown)."""

    topic: str
    type: str
    encoding: str
    count: int
    qos_durability: str


@dataclass(frozen=True)
class BagSummary:
    """What `moveplan inspect` shows of an MCAP file; times are log times in [ns]."""

    profile: str
    library: str
    start_ns: int
    end_ns: int
    duration_s: float
    topics: tuple[TopicSummary, ...]
    metadata: tuple[str, ...]
    attachments: tuple[str, ...]


def summarize(path: Path) -> BagSummary:
    """Return profile, topics, counts, time range, metadata and attachment names of an MCAP file.

    Uses the summary section's statistics when present, else counts in one linear pass.

    Raises:
        InputError: The file is missing, not MCAP, truncated or corrupt.

    """
    with open_mcap(path) as stream:
        indexed = _summary_from_index(stream)
        if indexed is not None:
            return indexed
        contents = scan(path, stream, keep_topics=())
    return _bag_summary(
        contents.header or Header(profile="", library=""),
        contents.start_ns,
        contents.end_ns,
        [
            (channel, contents.schemas.get(channel.schema_id), contents.counts[channel.id])
            for channel in contents.channels.values()
        ],
        tuple(record.name for record in contents.metadata),
        tuple(record.name for record in contents.attachments),
    )


def _summary_from_index(stream: IO[bytes]) -> BagSummary | None:
    """Return the summary from the file's summary section, or None where that is incomplete."""
    stream.seek(0)
    try:
        reader = SeekingReader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
    except (*DAMAGE, OSError):
        return None  # no readable footer (unfinished or damaged): left to the linear pass
    if summary is None or summary.statistics is None:
        return None
    stats = summary.statistics
    if stats.metadata_count != len(summary.metadata_indexes):
        return None
    if stats.attachment_count != len(summary.attachment_indexes):
        return None
    return _bag_summary(
        header,
        stats.message_start_time if stats.message_count else 0,
        stats.message_end_time if stats.message_count else 0,
        [
            (
                channel,
                summary.schemas.get(channel.schema_id),
                stats.channel_message_counts.get(channel.id, 0),
            )
            for channel in summary.channels.values()
        ],
        tuple(index.name for index in summary.metadata_indexes),
        tuple(index.name for index in summary.attachment_indexes),
    )


def _bag_summary(
    header: Header,
    start_ns: int,
    end_ns: int,
    channels: list[tuple[Channel, Schema | None, int]],
    metadata: tuple[str, ...],
    attachments: tuple[str, ...],
) -> BagSummary:
    """Return a BagSummary of (channel, schema, message count) triples, sorted by topic."""
    topics = [
        TopicSummary(
            topic=channel.topic,
            type=schema.name if schema is not None else "",
            encoding=channel.message_encoding,
            count=count,
            qos_durability=durability(channel.metadata.get("offered_qos_profiles", "")),
        )
        for channel, schema, count in channels
    ]
    return BagSummary(
        profile=header.profile,
        library=header.library,
        start_ns=start_ns,
        end_ns=end_ns,
        duration_s=(end_ns - start_ns) / 1e9,
        topics=tuple(sorted(topics, key=lambda topic: topic.topic)),
        metadata=metadata,
        attachments=attachments,
    )
