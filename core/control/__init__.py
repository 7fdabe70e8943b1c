"""ros2_control as MoveIt drives it: the JointTrajectoryController, simulated hardware, and its tolerances."""

from .check.recording import check_recording, uses_velocities
from .check.report import CheckReport, CycleCheck, StepCheck
from .controller import Disturbance, ExecutionReport, simulate
from .goal_validation import validate_goal
from .plants import PLANTS, make_plant
from .results import ExecutionResult, Violation

__all__ = [
    "PLANTS", "CheckReport", "CycleCheck", "Disturbance", "ExecutionReport", "ExecutionResult", "StepCheck",
    "Violation", "check_recording", "make_plant", "simulate", "uses_velocities", "validate_goal",
]
