"""The planning settings of a MoveGroupCommander: planning time, planner, scaling factors, goal tolerances.

MoveIt's names and defaults: 5 s of planning time, the robot config's planner, and
joint_limits.yaml's default scaling factors until set.
"""

from __future__ import annotations

import math
import numbers
import reprlib
from dataclasses import replace
from typing import Any

from ..core.config import MIN_SCALING, PILZ_PLANNERS, PLANNERS, MotionSettings, Resolved, is_scaling, layered, resolved
from ..core.errors import UsageError, known
from ..core.pipeline import check_planning_time
from ._world import World

__all__ = ["PLANNING_TIME_S", "PlanningSettings", "real_number", "scaling"]

PLANNING_TIME_S = 5.0
"""MoveGroupCommander's default planning time in [s], MoveIt's."""

# MoveIt's move_group plans with 5 s unless told; the rest is the robot config's.
_MOVEIT_DEFAULTS = MotionSettings(planning_time=PLANNING_TIME_S)

_PILZ = "pilz_industrial_motion_planner"
_PIPELINES = ("", "ompl", _PILZ)  # MoveIt's pipeline ids moveplan plans with

_TOLERANCES = {"joint": 1e-4, "position": 1e-4, "orientation": 1e-3}  # MoveIt's goal tolerance defaults


class PlanningSettings:
    """How a group's motions are planned; MoveGroupCommander's setters and getters of it."""

    _world: World

    def __init__(self) -> None:
        self._motion = MotionSettings()  # what the setters set
        self._pipeline = "ompl"
        self._planner_id = ""
        self._tolerances = dict(_TOLERANCES)

    def get_goal_tolerance(self) -> tuple[float, float, float]:
        """Return the goal tolerances (joint, position, orientation) set; goals are reached within MoveIt's defaults."""
        return self._tolerances["joint"], self._tolerances["position"], self._tolerances["orientation"]

    def get_goal_joint_tolerance(self) -> float:
        """Return the joint goal tolerance set, in [rad] or [m]."""
        return self._tolerances["joint"]

    def get_goal_position_tolerance(self) -> float:
        """Return the position goal tolerance set, in [m]."""
        return self._tolerances["position"]

    def get_goal_orientation_tolerance(self) -> float:
        """Return the orientation goal tolerance set, in [rad]."""
        return self._tolerances["orientation"]

    def set_goal_tolerance(self, value: float) -> None:
        """Set all three goal tolerances (kept; moveplan reaches goals within 1e-4 m and 1e-3 rad); return None."""
        self._tolerances = dict.fromkeys(self._tolerances, _tolerance(value, "set_goal_tolerance"))

    def set_goal_joint_tolerance(self, value: float) -> None:
        """Set the joint goal tolerance (kept, see set_goal_tolerance); return None."""
        self._tolerances["joint"] = _tolerance(value, "set_goal_joint_tolerance")

    def set_goal_position_tolerance(self, value: float) -> None:
        """Set the position goal tolerance (kept, see set_goal_tolerance); return None."""
        self._tolerances["position"] = _tolerance(value, "set_goal_position_tolerance")

    def set_goal_orientation_tolerance(self, value: float) -> None:
        """Set the orientation goal tolerance (kept, see set_goal_tolerance); return None."""
        self._tolerances["orientation"] = _tolerance(value, "set_goal_orientation_tolerance")

    def get_planning_time(self) -> float:
        """Return the time a plan may search, in [s] (default 5, MoveIt's)."""
        return self._resolved().planning_time

    def set_planning_time(self, seconds: float) -> None:
        """Set the time a plan may search, in [s]; return None."""
        seconds = check_planning_time(real_number(seconds, "set_planning_time"), "set_planning_time")
        self._motion = replace(self._motion, planning_time=seconds)

    def get_planner_id(self) -> str:
        """Return the planner set, or the robot config's when none was."""
        return self._resolved().planner

    def set_planner_id(self, planner_id: str) -> None:
        """Plan with an OMPL geometric planner ("RRTConnect", "RRTConnectkConfigDefault") or Pilz's PTP, LIN, CIRC.

        "" goes back to the planning pipeline's default: the robot config's planner for OMPL,
        PTP for Pilz's. CIRC takes its interim or center point from the path constraints, as
        Pilz does. Return None.
        """
        if not isinstance(planner_id, str):
            raise UsageError(f"set_planner_id: expected a planner's name, got {planner_id!r}")
        name = planner_id.removeprefix("geometric::").removesuffix("kConfigDefault")
        if name and name not in (*PLANNERS, *PILZ_PLANNERS):
            raise UsageError(f"set_planner_id: unknown planner '{planner_id}'; OMPL geometric planners: "
                             f"{known(PLANNERS)}; Pilz's: {', '.join(PILZ_PLANNERS)}")
        self._planner_id = name
        self._motion = replace(self._motion, planner=name or self._pipeline_default())

    def get_planning_pipeline_id(self) -> str:
        """Return the planning pipeline: "ompl" (default) or "pilz_industrial_motion_planner"."""
        return self._pipeline

    def set_planning_pipeline_id(self, planning_pipeline: str) -> None:
        """Plan with MoveIt's "ompl" or "pilz_industrial_motion_planner" pipeline ("" is "ompl"); return None."""
        if planning_pipeline not in _PIPELINES:
            raise UsageError(f"set_planning_pipeline_id: unknown planning pipeline {planning_pipeline!r}; moveplan "
                             f"has {', '.join(p for p in _PIPELINES if p)}")
        self._pipeline = planning_pipeline or "ompl"
        if not self._planner_id:
            self._motion = replace(self._motion, planner=self._pipeline_default())

    def _pipeline_default(self) -> str | None:
        """Return the planner a pipeline plans with when no planner is set (None: the robot config's)."""
        return "PTP" if self._pipeline == _PILZ else None

    def set_num_planning_attempts(self, num_planning_attempts: int) -> None:
        """Accept MoveIt's number of attempts; a moveplan plan is one attempt, certified; return None."""
        if isinstance(num_planning_attempts, bool) or not isinstance(num_planning_attempts, numbers.Integral) \
                or num_planning_attempts < 0:
            raise UsageError(f"set_num_planning_attempts: expected an integer >= 0, got {num_planning_attempts!r}")

    def set_max_velocity_scaling_factor(self, value: float) -> None:
        """Scale the joints' velocity limits by `value` in (0, 1] (default: joint_limits.yaml's); return None."""
        self._motion = replace(self._motion, velocity_scaling=scaling(value, "set_max_velocity_scaling_factor"))

    def set_max_acceleration_scaling_factor(self, value: float) -> None:
        """Scale the joints' acceleration limits by `value` in (0, 1] (default: joint_limits.yaml's); return None."""
        self._motion = replace(self._motion,
                               acceleration_scaling=scaling(value, "set_max_acceleration_scaling_factor"))

    def _settings(self) -> MotionSettings:
        """Return the settings a motion is planned with now: the setters' over MoveIt's (None: the robot config's)."""
        return layered(self._motion, _MOVEIT_DEFAULTS)

    def _resolved(self) -> Resolved:
        """Return the settings a motion is planned with now, each one decided."""
        return resolved(self._settings(), defaults=self._world.config.motion)


def scaling(value: Any, where: str) -> float:
    """Return a scaling factor checked to lie in [MIN_SCALING, 1], else raise UsageError naming `where`."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not is_scaling(float(value)):
        raise UsageError(f"{where}: expected a value in the range from {MIN_SCALING:g} to 1 for scaling factor, "
                         f"got {value!r}")
    return float(value)


def real_number(value: Any, where: str) -> float:
    """Return `value` as a float if it is a finite number (no string), else raise UsageError naming `where`."""
    # numbers.Real: a numpy scalar, as a script computes it, is a number too.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise UsageError(f"{where}: expected a finite number, got {reprlib.repr(value)}")
    try:
        number = float(value)
    except OverflowError:  # an integer of 400 digits
        number = math.inf
    if not math.isfinite(number):
        raise UsageError(f"{where}: expected a finite number, got {reprlib.repr(value)}")
    return number


def _tolerance(value: Any, where: str) -> float:
    """Return a goal tolerance checked to be a finite number >= 0, else raise UsageError naming `where`."""
    tolerance = real_number(value, where)
    if tolerance < 0:
        raise UsageError(f"{where}: expected a tolerance >= 0, got {value!r}")
    return tolerance
