"""ros2_control as MoveIt drives it: the JointTrajectoryController, simulated hardware, and its tolerances."""

from .checking import CheckReport, check_recording
from .controller import Disturbance, ExecutionReport, simulate
from .plants import PLANTS, make_plant
from .tolerances import ExecutionResult, Violation

__all__ = [
    "PLANTS", "CheckReport", "Disturbance", "ExecutionReport", "ExecutionResult", "Violation", "check_recording",
    "make_plant", "simulate",
]
