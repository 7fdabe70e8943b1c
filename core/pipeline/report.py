"""An execution's result: its document (in the executed file and `--json`), and the executed file."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ..bag import messages as msgs
from ..bag import recording
from ..control.published import controller_states
from ..types import TfSamples

if TYPE_CHECKING:
    from pathlib import Path

    from .execute import PlanExecution

__all__ = ["execution_document", "finite", "write_execution"]


def write_execution(path: Path, execution: PlanExecution, distro: str = "jazzy", tf: TfSamples | None = None) -> None:
    """Write what `execution` did to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Log times run from 0, the execution's start; each step starts where the one before it
    ended (its start plus its duration_s, in whole nanoseconds: no drift over many steps).
    The result document is logged when the last step ended: that is when it was known.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        InputError: `path` cannot be written.
        ValueError: A step's output interface is not a JTC command interface.

    """
    steps, start_ns = [], 0
    for step in execution.steps:
        report = step.report
        times_ns = msgs.stamps_ns(report.times_s)
        states = controller_states(report, execution.controller, start_ns + times_ns, times_ns)
        steps.append(recording.ExecutedStep(report.joint_names, report.actual_positions, report.actual_velocities,
                                            states))
        start_ns += msgs.seconds_to_ns(report.duration_s)
    recording.write_execution(path, steps, execution_document(execution), start_ns,
                              controller=execution.controller.name, urdf=recording.plan_urdf(execution.plan),
                              distro=distro, tf=tf)


def execution_document(execution: PlanExecution) -> dict[str, Any]:
    """Return the result JSON document of an execution; non-finite numbers become null.

    Keys: ok, result {code, name, message}, violations (each with its step; times from the
    step's start), margins, then controller, duration_s and steps (name, ok, result,
    start_s and duration_s on the execution's timeline).
    """
    steps, start_ns = [], 0
    for step in execution.steps:
        report = step.report
        steps.append(
            {
                "name": step.name,
                "ok": report.ok,
                "result": report.result.name,
                "start_s": start_ns / 1e9,
                "duration_s": finite(report.duration_s),
            }
        )
        start_ns += msgs.seconds_to_ns(report.duration_s)
    result = execution.result
    return {
        "ok": execution.ok,
        "result": {"code": result.code, "name": result.name, "message": result.message},
        "violations": [
            {
                "step": name,
                "check": v.check,
                "joint": v.joint,
                "time_s": finite(v.time_s),
                "reference": finite(v.reference),
                "actual": finite(v.actual),
                "error": finite(v.error),
                "tolerance": finite(v.tolerance),
            }
            for name, v in execution.violations
        ],
        "margins": {joint: finite(margin) for joint, margin in execution.margins.items()},
        "controller": execution.controller.name,
        "duration_s": start_ns / 1e9,
        "steps": steps,
    }


def finite(value: float) -> float | None:
    """Return `value` as a float, or None (JSON null) if NaN or infinite (a diverged plant)."""
    number = float(value)
    return number if math.isfinite(number) else None
