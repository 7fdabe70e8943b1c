"""MotionBenchMaker problems planned by roboplan (C++, PyPI `roboplan`) and by `moveplan benchmark`, interleaved.

roboplan is a benchmark-only tool in a virtual environment of its own (its pins are not
moveplan's; never install it into moveplan's): see benchmarks/README.md.
    python benchmarks/roboplan_compare.py --roboplan-python /tmp/roboplan/bin/python [--count 10] [--seeds 1]
        [--mbm /work/shared/benchmarks/mbm] [--json]

Per seed, in turn (interleaved, so that both see the same machine): `moveplan benchmark --json`
on the problems, then a roboplan worker (this script under `--roboplan-python`, `--worker`) on the
same problems. roboplan plans as its examples do: RRT-Connect (`rrt_connect`), edges checked
every 0.05 rad, the planner seeded (`RRT.setRngSeed`), `--time-limit` as max_planning_time and no
cap on nodes (as roboplan's own RRT benchmark), so that, as for OMPL, only time ends a search; then
its PathShortcutter (0.05 rad steps, seeded) and its TOPP-RA at 10 ms.

roboplan's scene is the problem's: the problem's URDF and SRDF (roboplan's own loaders; the SRDF's
disabled pairs), the velocity and acceleration limits moveplan times with, the scene's boxes and
cylinders on `universe` (MoveIt's planning frame `world`, where every MotionBenchMaker state puts
the SRDF's floating virtual joint, and so panda_link0, at identity), the pairs the allowed
collision matrix allows turned off, and the world objects not checked against one another, as
MoveIt does not (roboplan pairs every new geometry with every other; a table's legs touching its
top made every start "in collision"). The Panda's fingers are
fixed joints in this URDF, so the start state has no joints outside the group. Per problem, the
start and goal are judged by both roboplan's scene and moveplan's checker; a disagreement is printed.

Reported per tool: success, median and p95 of plan and plan+simplify time, and of the whole call
(moveplan: `whole_call_s`, set-up to written file with the robot config loaded; roboplan: scene
set-up from the loaded description, planning, shortcutting, and its TOPP-RA time
parameterisation), the median joint-space path length, and paths valid on the exact meshes: every
returned path re-checked with moveplan's CollisionChecker at states at most `--step-mm` of robot
motion apart (roboplan's path before shortcutting too, in --json: `unshortcut_exact_valid`).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

MBM = Path(__file__).resolve().parent.parent / "tests" / "data" / "mbm"
GROUP = "panda_arm"


def worker() -> None:
    """Plan the problems on stdin (JSON) with roboplan; print one JSON run per problem (runs in roboplan's venv)."""
    import roboplan.core as rp

    job = json.load(sys.stdin)
    robot = Path(job["robot"])
    description = rp.loadUrdfSceneDescription(robot / "panda.urdf", [str(robot)])
    srdf = (robot / "panda.srdf").read_text()
    with tempfile.TemporaryDirectory() as folder:
        # roboplan reads limits only from a file in its own layout; JSON is YAML to its reader.
        limits_path = Path(folder) / "limits.yaml"
        limits_path.write_text(json.dumps({"joint_limits": job["limits"]}))
        limits = rp.loadJointLimitsConfig(limits_path)
    runs = []
    for problem in job["problems"]:
        began = time.perf_counter()
        scene = _scene(rp, description, srdf, limits, problem)
        set_up_s = time.perf_counter() - began
        runs.append(_plan(scene, problem, job, set_up_s))
    json.dump(runs, sys.stdout)


def _scene(rp: Any, description: Any, srdf: str, limits: Any, problem: dict[str, Any]) -> Any:
    """Return roboplan's Scene of the problem: robot, SRDF, Panda limits, world objects, allowed pairs."""
    scene = rp.Scene("panda", description)
    scene.importSrdf(srdf)
    scene.importJointLimitsFromConfig(limits)
    # MoveIt's scene poses are in the planning frame, `world`; the problems' states put the virtual
    # joint at identity, so world is panda_link0, the URDF's root, on pinocchio's universe.
    for obj in problem["objects"]:
        shape, transform = obj["shape"], np.asfortranarray(obj["transform"])
        if shape["kind"] == "box":
            scene.addBoxGeometry(obj["name"], "universe", rp.Box(*shape["size"]), transform, np.ones(4))
        else:
            scene.addCylinderGeometry(obj["name"], "universe", rp.Cylinder(shape["radius"], shape["length"]),
                                      transform, np.ones(4))
    # roboplan pairs a new geometry with every other, world objects included; MoveIt checks the
    # robot against the world, never the world against itself (a table's legs touch its top).
    names = [obj["name"] for obj in problem["objects"]]
    world_pairs = [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
    if world_pairs or problem["allowed"]:
        scene.setCollisions(world_pairs + [tuple(pair) for pair in problem["allowed"]], False)
    return scene


def _plan(scene: Any, problem: dict[str, Any], job: dict[str, Any], set_up_s: float) -> dict[str, Any]:
    """Return one run: roboplan's RRT-Connect, its shortcutter and its TOPP-RA on the problem."""
    import roboplan.core as rp
    import roboplan.rrt as rrt

    names, group, step = problem["joints"], job["group"], 0.05
    start, goal = np.array(problem["start"]), np.array(problem["goal"])
    run: dict[str, Any] = {
        "problem": problem["name"], "planner": "roboplan RRTConnect", "seed": job["seed"],
        "start_free": not scene.hasCollisions(scene.toFullJointPositions(group, start)),
        "goal_free": not scene.hasCollisions(scene.toFullJointPositions(group, goal)),
    }
    began = time.perf_counter()
    # As roboplan's examples: RRT-Connect, edges checked every 0.05 rad, seeded planner; nodes
    # all but uncapped (its own RRT benchmark raises the cap of 1000) so that, as for OMPL, the
    # time limit ends a search.
    options = rrt.RRTOptions(group_name=group, collision_check_step_size=step, rrt_connect=True,
                             max_nodes=1_000_000, max_planning_time=job["time_limit_s"])
    planner = rrt.RRT(scene, options)
    planner.setRngSeed(job["seed"])
    set_up_s += time.perf_counter() - began
    mark = time.perf_counter()
    try:
        raw = planner.plan(rp.JointConfiguration(names, start), rp.JointConfiguration(names, goal))
    except RuntimeError as exc:  # roboplan raises when it finds no path
        return {**run, "ok": False, "error": str(exc)}
    plan_s = time.perf_counter() - mark
    mark = time.perf_counter()
    shortcutting = rp.PathShortcuttingOptions(group_name=group, max_step_size=step, seed=job["seed"])
    path = rp.PathShortcutter(scene, shortcutting).shortcut(raw)
    simplify_s = time.perf_counter() - mark
    timing_s = _toppra(scene, path, group)
    return {**run, "ok": True, "search_s": plan_s, "simplify_s": simplify_s,
            "whole_call_s": set_up_s + plan_s + simplify_s + (timing_s or 0.0), "timed": timing_s is not None,
            "joints": list(path.joint_names), "path": np.asarray(path.positions).tolist(),
            "raw_path": np.asarray(raw.positions).tolist()}


def _toppra(scene: Any, path: Any, group: str) -> float | None:
    """Return the seconds roboplan's TOPP-RA takes to time `path` (10 ms samples), or None when it cannot."""
    import roboplan.toppra as toppra

    mark = time.perf_counter()
    try:
        toppra.PathParameterizerTOPPRA(scene, group).generate(path, toppra.TOPPRAOptions(dt=0.01))
    except RuntimeError:
        return None
    return time.perf_counter() - mark


def job_of(problems: list[Any], robot: Any, seed: int, args: argparse.Namespace) -> dict[str, Any]:
    """Return the worker's input: the problems as plain data, the group's joints and their limits."""
    joints = list(robot.joint_names)
    out = []
    for p in problems:
        objects = []
        for _, obj in p.objects:
            shape = obj.shape
            if shape.kind not in ("box", "cylinder"):
                sys.exit(f"roboplan_compare: {p.scene}: a {shape.kind} object; this script passes boxes and cylinders")
            data = ({"kind": "box", "size": list(shape.dims)} if shape.kind == "box"
                    else {"kind": "cylinder", "radius": shape.dims[0], "length": shape.dims[1]})
            objects.append({"name": obj.name, "shape": data, "transform": np.asarray(obj.transform).tolist()})
        out.append({"name": p.name, "joints": joints, "start": [p.start[j] for j in joints],
                    "goal": [p.goal[j] for j in joints],
                    "objects": objects, "allowed": [sorted(pair) for pair in p.allowed]})
    # The limits moveplan times with (URDF, overridden by joint_limits.yaml), in roboplan's layout:
    # its URDF loader alone leaves the accelerations unbounded.
    limits = {j: {"max_velocity": [robot.config.limits[j].max_velocity],
                  "max_acceleration": [robot.config.limits[j].max_acceleration]} for j in joints}
    return {"robot": str(args.mbm / "panda_robot"), "group": GROUP, "seed": seed, "limits": limits,
            "time_limit_s": args.time_limit, "problems": out}


def main() -> None:
    """Plan the problems with both tools, seed by seed in turn, and print the table (or --json)."""
    parser = arguments(__doc__, "roboplan")
    args = parser.parse_args()
    if args.worker:
        worker()
        return
    _check_python(args.roboplan_python)
    compare(args, "roboplan", args.roboplan_python, __file__, job_of)


def arguments(doc: str | None, tool: str) -> argparse.ArgumentParser:
    """Return the command line both comparisons take; `--TOOL-python` names the other tool's python."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument(f"--{tool}-python", type=Path, help=f"python of the virtual environment holding {tool}")
    parser.add_argument("--mbm", type=Path, default=MBM, help="folder holding problems/ and panda_robot/")
    parser.add_argument("--count", type=int, default=10, help="first N problems of each scenario")
    parser.add_argument("--seeds", type=int, default=1, help="seeds 0..S-1 per problem")
    parser.add_argument("--time-limit", type=float, default=10.0, help="planning time limit per problem [s]")
    parser.add_argument("--step-mm", type=float, default=5.0, help="validity check: robot motion between states")
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of the table")
    return parser


def compare(args: argparse.Namespace, tool: str, python: Path, script: str,
            job: Callable[[list[Any], Any, int, argparse.Namespace], dict[str, Any]]) -> None:
    """Per seed in turn, run `moveplan benchmark` and `script --worker` under `python` on `job`; print the table."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import pyroboplan_compare as shared  # problems, validity check and summary, shared with that comparison

    from moveplan.core.config.robot_config import load_robot_config
    from moveplan.core.model.robot import Robot

    problems = shared.load_problems(args.mbm / "problems", args.count)
    robot = Robot(load_robot_config(args.mbm / "panda_robot"), GROUP)
    checks: dict[str, Any] = {}
    runs: dict[str, list[dict[str, Any]]] = {tool: [], "moveplan": []}
    for seed in range(args.seeds):
        command = shared.moveplan_command(args.mbm, args.count, 1, args.time_limit)
        command[command.index("--seeds") + 1] = str(seed)
        mine, note = shared.run_moveplan(command, {(p.name, seed) for p in problems})
        print(note, file=sys.stderr)
        runs["moveplan"] += mine
        result = subprocess.run([str(python), script, "--worker"], input=json.dumps(job(problems, robot, seed, args)),
                                capture_output=True, text=True)
        if result.returncode != 0:
            reason = (result.stderr.strip().splitlines() or ["?"])[-1]
            sys.exit(f"{Path(script).stem}: {tool} could not plan these problems (exit {result.returncode}): {reason}")
        for run, problem in zip(json.loads(result.stdout), problems, strict=True):
            if problem.name not in checks:
                checks[problem.name] = _checker(robot, problem, run, tool)
            runs[tool].append(_judge(shared, checks[problem.name], run, robot, args.step_mm / 1e3))
    if runs[tool] and not any(r["ok"] for r in runs[tool]):
        errors = {str(r.get("error")) for r in runs[tool]}
        print(f"{Path(script).stem}: {tool} solved none of the problems: {'; '.join(sorted(errors))}", file=sys.stderr)
    rows = []
    for scenario in (*shared.scenario_names(problems), "overall"):
        row: dict[str, Any] = {"scenario": scenario}
        for name, tool_runs in runs.items():
            chosen = [r for r in tool_runs if scenario == "overall" or r["problem"].startswith(f"{scenario}/")]
            row[name] = {**shared.summary([{"path_length": None, **r} for r in chosen]),
                         **_whole([r for r in chosen if r["ok"]])}
        rows.append(row)
    if args.json:
        print(json.dumps({"problems": len(problems), "seeds": args.seeds, "summary": rows,
                          "runs": [{"tool": t, **r} for t, rs in runs.items() for r in rs]}, indent=1))
        return
    _print(rows, args, tool)


def _check_python(python: Path | None) -> None:
    """Exit with one line unless `python` runs and imports roboplan's planner, shortcutter and TOPP-RA."""
    need = "import numpy, roboplan.core, roboplan.rrt, roboplan.toppra"
    if python is None or not python.is_file() or subprocess.run([str(python), "-c", need],
                                                                capture_output=True).returncode != 0:
        sys.exit(f"roboplan_compare: --roboplan-python {python or '(missing)'}: not a python with roboplan "
                 "(python3.11 -m venv VENV && VENV/bin/pip install roboplan==0.7.0; see benchmarks/README.md)")


def _checker(robot: Any, problem: Any, run: dict[str, Any], tool: str) -> tuple[Any, Any]:
    """Return moveplan's exact checker of the problem and its reach; warn if the tool's scene disagrees on it."""
    from moveplan.core.collision._certify import reach
    from moveplan.core.collision.checker import CollisionChecker

    checker = CollisionChecker(robot, tuple(o for _, o in problem.objects), str(problem.scene), "exact")
    # The scene the tool plans in must be the problem's: both checkers judge start and goal alike.
    for state in ("start", "goal"):
        q = robot.configuration([getattr(problem, state)[j] for j in robot.joint_names])
        pair = checker.colliding_pair(q)
        if run[f"{state}_free"] != (pair is None):
            print(f"{tool}_compare: {problem.name}: {tool} calls the {state} "
                  f"{'free' if run[f'{state}_free'] else 'in collision'}, moveplan "
                  f"{f'in collision ({pair[0]} - {pair[1]})' if pair else 'free'}", file=sys.stderr)
    return checker, reach(robot, checker.geometry)


def _judge(shared: Any, check: tuple[Any, Any], run: dict[str, Any], robot: Any, step_m: float) -> dict[str, Any]:
    """Return the run with its path replaced by its validity on the exact meshes and its length [rad]."""
    if not run["ok"]:
        return run
    checker, reach_m = check
    index = [run["joints"].index(j) for j in robot.joint_names]
    values, raw = (np.asarray(run.pop(key))[:, index] for key in ("path", "raw_path"))
    run["exact_valid"] = shared.exact_valid(checker, reach_m, [robot.configuration(v) for v in values], step_m)
    run["unshortcut_exact_valid"] = shared.exact_valid(checker, reach_m, [robot.configuration(v) for v in raw], step_m)
    run["path_length"] = float(np.sum(np.linalg.norm(np.diff(values, axis=0), axis=1)))
    return run


def _whole(solved: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the median and p95 of the whole call [s] over solved runs."""
    values = [r["whole_call_s"] for r in solved if r.get("whole_call_s") is not None]
    return {"whole_median_s": float(np.median(values)) if values else None,
            "whole_p95_s": float(np.percentile(values, 95)) if values else None}


def _print(rows: list[dict[str, Any]], args: argparse.Namespace, tool: str) -> None:
    """Print one line per scenario and tool."""
    def ms(seconds: float | None) -> str:
        return "-" if seconds is None else f"{1e3 * seconds:.1f}"

    print(f"MotionBenchMaker, Panda: first {args.count} problems of each scenario x {args.seeds} seed(s), RRTConnect, "
          f"{args.time_limit:g} s limit; times in ms (median, p95 over solved runs); length: joint-space path [rad]; "
          f"valid: exact meshes, <= {args.step_mm:g} mm of motion between states")
    print(f"{'scenario':<23}{'tool':<10}{'ok':>9}{'plan med':>10}{'plan+simpl med':>16}{'p95':>9}"
          f"{'whole med':>11}{'p95':>9}{'length':>8}{'valid':>7}")
    for row in rows:
        for name in ("moveplan", tool):
            s = row[name]
            length = "-" if s["path_length_median"] is None else f"{s['path_length_median']:.2f}"
            solved = f"{s['ok']}/{s['runs']}"
            print(f"{row['scenario']:<23}{name:<10}{solved:>9}{ms(s['plan_median_s']):>10}"
                  f"{ms(s['total_median_s']):>16}{ms(s['total_p95_s']):>9}{ms(s['whole_median_s']):>11}"
                  f"{ms(s['whole_p95_s']):>9}{length:>8}{s['valid']:>7}")


if __name__ == "__main__":
    main()
