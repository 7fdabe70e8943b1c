"""Speed of `moveplan plan` on the UR10e: whole process against the import floor, planning per seed, --help.

Run from the repository root with moveplan installed:  python benchmarks/plan_speed.py [--runs 7] [--seeds 20]
Prints medians of several runs (machines are shared and noisy: compare ratios, not absolute times).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLAN = [sys.executable, "-m", "moveplan.cli.app", "plan", "--robot", str(ROOT / "configs/ur10e"),
        "--scene", str(ROOT / "samples/ur10e_table_scene.yaml"), "--start-named", "home",
        "--joints", "0.5,-1.2,-1.8,0,1.57,0"]
FLOOR = [sys.executable, "-c", "import numpy, pinocchio, coal, ompl"]
HELP = [sys.executable, "-m", "moveplan.cli.app", "--help"]


def wall(command: list[str]) -> float:
    """Return the wall time of one run of `command` in [s]."""
    began = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - began


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--seeds", type=int, default=20)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        out = str(Path(folder) / "out.mcap")
        wall(PLAN + ["-o", out])  # warm the file cache
        pairs = [(wall(PLAN + ["-o", out]), wall(FLOOR)) for _ in range(args.runs)]
        ratios = [p / f for p, f in pairs]
        print(f"whole plan process: median {statistics.median(p for p, _ in pairs):.2f} s; import floor "
              f"median {statistics.median(f for _, f in pairs):.2f} s; ratio median {statistics.median(ratios):.2f} "
              f"(min {min(ratios):.2f}, max {max(ratios):.2f}) over {args.runs} runs")
        steps = []
        for seed in range(args.seeds):
            result = subprocess.run(PLAN + ["-o", out, "--seed", str(seed), "--json"], check=True,
                                    capture_output=True, text=True)
            steps.append(json.loads(result.stdout)["steps"][0]["planning_time_s"])
        steps.sort()
        print(f"planning_time_s (goal to checked, timed trajectory) over {args.seeds} seeds: median "
              f"{1e3 * statistics.median(steps):.1f} ms, max {1e3 * steps[-1]:.1f} ms")
        helps = sorted(wall(HELP) for _ in range(args.runs))
        print(f"moveplan --help: median {statistics.median(helps):.3f} s over {args.runs} runs")


if __name__ == "__main__":
    main()
