"""Speed of check-tolerances on a long recording: moveplan's reader and check against rosbags.

Run from the repository root with moveplan (and rosbags) installed, after writing the file:
    python benchmarks/make_recording.py            # once: /tmp/moveplan_cycles.mcap, 1 h at 1 kHz
    python benchmarks/check_speed.py [--file /tmp/moveplan_cycles.mcap] [--rosbags-limit N]

Times (a) read_joint_states + check_recording(start="all") on the file, with the peak
resident memory of the process after it, then (b) reading the same file with rosbags
(AnyReader + deserialize, positions and velocities copied into arrays), and prints both
and their ratio. --rosbags-limit times rosbags on the first N messages only and
extrapolates (it reads about 50 k messages/s: an hour at 1 kHz takes over a minute).
Machines are shared and noisy: run it more than once.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import make_recording  # noqa: E402  (the cycle, controller and joints the file was made with)

from moveplan.core.bag.jointstates import read_joint_states  # noqa: E402
from moveplan.core.control.checking import check_recording, uses_velocities  # noqa: E402


def peak_rss_mb() -> float:
    """Return the peak resident memory of this process so far in [MB] (Linux: ru_maxrss in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def moveplan_check(path: Path) -> tuple[float, float, int]:
    """Return read and check wall times in [s] and the message count; prints the verdict."""
    plan, controller = make_recording.cycle_plan(), make_recording.controller()
    began = time.perf_counter()
    # As check-tolerances reads it: velocities only where the check uses them.
    series = read_joint_states(path, joints=make_recording.JOINTS,
                               velocities=uses_velocities(plan, controller))
    read = time.perf_counter()
    report = check_recording(plan, series, controller, make_recording.execution(), (),
                             start="all")
    checked = time.perf_counter()
    print(f"moveplan: {len(report.cycles)} cycles, failing {list(report.failing_cycles)}: "
          f"{report.result.name}")
    return read - began, checked - read, len(series.times_s)


def rosbags_read(path: Path, limit: int | None) -> tuple[float, int]:
    """Return the wall time in [s] to read and deserialize (up to `limit`) JointState messages."""
    from rosbags.highlevel import AnyReader

    began = time.perf_counter()
    count = 0
    with AnyReader([path]) as reader:
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
    parser.add_argument("--file", type=Path, default=Path("/tmp/moveplan_cycles.mcap"))
    parser.add_argument("--rosbags-limit", type=int, default=None)
    args = parser.parse_args()
    if not args.file.is_file():
        raise SystemExit(f"{args.file}: not found; write it with benchmarks/make_recording.py")
    read_s, check_s, count = moveplan_check(args.file)
    total_s = read_s + check_s
    print(f"(a) moveplan read {read_s:.2f} s + check --start all {check_s:.2f} s = {total_s:.2f} s "
          f"for {count} messages ({count / read_s / 1e6:.2f} M msg/s read); "
          f"peak RSS {peak_rss_mb():.0f} MB")
    rosbags_s, read_count = rosbags_read(args.file, args.rosbags_limit)
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
