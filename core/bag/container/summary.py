"""What `moveplan inspect` shows of any bag: profile, topics with types and counts, time range.

Of an MCAP file, taken from the summary section's statistics when they are complete, else
counted in one linear pass (an unfinished or damaged file) through the message indexes
that follow each chunk (core.bag.container._mcap_linear); either way after every CRC and size the
file records has been checked (core.bag.container.mcap_verify). Of a rosbag2 sqlite3 file, counted
by SQLite after its quick_check. Of a bag folder, its split files' summaries merged.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import IO

from mcap.reader import SeekingReader
from mcap.records import Channel, Header, Schema

from ...types import SkippedData
from ._db3 import check_pages, db3_info, open_db3, topic_counts
from ._files import bag_files
from ._mcap_linear import survey
from ._qos import durability
from .chunk_codecs import Skips
from .mcap_scan import DAMAGE, ClampedReads, open_mcap
from .mcap_verify import verify_mcap

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
    """What `moveplan inspect` shows of an MCAP file; times are log times in [ns].

    `skipped` lists the damaged parts left out (`skip_damaged`); the counts leave out the
    messages of a skipped chunk, as its message indexes count them.
    """

    profile: str
    library: str
    start_ns: int
    end_ns: int
    duration_s: float
    topics: tuple[TopicSummary, ...]
    metadata: tuple[str, ...]
    attachments: tuple[str, ...]
    skipped: tuple[SkippedData, ...] = ()


def summarize(path: Path, skip_damaged: bool = False) -> BagSummary:
    """Return profile, topics, counts, time range, metadata and attachment names of a bag.

    `path` is an MCAP or rosbag2 sqlite3 (.db3) file, or a bag folder (its splits merged).
    An MCAP file is checked whole first (every chunk decompressed, every CRC compared); its
    summary section is used when complete, else it is counted in one pass. A .db3 file's
    pages are checked by SQLite's quick_check. With `skip_damaged`, damaged MCAP chunks (or
    summary, data section, attachments) are skipped with a warning and listed in `skipped`.

    Raises:
        InputError: A file is missing, of neither kind, truncated or corrupt (naming the
            damaged part's offset and the check it fails).

    """
    skips = Skips(skip_damaged)
    summaries = [_db3_summary(file.path) if file.storage == "sqlite3" else _mcap_summary(file.path, skips)
                 for file in bag_files(path)]
    summary = summaries[0] if len(summaries) == 1 else _merged(summaries)
    return replace(summary, skipped=tuple(skips.found))


def _mcap_summary(path: Path, skips: Skips) -> BagSummary:
    """Return the summary of one MCAP file, checked whole: from its summary section, else counted."""
    with open_mcap(path) as stream:
        size = stream.seek(0, 2)
        verified = verify_mcap(path, stream, size, skips)
        indexed = _summary_from_index(stream, verified.lost) if verified.summary_sound else None
        if indexed is not None:
            return indexed
        found = survey(path, stream, size, skips)
    topics = [
        TopicSummary(topic, found.schemas.get(schema_id, ""), encoding,
                     found.counts.get(channel_id, 0) - verified.lost.get(channel_id, 0),
                     durability(metadata.get("offered_qos_profiles", "")))
        for channel_id, (topic, schema_id, encoding, metadata) in found.channels.items()
    ]
    return BagSummary(found.profile, found.library, found.start_ns, found.end_ns,
                      (found.end_ns - found.start_ns) / 1e9,
                      tuple(sorted(topics, key=lambda topic: topic.topic)),
                      tuple(found.metadata), tuple(found.attachments))


def _db3_summary(path: Path) -> BagSummary:
    """Return the summary of one rosbag2 sqlite3 file, its messages counted by SQLite."""
    with open_db3(path) as connection:
        check_pages(connection, path)
        info = db3_info(connection, path)
        counts, start_ns, end_ns = topic_counts(connection, [t.id for t in info.topics])
    schema = f", schema version {info.schema_version}" if info.schema_version else ""
    distro = f", {info.ros_distro}" if info.ros_distro else ""
    topics = [TopicSummary(t.name, t.type, t.serialization_format, counts.get(t.id, 0),
                           durability(t.offered_qos_profiles)) for t in info.topics]
    return BagSummary("ros2", f"rosbag2 sqlite3 storage{schema}{distro}", start_ns, end_ns,
                      (end_ns - start_ns) / 1e9, tuple(sorted(topics, key=lambda topic: topic.topic)),
                      (), ())


def _merged(summaries: list[BagSummary]) -> BagSummary:
    """Return the summary of a bag folder's splits: counts added, time range spanning theirs."""
    topics: dict[tuple[str, str, str], TopicSummary] = {}
    for summary in summaries:
        for topic in summary.topics:
            key = (topic.topic, topic.type, topic.encoding)
            known = topics.get(key)
            topics[key] = topic if known is None else replace(known, count=known.count + topic.count)
    timed = [s for s in summaries if any(t.count for t in s.topics)] or summaries[:1]
    start_ns, end_ns = min(s.start_ns for s in timed), max(s.end_ns for s in timed)
    first = summaries[0]
    return BagSummary(first.profile, first.library, start_ns, end_ns, (end_ns - start_ns) / 1e9,
                      tuple(sorted(topics.values(), key=lambda topic: topic.topic)),
                      tuple(dict.fromkeys(n for s in summaries for n in s.metadata)),
                      tuple(n for s in summaries for n in s.attachments))


def _summary_from_index(stream: IO[bytes], lost: dict[int, int]) -> BagSummary | None:
    """Return the summary from the file's summary section, or None where that is incomplete.

    `lost` counts per channel id the messages of chunks skipped as damaged: not counted.
    """
    size = stream.seek(0, 2)
    stream.seek(0)
    try:
        # Reads clamped to the file: a damaged record length is never a read (an allocation) of that size.
        # mcap's annotation asks for IO[bytes]; it only reads, seeks and tells.
        reader = SeekingReader(ClampedReads(stream, size), record_size_limit=size)  # type: ignore[arg-type]
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
                stats.channel_message_counts.get(channel.id, 0) - lost.get(channel.id, 0),
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
