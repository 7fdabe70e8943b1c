"""Robot configuration: the files a MoveIt config package holds, parsed into typed values.

Everything read from a file is checked here, with the file and key in every error; the
districts above never read a configuration file themselves.
"""

from .controllers import ControllerConfig, ExecutionConfig
from .goals import Goal, JointGoal, NamedGoal, PoseGoal, ShiftGoal, Start, StartFrom
from .limits import JointLimit
from .planners import PLANNERS
from .robot_config import RobotConfig, load_robot_config
from .srdf import Group
from .tasks import StepSpec, TaskFile, load_task

__all__ = [
    "Goal", "JointGoal", "NamedGoal", "PoseGoal", "ShiftGoal", "Start", "StartFrom",
    "PLANNERS", "ControllerConfig", "ExecutionConfig", "Group", "JointLimit", "RobotConfig", "StepSpec", "TaskFile",
    "load_robot_config", "load_task",
]
