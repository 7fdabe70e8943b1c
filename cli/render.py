"""Render results: rich tables for people (on stderr when --json is not given), JSON for scripts."""

from __future__ import annotations

import json
import logging
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

if TYPE_CHECKING:  # each command imports only the core modules it runs
    from moveplan.core.config.robot_config import RobotConfig
    from moveplan.core.control.check_report import CheckReport
    from moveplan.core.pipeline.benchmark import Run
    from moveplan.core.pipeline.execute import PlanExecution
    from moveplan.core.pipeline.inspection import Inspection
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
        "initial_sources": config.initial_sources,
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
                       lim.source["acceleration"])
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
        from moveplan.core.config.limits import DEFAULT_ACCELERATION

        _console.print(f"[yellow]no acceleration limit in the config[/yellow] for "
                       f"{', '.join(document['missing_acceleration'])}: plans use the default "
                       f"{DEFAULT_ACCELERATION:g} rad/s^2 (m/s^2 for prismatic joints)")


def inspect_summary(inspection: Inspection, as_json: bool, quiet: bool) -> None:
    """Print topics of any bag, and for a plan file each step's duration and peak rates."""
    path, summary, plan = inspection.path, inspection.summary, inspection.plan
    steps = [asdict(step) for step in inspection.steps]
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


def execution_summary(outcome: PlanExecution, output: Path | None, as_json: bool, quiet: bool) -> None:
    """Print the result, every violation and the per-joint margins, or the JSON document."""
    from moveplan.core.pipeline.report import execution_document

    document = execution_document(outcome)
    if output is not None:
        document["output"] = str(output)
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    _verdict(document, f"smallest margin to tolerance ({document['controller']})")
    _console.print(f"executed {len(document['steps'])} of {len(outcome.plan.steps)} steps in "
                   f"{_number(document['duration_s'], '.3f')} s")


def check_summary(report: CheckReport, recording: Path, as_json: bool, quiet: bool) -> None:
    """Print the verdict on a recording (per cycle with --start all), or its JSON document.

    A check with no complete execution is bad input (exit 3): the document says so under "error".
    """
    from moveplan.core.pipeline.report import check_document

    document = check_document(report, recording)
    for warning in document["warnings"]:
        logger.warning("%s", warning)
    if as_json:
        _emit(document)
        return
    if document["error"] is not None:
        print(f"moveplan: error: {document['error']['message']}", file=sys.stderr)
    if quiet:
        return
    _verdict(document, "smallest margin to tolerance")
    if "cycles" in document:
        _cycles(document)


def _cycles(document: dict[str, Any]) -> None:
    """Print how many executions a check found, which failed and which the recording cuts off."""
    failing = ", ".join(str(i) for i in document["failing_cycles"]) or "none"
    incomplete = len(document["incomplete_cycles"])
    cut = ", ".join(map(str, document["incomplete_cycles"]))
    cut = f" (cycle {cut}, cut off by the recording)" if incomplete else ""
    _console.print(f"{len(document['cycles'])} executions found; failing: {failing}; incomplete: {incomplete}{cut}")
    for cycle in document["cycles"]:
        if not cycle["ok"]:
            _console.print(f"  cycle {cycle['index']} at {_number(cycle['start_s'], '.3f')} s: "
                           f"{cycle['result']['name']}: {cycle['result']['message']}")


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
            table.add_row(v["step"], v["check"], v["joint"], _number(v["time_s"], ".3f"),
                          *(_number(v[key], ".4f") for key in ("reference", "actual", "error", "tolerance")))
        _console.print(table)
    if document["margins"]:
        table = Table(title=margins_title)
        table.add_column("joint")
        table.add_column("margin [rad]")
        for joint, margin in document["margins"].items():
            colour = "red" if margin is None or margin < 0 else "green"
            table.add_row(joint, f"[{colour}]{_number(margin, '.4f')}[/]")
        _console.print(table)


def _number(value: float | None, spec: str) -> str:
    """Return a document's number formatted, or "inf/nan" for its null: not finite (a diverged plant)."""
    return "inf/nan" if value is None else format(value, spec)


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
    table = Table(title=f"{len(runs)} runs; times in ms (median / p95); total = search + simplify + certify + timing; "
                        "whole call = set-up to written file, config loaded")
    for column in ("scenario", "planner", "solved", "search", "simplify", "certify", "timing", "total",
                   "whole call", "path [rad]", "duration [s]", "exact-valid"):
        table.add_column(escape(column), justify="left" if column in ("scenario", "planner") else "right")

    def ms(row: dict[str, Any], key: str) -> str:
        median, p95 = row[f"{key}_median_s"], row[f"{key}_p95_s"]
        return "-" if median is None else f"{1e3 * median:.3g} / {1e3 * p95:.3g}"

    def number(value: float | None, digits: int) -> str:
        return "-" if value is None else f"{value:.{digits}f}"

    for row in sorted(rows, key=lambda r: (r["scenario"] == "all", r["scenario"], r["planner"])):
        table.add_row(row["scenario"], row["planner"], f"{row['succeeded']}/{row['runs']}",
                      *(ms(row, stage) for stage in ("search", "simplify", "certify", "timing", "total", "whole_call")),
                      number(row["path_length_median"], 2),
                      number(row["duration_median_s"], 2), f"{row['exact_valid']}/{row['succeeded']}")
    # Piped to a file, rich would fold the table into 80 columns.
    (_console if _console.is_terminal else Console(width=200)).print(table)
