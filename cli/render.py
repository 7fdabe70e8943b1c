"""Render results: rich tables for people (on stderr when --json is not given), JSON for scripts."""

from __future__ import annotations

import json
import logging
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from moveplan.core.trajectory import peak_rates

if TYPE_CHECKING:  # each command imports only the core modules it runs
    from moveplan.core.bag.recording import BagSummary, PlanFile
    from moveplan.core.config.robot_config import RobotConfig
    from moveplan.core.control.checking import CheckReport
    from moveplan.core.pipeline.benchmark import Run
    from moveplan.core.pipeline.execute import PlanExecution
    from moveplan.core.types import Plan

__all__ = [
    "benchmark_progress", "benchmark_summary", "check_summary", "execution_summary", "inspect_summary", "plan_summary",
    "robot_summary",
]

_console = Console()
logger = logging.getLogger("moveplan")


def _emit(document: dict[str, Any]) -> None:
    print(json.dumps(document, indent=2))


def plan_summary(plan: Plan, output: Path, as_json: bool, quiet: bool) -> None:
    """Print what was planned: one row per step, or the plan JSON document."""
    steps = [
        {
            "name": s.name, "status": "ok", "goal": s.goal, "planner": s.planner,
            "planning_time_s": round(s.planning_time_s, 6), "duration_s": round(s.trajectory.duration_s, 6),
            "fraction": s.fraction, "residual": s.residual, "points": len(s.trajectory.times_s),
        }
        for s in plan.steps
    ]
    if as_json:
        _emit({"ok": True, "output": str(output), "robot": plan.robot_name, "group": plan.group,
               "steps": steps, "error": None})
        return
    if quiet:
        return
    table = Table(title=f"{plan.robot_name} / {plan.group} -> {output}")
    for column in ("step", "goal", "planner", "planning [ms]", "duration [s]", "points"):
        table.add_column(column)
    for s in steps:
        table.add_row(s["name"], _short(s["goal"]), s["planner"], f"{1e3 * s['planning_time_s']:.1f}",
                      f"{s['duration_s']:.3f}", str(s["points"]))
    _console.print(table)


def _short(goal: dict[str, Any]) -> str:
    text = json.dumps(goal, separators=(",", ":"))
    return text if len(text) <= 60 else text[:57] + "..."


def robot_summary(config: RobotConfig, as_json: bool, quiet: bool) -> None:
    """Print a robot config: groups, joints with limits and sources, named states, frames, controllers."""
    links = sorted({j.parent for j in config.urdf_joints.values()} | {j.child for j in config.urdf_joints.values()})
    document = {
        "name": config.name,
        "groups": {n: {"joints": list(g.joints), "base": g.base, "tip": g.tip} for n, g in config.srdf.groups.items()},
        "joints": {
            n: {"lower": lim.lower, "upper": lim.upper, "max_velocity": lim.max_velocity,
                "max_acceleration": None if np.isnan(lim.max_acceleration) else lim.max_acceleration,
                "continuous": lim.continuous, "source": lim.source}
            for n, lim in config.limits.items()
        },
        "named_states": {
            group: {name: [values.get(j) for j in config.srdf.groups[group].joints] for name, values in states.items()}
            for group, states in config.srdf.group_states.items()
        },
        "frames": links,
        "default_scaling": {"velocity": config.default_velocity_scaling,
                            "acceleration": config.default_acceleration_scaling},
        "controllers": {
            n: {"joints": list(c.joints), "update_rate": c.update_rate_hz,
                "command_interfaces": list(c.command_interfaces), "state_interfaces": list(c.state_interfaces),
                "constraints": {"goal_time": c.goal_time_s, "stopped_velocity_tolerance": c.stopped_velocity_tolerance,
                                **{j: {"trajectory": c.trajectory_tolerance[j], "goal": c.goal_tolerance[j]}
                                   for j in c.joints}}}
            for n, c in config.controllers.items()
        },
        "initial_positions": config.initial_positions,
        "sources": {k: str(v) for k, v in config.sources.items()},
        "kinematics": config.kinematics,
        "xacro_args": config.xacro_args,
        "missing_acceleration": list(config.missing_acceleration_limits()),
    }
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    _console.print(f"[bold]{config.name}[/bold]  ({config.root})")
    for name, group in config.srdf.groups.items():
        _console.print(f"group [bold]{name}[/bold]: {group.base} -> {group.tip}, joints {', '.join(group.joints)}")
    joints = Table(title="joints")
    for column in ("joint", "lower", "upper", "max vel", "max acc", "position from", "velocity from", "accel from"):
        joints.add_column(column)
    for name, lim in config.limits.items():
        joints.add_row(name, f"{lim.lower:.4g}", f"{lim.upper:.4g}", f"{lim.max_velocity:.4g}",
                       f"{lim.max_acceleration:.4g}", lim.source["position"], lim.source["velocity"],
                       lim.source["acceleration"] or "[red]missing[/red]")
    _console.print(joints)
    for group, states in document["named_states"].items():
        for name, values in states.items():
            _console.print(f"named state {group}/{name}: {values}")
    for name, controller in document["controllers"].items():
        _console.print(f"controller {name} @ {controller['update_rate']:g} Hz: {controller['constraints']}")
    _console.print(f"frames: {', '.join(links)}")
    for setting, source in document["sources"].items():
        _console.print(f"{setting} from {source}")
    if document["missing_acceleration"]:
        _console.print(f"[red]no acceleration limit[/red] for {', '.join(document['missing_acceleration'])}")


def inspect_summary(path: Path, summary: BagSummary, plan: PlanFile | None, as_json: bool, quiet: bool) -> None:
    """Print topics of any bag, and for a plan file each step's duration and peak rates."""
    steps = []
    if plan is not None:
        for step in plan.steps:
            peak_v, peak_a = peak_rates(step.trajectory)
            names = step.trajectory.joint_names
            v_limit = np.array([plan.limits[j]["max_velocity"] for j in names])
            a_limit = np.array([plan.limits[j]["max_acceleration"] for j in names])
            steps.append({
                "name": step.name, "start_s": step.start_s, "duration_s": step.trajectory.duration_s,
                "points": len(step.trajectory.times_s),
                "peak_velocity_fraction": float(np.max(peak_v / v_limit)),
                "peak_acceleration_fraction": float(np.max(peak_a / a_limit)),
            })
    document = {
        "file": str(path), "profile": summary.profile, "library": summary.library,
        "duration_s": summary.duration_s,
        "topics": [{"topic": t.topic, "type": t.type, "encoding": t.encoding, "count": t.count,
                    "durability": t.qos_durability} for t in summary.topics],
        "metadata": list(summary.metadata), "attachments": list(summary.attachments),
        "plan": None if plan is None else {"robot": plan.robot_name, "group": plan.group, "steps": steps},
    }
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    topics = Table(title=f"{path}  ({summary.profile}, {summary.duration_s:.3f} s)")
    for column in ("topic", "type", "count", "durability"):
        topics.add_column(column)
    for t in summary.topics:
        topics.add_row(t.topic, t.type, str(t.count), t.qos_durability)
    _console.print(topics)
    if steps:
        table = Table(title=f"plan: {plan.robot_name if plan else ''}")
        for column in ("step", "start [s]", "duration [s]", "points", "peak vel / limit", "peak acc / limit"):
            table.add_column(column)
        for s in steps:
            table.add_row(s["name"], f"{s['start_s']:.3f}", f"{s['duration_s']:.3f}", str(s["points"]),
                          f"{s['peak_velocity_fraction']:.2f}", f"{s['peak_acceleration_fraction']:.2f}")
        _console.print(table)


def _result(result: Any) -> dict[str, Any]:
    return {"code": result.code, "name": result.name, "message": result.message}


def _violations(violations: Any) -> list[dict[str, Any]]:
    return [{"check": v.check, "joint": v.joint, "time_s": v.time_s, "reference": v.reference, "actual": v.actual,
             "error": v.error, "tolerance": v.tolerance, "step": step} for step, v in violations]


def execution_document(outcome: PlanExecution) -> dict[str, Any]:
    """Return the execute JSON document of an execution."""
    return {
        "ok": outcome.ok,
        "result": _result(outcome.result),
        "violations": _violations(outcome.violations),
        "margins": outcome.margins,
        "duration_s": outcome.duration_s,
        "controller": outcome.controller.name,
        "steps": [{"name": s.name, "ok": s.report.ok, "result": s.report.result.name,
                   "duration_s": s.report.duration_s} for s in outcome.steps],
    }


def execution_summary(outcome: PlanExecution, output: Path | None, as_json: bool, quiet: bool) -> None:
    """Print the result, every violation and the per-joint margins, or the JSON document."""
    document = execution_document(outcome)
    if output is not None:
        document["output"] = str(output)
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    _verdict(document, f"smallest margin to tolerance ({outcome.controller.name})")
    _console.print(f"executed {len(outcome.steps)} of {len(outcome.plan.steps)} steps in {outcome.duration_s:.3f} s")


def check_summary(report: CheckReport, recording: Path, as_json: bool, quiet: bool) -> None:
    """Print the verdict on a recording (per cycle with --start all), or its JSON document.

    "ok" of a step or cycle is null when the recording cuts it off before a verdict (INCOMPLETE).
    A check with no complete execution is bad input (exit 3): the document says so under "error".
    """
    for warning in report.warnings:
        logger.warning("%s", warning)
    error = None if report.complete else {"exit_code": 3, "kind": "InputError",
                                          "message": f"{recording}: {report.result.message}"}
    document: dict[str, Any] = {
        "ok": report.ok, "result": _result(report.result), "violations": _violations(report.violations),
        "margins": report.margins, "duration_s": report.duration_s, "start_s": report.start_s,
        "steps": [{"name": s.name, "ok": s.ok if s.complete else None, "result": s.report.result.name,
                   "start_s": s.start_s, "duration_s": s.duration_s, "aligned_by": s.aligned_by}
                  for s in report.steps],
        "gaps": [{"start_s": start, "length_s": length} for start, length in report.gaps],
        "warnings": list(report.warnings),
        "error": error,
    }
    if report.cycles:
        document["cycles"] = [{"index": c.index, "start_s": c.start_s, "ok": c.ok if c.complete else None,
                               "result": _result(c.result), "worst_margin": c.worst_margin} for c in report.cycles]
        document["failing_cycles"] = list(report.failing_cycles)
        document["incomplete_cycles"] = list(report.incomplete_cycles)
    if as_json:
        _emit(document)
        return
    if error is not None:
        print(f"moveplan: error: {error['message']}", file=sys.stderr)
    if quiet:
        return
    _verdict(document, "smallest margin to tolerance")
    if report.cycles:
        failing = ", ".join(str(i) for i in report.failing_cycles) or "none"
        incomplete = len(report.incomplete_cycles)
        cut = ", ".join(map(str, report.incomplete_cycles))
        cut = f" (cycle {cut}, cut off by the recording)" if incomplete else ""
        _console.print(f"{len(report.cycles)} executions found; failing: {failing}; incomplete: {incomplete}{cut}")
        for cycle in report.cycles:
            if not cycle.ok:
                _console.print(f"  cycle {cycle.index} at {cycle.start_s:.3f} s: {cycle.result.name}: "
                               f"{cycle.result.message}")


def _verdict(document: dict[str, Any], margins_title: str) -> None:
    """Print a result line, the violations table and the margins table."""
    result = document["result"]
    colour = "green" if document["ok"] else "yellow" if result["name"] == "INCOMPLETE" else "red"
    _console.print(f"[{colour}]{result['name']}[/{colour}] ({result['code']}): {result['message']}")
    if document["violations"]:
        table = Table(title="violations")
        for column in ("step", "check", "joint", "time [s]", "reference", "actual", "error", "tolerance"):
            table.add_column(column)
        for v in document["violations"]:
            table.add_row(v["step"], v["check"], v["joint"], f"{v['time_s']:.3f}", f"{v['reference']:.4f}",
                          f"{v['actual']:.4f}", f"{v['error']:.4f}", f"{v['tolerance']:.4f}")
        _console.print(table)
    if document["margins"]:
        table = Table(title=margins_title)
        table.add_column("joint")
        table.add_column("margin [rad]")
        for joint, margin in document["margins"].items():
            table.add_row(joint, f"[{'red' if margin < 0 else 'green'}]{margin:.4f}[/]")
        _console.print(table)


@contextmanager
def benchmark_progress(total: int, quiet: bool) -> Iterator[Callable[[Run], None]]:
    """Yield a callback that advances a progress bar on stderr by one run (no bar when quiet or not a terminal)."""
    progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                        console=Console(stderr=True), disable=quiet, transient=True)
    with progress:
        task = progress.add_task("planning", total=total)
        failed = 0

        def advance(run: Run) -> None:
            nonlocal failed
            failed += not run.ok
            progress.update(task, advance=1, description=f"planning ({failed} failed)" if failed else "planning")

        yield advance


def benchmark_summary(runs: list[Run], rows: list[dict[str, Any]], as_json: bool, quiet: bool) -> None:
    """Print one row per scenario and planner, or the benchmark JSON document."""
    if as_json:
        _emit({"ok": True, "runs": [r.as_dict() for r in runs], "summary": rows, "error": None})
        return
    if quiet:
        return
    table = Table(title=f"{len(runs)} runs; times in ms (median / p95); total = search + simplify + certify + timing")
    for column in ("scenario", "planner", "solved", "search", "simplify", "certify", "timing", "total",
                   "path [rad]", "duration [s]", "exact-valid"):
        table.add_column(escape(column), justify="left" if column in ("scenario", "planner") else "right")

    def ms(row: dict[str, Any], key: str) -> str:
        median, p95 = row[f"{key}_median_s"], row[f"{key}_p95_s"]
        return "-" if median is None else f"{1e3 * median:.3g} / {1e3 * p95:.3g}"

    def number(value: float | None, digits: int) -> str:
        return "-" if value is None else f"{value:.{digits}f}"

    for row in sorted(rows, key=lambda r: (r["scenario"] == "all", r["scenario"], r["planner"])):
        table.add_row(row["scenario"], row["planner"], f"{row['succeeded']}/{row['runs']}",
                      *(ms(row, stage) for stage in ("search", "simplify", "certify", "timing", "total")),
                      number(row["path_length_median"], 2),
                      number(row["duration_median_s"], 2), f"{row['exact_valid']}/{row['succeeded']}")
    # Piped to a file, rich would fold the table into 80 columns.
    (_console if _console.is_terminal else Console(width=160)).print(table)
