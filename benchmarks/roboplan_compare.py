"""MotionBenchMaker problems planned by roboplan (C++, PyPI `roboplan`) and by `moveplan benchmark`, interleaved.

roboplan is a benchmark-only tool in a virtual environment of its own (its pins are not
moveplan's; never install it into moveplan's): see benchmarks/README.md.
    python benchmarks/roboplan_compare.py --roboplan-python /tmp/roboplan/bin/python [--count 10] [--seeds 1]
        [--mbm /work/shared/benchmarks/mbm] [--json]

Per seed, in turn (interleaved, so that both see the same machine): `moveplan benchmark --json`
on the problems, then a roboplan worker (this script under `--roboplan-python`, `--worker`) on the
same problems. roboplan plans as its RRT example does: RRT-Connect (`rrt_connect`), edges checked
every 0.05 rad, `--time-limit` as max_planning_time, seeded; then its PathShortcutter with its
defaults. Its scene is the problem's URDF and SRDF (roboplan's own loaders) with the scene's boxes
and cylinders as world geometry, and the pairs the allowed collision matrix allows turned off.

Reported per tool: success, median and p95 of plan and plan+simplify time, and of the whole call
(moveplan: `whole_call_s`, set-up to written file with the robot config loaded; roboplan: scene
set-up from the loaded description, planning, shortcutting, and its TOPP-RA time
parameterisation), and paths valid on the exact meshes: every returned path re-checked with
moveplan's CollisionChecker at states at most `--step-mm` of robot motion apart.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

MBM = Path(__file__).resolve().parent.parent / "tests" / "data" / "mbm"


def worker() -> None:
    """Plan the problems on stdin (JSON) with roboplan; print one JSON run per problem (runs in roboplan's venv)."""
    import roboplan.core as rp
    import roboplan.rrt as rrt

    job = json.load(sys.stdin)
    robot = Path(job["robot"])
    description = rp.loadUrdfSceneDescription(robot / "panda.urdf", [str(robot)])
    srdf = (robot / "panda.srdf").read_text()
    runs = []
    for problem in job["problems"]:
        began = time.perf_counter()
        scene = rp.Scene("panda", description)
        scene.importSrdf(srdf)
        scene.setRngSeed(job["seed"])
        for obj in problem["objects"]:
            shape, transform = obj["shape"], np.asfortranarray(obj["transform"])
            if shape["kind"] == "box":
                scene.addBoxGeometry(obj["name"], "universe", rp.Box(*shape["size"]), transform, np.ones(4))
            else:
                scene.addCylinderGeometry(obj["name"], "universe", rp.Cylinder(shape["radius"], shape["length"]),
                                          transform, np.ones(4))
        if problem["allowed"]:
            scene.setCollisions([tuple(pair) for pair in problem["allowed"]], False)
        names = problem["joints"]
        options = rrt.RRTOptions(group_name=job["group"], collision_check_step_size=0.05, rrt_connect=True,
                                 max_planning_time=job["time_limit_s"])
        planner = rrt.RRT(scene, options)
        start = rp.JointConfiguration(names, np.array(problem["start"]))
        goal = rp.JointConfiguration(names, np.array(problem["goal"]))
        set_up_s = time.perf_counter() - began
        run: dict[str, Any] = {"problem": problem["name"], "planner": "roboplan RRTConnect", "seed": job["seed"]}
        mark = time.perf_counter()
        try:
            raw = planner.plan(start, goal)
        except Exception as exc:  # noqa: BLE001 - roboplan raises on no path; a failed run
            runs.append({**run, "ok": False, "error": str(exc)})
            continue
        plan_s = time.perf_counter() - mark
        if raw is None or len(raw.positions) == 0:
            runs.append({**run, "ok": False, "error": "no path"})
            continue
        mark = time.perf_counter()
        path = rp.PathShortcutter(scene, rp.PathShortcuttingOptions(group_name=job["group"])).shortcut(raw)
        simplify_s = time.perf_counter() - mark
        timing_s = _toppra(scene, path, job["group"])
        runs.append({**run, "ok": True, "search_s": plan_s, "simplify_s": simplify_s,
                     "whole_call_s": set_up_s + plan_s + simplify_s + (timing_s or 0.0), "timed": timing_s is not None,
                     "joints": list(path.joint_names), "path": np.asarray(path.positions).tolist()})
    json.dump(runs, sys.stdout)


def _toppra(scene: Any, path: Any, group: str) -> float | None:
    """Return the seconds roboplan's TOPP-RA takes to time `path`, or None when it cannot."""
    try:
        import roboplan.toppra as toppra

        mark = time.perf_counter()
        toppra.PathParameterizerTOPPRA(scene, group).generate(path, 0.01)
        return time.perf_counter() - mark
    except Exception:  # noqa: BLE001 - reported as an untimed whole call
        return None


def _job(problems: list[Any], seed: int, args: argparse.Namespace) -> dict[str, Any]:
    """Return the worker's input: the problems as plain data."""
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
        joints = sorted(p.start)
        joints = [j for j in joints if j in p.goal]
        out.append({"name": p.name, "joints": joints, "start": [p.start[j] for j in joints],
                    "goal": [p.goal[j] for j in joints],
                    "objects": objects, "allowed": [sorted(pair) for pair in p.allowed]})
    return {"robot": str(args.mbm / "panda_robot"), "group": "panda_arm", "seed": seed,
            "time_limit_s": args.time_limit, "problems": out}


def main() -> None:
    """Plan the problems with both tools, seed by seed in turn, and print the table (or --json)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--roboplan-python", type=Path, help="python of the virtual environment holding roboplan")
    parser.add_argument("--mbm", type=Path, default=MBM, help="folder holding problems/ and panda_robot/")
    parser.add_argument("--count", type=int, default=10, help="first N problems of each scenario")
    parser.add_argument("--seeds", type=int, default=1, help="seeds 0..S-1 per problem")
    parser.add_argument("--time-limit", type=float, default=10.0, help="planning time limit per problem [s]")
    parser.add_argument("--step-mm", type=float, default=5.0, help="validity check: robot motion between states")
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of the table")
    args = parser.parse_args()
    if args.worker:
        worker()
        return
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import pyroboplan_compare as shared  # problems, validity check and summary, shared with that comparison

    from moveplan.core.collision.certify import reach
    from moveplan.core.collision.checker import CollisionChecker
    from moveplan.core.config.robot_config import load_robot_config
    from moveplan.core.model.robot import Robot

    if args.roboplan_python is None or not args.roboplan_python.exists():
        sys.exit("roboplan_compare: --roboplan-python must name the python of a venv with roboplan "
                 "(pip install roboplan==0.7.0 there; see benchmarks/README.md)")
    problems = shared.load_problems(args.mbm / "problems", args.count)
    robot = Robot(load_robot_config(args.mbm / "panda_robot"), shared.GROUP)
    checks = {}
    runs: dict[str, list[dict[str, Any]]] = {"roboplan": [], "moveplan": []}
    for seed in range(args.seeds):
        command = shared.moveplan_command(args.mbm, args.count, 1, args.time_limit)
        command[command.index("--seeds") + 1] = str(seed)
        mine, note = shared.run_moveplan(command, {(p.name, seed) for p in problems})
        print(note, file=sys.stderr)
        runs["moveplan"] += mine
        result = subprocess.run([str(args.roboplan_python), __file__, "--worker"], input=json.dumps(_job(
            problems, seed, args)), capture_output=True, text=True)
        if result.returncode != 0:
            reason = (result.stderr.strip().splitlines() or ["?"])[-1]
            sys.exit(f"roboplan_compare: roboplan could not plan these problems (exit {result.returncode}): {reason}")
        for run, problem in zip(json.loads(result.stdout), problems, strict=True):
            if run["ok"]:
                if problem.name not in checks:
                    checker = CollisionChecker(robot, tuple(o for _, o in problem.objects), str(problem.scene), "exact")
                    checks[problem.name] = (checker, reach(robot, checker.geometry))
                checker, reach_m = checks[problem.name]
                index = [run["joints"].index(j) for j in robot.joint_names]
                q = [robot.configuration(np.asarray(row)[index]) for row in run.pop("path")]
                run["exact_valid"] = shared.exact_valid(checker, reach_m, q, args.step_mm / 1e3)
                run["path_length"] = None
            runs["roboplan"].append(run)
    errors = {r.get("error") for r in runs["roboplan"] if not r["ok"]}
    if runs["roboplan"] and not any(r["ok"] for r in runs["roboplan"]):
        print(f"roboplan_compare: roboplan solved none of the problems: {'; '.join(sorted(map(str, errors)))} "
              "(the scene as this script builds it for roboplan is not yet the problem's)", file=sys.stderr)
    rows = []
    for scenario in (*shared.SCENARIOS, "overall"):
        row: dict[str, Any] = {"scenario": scenario}
        for tool, tool_runs in runs.items():
            chosen = [r for r in tool_runs if scenario == "overall" or r["problem"].startswith(f"{scenario}/")]
            row[tool] = {**shared.summary([{"path_length": None, **r} for r in chosen]),
                         **_whole([r for r in chosen if r["ok"]])}
        rows.append(row)
    if args.json:
        print(json.dumps({"problems": len(problems), "seeds": args.seeds, "summary": rows,
                          "runs": [{"tool": t, **r} for t, rs in runs.items() for r in rs]}, indent=1))
        return
    _print(rows, args)


def _whole(solved: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the median and p95 of the whole call [s] over solved runs."""
    values = [r["whole_call_s"] for r in solved if r.get("whole_call_s") is not None]
    return {"whole_median_s": float(np.median(values)) if values else None,
            "whole_p95_s": float(np.percentile(values, 95)) if values else None}


def _print(rows: list[dict[str, Any]], args: argparse.Namespace) -> None:
    """Print one line per scenario and tool."""
    def ms(seconds: float | None) -> str:
        return "-" if seconds is None else f"{1e3 * seconds:.1f}"

    print(f"MotionBenchMaker, Panda: first {args.count} problems of each scenario x {args.seeds} seed(s), RRTConnect; "
          f"times in ms; valid: exact meshes, <= {args.step_mm:g} mm of motion between states")
    print(f"{'scenario':<23}{'tool':<10}{'ok':>7}{'plan med':>10}{'plan+simpl med':>16}{'p95':>9}"
          f"{'whole med':>11}{'p95':>9}{'valid':>7}")
    for row in rows:
        for tool in ("moveplan", "roboplan"):
            s = row[tool]
            print(f"{row['scenario']:<23}{tool:<10}{s['ok']:>4}/{s['runs']:<2}{ms(s['plan_median_s']):>10}"
                  f"{ms(s['total_median_s']):>16}{ms(s['total_p95_s']):>9}{ms(s['whole_median_s']):>11}"
                  f"{ms(s['whole_p95_s']):>9}{s['valid']:>7}")


if __name__ == "__main__":
    main()
