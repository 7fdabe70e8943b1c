"""Panda in the shelf scene: planning with exact collision meshes against their convex hulls.

Run from the repository root with moveplan installed:
    python benchmarks/panda_meshes.py [--seeds 20] [--states 20000]

(a) Plans a task in samples/panda_shelf_scene.yaml (ready -> middle, bottom, upper bay -> ready)
    for seeds 0..N-1, each seed in its own `moveplan plan --seed k --json` process (OMPL's seed
    is process-wide), once per collision geometry mode, through temporary copies of
    configs/panda whose moveplan.yaml sets `planning: {collision: exact|convex}`. Reports runs
    that succeeded and the median and p95 of planning_time_s over all steps (goal to checked,
    timed trajectory: search, certification and timing).
(b) The cost of one collision check in [us] per state, batched as the planner checks them, on
    the states of the planned trajectories (best of 7 passes); and whether every state of the
    convex-mode plans is free under the exact meshes (what moveplan writes must be).
(c) Free space lost to hulls: of uniformly random states free under the meshes, the fraction
    that collide under the hulls; and the states free under hulls that collide under meshes
    (must be 0: a hull encloses its mesh). Also each robot mesh's hull volume / mesh volume.
Machines are shared and noisy: compare ratios, not absolute times.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import coal
import numpy as np
import yaml
from numpy.typing import NDArray

from moveplan.core.bag.plan_file import read_plan
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "configs" / "panda"
SCENE = ROOT / "samples" / "panda_shelf_scene.yaml"
MODES = ("exact", "convex")
# The bay goals documented in the scene file (inverse kinematics from `ready`).
STEPS = [
    {"name": "middle_bay", "joints": [1.513, -1.043, -1.364, -2.306, -2.866, 2.438, -0.46]},
    {"name": "bottom_bay", "joints": [1.335, 0.91, -1.024, -2.285, -2.66, 2.169, 1.317]},
    {"name": "upper_bay", "joints": [0.758, -0.295, -0.641, -1.742, 1.878, 3.284, 1.869]},
    {"name": "ready", "named": "ready"},
]


def config_copy(folder: Path, mode: str) -> Path:
    """Return a copy of configs/panda in `folder` whose moveplan.yaml selects collision `mode`."""
    target = folder / f"panda_{mode}"
    target.mkdir()
    for path in PANDA.iterdir():
        if path.is_file():
            (target / path.name).write_bytes(path.read_bytes())
    manifest = yaml.safe_load((PANDA / "moveplan.yaml").read_text())
    manifest["planning"]["collision"] = mode
    (target / "moveplan.yaml").write_text(yaml.safe_dump(manifest, sort_keys=False))
    return target


def plan_seeds(folder: Path, config: Path, mode: str, seeds: int) -> tuple[int, list[float], list[Path]]:
    """Return runs that succeeded, planning_time_s of every step [s], and the plan files."""
    task = folder / f"task_{mode}.yaml"
    task.write_text(yaml.safe_dump({"robot": str(config), "scene": str(SCENE), "start": {"named": "ready"},
                                    "steps": STEPS}, sort_keys=False))
    ok, times, files = 0, [], []
    for seed in range(seeds):
        out = folder / f"{mode}_{seed}.mcap"
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", "plan", str(task), "--seed",
                                 str(seed), "--json", "-o", str(out)], capture_output=True, text=True)
        report = json.loads(result.stdout)
        if result.returncode == 0:
            ok += 1
            files.append(out)
        else:
            print(f"  {mode} seed {seed}: exit {result.returncode}: {report['error']['message']}")
        times += [s["planning_time_s"] for s in report.get("steps") or [] if s.get("status") == "ok"]
    return ok, times, files


def plan_states(robot: Robot, files: list[Path], limit: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Return up to `limit` configurations (nq, k) drawn from the trajectories in `files`."""
    values = np.concatenate([s.trajectory.positions for f in files for s in read_plan(f).steps])
    if len(values) > limit:
        values = values[rng.choice(len(values), limit, replace=False)]
    return robot.configurations(values, robot.neutral())


def us_per_state(checkers: dict[str, CollisionChecker], states: NDArray[np.float64],
                 passes: int = 7) -> dict[str, float]:
    """Return each checker's best time of `passes` batched checks of `states`, in [us] per state.

    Passes alternate between the checkers, so a change in the machine's load hits both.
    """
    best = dict.fromkeys(checkers, np.inf)
    for _ in range(passes):
        for mode, checker in checkers.items():
            began = time.perf_counter()
            checker.free_batch(states)
            best[mode] = min(best[mode], time.perf_counter() - began)
    return {mode: 1e6 * seconds / states.shape[1] for mode, seconds in best.items()}


def hull_volumes(checker: CollisionChecker) -> list[tuple[str, float]]:
    """Return (geometry, hull volume / mesh volume) of every robot mesh."""
    ratios = []
    for obj in checker.geometry.geometryObjects:
        if isinstance(obj.geometry, coal.ConvexBase) and obj.meshPath.endswith((".stl", ".dae", ".obj")):
            mesh = coal.MeshLoader().load(obj.meshPath, np.asarray(obj.meshScale))
            ratios.append((str(obj.name), obj.geometry.computeVolume() / mesh.computeVolume()))
    return ratios


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--states", type=int, default=20000, help="states for (b) and (c)")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    robot = Robot(load_robot_config(PANDA))
    objects = load_scene(SCENE, robot).objects
    checkers = {mode: CollisionChecker(robot, objects, str(SCENE), geometry=mode) for mode in MODES}

    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        files: dict[str, list[Path]] = {}
        for mode in MODES:
            ok, times, files[mode] = plan_seeds(folder, config_copy(folder, mode), mode, args.seeds)
            rows[mode] = (ok, times)
        states = {mode: plan_states(robot, files[mode], args.states, rng) for mode in MODES if files[mode]}
    pooled = np.concatenate(list(states.values()), axis=1)
    cost = us_per_state(checkers, pooled)
    convex_plans_free = checkers["exact"].free_batch(states["convex"]) if "convex" in states else np.array([])

    values = rng.uniform(robot.lower, robot.upper, (args.states, robot.dof))
    random_states = robot.configurations(values, robot.neutral())
    free = {mode: checkers[mode].free_batch(random_states) for mode in MODES}
    lost = int(np.sum(free["exact"] & ~free["convex"]))
    unsafe = int(np.sum(free["convex"] & ~free["exact"]))
    random_cost = us_per_state(checkers, random_states)

    print(f"Panda, {SCENE.relative_to(ROOT)}, task ready -> 3 bays -> ready ({len(STEPS)} steps), "
          f"{args.seeds} seeds per mode, RRTConnect, 1 s per step")
    print(f"{'mode':<8}{'runs ok':>9}{'steps':>7}{'plan median':>13}{'plan p95':>10}"
          f"{'check, plan states':>20}{'check, random':>15}")
    for mode in MODES:
        ok, times = rows[mode]
        median, p95 = (np.median(times), np.percentile(times, 95)) if times else (np.nan, np.nan)
        print(f"{mode:<8}{f'{ok}/{args.seeds}':>9}{len(times):>7}{1e3 * median:>10.1f} ms{1e3 * p95:>7.1f} ms"
              f"{cost[mode]:>15.2f} us{random_cost[mode]:>10.2f} us")
    print(f"check cost exact / convex: {cost['exact'] / cost['convex']:.2f}x on {pooled.shape[1]} plan states, "
          f"{random_cost['exact'] / random_cost['convex']:.2f}x on {args.states} random states")
    print(f"convex-mode plan states free under exact meshes: {int(convex_plans_free.sum())}/{convex_plans_free.size}")
    exact_free = int(free["exact"].sum())
    print(f"free space lost to hulls: {lost} of {exact_free} random states free under meshes collide under "
          f"hulls ({100 * lost / max(exact_free, 1):.2f} %); free under hulls but colliding under meshes: {unsafe}")
    ratios = hull_volumes(checkers["convex"])
    worst = max(ratios, key=lambda r: r[1])
    print(f"hull volume / mesh volume over {len(ratios)} robot meshes: max {worst[1]:.4f} ({worst[0]})")


if __name__ == "__main__":
    main()
