"""MotionBenchMaker problems planned by VAMP (C++ SIMD, PyPI `vamp-planner`) and by `moveplan benchmark`, interleaved.

VAMP is a benchmark-only tool in a virtual environment of its own (see benchmarks/README.md):
    python benchmarks/vamp_compare.py --vamp-python /tmp/vamp/bin/python [--count 10] [--seeds 1]
        [--mbm /work/shared/benchmarks/mbm] [--json]

Per seed, in turn (so that both see the same machine): `moveplan benchmark --json` on the
problems, then a VAMP worker (this script under `--vamp-python`, `--worker`) on the same problems.
VAMP plans as its own MotionBenchMaker evaluation (scripts/evaluate_mbm.py) does: its Panda
(compiled-in sphere model and joint bounds), RRT-Connect with its default settings and the
Panda's range, the Halton sampler reset per problem and moved on by 10,000 samples a seed, then
its `simplify` with default settings. Its scene is the problem's as VAMP's own converter builds
it (`problem_dict_to_vamp`): boxes as cuboids, cylinders as capsules, but in the box scenario,
whose grasp comes down onto a cylinder, as cuboids. VAMP has no time parameterisation or output
file; its whole call here is environment set-up, plan and simplify.

Times are taken in Python around each call (VAMP "called from Python"); VAMP's own clock for the
search is in --json (`search_own_s`). The table's columns and the validity check (every returned
path re-checked on the exact meshes with moveplan's checker, at most `--step-mm` of robot motion
between states) are roboplan_compare.py's.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import roboplan_compare as common  # noqa: E402  (the comparison's loop, checks and table)

SEED_SKIP = 10_000


def worker() -> None:
    """Plan the problems on stdin (JSON) with VAMP; print one JSON run per problem (runs in VAMP's venv)."""
    import vamp

    job = json.load(sys.stdin)
    panda = vamp.panda
    settings = vamp.RRTCSettings()
    settings.range = vamp.ROBOT_RRT_RANGES["panda"]
    settings.max_iterations = settings.max_samples = vamp.DEFAULT_ITERATIONS
    simplifying = vamp.SimplifySettings()
    sampler = panda.halton()
    runs = []
    for problem in job["problems"]:
        began = time.perf_counter()
        environment = _environment(vamp, problem)
        set_up_s = time.perf_counter() - began
        sampler.reset()
        sampler.skip(SEED_SKIP * job["seed"])
        runs.append(_plan(panda, environment, settings, simplifying, sampler, problem, job, set_up_s))
    json.dump(runs, sys.stdout)


def _environment(vamp: Any, problem: dict[str, Any]) -> Any:
    """Return VAMP's Environment of the problem's objects, as VAMP's problem_dict_to_vamp builds one."""
    from vamp.transformations import euler_from_matrix

    environment = vamp.Environment()
    as_boxes = problem["name"].startswith("box_")  # VAMP's converter: the box scenario's cylinders as cuboids
    for obj in problem["objects"]:
        transform, shape = np.asarray(obj["transform"]), obj["shape"]
        centre = transform[:3, 3]
        euler = list(euler_from_matrix(transform))
        if shape["kind"] == "box":
            environment.add_cuboid(vamp.Cuboid(centre.tolist(), euler, [d / 2 for d in shape["size"]]))
        elif as_boxes:
            radius = shape["radius"]
            environment.add_cuboid(vamp.Cuboid(centre.tolist(), euler, [radius, radius, shape["length"] / 2]))
        else:  # as VAMP's converter: the MoveIt pose as it is (0.6.4's constructor from endpoints crashes)
            environment.add_capsule(vamp.Cylinder(centre.tolist(), euler, shape["radius"], shape["length"]))
    return environment


def _plan(panda: Any, environment: Any, settings: Any, simplifying: Any, sampler: Any, problem: dict[str, Any],
          job: dict[str, Any], set_up_s: float) -> dict[str, Any]:
    """Return one run: VAMP's RRT-Connect and its simplification on the problem, timed from Python."""
    names = list(panda.joint_names())
    order = [problem["joints"].index(name) for name in names]
    start = np.asarray(problem["start"], dtype=np.float32)[order]
    goal = np.asarray(problem["goal"], dtype=np.float32)[order]
    run: dict[str, Any] = {
        "problem": problem["name"], "planner": "VAMP RRTConnect", "seed": job["seed"],
        "start_free": bool(panda.validate(start, environment)), "goal_free": bool(panda.validate(goal, environment)),
    }
    began = time.perf_counter()
    result = panda.rrtc(start, goal, environment, settings, sampler)
    plan_s = time.perf_counter() - began
    if not result.solved:
        return {**run, "ok": False, "error": f"no path in {result.iterations} iterations"}
    began = time.perf_counter()
    simple = panda.simplify(result.path, environment, simplifying, sampler)
    simplify_s = time.perf_counter() - began
    return {**run, "ok": True, "search_s": plan_s, "simplify_s": simplify_s, "search_own_s": result.nanoseconds / 1e9,
            "whole_call_s": set_up_s + plan_s + simplify_s, "joints": names,
            "path": simple.path.numpy().astype(float).tolist(), "raw_path": result.path.numpy().astype(float).tolist()}


def _check_python(python: Path | None) -> None:
    """Exit with one line unless `python` runs and imports VAMP with its Panda."""
    if python is None or not python.is_file() or subprocess.run(
            [str(python), "-c", "import vamp; vamp.panda.rrtc"], capture_output=True).returncode != 0:
        sys.exit(f"vamp_compare: --vamp-python {python or '(missing)'}: not a python with VAMP's Panda "
                 "(python3.11 -m venv VENV && VENV/bin/pip install vamp-planner==0.6.4; see benchmarks/README.md)")


def main() -> None:
    """Plan the problems with both tools, seed by seed in turn, and print the table (or --json)."""
    args = common.arguments(__doc__, "vamp").parse_args()
    if args.worker:
        worker()
        return
    _check_python(args.vamp_python)
    common.compare(args, "vamp", args.vamp_python, __file__, common.job_of)


if __name__ == "__main__":
    main()
