"""MotionBenchMaker problems planned by pyroboplan and by `moveplan benchmark`, side by side.

Run from the repository root with moveplan and its `bench` extra installed (pip install ".[bench]"):
    python benchmarks/pyroboplan_compare.py [--count 10] [--seeds 1] [--time-limit 10] [--json]

For the first `--count` problems of each scenario in MBM/problems (a moveit_msgs/PlanningScene
and MotionPlanRequest per problem, read here as YAML) and each seed 0..S-1:

- pyroboplan plans as its Panda example does (examples/rrt_panda.py): RRTPlanner with that
  example's options (a one-tree RRT; `--connect` grows two trees with RRT-Connect) and
  `--time-limit` as max_planning_time, then `shortcut_path` with its defaults. Its collision
  model is pinocchio's, from MBM/panda_robot's URDF, with all pairs minus the SRDF's disabled
  pairs, minus the pairs the scene's allowed collision matrix allows; the scene's boxes and
  cylinders are world geometry objects paired with every robot geometry the matrix does not
  allow them to touch. Plan time is `plan()`, simplify time `shortcut_path()`.
- `moveplan benchmark --json` runs as a subprocess on the same problems and seeds; its runs are
  read as they are (its own search_s, simplify_s and exact_valid). Without that command, pyroboplan
  runs alone and the report says so.
- Valid: pyroboplan's returned path (after shortcutting) re-checked with moveplan's
  CollisionChecker on the exact meshes, at states at most `--step-mm` of robot motion apart
  along each segment (moveplan.core.certify). The runs in --json also say whether the path
  before shortcutting passes the same check (`unshortcut_exact_valid`).

Medians and p95 are over the runs that found a path; the ratio is pyroboplan's median
plan+simplify time over moveplan's. Machines are shared and noisy: compare ratios, not single times.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import yaml
from numpy.typing import NDArray

from moveplan.core.collision._certify import reach, segment_states
from moveplan.core.collision.checker import CollisionChecker, coal_geometry
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.types import CollisionObject, Shape

# The repository carries 10 problems a scenario; --mbm names a folder with more.
MBM = Path(__file__).resolve().parent.parent / "tests" / "data" / "mbm"
SCENARIOS = ("table_pick_panda", "bookshelf_small_panda", "box_panda")
GROUP = "panda_arm"
# examples/rrt_panda.py's RRTPlannerOptions; max_planning_time and rng_seed are set per run,
# and --connect turns on rrt_connect and bidirectional_rrt.
RRT_OPTIONS = {
    "max_step_size": 0.05,
    "max_connection_dist": 0.5,
    "rrt_connect": False,
    "bidirectional_rrt": False,
    "rrt_star": False,
    "max_rewire_dist": 3.0,
    "fast_return": True,
    "goal_biasing_probability": 0.15,
    "collision_distance_padding": 0.0,
}


@dataclass(frozen=True)
class Problem:
    """One MotionBenchMaker problem: start and goal joint values, scene objects, allowed pairs.

    Attributes:
        name: `scenario/NNNN`, as `moveplan benchmark` names it.
        scene: The scene file, for messages.
        start: Joint name -> start position [rad].
        goal: Joint name -> goal position [rad].
        objects: (collision object id, placed primitive) per primitive.
        allowed: Pairs of names the allowed collision matrix lets touch.
    """

    name: str
    scene: Path
    start: dict[str, float]
    goal: dict[str, float]
    objects: tuple[tuple[str, CollisionObject], ...]
    allowed: frozenset[frozenset[str]]


def scenarios(problems: Path) -> list[str]:
    """Return the scenario folders in `problems` holding requests: the shared set's three first, then the others."""
    found = sorted(p.name for p in problems.iterdir() if p.is_dir() and any(p.glob("request*.yaml")))
    return [s for s in SCENARIOS if s in found] + [s for s in found if s not in SCENARIOS]


def scenario_names(problems: list[Problem]) -> list[str]:
    """Return the scenarios of `problems`, in their order."""
    return list(dict.fromkeys(p.name.split("/")[0] for p in problems))


def load_problems(problems: Path, count: int) -> list[Problem]:
    """Return the first `count` problems of each scenario, scenario by scenario."""
    out = []
    for scenario in scenarios(problems):
        for request_path in sorted((problems / scenario).glob("request*.yaml"))[:count]:
            number = request_path.stem.removeprefix("request")
            scene_path = request_path.with_name(f"scene{number}.yaml")
            request = yaml.safe_load(request_path.read_text())
            scene = yaml.safe_load(scene_path.read_text())
            joint_state = request["start_state"]["joint_state"]
            start = dict(zip(joint_state["name"], joint_state["position"], strict=True))
            (constraints,) = request["goal_constraints"]
            goal = {c["joint_name"]: float(c["position"]) for c in constraints["joint_constraints"]}
            out.append(Problem(f"{scenario}/{number}", scene_path, start, goal, scene_objects(scene, scene_path),
                               allowed_pairs(scene)))
    return out


def scene_objects(scene: dict[str, Any], path: Path) -> tuple[tuple[str, CollisionObject], ...]:
    """Return (object id, collision object) for every primitive of the scene's world objects."""
    out = []
    for obj in (scene.get("world") or {}).get("collision_objects") or []:
        planning_T_object = pose_matrix(obj["pose"]) if "pose" in obj else np.eye(4)
        primitives = obj.get("primitives") or []
        for k, (primitive, pose) in enumerate(zip(primitives, obj["primitive_poses"], strict=True)):
            name = obj["id"] if len(primitives) == 1 else f"{obj['id']}_{k}"
            transform = planning_T_object @ pose_matrix(pose)
            out.append((obj["id"], CollisionObject(name, moveit_shape(primitive, f"{path}: {name}"), transform)))
    return tuple(out)


def pose_matrix(pose: dict[str, Any]) -> NDArray[np.float64]:
    """Return the 4x4 transform of a MoveIt pose (position [x, y, z], orientation [x, y, z, w])."""
    quaternion = np.asarray(pose["orientation"], dtype=float)
    xyzquat = np.concatenate([np.asarray(pose["position"], dtype=float), quaternion / np.linalg.norm(quaternion)])
    return np.array(pin.XYZQUATToSE3(xyzquat).homogeneous)


def moveit_shape(primitive: dict[str, Any], where: str) -> Shape:
    """Return moveplan's Shape of a shape_msgs/SolidPrimitive (MoveIt writes a cylinder as [height, radius])."""
    kind, dims = primitive["type"].lower(), [float(d) for d in primitive["dimensions"]]
    if kind == "box":
        return Shape("box", tuple(dims))
    if kind == "cylinder":
        height, radius = dims
        return Shape("cylinder", (radius, height))
    if kind == "sphere":
        return Shape("sphere", (dims[0],))
    raise ValueError(f"{where}: primitive type '{kind}': expected box, cylinder or sphere")


def allowed_pairs(scene: dict[str, Any]) -> frozenset[frozenset[str]]:
    """Return the pairs of names the scene's allowed collision matrix allows to touch."""
    acm = scene.get("allowed_collision_matrix") or {}
    names, values = acm.get("entry_names") or [], acm.get("entry_values") or []
    return frozenset(
        frozenset((names[i], names[j]))
        for i in range(len(names)) for j in range(i + 1, len(names)) if values[i][j]
    )


def pyroboplan_models(robot_dir: Path, problem: Problem) -> tuple[pin.Model, pin.GeometryModel]:
    """Return pinocchio's model and collision model of the robot in the problem's scene, pairs set."""
    from pyroboplan.core.utils import set_collisions

    model, collision_model, _ = pin.buildModelsFromUrdf(str(robot_dir / "panda.urdf"), package_dirs=str(robot_dir))
    robot_geometries = [(g.name, model.frames[g.parentFrame].name) for g in collision_model.geometryObjects]
    # pyroboplan.models.panda.add_self_collisions, with this robot's SRDF.
    collision_model.addAllCollisionPairs()
    pin.removeCollisionPairs(model, collision_model, str(robot_dir / "panda.srdf"))
    for pair in problem.allowed:
        a, b = sorted(pair)
        if model.existFrame(a) and model.existFrame(b):
            set_collisions(model, collision_model, a, b, False)
    # pyroboplan.models.panda.add_object_collisions, with the scene's objects.
    for object_id, obj in problem.objects:
        collision_model.addGeometryObject(
            pin.GeometryObject(obj.name, 0, pin.SE3(obj.transform), coal_geometry(obj.shape, str(problem.scene))))
        for name, link in robot_geometries:
            if frozenset((object_id, link)) not in problem.allowed:
                set_collisions(model, collision_model, obj.name, name, True)
    return model, collision_model


def joint_vector(model: pin.Model, values: dict[str, float]) -> NDArray[np.float64]:
    """Return pinocchio's configuration (revolute joints only) from joint name -> value."""
    q = pin.neutral(model)
    for jid in range(1, model.njoints):
        q[model.idx_qs[jid]] = values[model.names[jid]]
    return np.array(q)


def run_pyroboplan(
    robot_dir: Path, problem: Problem, seed: int, time_limit_s: float, connect: bool
) -> tuple[dict[str, Any], Any, Any]:
    """Return a run record in `moveplan benchmark`'s shape, the planner's path and the shortcut one (lists of q)."""
    from pyroboplan.planning.path_shortcutting import shortcut_path
    from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions

    model, collision_model = pyroboplan_models(robot_dir, problem)
    options = RRTPlannerOptions(**{**RRT_OPTIONS, "rrt_connect": connect, "bidirectional_rrt": connect},
                                max_planning_time=time_limit_s, rng_seed=seed)
    planner = RRTPlanner(model, collision_model, options=options)
    q_start, q_goal = joint_vector(model, problem.start), joint_vector(model, problem.goal)
    said = io.StringIO()  # pyroboplan prints its outcome; stdout is ours (--json)
    simplify_s, raw, path = 0.0, None, None
    with contextlib.redirect_stdout(said):
        began = time.perf_counter()
        raw = planner.plan(q_start, q_goal)
        plan_s = time.perf_counter() - began
        if raw:
            began = time.perf_counter()
            path = shortcut_path(model, collision_model, list(raw))
            simplify_s = time.perf_counter() - began
    messages = said.getvalue().split("\n")
    run = {
        "problem": problem.name, "planner": "pyroboplan RRTConnect" if connect else "pyroboplan RRT",
        "seed": seed, "ok": path is not None,
        "search_s": plan_s, "simplify_s": simplify_s, "total_s": plan_s + simplify_s,
        "path_length": float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1))) if path else None,
        "duration_s": None, "exact_valid": None,
        "error": None if path else next((m for m in reversed(messages) if m.strip()), "no path"),
    }
    return run, raw, path


def exact_valid(checker: CollisionChecker, reach_m: NDArray[np.float64], path: Any, step_m: float) -> bool:
    """Return True if every state along the path's segments, at most `step_m` [m] of motion apart, is free."""
    robot = checker.robot
    values = np.array([robot.values(np.asarray(q, dtype=float)) for q in path])
    base = robot.neutral()
    for a, b in zip(values[:-1], values[1:], strict=True):
        if not checker.free_batch(robot.configurations(segment_states(a, b, reach_m, step_m), base)).all():
            return False
    return True


def moveplan_command(mbm: Path, count: int, seeds: int, time_limit_s: float) -> list[str]:
    """Return the `moveplan benchmark` command line for the same problems and seeds."""
    return [sys.executable, "-m", "moveplan.cli.app", "benchmark", str(mbm / "problems"),
            "--robot", str(mbm / "panda_robot"), "--count", str(count), "--seeds", f"0-{seeds - 1}",
            "--planning-time", f"{time_limit_s:g}", "--json"]


def run_moveplan(command: list[str], keys: set[tuple[str, int]]) -> tuple[list[dict[str, Any]], str]:
    """Return `moveplan benchmark`'s runs on `keys` (problem, seed), and a note on what happened."""
    result = subprocess.run(command, capture_output=True, text=True)
    try:
        report = json.loads(result.stdout)
    except json.JSONDecodeError:
        report = {}
    if not isinstance(report, dict) or "runs" not in report:
        error = report.get("error") if isinstance(report, dict) else None
        reason = error.get("message") if isinstance(error, dict) else (result.stderr.strip().splitlines() or ["?"])[-1]
        return [], f"`moveplan benchmark` failed (exit {result.returncode}): {reason}; pyroboplan ran alone"
    runs = [r for r in report["runs"] if (r["problem"], r["seed"]) in keys]
    missing = len(keys) - len({(r["problem"], r["seed"]) for r in runs})
    note = f"`moveplan benchmark`: {len(runs)} runs" + (f", {missing} problem/seed pairs missing" if missing else "")
    return runs, note


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Return runs, successes, median and p95 of plan and plan+simplify time [s], valid count, median length."""
    solved = [r for r in runs if r["ok"]]
    plan = [r["search_s"] for r in solved]
    total = [r["search_s"] + r["simplify_s"] for r in solved]
    lengths = [r["path_length"] for r in solved if r["path_length"] is not None]
    return {
        "runs": len(runs),
        "ok": len(solved),
        "plan_median_s": float(np.median(plan)) if plan else None,
        "plan_p95_s": float(np.percentile(plan, 95)) if plan else None,
        "total_median_s": float(np.median(total)) if total else None,
        "total_p95_s": float(np.percentile(total, 95)) if total else None,
        "valid": sum(1 for r in solved if r["exact_valid"]),
        "path_length_median": float(np.median(lengths)) if lengths else None,
    }


def summaries(runs: dict[str, list[dict[str, Any]]], names: list[str]) -> list[dict[str, Any]]:
    """Return per scenario in `names` and overall: each tool's summary and pyroboplan/moveplan of the median totals."""
    rows = []
    for scenario in (*names, "overall"):
        row: dict[str, Any] = {"scenario": scenario}
        for tool, tool_runs in runs.items():
            chosen = [r for r in tool_runs if scenario == "overall" or r["problem"].startswith(f"{scenario}/")]
            row[tool] = summary(chosen)
        mine, theirs = row["pyroboplan"]["total_median_s"], row.get("moveplan", {}).get("total_median_s")
        row["ratio"] = mine / theirs if mine is not None and theirs else None
        rows.append(row)
    return rows


def milliseconds(seconds: float | None) -> str:
    """Return a time in [s] as milliseconds text, or '-' for none."""
    return "-" if seconds is None else f"{1e3 * seconds:.1f} ms"


def print_table(rows: list[dict[str, Any]], tools: list[str]) -> None:
    """Print one line per scenario and tool, and the ratio of median plan+simplify times."""
    print(f"{'scenario':<23}{'tool':<12}{'ok':>7}{'plan med':>12}{'plan p95':>12}{'plan+simpl med':>16}"
          f"{'p95':>12}{'valid':>7}{'ratio':>8}")
    for row in rows:
        for tool in tools:
            s = row[tool]
            solved = f"{s['ok']}/{s['runs']}"
            ratio = f"{row['ratio']:.1f}x" if tool == "pyroboplan" and row["ratio"] is not None else ""
            print(f"{row['scenario']:<23}{tool:<12}{solved:>7}{milliseconds(s['plan_median_s']):>12}"
                  f"{milliseconds(s['plan_p95_s']):>12}{milliseconds(s['total_median_s']):>16}"
                  f"{milliseconds(s['total_p95_s']):>12}{s['valid']:>7}{ratio:>8}")


def main() -> None:
    """Plan the subset with both tools and print the table (or, with --json, one JSON document)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mbm", type=Path, default=MBM, help="folder holding problems/ and panda_robot/")
    parser.add_argument("--count", type=int, default=10, help="first N problems of each scenario")
    parser.add_argument("--seeds", type=int, default=1, help="seeds 0..S-1 per problem")
    parser.add_argument("--time-limit", type=float, default=10.0, help="planning time limit per problem [s]")
    parser.add_argument("--step-mm", type=float, default=5.0, help="validity check: robot motion between states")
    parser.add_argument("--connect", action="store_true", help="pyroboplan: bidirectional RRT-Connect")
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of the table")
    args = parser.parse_args()
    try:
        import pyroboplan  # noqa: F401 - a benchmark-only extra
    except ImportError:
        sys.exit('pyroboplan is not installed: pip install ".[bench]" (see benchmarks/README.md)')

    robot_dir = args.mbm / "panda_robot"
    problems = load_problems(args.mbm / "problems", args.count)
    keys = {(p.name, seed) for p in problems for seed in range(args.seeds)}
    command = moveplan_command(args.mbm, args.count, args.seeds, args.time_limit)
    moveplan_runs, note = run_moveplan(command, keys)
    print(note, file=sys.stderr)

    robot = Robot(load_robot_config(robot_dir), GROUP)
    pyroboplan_runs = []
    for problem in problems:
        if problem.allowed - robot.config.srdf.disabled_pairs:
            # moveplan's checker takes the SRDF's disabled pairs only; here the two agree.
            print(f"{problem.scene}: the allowed collision matrix allows pairs the SRDF does not disable; "
                  "the validity check is stricter than the planner", file=sys.stderr)
        checker = CollisionChecker(robot, tuple(obj for _, obj in problem.objects), str(problem.scene), "exact")
        reach_m = reach(robot, checker.geometry)
        for seed in range(args.seeds):
            run, raw, path = run_pyroboplan(robot_dir, problem, seed, args.time_limit, args.connect)
            if path is not None:
                run["exact_valid"] = exact_valid(checker, reach_m, path, args.step_mm / 1e3)
                run["unshortcut_exact_valid"] = exact_valid(checker, reach_m, raw, args.step_mm / 1e3)
            pyroboplan_runs.append(run)
            outcome = (f"valid {run['exact_valid']} (before shortcutting: {run.get('unshortcut_exact_valid')})"
                       if run["ok"] else f"failed: {run['error']}")
            print(f"{problem.name} seed {seed}: plan {milliseconds(run['search_s'])}, "
                  f"simplify {milliseconds(run['simplify_s'])}, {outcome}", file=sys.stderr)

    runs = {"pyroboplan": pyroboplan_runs}
    if moveplan_runs:
        runs["moveplan"] = moveplan_runs
    rows = summaries(runs, scenario_names(problems))
    if args.json:
        document = {
            "problems": len(problems), "seeds": args.seeds, "time_limit_s": args.time_limit, "connect": args.connect,
            "step_m": args.step_mm / 1e3, "moveplan": {"ran": bool(moveplan_runs), "note": note},
            "summary": rows, "runs": [{"tool": tool, **r} for tool, tool_runs in runs.items() for r in tool_runs],
        }
        print(json.dumps(document, indent=1))
        return
    print(f"MotionBenchMaker, Panda: first {args.count} problems of each scenario x {args.seeds} seed(s), "
          f"{args.time_limit:g} s limit, pyroboplan {'RRTConnect' if args.connect else 'RRT'}; "
          f"valid: exact meshes, <= {args.step_mm:g} mm of motion between states")
    print(note)
    print_table(rows, list(runs))


if __name__ == "__main__":
    main()
