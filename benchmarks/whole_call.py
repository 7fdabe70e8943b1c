"""Where a whole `moveplan plan` call goes, phase by phase, on MotionBenchMaker problems: fixed work against the step.

Run from the repository root with moveplan installed:
    python benchmarks/whole_call.py [--mbm DIR] [--robot DIR] [--count 30] [--seeds 1] [--one-shot 5]
Each problem is solved as `moveplan benchmark` solves it (one warm process, the robot config loaded
once, the plan written to a file), with the pipeline's phases timed where they are called: reading
the request, the robot's group, the scene, setting up the collision checks, the step (its
planning_time_s), assembling the plan (its /tf samples apart), /tf, writing the file. Prints the
median of each phase and of the whole call, and the whole call over the step; the step's own parts
(search, simplify, timing, certification) as medians, and certification's share of all the steps'
time with its tail: a path that grazes an obstacle for long takes many exact checks to certify.
With --one-shot N, also the first N problems planned by a fresh `moveplan plan` process each, whose
step starts without the sphere filter (its planning_time_s against the warm one's). Machines are
shared and noisy: compare ratios and medians.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from moveplan.core import bag
from moveplan.core.config import load_robot_config
from moveplan.core.pipeline import benchmark
from moveplan.core.pipeline import plan as pipeline

ROOT = Path(__file__).resolve().parents[1]
PHASES = ("request", "robot", "scene", "checks", "step", "assemble", "tf", "write")
STEP_PARTS = ("search", "simplify", "timing", "certify")  # the step's parts, as `moveplan benchmark` reports them
_TIMED = {"request": (pipeline, "resolve_request"), "robot": (pipeline, "_robot"), "scene": (pipeline, "load_scene"),
          "checks": (pipeline, "build_problem"), "assemble": (pipeline, "assemble"), "tf": (pipeline, "_tf_samples"),
          "write": (bag, "write_plan")}


def _timing(spent: dict[str, float]) -> None:
    """Wrap each timed phase's function where the pipeline calls it, adding its time to `spent`."""
    for phase, (module, name) in _TIMED.items():
        function = getattr(module, name)

        def timed(*args: Any, _function: Callable[..., Any] = function, _phase: str = phase, **kwargs: Any) -> Any:
            began = time.perf_counter()
            try:
                return _function(*args, **kwargs)
            finally:
                spent[_phase] += time.perf_counter() - began

        setattr(module, name, timed)


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mbm", type=Path, default=ROOT / "tests" / "data" / "mbm" / "problems",
                        help="folder of MotionBenchMaker problems, with panda_robot beside it or in its parent")
    parser.add_argument("--robot", type=Path, help="the problems' robot config (default: panda_robot beside them)")
    parser.add_argument("--count", type=int, default=30, help="problems per scenario")
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--one-shot", type=int, default=0, help="also plan the first N problems one process each")
    args = parser.parse_args()
    robot = args.robot or next(p for p in (args.mbm / "panda_robot", args.mbm.parent / "panda_robot") if p.is_dir())
    problems = benchmark.find_problems([args.mbm], args.count)
    config = load_robot_config(robot)
    spent: dict[str, float] = defaultdict(float)
    _timing(spent)
    rows: list[dict[str, float]] = []
    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "plan.mcap"
        benchmark._solve(problems[0], config, "RRTConnect", 0, (1.0, None), False, output)  # the process warm
        for seed in range(args.seeds):
            for problem in problems:
                spent.clear()
                run = benchmark._solve(problem, config, "RRTConnect", seed, (1.0, None), False, output)
                if run.ok:
                    rows.append({**spent, "step": run.planning_time_s, "whole": run.whole_call_s,
                                 **{part: getattr(run, f"{part}_s") for part in STEP_PARTS},
                                 "assemble": spent["assemble"] - spent["tf"]})
        print(f"{len(rows)} solved runs of {len(problems)} problems x {args.seeds} seeds ({robot}); median ms:")
        for phase in (*PHASES, "whole"):
            print(f"  {phase:9s} {1e3 * statistics.median(r.get(phase, 0.0) for r in rows):7.2f}")
            if phase == "step":
                for part in STEP_PARTS:
                    print(f"    {part:9s} {1e3 * statistics.median(r[part] for r in rows):7.2f}")
        fixed = [r["whole"] - r["step"] for r in rows]
        print(f"  whole call / step: median {statistics.median(r['whole'] / r['step'] for r in rows):.2f}; "
              f"fixed work (whole - step) median {1e3 * statistics.median(fixed):.2f} ms")
        certify = [r["certify"] for r in rows]
        p90, p99, most = 1e3 * np.percentile(certify, (90, 99, 100))
        print(f"  certification: {sum(certify) / sum(r['step'] for r in rows):.0%} of all the steps' time; "
              f"p90 {p90:.1f}, p99 {p99:.1f}, max {most:.1f} ms")
        if args.one_shot:
            _one_shot(problems[: args.one_shot], robot, config, output)


def _one_shot(problems: list[benchmark.ProblemFiles], robot: Path, config: Any, output: Path) -> None:
    """Print each problem's planning_time_s from a fresh process against the warm process's, same seed."""
    ratios, walls = [], []
    for problem in problems:
        # The warm process plans with RRTConnect as the benchmark does: so must the fresh one (not the request's).
        command = [sys.executable, "-m", "moveplan.cli.app", "plan", "--robot", str(robot), "--scene",
                   str(problem.scene), "--request", str(problem.request), "--planner", "RRTConnect", "--seed", "0",
                   "-o", str(output), "--json"]
        began = time.perf_counter()
        result = subprocess.run(command, capture_output=True, text=True, check=True)
        walls.append(time.perf_counter() - began)
        fresh = sum(step["planning_time_s"] for step in json.loads(result.stdout)["steps"])
        warm = benchmark._solve(problem, config, "RRTConnect", 0, (1.0, None), False, output).planning_time_s
        ratios.append(fresh / warm)
        print(f"  one-shot {problem.name}: planning_time {1e3 * fresh:.1f} ms, in a warm process {1e3 * warm:.1f} ms; "
              f"the process {1e3 * walls[-1]:.0f} ms")
    print(f"  one-shot / warm planning_time: median {statistics.median(ratios):.2f}; the one-shot process: median "
          f"{1e3 * statistics.median(walls):.0f} ms, mean {1e3 * statistics.mean(walls):.0f} ms")


if __name__ == "__main__":
    main()
