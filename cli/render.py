"""Render results: rich tables for people (on stderr when --json is not given), JSON for scripts."""

from __future__ import annotations

import json
import logging
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from .tables import console as _console
from .tables import emit as _emit
from .tables import escape_controls, is_terminal, show, table
from .tables import number as _number

if TYPE_CHECKING:  # each command imports only the core modules it runs
    from ..core.config import RobotConfig
    from ..core.control import CheckReport
    from ..core.pipeline import Inspection, ItemResult, PlanExecution, PlanResult, Run, StateResult
    from ..core.types import RobotState

__all__ = [
    "PROGRESS_EVERY_S", "benchmark_progress", "benchmark_summary", "check_summary", "execution_summary",
    "fleet_progress", "fleet_report", "inspect_summary", "plan_summary", "robot_summary", "state_summary",
]

logger = logging.getLogger("moveplan")


def plan_summary(plan: PlanResult, output: Path, as_json: bool, quiet: bool) -> None:
    """Print what was planned: one row per step and where each ends, or the plan JSON document."""
    from ..core.pipeline import plan_document

    document = plan_document(plan, output)
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    rows = table(f"{plan.robot_name} / {plan.group} -> {output}",
                 ("step", "goal", "planner", "planning [ms]", "duration [s]", "points"), left=3)
    for s in document["steps"]:
        rows.add_row(s["name"], _short(s["goal"]), s["planner"], f"{1e3 * s['planning_time_s']:.1f}",
                     f"{s['duration_s']:.3f}", str(s["points"]))
    show(rows)
    if plan.end_states:
        _end_poses([s.name for s in plan.steps], plan.end_states)


def _end_poses(names: list[str], states: tuple[RobotState, ...]) -> None:
    """Print one row per step: where its end puts the link its goal moved (the tip's), in the planning frame."""
    pose = states[0].pose
    links = {state.pose.link for state in states}
    if len(links) == 1:
        rows = table(f"end of each step: {pose.link} in {pose.frame}", ("step", "position [m]", "rpy [rad]"))
        for name, state in zip(names, states, strict=True):
            rows.add_row(name, _triple(state.pose.position, ".4f"), _triple(state.pose.rpy, ".4f"))
    else:
        rows = table(f"end of each step, in {pose.frame}", ("step", "link", "position [m]", "rpy [rad]"))
        for name, state in zip(names, states, strict=True):
            rows.add_row(name, state.pose.link, _triple(state.pose.position, ".4f"), _triple(state.pose.rpy, ".4f"))
    show(rows)


def _triple(values: tuple[float, ...], spec: str) -> str:
    """Return values as `[a, b, c]`, each formatted by `spec`."""
    return "[" + ", ".join(_unsigned_zero(format(v, spec)) for v in values) + "]"


def _unsigned_zero(text: str) -> str:
    """Return a formatted number, without the sign of a value that rounds to zero ("-0.0000")."""
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def _short(goal: dict[str, Any]) -> str:
    text = json.dumps(goal, separators=(",", ":"))
    return text if len(text) <= 60 else text[:57] + "..."


def robot_summary(config: RobotConfig, as_json: bool, quiet: bool) -> None:
    """Print a robot config: groups, joints with limits and sources, named states, frames, controllers."""
    from ..core.pipeline import robot_document

    document = robot_document(config)
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    _console.print(f"[bold]{config.name}[/bold]  ({config.root})")
    for name, group in config.srdf.groups.items():
        _console.print(f"group [bold]{name}[/bold]: {group.base} -> {group.tip}, joints {', '.join(group.joints)}")
    joints = table("joints; limits in rad or m, and per s, per s^2", ("joint", "lower", "upper", "max vel", "max acc",
                                                                      "position from", "velocity from", "accel from"))
    for name, lim in config.limits.items():
        joints.add_row(name, f"{lim.lower:.4g}", f"{lim.upper:.4g}", f"{lim.max_velocity:.4g}",
                       f"{lim.max_acceleration:.4g}", lim.source["position"], lim.source["velocity"],
                       lim.source["acceleration"])
    show(joints)
    for group, states in document["named_states"].items():
        for name, values in states.items():
            _console.print(f"named state {group}/{name}: {values}")
    for name, controller in document["controllers"].items():
        _console.print(f"controller {name} @ {controller['update_rate']:g} Hz: {controller['constraints']}")
    _console.print(f"frames: {', '.join(document['frames'])}")
    for setting, source in document["sources"].items():
        _console.print(f"{setting} from {source}")
    if document["missing_acceleration"]:
        from ..core.config import DEFAULT_ACCELERATION

        _console.print(f"[yellow]no acceleration limit in the config[/yellow] for "
                       f"{', '.join(document['missing_acceleration'])}: plans use the default "
                       f"{DEFAULT_ACCELERATION:g} rad/s^2 (m/s^2 for prismatic joints)")


def state_summary(result: StateResult, as_json: bool, quiet: bool) -> None:
    """Print a robot state: a table of joint values, then the link's pose in the frame; or its JSON document."""
    from ..core.pipeline import state_document

    state, pose = result.state, result.state.pose
    if as_json:
        _emit(state_document(result))
        return
    if quiet:
        return
    joints = table(f"{result.robot} / {result.group}: {result.source}", ("joint", "value [rad]", "value [deg]"))
    for name, value in state.joints.items():
        if name in state.prismatic:
            joints.add_row(name, f"{_unsigned_zero(format(value, '.6f'))} m", "-")
        else:
            joints.add_row(name, _unsigned_zero(format(value, ".6f")), _unsigned_zero(format(np.degrees(value), ".4f")))
    show(joints)
    pose_table = table(f"{pose.link} in {pose.frame}", [""] * 5, show_header=False)
    for label, values in (("position [m]", pose.position), ("rpy [rad]", pose.rpy),
                          ("quaternion [x, y, z, w]", pose.quaternion)):
        pose_table.add_row(escape(label), *(_unsigned_zero(format(v, ".6f")) for v in values))
    show(pose_table)


def inspect_summary(inspection: Inspection, as_json: bool, quiet: bool) -> None:
    """Print topics of any bag, and for a plan file each step's duration, peak rates and end state."""
    from ..core.pipeline import inspect_document

    path, summary, plan = inspection.path, inspection.summary, inspection.plan
    document = inspect_document(inspection)
    steps = document["plan"]["steps"] if document["plan"] else []
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    topics = table(f"{path}  ({summary.profile}, {summary.duration_s:.3f} s)",
                   ("topic", "type", "count", "durability"), left=2)
    for t in summary.topics:
        # Names come from the file: control characters in them must not reach the terminal.
        topics.add_row(*(escape_controls(text) for text in (t.topic, t.type, str(t.count), t.qos_durability)))
    show(topics)
    if steps:
        rows = table(f"plan: {plan.robot_name if plan else ''}",
                     ("step", "start [s]", "duration [s]", "points", "peak vel / limit", "peak acc / limit"))
        for s in steps:
            rows.add_row(s["name"], f"{s['start_s']:.3f}", f"{s['duration_s']:.3f}", str(s["points"]),
                         f"{s['peak_velocity_fraction']:.2f}", f"{s['peak_acceleration_fraction']:.2f}")
        show(rows)
        if inspection.end_states:
            _end_poses([s["name"] for s in steps], inspection.end_states)


def execution_summary(outcome: PlanExecution, output: Path | None, as_json: bool, quiet: bool) -> None:
    """Print the result, every violation and the per-joint margins, or the JSON document."""
    from ..core.pipeline import execution_document

    document = execution_document(outcome, output)
    if as_json:
        _emit(document)
        return
    if quiet:
        _failure_line("execute", document)
        return
    _verdict(document, f"smallest margin to tolerance ({document['controller']})")
    _steps(document)
    _tracking(document)
    _console.print(f"executed {len(document['steps'])} of {len(outcome.plan.steps)} steps in "
                   f"{_number(document['duration_s'], '.3f')} s")


def check_summary(report: CheckReport, recording: Path, as_json: bool, quiet: bool) -> None:
    """Print the verdict on a recording (per cycle with --start all), or its JSON document.

    A check with no complete execution is bad input (exit 3): the document says so under "error".
    """
    from ..core.pipeline import check_document

    document = check_document(report, recording)
    for warning in document["warnings"]:
        logger.warning("%s", warning)
    if as_json:
        _emit(document)
        return
    if document["error"] is not None:
        print(f"moveplan: error: {document['error']['message']}", file=sys.stderr)
    if quiet:
        if document["error"] is None:
            _failure_line("check-tolerances", document)
        return
    _verdict(document, "smallest margin to tolerance")
    _steps(document)
    _tracking(document)
    if "cycles" in document:
        _cycles(document)


def _failure_line(command: str, document: dict[str, Any]) -> None:
    """Print on stderr, if the verdict is a failure, one line naming the result and the worst violation (--quiet).

    The worst is the one furthest beyond its tolerance; one whose numbers are not finite (a diverged plant) first.
    """
    if document["ok"]:
        return
    result, violations = document["result"], document["violations"]
    detail = result["message"]
    if violations:
        def excess(v: dict[str, Any]) -> float:
            return float("inf") if v["error"] is None else abs(v["error"]) - v["tolerance"]

        v = max(violations, key=excess)
        detail = (f"{v['joint'] or v['check']} at {_number(v['time_s'], '.3f')} s in step '{v['step']}': "
                  f"{v['check']} error {_number(v['error'], '.4g')}, tolerance {_number(v['tolerance'], '.4g')} "
                  f"({len(violations)} violation{'s' if len(violations) > 1 else ''})")
    print(" ".join(f"moveplan: {command}: {result['name']}: {detail}".split()), file=sys.stderr)


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
        rows = table("violations", ("step", "check", "joint", "time [s]", "reference", "actual", "error",
                                    "tolerance", "unit"), left=3)
        for v in document["violations"]:
            rows.add_row(v["step"], v["check"], v["joint"], _number(v["time_s"], ".3f"),
                         *(_number(v[key], ".4f") for key in ("reference", "actual", "error", "tolerance")), v["unit"])
        show(rows)
    if document["margins"]:
        rows = table(margins_title, ("joint", "margin [rad]"))
        for joint, margin in document["margins"].items():
            colour = "red" if margin is None or margin < 0 else "green"
            rows.add_row(joint, f"[{colour}]{_number(margin, '.4f')}[/]")
        show(rows)
    _unchecked(document)


def _unchecked(document: dict[str, Any]) -> None:
    """Print which joints the controller checks nothing for: a tolerance of 0 is JTC's "not checked"."""
    unchecked = document.get("unchecked") or {}
    joints = set(document["margins"]) | {j for names in unchecked.values() for j in names}
    parts = []
    for check in ("path", "goal"):
        names = unchecked.get(check) or []
        if names:
            parts.append(f"{check} {'of every joint' if set(names) == joints else 'of ' + ', '.join(names)}")
    if parts:
        nothing = " (nothing is checked)" if all(set(unchecked.get(c) or []) == joints for c in ("path", "goal")) \
            else ""
        _console.print(f"[yellow]not checked[/yellow]{nothing}: {'; '.join(parts)}: its tolerance is 0, "
                       "which the controller does not check")


def _steps(document: dict[str, Any]) -> None:
    """Print each step's verdict: its result and duration (INCOMPLETE where a recording cuts it off)."""
    steps = document.get("steps") or []
    if not steps:
        return
    rows = table("steps", ("step", "result", "start [s]", "duration [s]"))
    for step in steps:
        colour = "green" if step["ok"] else "yellow" if step["ok"] is None else "red"
        rows.add_row(step["name"], f"[{colour}]{step['result']}[/]", _number(step["start_s"], ".3f"),
                     _number(step["duration_s"], ".3f"))
    show(rows)


def _tracking(document: dict[str, Any]) -> None:
    """Print per joint how it tracked (worst over the steps), and name the joints that ring, whatever the verdict."""
    tracking = document.get("tracking") or {}
    if not tracking:
        return
    cycle = document.get("tracking_cycle")
    of_cycle = f" of cycle {cycle}" if cycle is not None else ""
    title = (f"tracking [rad], worst over the steps{of_cycle}; osc: error sign changes after the stop "
             "(over the step, for a step aborted in motion)")
    rows = table(title, ("joint", "peak err", "overshoot", "settle [s]", "osc", "final err"))
    for joint, t in tracking.items():
        settling = "-" if t["settling_time_s"] is None else f"{t['settling_time_s']:.3f}"
        oscillations = f"[red]{t['oscillations']}[/]" if t["ringing"] else str(t["oscillations"])
        rows.add_row(joint, _number(t["peak_error"], ".2e"), _number(t["overshoot"], ".2e"), settling, oscillations,
                     _number(t["final_error"], ".2e"))
    show(rows)
    ringing = [f"{joint} ({t['oscillations']})" for joint, t in tracking.items() if t["ringing"]]
    if ringing:
        _console.print(f"[yellow]ringing[/yellow] (error sign changes after the stop): {', '.join(ringing)}")


PROGRESS_EVERY_S = 5.0
"""Seconds between two progress lines of `benchmark` on a stderr that is no terminal (a CI log)."""


@contextmanager
def benchmark_progress(total: int, quiet: bool) -> Iterator[Callable[[Run], None]]:
    """Yield a callback that counts a finished run: a bar on a terminal, else a line now and then; none when quiet.

    On a file or a pipe, a line such as `benchmark: 120/1500 runs, 118 solved, 42 s` once a run ends
    PROGRESS_EVERY_S after the last line: a CI job's log shows the benchmark is alive.
    """
    with _progress(total, quiet, "benchmark", "planning", "runs", ("solved", "failed")) as count:
        yield lambda run: count(run.ok)


@contextmanager
def fleet_progress(total: int, quiet: bool) -> Iterator[Callable[[ItemResult], None]]:
    """Yield a callback that counts a checked item, as benchmark_progress counts runs."""
    with _progress(total, quiet, "check-tolerances", "checking", "items", ("passed", "not passed")) as count:
        yield lambda result: count(result.exit_code == 0)


@contextmanager
def _progress(total: int, quiet: bool, command: str, doing: str, unit: str,
              words: tuple[str, str]) -> Iterator[Callable[[bool], None]]:
    """Yield a callback taking whether a finished piece of work went well: a bar on a terminal, else lines."""
    if quiet or not is_terminal(sys.stderr):
        yield (lambda good: None) if quiet else _progress_lines(total, command, unit, words[0])
        return
    progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                        console=Console(stderr=True), transient=True)
    with progress:
        task = progress.add_task(doing, total=total)
        bad = 0

        def advance(good: bool) -> None:
            nonlocal bad
            bad += not good
            progress.update(task, advance=1, description=f"{doing} ({bad} {words[1]})" if bad else doing)

        yield advance


def _progress_lines(total: int, command: str, unit: str, word: str) -> Callable[[bool], None]:
    """Return a callback that counts finished work and prints a progress line on stderr every PROGRESS_EVERY_S."""
    began = last = time.monotonic()
    done = good_ones = 0

    def advance(good: bool) -> None:
        nonlocal done, good_ones, last
        done, good_ones = done + 1, good_ones + good
        now = time.monotonic()
        if now - last >= PROGRESS_EVERY_S:
            last = now
            print(f"{command}: {done}/{total} {unit}, {good_ones} {word}, {now - began:.0f} s", file=sys.stderr,
                  flush=True)

    return advance


def fleet_report(results: list[ItemResult], resumed: list[dict[str, str]], as_json: bool, quiet: bool) -> None:
    """Print a batch check: a line per item that did not pass and the counts; or its JSON document."""
    from ..core.pipeline import fleet_summary

    summary = fleet_summary(results, resumed)
    if as_json:
        items = [{"index": r.item.index, "plan": str(r.item.plan), "recording": str(r.item.recording),
                  "columns": r.item.columns, "exit_code": r.exit_code, **r.document} for r in results]
        _emit({"items": items, "summary": summary})
        return
    if quiet:
        return
    for failing in summary["failing"]:
        _console.print(f"{escape(failing['recording'])} against {escape(failing['plan'])}: {failing['result']} "
                      f"(exit {failing['exit_code']})", soft_wrap=True)
    resumed_text = f", {summary['resumed']} judged before (--resume)" if summary["resumed"] else ""
    worst = summary["worst_margins"][0] if summary["worst_margins"] else None
    smallest = (f"; smallest margin {worst['margin']:.3g} ({worst['joint']}, {escape(worst['recording'])})"
                if worst else "")
    _console.print(f"{summary['items']} items: {summary['passed']} passed, {summary['failed']} failed, "
                  f"{summary['unreadable']} not checked{resumed_text}{smallest}", soft_wrap=True)


def benchmark_summary(runs: list[Run], rows: list[dict[str, Any]], as_json: bool, quiet: bool) -> None:
    """Print one row per scenario and planner, or the benchmark JSON document."""
    if as_json:
        from ..core.pipeline import benchmark_document

        _emit(benchmark_document(runs, rows))
        return
    if quiet:
        return
    rows_table = table(f"{len(runs)} runs; times in ms (median / p95); total = search + simplify + certify + timing; "
                       "whole call = set-up to written file, config loaded",
                       ("scenario", "planner", "solved", "search", "simplify", "certify", "timing", "total",
                        "whole call", "path [rad]", "duration [s]", "exact-valid"), left=2)

    def ms(row: dict[str, Any], key: str) -> str:
        median, p95 = row[f"{key}_median_s"], row[f"{key}_p95_s"]
        return "-" if median is None else f"{1e3 * median:.3g} / {1e3 * p95:.3g}"

    def number(value: float | None, digits: int) -> str:
        return "-" if value is None else f"{value:.{digits}f}"

    for row in sorted(rows, key=lambda r: (r["scenario"] == "all", r["scenario"], r["planner"])):
        rows_table.add_row(row["scenario"], row["planner"], f"{row['succeeded']}/{row['runs']}",
                      *(ms(row, stage) for stage in ("search", "simplify", "certify", "timing", "total", "whole_call")),
                           number(row["path_length_median"], 2),
                           number(row["duration_median_s"], 2),
                           "-" if row["exact_valid"] is None else f"{row['exact_valid']}/{row['succeeded']}")
    show(rows_table)
