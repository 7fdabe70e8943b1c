"""The result documents of plan, robot, state, inspect and benchmark, and of a failed command: what `--json` prints.

cli/ renders them (JSON as built, tables drawn from them) and adds nothing; execute's and
check-tolerances' documents are report.py's, tune-pid's tuning.py's. docs/cli.md lists the keys.
Only the standard library is imported here: the CLI builds a failure's document on any error.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..config import RobotConfig
    from ..errors import MoveplanError
    from .benchmark import Run
    from .inspection import Inspection
    from .plan import PlanResult
    from .robot_state import StateResult

__all__ = [
    "benchmark_document", "failure_document", "inspect_document", "plan_document", "plan_failure_document",
    "robot_document", "state_document", "step_documents",
]


def plan_document(plan: PlanResult, output: Path) -> dict[str, Any]:
    """Return the document of a plan written to `output`."""
    return {"ok": True, "output": str(output), "robot": plan.robot_name, "group": plan.group,
            "steps": step_documents(plan), "error": None}


def plan_failure_document(error: MoveplanError) -> dict[str, Any]:
    """Return what a failed plan's document holds besides its error: the steps planned, then the failing one."""
    plan: PlanResult | None = error.partial
    steps = step_documents(plan) if plan else []
    if error.step is not None:
        steps.append({"name": error.step, "status": "error"})
    return {"output": None, "robot": plan.robot_name if plan else None, "group": plan.group if plan else None,
            "steps": steps}


def step_documents(plan: PlanResult) -> list[dict[str, Any]]:
    """Return the plan document's "steps": each planned step, its goal, planning, trajectory and end state."""
    return [
        {
            "name": s.name, "status": "ok", "goal": s.goal, "planner": s.planner,
            "planning_time_s": round(s.planning_time_s, 6), "duration_s": round(s.trajectory.duration_s, 6),
            "fraction": s.fraction, "residual": s.residual, "points": len(s.trajectory.times_s),
            "end_state": end.as_dict(),
        }
        for s, end in zip(plan.steps, plan.end_states, strict=True)
    ]


def robot_document(config: RobotConfig) -> dict[str, Any]:
    """Return the document of a robot config: groups, joints with limits and sources, named states, controllers."""
    links = sorted({j.parent for j in config.urdf_joints.values()} | {j.child for j in config.urdf_joints.values()})
    return {
        "name": config.name,
        "groups": {n: {"joints": list(g.joints), "base": g.base, "tip": g.tip} for n, g in config.srdf.groups.items()},
        "joints": {
            n: {"lower": lim.lower, "upper": lim.upper, "max_velocity": lim.max_velocity,
                "max_acceleration": None if math.isnan(lim.max_acceleration) else lim.max_acceleration,
                "continuous": lim.continuous, "source": lim.source}
            for n, lim in config.limits.items()
        },
        "named_states": {
            group: {name: [values.get(j) for j in config.srdf.groups[group].joints] for name, values in states.items()}
            for group, states in config.srdf.group_states.items()
        },
        "frames": links,
        "default_scaling": {"velocity": config.motion.velocity_scaling,
                            "acceleration": config.motion.acceleration_scaling},
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


def state_document(result: StateResult) -> dict[str, Any]:
    """Return the document of a robot state: the group's joint values and the link's pose in the frame."""
    return {"ok": True, "robot": result.robot, "group": result.group, "source": result.source,
            **result.state.as_dict(), "error": None}


def inspect_document(inspection: Inspection) -> dict[str, Any]:
    """Return the document of an inspected bag: profile, topics, and for a plan file each step and its end state."""
    summary, plan = inspection.summary, inspection.plan
    ends: list[dict[str, Any] | None] = [state.as_dict() for state in inspection.end_states]
    ends = ends or [None] * len(inspection.steps)
    steps = [{**asdict(step), "end_state": end} for step, end in zip(inspection.steps, ends, strict=True)]
    return {
        "file": str(inspection.path), "profile": summary.profile, "library": summary.library,
        "duration_s": summary.duration_s,
        "topics": [{"topic": t.topic, "type": t.type, "encoding": t.encoding, "count": t.count,
                    "durability": t.qos_durability} for t in summary.topics],
        "metadata": list(summary.metadata), "attachments": list(summary.attachments),
        "plan": None if plan is None else {"robot": plan.robot_name, "group": plan.group, "steps": steps},
        "skipped": [part.as_dict() for part in summary.skipped],
    }


def benchmark_document(runs: list[Run], rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the document of a benchmark: every run, and the summary rows per scenario and planner."""
    return {"ok": True, "runs": [r.as_dict() for r in runs], "summary": rows, "error": None}


def failure_document(
    exit_code: int, kind: str, message: str, context: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """Return the document of a failed command: what the command adds (`context`, a plan's steps), then the error."""
    return {"ok": False, **(context or {}), "error": {"exit_code": exit_code, "kind": kind, "message": message}}
