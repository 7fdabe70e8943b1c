"""Whether MotionBenchMaker problems plan the same with the sphere filter and with coal alone.

Run from the repository root with moveplan installed:
    python tools/filter_identity.py [--mbm DIR] [--robot DIR] [--count 10] [--seeds 1] [--planner RRTConnect]
Each problem and seed is planned twice in this process, as `moveplan benchmark` plans it: first
with coal alone (what a one-shot `moveplan plan` does until the filter pays for itself), then
with the sphere filter built at once (what `moveplan benchmark` does). The filter may change
only how fast an answer comes (core/pipeline/_checks.py): the motions the search checks, the
path and the timed trajectory must be the same. Prints the runs that differ and their count.
The coal-alone runs come first: a process that has built one filter builds the next at once.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from moveplan.core.config import MotionSettings, RobotConfig, load_robot_config
from moveplan.core.errors import NoPlan
from moveplan.core.pipeline import benchmark
from moveplan.core.pipeline import plan as pipeline

ROOT = Path(__file__).resolve().parents[1]
NEVER = 10**15  # states before a one-shot command would build the filter: never, here


def main() -> None:
    """Print the runs whose plans differ with the filter and without it."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mbm", type=Path, default=ROOT / "tests" / "data" / "mbm" / "problems",
                        help="folder of MotionBenchMaker problems, with panda_robot beside it or in its parent")
    parser.add_argument("--robot", type=Path, help="the problems' robot config (default: panda_robot beside them)")
    parser.add_argument("--count", type=int, default=10, help="problems per scenario")
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--planner", default="RRTConnect")
    args = parser.parse_args()
    robot = args.robot or next(p for p in (args.mbm / "panda_robot", args.mbm.parent / "panda_robot") if p.is_dir())
    config = load_robot_config(robot)
    runs = [(problem, seed) for problem in benchmark.find_problems([args.mbm], args.count)
            for seed in range(args.seeds)]
    alone = [_planned(problem, seed, config, args.planner, NEVER) for problem, seed in runs]
    filtered = [_planned(problem, seed, config, args.planner, 0) for problem, seed in runs]
    differ = [(problem.name, seed) for (problem, seed), a, b in zip(runs, alone, filtered, strict=True) if a != b]
    for name, seed in differ[:20]:
        print(f"differs: {name} seed {seed}")
    print(f"{len(runs)} runs ({robot}, {args.planner}): {len(differ)} plan differently with the filter than without it")


def _planned(problem: benchmark.ProblemFiles, seed: int, config: RobotConfig, planner: str, after: int) -> tuple[
        object, ...]:
    """Return what a run's plan is judged by: motions checked, and each step's path length and trajectory."""
    flags = pipeline.PlanFlags(robot=config.root, scene=problem.scene, request=problem.request,
                               motion=MotionSettings(planner=planner, planning_time=1.0), seed=seed)
    try:
        plan, _ = pipeline.planned(pipeline.resolve_request(None, flags), config=config, filter_after=after)
    except NoPlan as exc:
        return ("no plan", str(exc))
    return tuple((step.stats["checks"], step.stats["path_length"], step.trajectory.times_s.tobytes(),
                  np.asarray(step.trajectory.positions).tobytes()) for step in plan.steps)


if __name__ == "__main__":
    main()
