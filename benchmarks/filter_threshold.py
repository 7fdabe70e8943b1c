"""What sets how long a one-shot `moveplan plan` checks with coal alone before it builds the sphere filter.

Run from the repository root with moveplan installed:
    python benchmarks/filter_threshold.py [--mbm DIR] [--robot DIR] [--count 3] [--fresh 5] [--fit] [--compile]
The rule (core/pipeline/_checks.py) is rent or buy: build the filter once the states asked about
have cost, checked by coal alone, what building it costs. Printed:
(a) building it in a fresh process: its kernels loaded (compiled ahead of time, or numba imported
    and its cached kernels loaded, whichever this install has), the filter made, and the kernels'
    first calls (the build in the first plan with the filter, after one with coal alone), median
    of --fresh processes;
    with --fit also into an empty moveplan cache (the robot's spheres and tables fitted), and
    with --compile into an empty numba cache (the compilation);
(b) per MotionBenchMaker problem (the first --count of each scenario: the repository's, or --mbm a
    folder with more), the step with coal alone and with the filter, each in a process of its own
    and the best of two, over the states the step asks about: what a state costs more without the
    filter; medians per scenario and overall;
(c) the thresholds (a) / median (b): FILTER_AFTER_STATES (numba's JIT), FILTER_AFTER_STATES_UNFITTED and
    FILTER_AFTER_STATES_UNCOMPILED; a filter whose kernels are compiled ahead of time and whose robot is
    fitted is built at once (AT_ONCE_IF_FITTED);
(d) the problems whose plans differ with the filter and with coal alone (motions checked, path,
    trajectory): the filter may change only how fast an answer comes, so none should.
Machines are shared and noisy: compare ratios and medians.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from moveplan.core.collision import count_unfiltered, kernels_native
from moveplan.core.config import MotionSettings
from moveplan.core.pipeline import _checks, benchmark
from moveplan.core.pipeline import plan as pipeline

ROOT = Path(__file__).resolve().parents[1]
NEVER = 10**15  # states: the filter is never built


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mbm", type=Path, default=ROOT / "tests" / "data" / "mbm" / "problems",
                        help="folder of MotionBenchMaker problems, with panda_robot beside it or in its parent")
    parser.add_argument("--robot", type=Path, help="the problems' robot config (default: panda_robot beside them)")
    parser.add_argument("--count", type=int, default=3, help="problems per scenario")
    parser.add_argument("--fresh", type=int, default=5, help="fresh processes timing the build")
    parser.add_argument("--fit", action="store_true", help="also time the build into an empty moveplan cache")
    parser.add_argument("--compile", action="store_true", help="also time the compilation into an empty numba cache")
    parser.add_argument("--worker", choices=("coal", "filter", "build"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    robot = args.robot or next(p for p in (args.mbm / "panda_robot", args.mbm.parent / "panda_robot") if p.is_dir())
    problems = benchmark.find_problems([args.mbm], args.count)
    if args.worker:
        print(json.dumps(_work(args.worker, robot, problems)))
        return
    build = statistics.median(_worker("build", args) for _ in range(args.fresh))
    coal, filtered = _worker("coal", args), _worker("filter", args)
    extra: dict[str, list[float]] = {}
    ratios = []
    for problem, (coal_s, asked, _), (filter_s, _, _) in zip(problems, coal, filtered, strict=True):
        extra.setdefault(problem.scenario, []).append((coal_s - filter_s) / asked)
        ratios.append(coal_s / filter_s)
        print(f"  {problem.name}: {asked} states, coal alone {1e3 * coal_s:.1f} ms, "
              f"with the filter {1e3 * filter_s:.1f} ms")
    for scenario, values in extra.items():
        print(f"  {scenario}: {1e6 * statistics.median(values):.2f} us a state more with coal alone (median)")
    rent = statistics.median(value for values in extra.values() for value in values)
    kind = "compiled ahead of time" if kernels_native() else "numba's JIT"
    print(f"(a) the filter's build in a fresh process ({kind}): median {1e3 * build:.0f} ms of {args.fresh}")
    print(f"(b) a state checked with coal alone: {1e6 * rent:.2f} us more than with the filter (median of "
          f"{len(problems)} problems); the step with coal alone over the step with the filter: median "
          f"{statistics.median(ratios):.2f}")
    print(f"(c) the build is worth {build / rent:,.0f} states (FILTER_AFTER_STATES, for numba's JIT: "
          f"{_checks.FILTER_AFTER_STATES:,}; compiled ahead of time, a fitted robot's filter is built at once)")
    differ = [problem.name for problem, a, b in zip(problems, coal, filtered, strict=True) if a[2] != b[2]]
    print(f"(d) plans that differ with the filter and with coal alone: {len(differ)} of {len(problems)}"
          + "".join(f"\n    {name}" for name in differ))
    if args.fit:
        with tempfile.TemporaryDirectory() as cache:
            fitted = _worker("build", args, {"MOVEPLAN_CACHE_DIR": cache})
        print(f"    into an empty moveplan cache: {fitted:.1f} s; FILTER_AFTER_STATES_UNFITTED: "
              f"{fitted / rent:,.0f} states (now {_checks.FILTER_AFTER_STATES_UNFITTED:,})")
    if args.compile:
        with tempfile.TemporaryDirectory() as cache:
            compiled = _worker("build", args, {"NUMBA_CACHE_DIR": cache})
        print(f"    compiled into an empty cache: {compiled:.1f} s; FILTER_AFTER_STATES_UNCOMPILED: "
              f"{compiled / rent:,.0f} states (now {_checks.FILTER_AFTER_STATES_UNCOMPILED:,})")


def _worker(kind: str, args: argparse.Namespace, env: dict[str, str] | None = None) -> Any:
    """Return what a fresh process of this script measures as `kind`."""
    command = [sys.executable, __file__, "--worker", kind, "--mbm", str(args.mbm), "--count", str(args.count),
               *(["--robot", str(args.robot)] if args.robot else [])]
    result = subprocess.run(command, capture_output=True, text=True, check=True, env={**os.environ, **(env or {})})
    return json.loads(result.stdout)


def _work(kind: str, robot: Path, problems: tuple[benchmark.ProblemFiles, ...]) -> Any:
    """Return per problem, with `kind`'s checks, the best of two steps' planning time [s], states asked, plan digest.

    `build`: the build's cost [s] alone, as the first problem's first plan with the filter builds it
    (after a plan with coal alone, which set up everything else).
    """
    if kind == "build":
        _planned(robot, problems[0], NEVER)
        spent: list[float] = []
        build = _checks.build_sphere_filter

        def timed(*args: Any) -> Any:
            began = time.perf_counter()
            try:
                return build(*args)
            finally:
                spent.append(time.perf_counter() - began)

        _checks.build_sphere_filter = timed
        _planned(robot, problems[0], 0)
        return spent[0]
    after = NEVER if kind == "coal" else 0
    return [min(_planned(robot, problem, after)[1:], _planned(robot, problem, after)[1:]) for problem in problems]


def _planned(robot: Path, problem: benchmark.ProblemFiles, after: int) -> tuple[float, float, int, str]:
    """Return a plan's wall time [s], its steps' planning time [s], the states asked and a digest of what it plans.

    The filter is built after `after` states. The digest covers each step's motions checked, path length and
    timed trajectory.
    """
    flags = pipeline.PlanFlags(robot=robot, scene=problem.scene, request=problem.request, seed=0,
                               motion=MotionSettings(planner="RRTConnect", planning_time=1.0))
    request = pipeline.resolve_request(None, flags)
    unfiltered, began = count_unfiltered(0), time.perf_counter()
    plan = pipeline.plan(request, filter_after=after)
    wall = time.perf_counter() - began
    digest = hashlib.sha256()
    for step in plan.steps:
        digest.update(repr((step.stats["checks"], step.stats["path_length"])).encode())
        digest.update(step.trajectory.times_s.tobytes() + step.trajectory.positions.tobytes())
    return wall, sum(step.planning_time_s for step in plan.steps), count_unfiltered(0) - unfiltered, digest.hexdigest()


if __name__ == "__main__":
    main()
