"""Speed and peak memory of check-tolerances and inspect on long recordings, against rosbags.

Run from the repository root with moveplan (and rosbags) installed:
    python benchmarks/check_speed.py [--messages 3600000] [--unindexed | --db3] [--what check]
        [--rosbags-limit N | --no-rosbags] [--file PATH]

The recording is benchmarks/make_recording.py's cycle (a UR10e repeating a pick cycle at
1 kHz, two faulty cycles), `--messages` long, written under /tmp the first time it is
asked for (by a child process, so that writing it does not count in the peak memory):
/tmp/moveplan_cycles_<N>.mcap, indexed as rosbag2 writes it; with --unindexed the same file
cut before its summary section (an unfinished recording: chunks and message indexes, no
summary or footer); with --db3 the same messages in a rosbag2 sqlite3 bag folder with
Humble's schema (/tmp/moveplan_cycles_<N>_db3/). `--file` names a file of your own instead.

`--what check` times reading the joint states and checking every cycle (`start="all"`) in
process, as `moveplan check-tolerances PLAN REC --start all` does after reading the plan;
`--what inspect` times `inspect_file`, as `moveplan inspect REC`. It prints the peak resident
memory of the process after it (what `/usr/bin/time -v` reports as its maximum resident
set size), then times rosbags reading the same file (AnyReader + deserialize, positions and
velocities copied into arrays) unless --no-rosbags; --rosbags-limit times rosbags on the
first N messages only and extrapolates (it reads about 50 k messages/s).
Machines are shared and noisy: run it more than once.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import make_recording  # noqa: E402  (the cycle, controller and joints the file was made with)

RATE_HZ = 1000.0
# rosbag2's metadata.yaml for a sqlite3 bag of one JointState topic, version 8 (Humble's writer
# writes 5; readers take either).
_METADATA = """rosbag2_bagfile_information:
  version: 5
  storage_identifier: sqlite3
  duration:
    nanoseconds: {duration}
  starting_time:
    nanoseconds_since_epoch: {start}
  message_count: {count}
  topics_with_message_count:
    - topic_metadata:
        name: /joint_states
        type: sensor_msgs/msg/JointState
        serialization_format: cdr
        offered_qos_profiles: ""
      message_count: {count}
  compression_format: ""
  compression_mode: ""
  relative_file_paths:
    - {name}_0.db3
  files:
    - path: {name}_0.db3
      starting_time:
        nanoseconds_since_epoch: {start}
      duration:
        nanoseconds: {duration}
      message_count: {count}
"""


def peak_rss_mb() -> float:
    """Return the peak resident memory of this process so far in [MB] (Linux: ru_maxrss in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def recording_path(messages: int, kind: str) -> Path:
    """Return where the recording of `messages` messages of `kind` (indexed, unindexed, db3) lies."""
    base = Path(f"/tmp/moveplan_cycles_{messages}")
    return {"indexed": base.with_suffix(".mcap"), "unindexed": Path(f"{base}_unindexed.mcap"),
            "db3": Path(f"{base}_db3")}[kind]


def make(messages: int, kind: str) -> None:
    """Write the recording of `messages` messages of `kind`, and the indexed one it derives from."""
    indexed = recording_path(messages, "indexed")
    if not indexed.exists():
        partial = indexed.with_suffix(".partial")
        make_recording.write(partial, messages / RATE_HZ, RATE_HZ,
                             make_recording.parse_faults("100:spike,250:late"), 0)
        partial.rename(indexed)
    target = recording_path(messages, kind)
    if target.exists():
        return
    if kind == "unindexed":
        _cut_summary(indexed, target)
    elif kind == "db3":
        _write_db3(indexed, target)


def _cut_summary(source: Path, target: Path) -> None:
    """Copy `source` up to its summary section: what a recorder that never finished leaves."""
    with source.open("rb") as stream:
        size = stream.seek(0, 2)
        stream.seek(size - 8 - 20)  # the footer's summary_start, before its 20 bytes end and the magic
        summary_start = int.from_bytes(stream.read(8), "little")
        stream.seek(0)
        with target.open("wb") as out:
            remaining = summary_start
            while remaining:
                block = stream.read(min(remaining, 1 << 24))
                out.write(block)
                remaining -= len(block)


def _write_db3(source: Path, folder: Path) -> None:
    """Write the JointState messages of MCAP `source` as a rosbag2 sqlite3 bag with Humble's schema."""
    from mcap.reader import make_reader

    partial = folder.with_name(folder.name + ".partial")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir()
    database = sqlite3.connect(partial / f"{folder.name}_0.db3")
    database.executescript(
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
        "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
        "metadata TEXT NOT NULL);"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
        "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
        "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "INSERT INTO schema VALUES (3, 'humble');"
        "INSERT INTO topics VALUES (1, '/joint_states', 'sensor_msgs/msg/JointState', 'cdr', '');")
    first = last = count = 0
    with source.open("rb") as stream:
        batch: list[tuple[int, bytes]] = []
        for _, _, message in make_reader(stream).iter_messages():
            first = first or message.log_time
            last = message.log_time
            batch.append((message.log_time, message.data))
            if len(batch) == 100_000:
                database.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?, ?)",
                                     batch)
                count += len(batch)
                batch.clear()
        database.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?, ?)", batch)
        count += len(batch)
    database.commit()
    database.close()
    (partial / "metadata.yaml").write_text(_METADATA.format(
        duration=last - first, start=first, count=count, name=folder.name))
    partial.rename(folder)


def moveplan_check(path: Path) -> tuple[float, float, int]:
    """Return read and check wall times in [s] and the message count; prints the verdict."""
    from moveplan.core.bag import jointstates
    from moveplan.core.control.check.recording import check_recording, uses_velocities

    plan, controller = make_recording.cycle_plan(), make_recording.controller()
    began = time.perf_counter()
    # As check-tolerances reads it: velocities only where the check uses them.
    opened = getattr(jointstates, "open_joint_states", None) or jointstates.read_joint_states
    series: Any = opened(path, joints=make_recording.JOINTS,
                         velocities=uses_velocities(plan, controller))
    read = time.perf_counter()
    report = check_recording(plan, series, controller, make_recording.execution(), (),
                             start="all")
    checked = time.perf_counter()
    print(f"moveplan: {len(report.cycles)} cycles, failing {list(report.failing_cycles)}: "
          f"{report.result.name}")
    count = series.count if hasattr(series, "count") else len(series.times_s)
    return read - began, checked - read, count


def moveplan_inspect(path: Path) -> float:
    """Return the wall time in [s] of inspect_file on `path`; prints the topics."""
    from moveplan.core.pipeline.inspection import inspect_file

    began = time.perf_counter()
    inspection = inspect_file(path)
    elapsed = time.perf_counter() - began
    topics = ", ".join(f"{t.topic} ({t.count})" for t in inspection.summary.topics)
    print(f"moveplan inspect: {topics}; {inspection.summary.duration_s:.3f} s")
    return elapsed


def rosbags_read(path: Path, limit: int | None) -> tuple[float, int]:
    """Return the wall time in [s] to read and deserialize (up to `limit`) JointState messages."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    began = time.perf_counter()
    count = 0
    # A Humble .db3 holds no message definitions: rosbags then takes them from its typestore.
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        connections = [c for c in reader.connections if c.topic == "/joint_states"]
        total = sum(c.msgcount for c in connections)
        size = min(total, limit) if limit else total
        positions = np.empty((size, 6))
        velocities = np.empty((size, 6))
        stamps = np.empty(size, dtype=np.int64)
        for connection, _, raw in reader.messages(connections=connections):
            message: Any = reader.deserialize(raw, connection.msgtype)
            positions[count] = message.position
            velocities[count] = message.velocity
            stamps[count] = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
            count += 1
            if count == size:
                break
    return time.perf_counter() - began, count


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--messages", type=int, default=3_600_000)
    kinds = parser.add_mutually_exclusive_group()
    kinds.add_argument("--unindexed", action="store_true")
    kinds.add_argument("--db3", action="store_true")
    parser.add_argument("--file", type=Path, default=None)
    parser.add_argument("--what", choices=("check", "inspect"), default="check")
    parser.add_argument("--rosbags-limit", type=int, default=None)
    parser.add_argument("--no-rosbags", action="store_true")
    parser.add_argument("--make-only", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    kind = "unindexed" if args.unindexed else "db3" if args.db3 else "indexed"
    if args.make_only:
        make(args.messages, kind)
        return
    path = args.file or recording_path(args.messages, kind)
    if not path.exists():
        print(f"writing {path} ...", file=sys.stderr)
        subprocess.run([sys.executable, __file__, "--make-only", f"--messages={args.messages}",
                        *([f"--{kind}"] if kind != "indexed" else [])], check=True,
                       env={**os.environ, "PYTHONWARNINGS": "ignore"})
    if args.what == "inspect":
        elapsed = moveplan_inspect(path)
        print(f"(a) moveplan inspect {elapsed:.2f} s on {path}; peak RSS {peak_rss_mb():.0f} MB")
        return
    read_s, check_s, count = moveplan_check(path)
    total_s = read_s + check_s
    print(f"(a) moveplan read {read_s:.2f} s + check --start all {check_s:.2f} s = {total_s:.2f} s "
          f"for {count} messages ({count / read_s / 1e6:.2f} M msg/s read) from {path}; "
          f"peak RSS {peak_rss_mb():.0f} MB")
    if args.no_rosbags:
        return
    try:
        rosbags_s, read_count = rosbags_read(path, args.rosbags_limit)
    except Exception as exc:  # rosbags reads .db3 only with apsw installed
        print(f"(b) rosbags could not read {path}: {type(exc).__name__}: {exc}")
        return
    note = ""
    if read_count < count:
        note = f" (measured on {read_count} messages, {rosbags_s:.2f} s, extrapolated)"
        rosbags_s *= count / read_count
    print(f"(b) rosbags read + deserialize {rosbags_s:.2f} s{note} "
          f"({count / rosbags_s / 1e3:.0f} k msg/s)")
    print(f"ratio: rosbags read / moveplan read = {rosbags_s / read_s:.1f}x; "
          f"rosbags read / moveplan read + check = {rosbags_s / total_s:.1f}x")


if __name__ == "__main__":
    main()
