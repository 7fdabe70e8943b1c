"""What `moveplan inspect` shows of a bag: its topics and, for a plan file, each step's peak rates and end state.

A bag is an MCAP file, a rosbag2 sqlite3 (.db3) file, or a bag folder; a plan file is MCAP.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..bag import END_STATES_KEY, BagSummary, PlanFile, summarize
from ..errors import InputError
from ..trajectory import peak_rates
from ..types import RobotState
from ._plan_files import plan_config, read_valid_plan

__all__ = ["Inspection", "StepPeaks", "end_states", "inspect_file", "step_peaks"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class StepPeaks:
    """One plan step's timing and how close it comes to the joint limits.

    Attributes:
        name: The step's name.
        start_s: Start on the plan's timeline in [s].
        duration_s: Duration in [s].
        points: Trajectory points.
        peak_velocity_fraction: Largest |velocity| / max_velocity over the joints, anywhere along
            the interpolation (1.0: at the unscaled limit).
        peak_acceleration_fraction: Largest |acceleration| / max_acceleration, likewise.
    """

    name: str
    start_s: float
    duration_s: float
    points: int
    peak_velocity_fraction: float
    peak_acceleration_fraction: float


@dataclass(frozen=True)
class Inspection:
    """A bag's summary, and for a plan file the plan, its steps' peak rates and end states (else None and ()).

    `end_states` is empty also when the plan's embedded robot config does not load (a warning says why).
    """

    path: Path
    summary: BagSummary
    plan: PlanFile | None
    steps: tuple[StepPeaks, ...] = ()
    end_states: tuple[RobotState, ...] = ()


def inspect_file(path: Path, skip_damaged: bool = False) -> Inspection:
    """Return the summary of any bag (MCAP, .db3 or a bag folder); a plan file (moveplan metadata) is read back too.

    The summary comes from an MCAP file's summary section, or is counted in one pass
    through the message indexes of an unfinished file, in memory that does not grow with
    the file; every chunk and CRC is checked first. With `skip_damaged`, damaged chunks are
    left out with a warning and listed in summary.skipped (a plan file is never read so).
    """
    summary = summarize(path, skip_damaged)
    if "moveplan" not in summary.metadata or not path.is_file():
        return Inspection(path, summary, None)
    plan = read_valid_plan(path)
    return Inspection(path, summary, plan, step_peaks(plan, path), end_states(plan, path))


def end_states(plan: PlanFile, path: Path) -> tuple[RobotState, ...]:
    """Return where each step ends: group joints and the tip's pose in the planning frame.

    As the plan file records them; a file that records none (written before moveplan did, or
    whose record is damaged) has them computed by its embedded config, with joints outside the
    trajectories at the config's initial positions. A plan whose config does not load gives ()
    and a warning: the rest of the summary stands without it.
    """
    recorded = plan.metadata.get(END_STATES_KEY)
    if recorded is not None:
        try:
            states = tuple(RobotState.from_dict(entry) for entry in json.loads(recorded))
            if len(states) == len(plan.steps):
                return states
        except (ValueError, TypeError, KeyError, AttributeError):
            pass
        logger.warning("%s: its recorded end states are unreadable; computing them from its robot config", path)
    # Imported here: reading the recorded states needs no kinematics (pinocchio).
    from ..model import Robot, empty_scene
    from .robot_state import robot_state

    try:
        robot = Robot(plan_config(plan, path), plan.group)
    except InputError as exc:
        logger.warning("%s: no end states: %s", path, exc)
        return ()
    ends: list[RobotState] = []
    for step in plan.steps:
        trajectory = step.trajectory
        q = robot.neutral()
        for joint, value in zip(trajectory.joint_names, trajectory.positions[-1], strict=True):
            q = robot.set_joint(q, joint, float(value))
        ends.append(robot_state(robot, empty_scene(), q))
    return tuple(ends)


def step_peaks(plan: PlanFile, path: Path) -> tuple[StepPeaks, ...]:
    """Return each step's duration and peak velocity and acceleration as fractions of the plan's limits."""
    steps = []
    for step in plan.steps:
        peak_v, peak_a = peak_rates(step.trajectory)
        names = step.trajectory.joint_names
        unknown = next((j for j in names if j not in plan.limits), None)
        if unknown is not None:
            raise InputError(f"{path}: step '{step.name}' moves joint '{unknown}', which the plan's "
                             "limits do not name")
        v_limit = np.array([plan.limits[j].get("max_velocity", np.nan) for j in names])
        a_limit = np.array([plan.limits[j].get("max_acceleration", np.nan) for j in names])
        steps.append(StepPeaks(
            name=step.name, start_s=step.start_s, duration_s=step.trajectory.duration_s,
            points=len(step.trajectory.times_s),
            peak_velocity_fraction=float(np.max(peak_v / v_limit)),
            peak_acceleration_fraction=float(np.max(peak_a / a_limit)),
        ))
    return tuple(steps)
