"""Writing MCAP: moveplan's writer against the mcap library's Writer, set up alike, on plan- and recording-sized bags.

Run from the repository root with moveplan installed:
    python benchmarks/mcap_write.py [--repeats 30]
Each bag is written in memory by both writers, alternating, mcap's compressing its chunks at
moveplan's zstd level; both make the same bytes (checked here too, and in
tests/bag/test_mcap_writer.py). A plan file is ~120 messages (a /tf sample of
~700 bytes at 30 Hz, the trajectories, the scene's markers) and its attachments; an executed
file of a minute at 500 Hz is 30,000 joint states and controller states of ~300 bytes. Prints
the median time of each writer and their ratio. Machines are shared and noisy: compare ratios.
"""

from __future__ import annotations

import argparse
import io
import statistics
import time
from collections.abc import Callable
from functools import partial
from typing import Any
from unittest.mock import patch

import mcap.writer
import zstandard

from moveplan.core.bag.container._mcap_writer import ZSTD_LEVEL, McapWriter


def _bag(messages: int, size: int, channels: int, attachments: int) -> Callable[[Any], None]:
    """Return a function writing a bag of `messages` of `size` bytes round-robin on `channels`, to a writer."""
    payloads = [bytes([k % 251]) * size for k in range(messages)]

    def write(writer: Any) -> None:
        writer.start("ros2", "moveplan benchmark")
        ids = [writer.register_channel(f"/topic{k}", "cdr", writer.register_schema(f"pkg/msg/T{k}", "ros2msg",
                                                                                 b"float64 x\n"), {"qos": "- {}"})
               for k in range(channels)]
        for k, data in enumerate(payloads):
            writer.add_message(ids[k % channels], 33_333_333 * k, data, 33_333_333 * k)
        writer.add_metadata("moveplan", {"robot_name": "ur10e", "steps": "[]"})
        for k in range(attachments):
            writer.add_attachment(0, 0, f"config{k}.yaml", "application/yaml", b"x" * 20_000)
        writer.finish()

    return write


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=30)
    args = parser.parse_args()
    bags = {"plan file (120 messages)": (_bag(120, 700, 6, 4), args.repeats),
            "executed file (30,000 messages)": (_bag(30_000, 300, 3, 4), max(3, args.repeats // 10))}
    for name, (write, repeats) in bags.items():
        times: dict[str, list[float]] = {"moveplan": [], "mcap": []}
        outputs: dict[str, bytes] = {}
        for _ in range(repeats):
            for who in times:
                stream = io.BytesIO()
                writer = McapWriter(stream) if who == "moveplan" else mcap.writer.Writer(
                    stream, compression=mcap.writer.CompressionType.ZSTD, enable_data_crcs=True)
                with patch.object(mcap.writer.zstandard, "compress", partial(zstandard.compress, level=ZSTD_LEVEL)):
                    began = time.perf_counter()
                    write(writer)
                    times[who].append(time.perf_counter() - began)
                outputs[who] = stream.getvalue()
        same = "same bytes" if outputs["moveplan"] == outputs["mcap"] else "DIFFERENT BYTES"
        ours, theirs = (statistics.median(times[w]) for w in ("moveplan", "mcap"))
        print(f"{name}: moveplan {1e3 * ours:.2f} ms, mcap {1e3 * theirs:.2f} ms (medians of {repeats}): "
              f"{theirs / ours:.1f}x; {same}")


if __name__ == "__main__":
    main()
