"""Reading YAML: moveplan's reader against PyYAML over libyaml, on MotionBenchMaker scenes and requests.

Run from the repository root with moveplan installed:
    python benchmarks/yaml_read.py [--mbm DIR] [--repeats 5]
Each file is read by libyaml's parse alone (events counted in C, no value built: the floor),
by PyYAML (yaml.load with moveplan's loader: libyaml's parse, a Python node per value, a
constructor call per node) and by moveplan's parse_yaml (the same limits, the plain part of
YAML read line by line, core/config/_plain_yaml.py). Both give the same values (checked here,
and in tests/config/test_plain_yaml.py). Prints the median time per file of each and the ratio.
Machines are shared and noisy: compare ratios.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from moveplan.core.config import fields

ROOT = Path(__file__).resolve().parents[1]


def _per_file(read: Callable[[str], Any], texts: list[str], repeats: int) -> list[float]:
    """Return each text's best time of `repeats` readings [s]."""
    best = []
    for text in texts:
        times = []
        for _ in range(repeats):
            began = time.perf_counter()
            read(text)
            times.append(time.perf_counter() - began)
        best.append(min(times))
    return best


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mbm", type=Path, default=ROOT / "tests" / "data" / "mbm" / "problems",
                        help="folder of MotionBenchMaker problems (scenario folders of scene and request YAML)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    for kind in ("scene", "request"):
        paths = sorted(args.mbm.glob(f"*/{kind}*.yaml"))
        texts = [p.read_text(encoding="utf-8") for p in paths]
        for path, text in zip(paths, texts, strict=True):
            if fields.parse_yaml(text, path) != yaml.load(text, Loader=fields._Loader):  # noqa: S506 - safe loader
                raise SystemExit(f"{path}: moveplan reads other values than PyYAML")
        where = Path(kind)
        floor = _per_file(fields._count_events, texts, args.repeats)
        pyyaml = _per_file(lambda text: yaml.load(text, Loader=fields._Loader), texts, args.repeats)  # noqa: S506
        moveplan = _per_file(lambda text, where=where: fields.parse_yaml(text, where), texts, args.repeats)
        print(f"{len(texts)} {kind}s, median {statistics.median(len(t) for t in texts):.0f} bytes; median ms per file:")
        print(f"  libyaml parse alone {1e3 * statistics.median(floor):6.3f}")
        print(f"  PyYAML              {1e3 * statistics.median(pyyaml):6.3f}")
        print(f"  moveplan            {1e3 * statistics.median(moveplan):6.3f}   "
              f"({statistics.median(p / m for p, m in zip(pyyaml, moveplan, strict=True)):.1f}x faster)")


if __name__ == "__main__":
    main()
