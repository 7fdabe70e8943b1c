"""Robot configuration: the files a MoveIt config package holds, parsed into typed values.

Everything read from a file is checked here, with the file and key in every error; the
districts above never read a configuration file themselves.
"""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._initial_state import default_position
    from .collision_objects import AttachedMessage, ObjectMessage, attached_collision_object, collision_object
    from .constraints import JointBound, OrientationBound, PathConstraints, PositionBound, path_constraints
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
    from .meshes import mesh_file
    from .motion import MIN_SCALING, MotionSettings, Resolved, is_planning_time, is_scaling, layered, resolved
    from .moveit_request import MotionPlanRequest, PositionGoal, load_motion_plan_request
    from .planners import PILZ_PLANNERS, PLANNERS
    from .planning_scene_yaml import (
        PLANNING_SCENE_KEYS,
        AllowedCollisions,
        FixedTransform,
        PlanningSceneFile,
        parse_planning_scene,
    )
    from .poses import pose_matrix
    from .robot_config import RobotConfig, load_robot_config
    from .scene_yaml import SceneFile, check_shape_count, first_repeated, parse_scene
    from .sources import CONFIG_FILE
    from .srdf import Group
    from .tasks import MAX_SEED, StepSpec, TaskFile, load_task
    from .xacro import PackagePath, parse_xacro_args

__all__ = [
    "CONFIG_FILE",
    "DEFAULT_ACCELERATION",
    "MAX_MAGNITUDE",
    "MAX_SEED",
    "MIN_SCALING",
    "PILZ_PLANNERS",
    "PLANNERS",
    "PLANNING_SCENE_KEYS",
    "SHIFT_AXES",
    "AllowedCollisions",
    "AttachedMessage",
    "ControllerConfig",
    "ExecutionConfig",
    "FixedTransform",
    "Goal",
    "Group",
    "JointBound",
    "JointGoal",
    "JointLimit",
    "MotionPlanRequest",
    "MotionSettings",
    "NamedGoal",
    "ObjectMessage",
    "OrientationBound",
    "PackagePath",
    "PathConstraints",
    "PlanningSceneFile",
    "PoseGoal",
    "PositionBound",
    "PositionGoal",
    "Resolved",
    "RobotConfig",
    "SceneFile",
    "ShiftGoal",
    "Start",
    "StartFrom",
    "StepSpec",
    "TaskFile",
    "angle",
    "attached_collision_object",
    "check_carried",
    "check_joint_units",
    "check_keys",
    "check_shape_count",
    "collision_object",
    "coordinate",
    "default_controller",
    "default_position",
    "expression",
    "first_repeated",
    "is_planning_time",
    "is_scaling",
    "layered",
    "load_motion_plan_request",
    "load_robot_config",
    "load_task",
    "load_yaml",
    "mapping",
    "mesh_file",
    "number",
    "parse_controllers",
    "parse_planning_scene",
    "parse_scene",
    "parse_xacro_args",
    "parse_yaml",
    "path_constraints",
    "pose_angle",
    "pose_angles",
    "pose_matrix",
    "read_input",
    "read_input_text",
    "resolved",
    "tuned_controllers_text",
]

__getattr__ = lazy_exports(__name__, {
    "CONFIG_FILE": "sources",
    "DEFAULT_ACCELERATION": "limits",
    "MAX_MAGNITUDE": "fields",
    "MAX_SEED": "tasks",
    "MIN_SCALING": "motion",
    "PILZ_PLANNERS": "planners",
    "PLANNERS": "planners",
    "PLANNING_SCENE_KEYS": "planning_scene_yaml",
    "SHIFT_AXES": "goals",
    "AllowedCollisions": "planning_scene_yaml",
    "AttachedMessage": "collision_objects",
    "ControllerConfig": "controllers",
    "ExecutionConfig": "controllers",
    "FixedTransform": "planning_scene_yaml",
    "Goal": "goals",
    "Group": "srdf",
    "JointBound": "constraints",
    "JointGoal": "goals",
    "JointLimit": "limits",
    "MotionPlanRequest": "moveit_request",
    "MotionSettings": "motion",
    "NamedGoal": "goals",
    "ObjectMessage": "collision_objects",
    "OrientationBound": "constraints",
    "PackagePath": "xacro",
    "PathConstraints": "constraints",
    "PlanningSceneFile": "planning_scene_yaml",
    "PoseGoal": "goals",
    "PositionBound": "constraints",
    "PositionGoal": "moveit_request",
    "Resolved": "motion",
    "RobotConfig": "robot_config",
    "SceneFile": "scene_yaml",
    "ShiftGoal": "goals",
    "Start": "goals",
    "StartFrom": "goals",
    "StepSpec": "tasks",
    "TaskFile": "tasks",
    "angle": "fields",
    "attached_collision_object": "collision_objects",
    "check_carried": "embed",
    "check_joint_units": "joint_units",
    "check_keys": "fields",
    "check_shape_count": "scene_yaml",
    "collision_object": "collision_objects",
    "coordinate": "fields",
    "default_controller": "controllers",
    "default_position": "_initial_state",
    "expression": "fields",
    "first_repeated": "scene_yaml",
    "is_planning_time": "motion",
    "is_scaling": "motion",
    "layered": "motion",
    "load_motion_plan_request": "moveit_request",
    "load_robot_config": "robot_config",
    "load_task": "tasks",
    "load_yaml": "fields",
    "mapping": "fields",
    "mesh_file": "meshes",
    "number": "fields",
    "parse_controllers": "controllers",
    "parse_planning_scene": "planning_scene_yaml",
    "parse_scene": "scene_yaml",
    "parse_xacro_args": "xacro",
    "parse_yaml": "fields",
    "path_constraints": "constraints",
    "pose_angle": "fields",
    "pose_angles": "fields",
    "pose_matrix": "poses",
    "read_input": "fields",
    "read_input_text": "fields",
    "resolved": "motion",
    "tuned_controllers_text": "controllers_write",
})
