"""MoveIt's moveit_msgs/MotionPlanRequest, written as YAML: start state, goal, group, planner and limits.

Read as move_group reads one, with these choices:

- `goal_constraints` are alternatives; moveplan plans to the first (a warning says so when
  there are more). A goal is joint constraints (a joint goal), one position and one
  orientation constraint on one link (a pose goal of that link: the constraint region's
  first pose, moved back by `target_point_offset` along the orientation), or a position
  constraint alone (a position goal, orientation free: what MoveGroupInterface's
  setPositionTarget sends). Tolerances and weights are ignored: moveplan reaches the goal itself.
- `planner_id`: "geometric::" is dropped, then a MoveIt planner config name maps to the
  longest OMPL planner name that begins it (RRTConnectkConfigDefault -> RRTConnect), with
  BKPIECE, LBKPIECE and KPIECE meaning BKPIECE1, LBKPIECE1 and KPIECE1. Empty: the robot
  config's default planner. A name of no available planner is an error.
- `allowed_planning_time` 0 or missing: the default planning time.
- `max_velocity_scaling_factor`, `max_acceleration_scaling_factor`: as MoveIt's time
  parameterisation reads them, a value in (0, 1] is used and anything else (0 included,
  MoveIt's "not set") means 1.0, the full limits; values other than 0 log a warning.
  A factor left out of the file is not set: the task's or robot config's default applies.
- `start_state.attached_collision_objects` are checked here and kept as written; they are
  attached to the scene as MoveIt attaches them (core/model/planning_scene.py
  `attach_request_objects`), their mesh files found through the robot config's packages.
- Ignored: `num_planning_attempts` (one search per step), `workspace_parameters` (the
  joint limits bound the search), `pipeline_id`, `reference_trajectories` and Cartesian
  speed limits (warnings where set). Trajectory constraints and visibility constraints are
  errors.
- `path_constraints` hold every state of the motion (config/constraints.py).
- Every number is finite and within MAX_MAGNITUDE, as on the command line; attempts are an
  int32 at least 0, planning time at least 0.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError, known
from .collision_objects import attached_object
from .constraints import ARC_POINTS, arc_point, path_constraints
from .fields import MAX_MAGNITUDE, check_keys, coordinate, mapping, number, parse_yaml, read_input, text_of
from .goals import JointGoal, PoseGoal
from .motion import MIN_SCALING, MotionSettings
from .planners import PILZ_PLANNERS, PLANNERS
from .poses import pose_matrix
from .ros_messages import header_frame, point, pose, quaternion, robot_state, yaml_list
from .tasks import StepSpec

__all__ = ["MAX_ATTEMPTS", "MotionPlanRequest", "PositionGoal", "load_motion_plan_request", "planner_name"]

logger = logging.getLogger(__name__)

_REQUEST_KEYS = {
    "workspace_parameters", "start_state", "goal_constraints", "path_constraints", "trajectory_constraints",
    "reference_trajectories", "pipeline_id", "planner_id", "group_name", "num_planning_attempts",
    "allowed_planning_time", "max_velocity_scaling_factor", "max_acceleration_scaling_factor",
    "cartesian_speed_limited_link", "max_cartesian_speed",
    "cartesian_speed_end_effector_link",  # Humble's name of cartesian_speed_limited_link
}
_CONSTRAINTS_KEYS = {
    "name", "joint_constraints", "position_constraints", "orientation_constraints", "visibility_constraints",
}
_JOINT_KEYS = {"joint_name", "position", "tolerance_above", "tolerance_below", "weight"}
_POSITION_KEYS = {"header", "link_name", "target_point_offset", "constraint_region", "weight"}
_REGION_KEYS = {"primitives", "primitive_poses", "meshes", "mesh_poses"}
_WORKSPACE_KEYS = {"header", "min_corner", "max_corner"}
_ORIENTATION_KEYS = {
    "header", "orientation", "link_name", "absolute_x_axis_tolerance", "absolute_y_axis_tolerance",
    "absolute_z_axis_tolerance", "parameterization", "weight",
}
# MoveIt's planner configs name these without OMPL's version suffix.
_ALIASES = {"BKPIECE": "BKPIECE1", "LBKPIECE": "LBKPIECE1", "KPIECE": "KPIECE1"}
# OMPL geometric planners the Python bindings do not offer: named so that a config like
# "RRTXstatickConfigDefault" is reported as unavailable, not taken for RRT.
_UNAVAILABLE = (
    "RRTXstatic", "RRTsharp", "TRRT", "BiTRRT", "LBTRRT", "LazyLBTRRT", "LazyRRT", "pRRT", "LazyPRM",
    "LazyPRMstar", "SPARS", "SPARStwo", "EST", "BiEST", "ProjEST", "SBL", "pSBL", "STRIDE", "PDST",
    "AITstar", "ABITstar", "EITstar", "CForest", "STRRTstar", "SST",
)

MAX_ATTEMPTS = 2**31 - 1
"""Largest num_planning_attempts: the field is an int32."""


@dataclass(frozen=True)
class PositionGoal(PoseGoal):
    """A position of a link with its orientation left free (a position constraint alone, as setPositionTarget sends).

    `xyz` is where the link's origin goes, in `frame`; `rpy` and `quat` stay None.
    """

    def describe(self) -> dict[str, Any]:
        """Return the goal as the plan JSON reports it: {"pose": {..., "orientation": "free"}}."""
        described = super().describe()
        described["pose"]["orientation"] = "free"
        return described


@dataclass(frozen=True)
class MotionPlanRequest:
    """What moveplan uses of a MotionPlanRequest; None where the request leaves a setting to the defaults.

    Attributes:
        source: The request file.
        group_name: Planning group.
        start: start_state.joint_state as joint -> position in [rad] or [m]; may name joints
            outside the group (a Panda's fingers), which then hold those values.
        goal: The first goal alternative as a step, named after the file; None without goals.
        motion: planner_id, allowed_planning_time and the scaling factors, as the settings
            they give (None where the file leaves one to the default).
        raw: The file's bytes, embedded in plan files.
        attached: start_state.attached_collision_objects as written (each with a link name
            and an object id); attached to the scene with the robot at the start.
    """

    source: Path
    group_name: str | None
    start: dict[str, float]
    goal: StepSpec | None
    motion: MotionSettings
    raw: bytes = b""
    attached: tuple[Any, ...] = ()


def load_motion_plan_request(path: Path) -> MotionPlanRequest:
    """Return the MotionPlanRequest in a YAML file."""
    source = str(path)
    raw = read_input(path)  # once: what is parsed is what the plan embeds
    top = mapping(parse_yaml(text_of(raw, path), path), source)
    check_keys(top, _REQUEST_KEYS, source)
    _check_unsupported(top, source)

    joints, attached = robot_state(top.get("start_state"), f"{source}: start_state")
    for k, entry in enumerate(attached):
        attached_object(entry, f"{source}: start_state.attached_collision_objects[{k}]")
    alternatives = yaml_list(top.get("goal_constraints"), f"{source}: goal_constraints")
    if len(alternatives) > 1:
        logger.warning("%s: goal_constraints has %d alternatives; moveplan plans to the first",
                       source, len(alternatives))
    goal = None
    written = top.get("path_constraints") or {}
    arc, constraints = None, None
    if top.get("planner_id") == "CIRC" and isinstance(written, dict) and written.get("name") in ARC_POINTS:
        arc = arc_point(written, f"{source}: path_constraints")  # Pilz's CIRC: its point, not a constraint
    else:
        constraints = path_constraints(written, f"{source}: path_constraints")
    if alternatives:
        goal = StepSpec(path.stem, _goal(alternatives[0], f"{source}: goal_constraints[0]"), constraints=constraints,
                        arc=arc)

    group = top.get("group_name", "")
    if not isinstance(group, str):
        raise ConfigError(f"{source}: group_name: expected a group name, got {group!r}")
    planner_id = top.get("planner_id", "")
    if not isinstance(planner_id, str):
        raise ConfigError(f"{source}: planner_id: expected a planner name, got {planner_id!r}")
    planning_time = coordinate(top.get("allowed_planning_time", 0.0), f"{source}: allowed_planning_time")
    if planning_time < 0:
        raise ConfigError(f"{source}: allowed_planning_time: expected seconds >= 0, got {planning_time!r}")
    attempts = top.get("num_planning_attempts", 0)
    if isinstance(attempts, bool) or not isinstance(attempts, int) or not 0 <= attempts <= MAX_ATTEMPTS:
        raise ConfigError(f"{source}: num_planning_attempts: expected an integer in 0..{MAX_ATTEMPTS}, "
                          f"got {str(attempts)[:40]}")
    return MotionPlanRequest(
        source=path,
        group_name=group or None,
        start=joints,
        goal=goal,
        motion=MotionSettings(
            planner=planner_name(planner_id, f"{source}: planner_id"),
            planning_time=planning_time or None,
            velocity_scaling=_scaling(top, "max_velocity_scaling_factor", source),
            acceleration_scaling=_scaling(top, "max_acceleration_scaling_factor", source),
        ),
        raw=raw,
        attached=tuple(attached),
    )


def planner_name(planner_id: str, where: str) -> str | None:
    """Return the OMPL or Pilz planner a MoveIt planner_id names, or None for an empty one (the default)."""
    name = planner_id.removeprefix("geometric::")
    if not name:
        return None
    if name in PILZ_PLANNERS:
        return name
    candidates = {p: p for p in _UNAVAILABLE} | {p: p for p in PLANNERS}
    candidates |= {alias: full for alias, full in _ALIASES.items() if full in PLANNERS}
    matches = [c for c in candidates if name.startswith(c)]
    planner = candidates[max(matches, key=len)] if matches else ""
    if planner not in PLANNERS:
        raise ConfigError(f"{where}: '{planner_id}' names no available OMPL geometric planner nor Pilz's "
                          f"{', '.join(PILZ_PLANNERS)}; known: {known(PLANNERS)}")
    return planner


def _check_unsupported(top: dict[str, Any], source: str) -> None:
    """Raise ConfigError for request fields that would change the motion but that moveplan cannot honour."""
    trajectory = mapping(top.get("trajectory_constraints"), f"{source}: trajectory_constraints")
    check_keys(trajectory, {"constraints"}, f"{source}: trajectory_constraints")
    if yaml_list(trajectory.get("constraints"), f"{source}: trajectory_constraints.constraints"):
        raise ConfigError(f"{source}: trajectory_constraints: not supported")
    if yaml_list(top.get("reference_trajectories"), f"{source}: reference_trajectories"):
        logger.warning("%s: reference_trajectories are ignored", source)
    pipeline = top.get("pipeline_id", "")
    if pipeline not in ("", "ompl"):
        logger.warning("%s: pipeline_id '%s' is ignored; moveplan plans with OMPL", source, str(pipeline)[:80])
    if coordinate(top.get("max_cartesian_speed", 0.0), f"{source}: max_cartesian_speed") > 0:
        logger.warning("%s: max_cartesian_speed is ignored; the joint limits bound the motion", source)
    workspace = mapping(top.get("workspace_parameters"), f"{source}: workspace_parameters")
    check_keys(workspace, _WORKSPACE_KEYS, f"{source}: workspace_parameters")
    header_frame(workspace, f"{source}: workspace_parameters", "")
    for corner in ("min_corner", "max_corner"):
        point(workspace.get(corner, [0.0, 0.0, 0.0]), f"{source}: workspace_parameters.{corner}")


def _scaling(top: dict[str, Any], key: str, source: str) -> float | None:
    """Return a scaling factor as MoveIt's time parameterisation reads it: outside (0, 1] is 1.0."""
    if key not in top:
        return None
    factor = coordinate(top[key], f"{source}: {key}")
    if 0.0 < factor < MIN_SCALING:
        raise ConfigError(f"{source}: {key}: {factor:g} is below moveplan's limit of {MIN_SCALING:g}")
    if 0.0 < factor <= 1.0:
        return factor
    if factor != 0.0:
        logger.warning("%s: %s %g is outside (0, 1]; using 1.0, as MoveIt does", source, key, factor)
    return 1.0


def _goal(value: Any, where: str) -> JointGoal | PoseGoal:
    """Return the step goal of one moveit_msgs/Constraints: a joint, pose or position goal."""
    entry = mapping(value, where)
    check_keys(entry, _CONSTRAINTS_KEYS, where)
    joints = yaml_list(entry.get("joint_constraints"), f"{where}.joint_constraints")
    positions = yaml_list(entry.get("position_constraints"), f"{where}.position_constraints")
    orientations = yaml_list(entry.get("orientation_constraints"), f"{where}.orientation_constraints")
    if yaml_list(entry.get("visibility_constraints"), f"{where}.visibility_constraints"):
        raise ConfigError(f"{where}.visibility_constraints: not supported")
    if joints and (positions or orientations):
        raise ConfigError(f"{where}: give joint constraints or position and orientation constraints, not both")
    if joints:
        return _joint_goal(joints, where)
    if len(positions) != 1 or len(orientations) > 1:
        raise ConfigError(f"{where}: a goal needs joint constraints, or one position constraint and at most one "
                          f"orientation constraint (got {len(positions)} and {len(orientations)})")
    return _pose_goal(positions[0], orientations[0] if orientations else None, where)


def _joint_goal(constraints: list[Any], where: str) -> JointGoal:
    """Return the joint goal of moveit_msgs/JointConstraint entries (tolerances checked, then ignored)."""
    goal: dict[str, float] = {}
    for k, item in enumerate(constraints):
        at = f"{where}.joint_constraints[{k}]"
        constraint = mapping(item, at)
        check_keys(constraint, _JOINT_KEYS, at)
        name = constraint.get("joint_name")
        if not isinstance(name, str) or not name:
            raise ConfigError(f"{at}.joint_name: expected a joint name, got {name!r}")
        if name in goal:
            raise ConfigError(f"{at}.joint_name: joint '{name}' is constrained twice")
        goal[name] = coordinate(constraint.get("position"), f"{at}.position")
        _check_numbers(constraint, ("tolerance_above", "tolerance_below", "weight"), at)
    return JointGoal.by_name(goal)


def _pose_goal(position_value: Any, orientation_value: Any, where: str) -> PoseGoal:
    """Return the pose goal of a link from a position and an orientation constraint on it (None: orientation free)."""
    at_p, at_o = f"{where}.position_constraints[0]", f"{where}.orientation_constraints[0]"
    position = mapping(position_value, at_p)
    check_keys(position, _POSITION_KEYS, at_p)
    _check_numbers(position, ("weight",), at_p)
    centre = _region_centre(position.get("constraint_region"), f"{at_p}.constraint_region")
    offset = np.array(point(position.get("target_point_offset", [0.0, 0.0, 0.0]), f"{at_p}.target_point_offset"))
    link = position.get("link_name")
    if not isinstance(link, str) or not link:
        raise ConfigError(f"{at_p}.link_name: expected a link name, got {link!r}")
    frame = header_frame(position, at_p, "")
    if orientation_value is None:
        if offset.any():
            raise ConfigError(f"{at_p}.target_point_offset: not supported in a goal without an orientation "
                              "constraint (where the point is depends on the orientation); give the link origin")
        x, y, z = (float(v) for v in centre)
        return PositionGoal(xyz=(x, y, z), frame=frame or None, link=link)
    orientation = mapping(orientation_value, at_o)
    check_keys(orientation, _ORIENTATION_KEYS, at_o)
    _check_numbers(orientation, ("absolute_x_axis_tolerance", "absolute_y_axis_tolerance",
                                 "absolute_z_axis_tolerance", "weight"), at_o)
    if orientation.get("link_name") != link:
        raise ConfigError(f"{at_o}.link_name: {orientation.get('link_name')!r} is not the position constraint's "
                          f"link '{link}'")
    if header_frame(orientation, at_o, "") != frame:
        raise ConfigError(f"{at_o}.header.frame_id: '{header_frame(orientation, at_o, '')}' is not the position "
                          f"constraint's frame '{frame}'; give both in one frame")
    quat = quaternion(orientation.get("orientation"), f"{at_o}.orientation") or [0.0, 0.0, 0.0, 1.0]
    rotation = pose_matrix(None, None, quat, f"{at_o}.orientation")[:3, :3]
    # The offset point, fixed in the link, must reach the centre: the link origin sits back from it.
    origin = centre - rotation @ offset
    norm = float(np.linalg.norm(quat))
    x, y, z = (float(v) for v in origin)
    qx, qy, qz, qw = (v / norm for v in quat)
    return PoseGoal(xyz=(x, y, z), quat=(qx, qy, qz, qw), frame=frame or None, link=link)


def _region_centre(value: Any, where: str) -> NDArray[np.float64]:
    """Return the centre of a constraint region (moveit_msgs/BoundingVolume): its first primitive's or mesh's pose."""
    region = mapping(value, where)
    check_keys(region, _REGION_KEYS, where)
    for k, primitive in enumerate(yaml_list(region.get("primitives"), f"{where}.primitives")):
        at = f"{where}.primitives[{k}]"
        entry = mapping(primitive, at)
        for i, size in enumerate(yaml_list(entry.get("dimensions"), f"{at}.dimensions")):
            number(size, f"{at}.dimensions[{i}]", bound=MAX_MAGNITUDE)
    poses = (yaml_list(region.get("primitive_poses"), f"{where}.primitive_poses")
             or yaml_list(region.get("mesh_poses"), f"{where}.mesh_poses"))
    if not poses:
        raise ConfigError(f"{where}.primitive_poses: the region needs a pose, its centre is the goal")
    return pose(poses[0], f"{where}.primitive_poses[0]")[:3, 3]


def _check_numbers(entry: dict[str, Any], keys: tuple[str, ...], where: str) -> None:
    """Raise ConfigError unless each of `keys` present in `entry` is a finite number within MAX_MAGNITUDE."""
    for key in keys:
        if key in entry:
            number(entry[key], f"{where}.{key}", bound=MAX_MAGNITUDE)
