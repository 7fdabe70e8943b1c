"""Robot configuration: the files a MoveIt config package holds, parsed into typed values.

Everything read from a file is checked here, with the file and key in every error; the
districts above never read a configuration file themselves.
"""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .controllers import ControllerConfig, ExecutionConfig, default_controller, parse_controllers
    from .controllers_write import tuned_controllers_text
    from .embed import check_carried
    from .fields import (
        MAX_MAGNITUDE,
        angle,
        check_keys,
        coordinate,
        expression,
        load_yaml,
        mapping,
        number,
        parse_yaml,
        pose_angle,
        pose_angles,
        read_input,
        read_input_text,
    )
    from .goals import SHIFT_AXES, Goal, JointGoal, NamedGoal, PoseGoal, ShiftGoal, Start, StartFrom
    from .joint_units import check_joint_units
    from .limits import DEFAULT_ACCELERATION, JointLimit
    from .motion import MIN_SCALING, MotionSettings, Resolved, is_planning_time, is_scaling, layered, resolved
    from .planners import PLANNERS
    from .robot_config import RobotConfig, load_robot_config
    from .sources import CONFIG_FILE
    from .srdf import Group
    from .tasks import MAX_SEED, StepSpec, TaskFile, load_task
    from .xacro import PackagePath, parse_xacro_args

__all__ = [
    "CONFIG_FILE",
    "ControllerConfig",
    "DEFAULT_ACCELERATION",
    "ExecutionConfig",
    "Goal",
    "Group",
    "JointGoal",
    "JointLimit",
    "MAX_MAGNITUDE",
    "MAX_SEED",
    "MIN_SCALING",
    "MotionSettings",
    "NamedGoal",
    "PLANNERS",
    "PackagePath",
    "PoseGoal",
    "Resolved",
    "RobotConfig",
    "SHIFT_AXES",
    "ShiftGoal",
    "Start",
    "StartFrom",
    "StepSpec",
    "TaskFile",
    "angle",
    "check_carried",
    "check_joint_units",
    "check_keys",
    "coordinate",
    "default_controller",
    "expression",
    "is_planning_time",
    "is_scaling",
    "layered",
    "load_robot_config",
    "load_task",
    "load_yaml",
    "mapping",
    "number",
    "parse_controllers",
    "parse_xacro_args",
    "parse_yaml",
    "pose_angle",
    "pose_angles",
    "read_input",
    "read_input_text",
    "resolved",
    "tuned_controllers_text",
]

__getattr__ = lazy_exports(__name__, {
    "CONFIG_FILE": "sources",
    "ControllerConfig": "controllers",
    "DEFAULT_ACCELERATION": "limits",
    "ExecutionConfig": "controllers",
    "Goal": "goals",
    "Group": "srdf",
    "JointGoal": "goals",
    "JointLimit": "limits",
    "MAX_MAGNITUDE": "fields",
    "MAX_SEED": "tasks",
    "MIN_SCALING": "motion",
    "MotionSettings": "motion",
    "NamedGoal": "goals",
    "PLANNERS": "planners",
    "PackagePath": "xacro",
    "PoseGoal": "goals",
    "Resolved": "motion",
    "RobotConfig": "robot_config",
    "SHIFT_AXES": "goals",
    "ShiftGoal": "goals",
    "Start": "goals",
    "StartFrom": "goals",
    "StepSpec": "tasks",
    "TaskFile": "tasks",
    "angle": "fields",
    "check_carried": "embed",
    "check_joint_units": "joint_units",
    "check_keys": "fields",
    "coordinate": "fields",
    "default_controller": "controllers",
    "expression": "fields",
    "is_planning_time": "motion",
    "is_scaling": "motion",
    "layered": "motion",
    "load_robot_config": "robot_config",
    "load_task": "tasks",
    "load_yaml": "fields",
    "mapping": "fields",
    "number": "fields",
    "parse_controllers": "controllers",
    "parse_xacro_args": "xacro",
    "parse_yaml": "fields",
    "pose_angle": "fields",
    "pose_angles": "fields",
    "read_input": "fields",
    "read_input_text": "fields",
    "resolved": "motion",
    "tuned_controllers_text": "controllers_write",
})
