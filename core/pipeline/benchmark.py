"""Planning benchmarks: many problems, planners and seeds; success, times, path quality, exact validity.

A problem is a MoveIt PlanningScene + MotionPlanRequest pair (`sceneNNNN.yaml`,
`requestNNNN.yaml`, as MotionBenchMaker writes them) or a moveplan task file.
Worker processes take (planner, seed, problem) runs from one queue; every run is seeded
anew, so a problem and seed give the same path here as with `moveplan plan`, whichever
process ran it. A benchmark split into shards (`shard`) on several machines is put back
together by `read_runs` from the shards' CSV files.
"""

from __future__ import annotations

import csv
import functools
import io
import logging
import re
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..bag import atomic_file
from ..errors import ConfigError, InputError, NoPlan, UsageError
from ._engines import spread
from .request import RobotSource

__all__ = [
    "STAGES", "ProblemFiles", "Run", "Solver", "find_problems", "plot_benchmark", "read_runs", "run_benchmark",
    "shard", "summarize", "write_benchmark_html", "write_csv",
]

logger = logging.getLogger(__name__)

_PAIR = re.compile(r"scene(\w*)\.ya?ml$")
# What a step's time is spent on, and their sum; the steps' whole wall time, IK included; and the
# whole call, set-up to written file.
STAGES = ("search", "simplify", "certify", "timing", "total", "planning_time", "whole_call")


@dataclass(frozen=True)
class ProblemFiles:
    """One planning problem: a scene + request pair, or a task file (`request` is then None)."""

    name: str
    scenario: str
    scene: Path | None
    request: Path | None
    task: Path | None = None


@dataclass(frozen=True)
class Run:
    """The outcome of one problem, planner and seed; times in [s], path length in [rad].

    `total_s` is search + simplification + certification + time parameterisation;
    `planning_time_s` is the steps' wall time from goal to certified trajectory (IK included).
    `whole_call_s` is what one `moveplan plan` of the problem costs once the robot config is
    loaded (a process loads it once): request and scene read, collision checks set up, every
    step planned and timed, /tf samples computed and the plan file written; the benchmark's own
    exact-mesh re-check is left out.
    """

    problem: str
    scenario: str
    planner: str
    seed: int
    ok: bool
    search_s: float = float("nan")
    simplify_s: float = float("nan")
    certify_s: float = float("nan")
    timing_s: float = float("nan")
    total_s: float = float("nan")
    planning_time_s: float = float("nan")
    whole_call_s: float = float("nan")
    checks: int = 0
    path_length: float = float("nan")
    duration_s: float = float("nan")
    exact_valid: bool | None = None
    error: str | None = None

    def as_dict(self) -> dict[str, Any]:
        """Return the run as a JSON-ready dict (NaN as None)."""
        return {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in asdict(self).items()}


def _folders(root: Path) -> list[Path]:
    """Return `root` and every folder below it, symbolic links followed, each real folder once."""
    # rglob skips linked folders; a dataset is often a folder of links to scenarios kept elsewhere.
    found, seen, stack = [], set(), [root]
    while stack:
        folder = stack.pop()
        real = folder.resolve()
        if real in seen:  # a link back up the tree, or two links to one folder
            continue
        seen.add(real)
        found.append(folder)
        try:
            children = sorted((child for child in folder.iterdir() if child.is_dir()), reverse=True)
        except PermissionError:  # as rglob: a folder that cannot be listed holds no problems
            continue
        stack.extend(children)  # popped in name order: of two links to one folder, the first name counts
    return found


def find_problems(paths: Sequence[Path], count: int | None = None) -> tuple[ProblemFiles, ...]:
    """Return the problems in `paths`: folders of scene/request pairs (searched recursively) or task files.

    `count` keeps the first problems of each folder.
    """
    problems: list[ProblemFiles] = []
    for path in paths:
        if path.is_file():
            problems.append(ProblemFiles(path.stem, path.parent.name, None, None, task=path))
            continue
        if not path.is_dir():
            raise ConfigError(f"{path}: no such problem folder or task file")
        scenes_in = {folder: [(scene, match) for scene in sorted(folder.glob("scene*.y*ml"))
                              if (match := _PAIR.search(scene.name))] for folder in _folders(path)}
        folders = sorted(folder for folder, scenes in scenes_in.items() if scenes)
        if not folders:
            raise ConfigError(f"{path}: no sceneNNNN.yaml / requestNNNN.yaml pairs found")
        for folder in folders:
            found = []
            for scene, match in scenes_in[folder]:
                request = folder / f"request{match.group(1)}{scene.suffix}"
                if not request.is_file():
                    raise ConfigError(f"{scene}: no matching {request.name} beside it")
                found.append(ProblemFiles(f"{folder.name}/{match.group(1)}", folder.name, scene, request))
            problems.extend(found[:count] if count else found)
    if not problems:
        raise UsageError("no problems to run")
    return tuple(problems)


def shard(problems: Sequence[ProblemFiles], index: int, count: int) -> tuple[ProblemFiles, ...]:
    """Return shard `index` of `count` (1-based): every count-th problem from the index-th, so shards balance.

    Raises:
        UsageError: `index` is not in 1..count, or the shard holds no problem.
    """
    if not 1 <= index <= count:
        raise UsageError(f"--shard {index}/{count}: expected K/N with 1 <= K <= N")
    chosen = tuple(problems[index - 1 :: count])
    if not chosen:
        raise UsageError(f"--shard {index}/{count}: no problem falls in this shard ({len(problems)} problems)")
    return chosen


def run_benchmark(
    robot: Path | RobotSource,
    problems: Sequence[ProblemFiles],
    planners: Sequence[str],
    seeds: Sequence[int],
    planning_time: float,
    jobs: int | None = None,
    on_run: Callable[[Run], None] | None = None,
    timeout: float | None = None,
    exact_check: bool = True,
    engine: str = "local",
    ray_address: str | None = None,
) -> list[Run]:
    """Return every run of every problem with every planner and seed, in a stable order.

    `jobs` worker processes (engine "local") or Ray actors (engine "ray", on the cluster at
    `ray_address` or RAY_ADDRESS; `jobs` None: one per CPU) take (planner, seed, problem) runs
    from one queue, so a single planner and seed spread over the cores too; every run is
    seeded anew, so which worker ran it changes nothing but its times. `on_run` is called in
    this process as each run completes (for a progress bar). `planning_time` is each search's
    budget of work; `timeout` its wall-clock safety limit (None: the default for the budget).
    Without `exact_check`, the independent mesh re-check of each plan is skipped (exact_valid None).
    """
    work = [(planner, seed, index) for planner in planners for seed in seeds for index in range(len(problems))]
    order = {p.name: i for i, p in enumerate(problems)}
    runs: list[Run] = []

    def arrived(run: Run) -> None:
        runs.append(run)
        if on_run is not None:
            on_run(run)

    spread(functools.partial(Solver, robot, tuple(problems), (planning_time, timeout), exact_check), work, jobs,
           engine, ray_address, arrived)
    return sorted(runs, key=lambda r: (list(planners).index(r.planner), r.seed, order[r.problem]))


class Solver:
    """A benchmark worker: the robot config loaded once, then (planner, seed, problem index) runs solved in turn."""

    def __init__(self, robot: Path | RobotSource, problems: tuple[ProblemFiles, ...],
                 budget: tuple[float, float | None], exact_check: bool) -> None:
        """Load the robot config; the problems are solved later, by index."""
        from ..config import load_robot_config

        self._config = robot.load() if isinstance(robot, RobotSource) else load_robot_config(robot)
        self._problems, self._budget, self._exact = problems, budget, exact_check
        self._folder = tempfile.TemporaryDirectory(prefix="moveplan-benchmark-")
        self._warm = False

    def run(self, task: tuple[str, int, int]) -> Run:
        """Return the run of one (planner, seed, problem index)."""
        planner, seed, index = task
        output = Path(self._folder.name) / "plan.mcap"
        if not self._warm:
            # Once untimed: the process's one-time set-up (numba's kernels, the sphere models) is
            # no part of any call, as the config's loading is not.
            _solve(self._problems[0], self._config, planner, seed, self._budget, self._exact, output)
            self._warm = True
        return _solve(self._problems[index], self._config, planner, seed, self._budget, self._exact, output)


def _solve(problem: ProblemFiles, config: Any, planner: str, seed: int, budget: tuple[float, float | None],
           exact_check: bool, output: Path) -> Run:
    """Return the run of one problem, its plan written to `output`; no plan is a failed run, bad input an error.

    `budget` is the search's planning time and wall-clock timeout.
    """
    from ..bag import write_plan
    from ..config import MotionSettings, load_task
    from . import plan as pipeline

    began = time.perf_counter()
    flags = pipeline.PlanFlags(robot=config.root, scene=problem.scene, request=problem.request,
                               motion=MotionSettings(planner=planner, planning_time=budget[0]), timeout=budget[1],
                               seed=seed)
    request = pipeline.resolve_request(load_task(problem.task) if problem.task else None, flags)
    where: dict[str, Any] = {"problem": problem.name, "scenario": problem.scenario, "planner": planner, "seed": seed}
    try:
        plan, planned_in = pipeline.planned(request, config=config)
    except NoPlan as exc:
        return Run(**where, ok=False, error=str(exc))
    write_plan(output, plan)
    whole_call_s = time.perf_counter() - began
    # After the call, not inside it: its mesh checks leave the caches cold, which made the writing it preceded
    # 0.3-0.4 ms slower (and the whole call ~1 ms), a cost no plan without a referee pays.
    exact = pipeline.exact_valid(plan, planned_in) if exact_check else None
    steps = [step.stats for step in plan.steps]

    def total(key: str) -> float:
        return float(sum(s.get(key, 0.0) for s in steps))

    stages: dict[str, Any] = {"search_s": total("plan_s"), "simplify_s": total("simplify_s"),
                              "certify_s": total("certify_s"), "timing_s": total("timing_s")}
    return Run(
        **where, ok=True, **stages, total_s=sum(stages.values()),
        planning_time_s=sum(s.planning_time_s for s in plan.steps), whole_call_s=whole_call_s,
        checks=int(total("checks")),
        path_length=total("path_length"), duration_s=sum(s.trajectory.duration_s for s in plan.steps),
        exact_valid=exact,
    )


def summarize(runs: Iterable[Run]) -> list[dict[str, Any]]:
    """Return one row per (scenario, planner) and one per planner over all scenarios, with the statistics."""
    runs = list(runs)
    groups: dict[tuple[str, str], list[Run]] = {}
    for run in runs:
        groups.setdefault((run.scenario, run.planner), []).append(run)
        groups.setdefault(("all", run.planner), []).append(run)
    rows = []
    for (scenario, planner), members in groups.items():
        ok = [r for r in members if r.ok]

        def stat(field: str, q: float, ok: list[Run] = ok) -> float | None:
            values = [getattr(r, field) for r in ok]
            return float(np.percentile(values, q)) if values else None

        row: dict[str, Any] = {
            "scenario": scenario, "planner": planner, "runs": len(members), "succeeded": len(ok),
            "success_rate": len(ok) / len(members)}
        for stage in STAGES:
            row[f"{stage}_median_s"], row[f"{stage}_p95_s"] = stat(f"{stage}_s", 50), stat(f"{stage}_s", 95)
        rows.append({
            **row,
            "path_length_median": stat("path_length", 50), "duration_median_s": stat("duration_s", 50),
            # None where no run was re-checked (benchmark --no-exact-check).
            "exact_valid": sum(1 for r in ok if r.exact_valid) if any(r.exact_valid is not None for r in ok) else None,
        })
    return rows


def read_runs(paths: Sequence[Path]) -> list[Run]:
    """Return the runs of benchmark CSV files (each one shard's `--csv`), in file order.

    Raises:
        InputError: A file is missing, not a benchmark CSV (its header), holds a malformed
            value, or repeats a run (problem, planner, seed) another row or file holds; the
            message names the file and row.
    """
    fields = Run.__dataclass_fields__
    runs: list[Run] = []
    seen: dict[tuple[str, str, int], str] = {}
    for path in paths:
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
        reader = csv.DictReader(io.StringIO(text, newline=""))
        if reader.fieldnames is None or set(reader.fieldnames) != set(fields):
            raise InputError(f"{path}: not a benchmark CSV (expected the columns {', '.join(fields)})")
        for number, row in enumerate(reader, start=2):
            where = f"{path}: row {number}"
            try:
                run = Run(**{name: _cell(row[name], fields[name].type) for name in fields})
            except (ValueError, TypeError) as exc:
                raise InputError(f"{where}: {exc}") from None
            key = (run.problem, run.planner, run.seed)
            if key in seen:
                raise InputError(f"{where}: problem {run.problem}, planner {run.planner}, seed {run.seed} "
                                 f"is also in {seen[key]}: shards overlap")
            seen[key] = where
            runs.append(run)
    return runs


def _cell(text: str | None, kind: Any) -> Any:
    """Return a CSV cell as the Run field of type `kind` (written by write_csv: empty for None)."""
    if text is None:
        raise ValueError("a cell is missing")
    kind = str(kind)
    if kind == "str":
        return text
    if kind == "str | None":
        return text or None
    if kind == "int":
        return int(text)
    if kind in ("bool", "bool | None"):
        if text == "" and kind == "bool | None":
            return None
        if text not in ("True", "False"):
            raise ValueError(f"expected True or False, got {text!r}")
        return text == "True"
    return float(text) if text else float("nan")


def write_csv(runs: Iterable[Run], path: Path) -> None:
    """Write one CSV row per run to `path` (through a temporary file, so a failure leaves none).

    Raises:
        UsageError: `path` cannot be an output file (a directory, a symbolic link, a device).
        InputError: `path` cannot be written.

    """
    fields = list(Run.__dataclass_fields__)
    with atomic_file(path) as stream:
        text = io.TextIOWrapper(stream, encoding="utf-8", newline="")
        writer = csv.DictWriter(text, fieldnames=fields)
        writer.writeheader()
        for run in runs:
            writer.writerow(run.as_dict())
        text.flush()
        text.detach()  # the stream is atomic_file's to close


def write_benchmark_html(path: Path, runs: Sequence[Run], rows: Sequence[dict[str, Any]]) -> None:
    """Write a benchmark's HTML report: per planner and scenario the summary, a row per run opening its times."""
    from .html_report import write_html

    def ms(value: float) -> float | None:
        return None if value != value else round(1e3 * value, 4)

    overall = [r for r in rows if r["scenario"] == "all"]
    summary = [("runs", str(len(runs)))] + [
        (f"{r['planner']}", f"{r['succeeded']}/{r['runs']} solved, total median "
                            f"{1e3 * (r['total_median_s'] or 0):.3g} ms, exact-valid {r['exact_valid']}")
        for r in overall]
    columns = ["problem", "scenario", "planner", "seed", "solved", "search [ms]", "total [ms]", "whole call [ms]",
               "path [rad]", "duration [s]", "exact-valid", "error"]
    table = [[r.problem, r.scenario, r.planner, r.seed, str(r.ok), ms(r.search_s), ms(r.total_s), ms(r.whole_call_s),
              None if r.path_length != r.path_length else r.path_length,
              None if r.duration_s != r.duration_s else r.duration_s,
              "" if r.exact_valid is None else str(r.exact_valid), r.error or ""] for r in runs]
    details: list[dict[str, Any] | None] = [
        {"bars": [[stage, ms(getattr(r, f"{stage}_s")), "ms"] for stage in STAGES]} if r.ok else None for r in runs]
    write_html(path, "moveplan benchmark", summary, columns, table, details, 4)


def plot_benchmark(runs: Iterable[Run], path: Path) -> None:
    """Write a PNG of the distributions of search and total times, one panel per scenario (as `write_csv`)."""
    import matplotlib

    matplotlib.use("Agg")  # files only; never a window
    from matplotlib import pyplot

    runs = list(runs)
    scenarios = sorted({r.scenario for r in runs})
    planners = list(dict.fromkeys(r.planner for r in runs))
    figure, axes = pyplot.subplots(1, len(scenarios), figsize=(5 * len(scenarios), 4), squeeze=False)
    for axis, scenario in zip(axes[0], scenarios, strict=True):
        for index, planner in enumerate(planners):
            ok = [r for r in runs if r.scenario == scenario and r.planner == planner and r.ok]
            total = len([r for r in runs if r.scenario == scenario and r.planner == planner])
            color = f"C{index}"
            for field, style in (("search_s", "--"), ("total_s", "-")):
                values = np.sort([getattr(r, field) * 1e3 for r in ok])
                if len(values):
                    # A cumulative distribution over all runs: a failed run never reaches the top.
                    axis.step(values, np.arange(1, len(values) + 1) / total, style, color=color, where="post",
                              label=f"{planner} {'search' if field == 'search_s' else 'total'}")
        axis.set_xscale("log")
        axis.set_ylim(0.0, 1.02)
        axis.set_xlabel("time [ms]")
        axis.set_ylabel("fraction of runs solved")
        axis.set_title(scenario)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize="small", loc="lower right")
    figure.tight_layout()
    try:
        with atomic_file(path) as stream:
            figure.savefig(stream, format="png", dpi=100)
    finally:
        pyplot.close(figure)
