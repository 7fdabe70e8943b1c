"""Speed and success of `solve_ik` on the UR10e for random reachable, collision-free poses of tool0.

Run from the repository root with moveplan installed:
    python benchmarks/ik_speed.py [--poses 1000] [--seed 0] [--start home|near|both] [--scene FILE]
                                  [--exhaustive]

Targets are the forward kinematics of random configurations drawn uniformly within the joint
limits (fixed seed), kept if collision-free (self-collision, plus the scene if given). Each solve
checks collisions through `is_free`. Starts: "home" is [0, -pi/2, -pi/2, 0, 0, 0] (far moves from
a wrist singularity); "near" is the target's configuration plus N(0, 0.1 rad) per joint, clipped
to the limits (tracking-sized moves). Machines are shared and noisy: the median is the figure to
compare. No asserts on time.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import GoalUnreachable
from moveplan.core.model.kinematics import solve_ik
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[1]
HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
LINK = "tool0"


def run(robot: Robot, checker: CollisionChecker, count: int, seed: int, start_mode: str,
        exhaustive: bool) -> None:
    """Print the figures for one start mode."""
    rng = np.random.default_rng(seed)
    base = robot.neutral()
    targets: list[NDArray[np.float64]] = []
    starts: list[NDArray[np.float64]] = []
    while len(targets) < count:
        values = rng.uniform(robot.lower, robot.upper)
        if checker.in_collision(robot.configuration(values, base)):
            continue
        targets.append(robot.frame_pose(robot.configuration(values, base), LINK))
        near = np.clip(values + rng.normal(0.0, 0.1, robot.dof), robot.lower, robot.upper)
        starts.append(HOME if start_mode == "home" else near)

    def is_free(values: NDArray[np.float64]) -> bool:
        return not checker.in_collision(robot.configuration(values, base))

    for target, start in zip(targets[:20], starts[:20], strict=True):  # warm caches and allocators
        try:
            solve_ik(robot, target, LINK, start, base=base, is_free=is_free, exhaustive=exhaustive)
        except GoalUnreachable:
            pass
    times_ms: list[float] = []
    attempts: list[int] = []
    moves: list[float] = []
    failures: list[str] = []
    worst_position = worst_angle = 0.0
    outside = 0
    for index, (target, start) in enumerate(zip(targets, starts, strict=True)):
        began = time.perf_counter()
        try:
            solution = solve_ik(robot, target, LINK, start, base=base, is_free=is_free, seed=index,
                                exhaustive=exhaustive)
        except GoalUnreachable as error:
            times_ms.append(1e3 * (time.perf_counter() - began))
            failures.append(str(error))
            continue
        times_ms.append(1e3 * (time.perf_counter() - began))
        attempts.append(solution.attempts)
        moves.append(float(np.linalg.norm(solution.values - start)))
        worst_position = max(worst_position, solution.position_error_m)
        worst_angle = max(worst_angle, solution.orientation_error_rad)
        values = solution.values
        outside += bool(np.any(values < robot.lower) or np.any(values > robot.upper))
    times_ms.sort()
    p95 = times_ms[min(len(times_ms) - 1, int(0.95 * len(times_ms)))]
    start_text = ("home [0, -pi/2, -pi/2, 0, 0, 0]" if start_mode == "home"
                  else "near: target configuration + N(0, 0.1 rad)")
    print(f"start = {start_text}" + (", exhaustive=True" if exhaustive else ""))
    median = statistics.median(times_ms)
    local = 100 * attempts.count(1) / len(attempts)
    print(f"  success {100 * len(attempts) / count:.1f} % ({len(attempts)}/{count}); "
          f"median {median:.3f} ms, p95 {p95:.3f} ms, max {times_ms[-1]:.1f} ms per solve")
    print(f"  mean attempts {statistics.fmean(attempts):.2f} (local solve from start enough: "
          f"{local:.1f} %); mean joint move {statistics.fmean(moves):.2f} rad")
    print(f"  worst residual {1e3 * worst_position:.4f} mm, {1e3 * worst_angle:.4f} mrad; "
          f"solutions outside limits: {outside}")
    for failure in failures[:5]:
        print(f"  failed: {failure}")


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--poses", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--start", choices=("home", "near", "both"), default="both")
    parser.add_argument("--scene", type=Path, default=None,
                        help="scene file (default: the robot alone)")
    parser.add_argument("--exhaustive", action="store_true",
                        help="run all attempts and keep the nearest valid solution")
    args = parser.parse_args()
    robot = Robot(load_robot_config(ROOT / "configs" / "ur10e"))
    objects = load_scene(args.scene, robot).objects if args.scene else ()
    checker = CollisionChecker(robot, objects)
    checked = f"robot + {args.scene}" if args.scene else "self-collision"
    print(f"solve_ik on the UR10e, link {LINK}, {args.poses} random collision-free poses "
          f"(seed {args.seed}), collision check: {checked}")
    for mode in ("home", "near") if args.start == "both" else (args.start,):
        run(robot, checker, args.poses, args.seed, mode, args.exhaustive)


if __name__ == "__main__":
    main()
