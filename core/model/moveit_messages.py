"""Readers for the ROS message types MoveIt's YAML files are made of: poses, states and collision objects.

A message field left out takes its ROS 2 default (zero, empty; a quaternion's w is 1).
Points, vectors and quaternions may be written as lists ([x, y, z], [x, y, z, w], as
MotionBenchMaker writes them) or as mappings ({x: .., y: .., z: ..}, as ROS 2 writes them).
Coordinates, joint positions and quaternion parts are finite and within MAX_MAGNITUDE.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import MAX_MAGNITUDE, PackagePath, check_keys, coordinate, mapping, number
from ..errors import ConfigError, UnknownName
from ..types import Shape
from .poses import pose_matrix
from .robot import Robot
from .scene import mesh_file

__all__ = [
    "ObjectMessage",
    "attached_object",
    "collision_object",
    "header_frame",
    "is_empty_pose",
    "joint_positions",
    "known_joints",
    "point",
    "pose",
    "quaternion",
    "robot_state",
    "string_list",
    "transform",
    "yaml_list",
]

logger = logging.getLogger(__name__)

_ROBOT_STATE_KEYS = {"joint_state", "multi_dof_joint_state", "attached_collision_objects", "is_diff"}
_JOINT_STATE_KEYS = {"header", "name", "position", "velocity", "effort"}
_MULTI_DOF_KEYS = {"header", "joint_names", "transforms", "twist", "wrench"}
_HEADER_KEYS = {"stamp", "frame_id", "seq"}  # seq: headers written by ROS 1
_ATTACHED_KEYS = {"link_name", "object", "touch_links", "detach_posture", "weight"}
_OBJECT_KEYS = {
    "header", "pose", "id", "type", "primitives", "primitive_poses", "meshes", "mesh_poses", "planes",
    "plane_poses", "subframe_names", "subframe_poses", "operation",
}
_PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}  # SolidPrimitive type constants
_DIMENSIONS = {"box": "x, y, z (full sizes)", "sphere": "radius", "cylinder": "height, radius",
               "cone": "height, radius"}
_ADD = (0, "add", "ADD", "\x00", b"\x00")  # CollisionObject.ADD as numbers, names or a byte


@dataclass(frozen=True)
class ObjectMessage:
    """A moveit_msgs/CollisionObject, parsed: shapes placed in the object frame, the object in its header frame.

    Attributes:
        id: The object's name.
        frame: Its header.frame_id, "" when empty (the planning frame, or an attached object's link).
        header_T_object: The object's pose in `frame`.
        parts: (name, shape, `object_T_shape`) per shape; empty for an object given by id alone
            (attaching the world object of that id).
        subframes: Subframe name -> `object_T_subframe`.
    """

    id: str
    frame: str
    header_T_object: NDArray[np.float64]
    parts: tuple[tuple[str, Shape, NDArray[np.float64]], ...]
    subframes: dict[str, NDArray[np.float64]]


def header_frame(entry: dict[str, Any], where: str, default: str) -> str:
    """Return a message's header.frame_id without a leading slash, or `default` when empty."""
    header = mapping(entry.get("header"), f"{where}.header")
    check_keys(header, _HEADER_KEYS, f"{where}.header")
    frame = header.get("frame_id", "")
    if not isinstance(frame, str):
        raise ConfigError(f"{where}.header.frame_id: expected a frame name, got {frame!r}")
    return frame.lstrip("/") or default


def robot_state(value: Any, where: str) -> tuple[dict[str, float], list[Any]]:
    """Return a moveit_msgs/RobotState's joint positions and its attached objects (as written)."""
    entry = mapping(value, where)
    check_keys(entry, _ROBOT_STATE_KEYS, where)
    joints = joint_positions(entry.get("joint_state"), f"{where}.joint_state")
    multi = mapping(entry.get("multi_dof_joint_state"), f"{where}.multi_dof_joint_state")
    check_keys(multi, _MULTI_DOF_KEYS, f"{where}.multi_dof_joint_state")
    names = string_list(multi.get("joint_names"), f"{where}.multi_dof_joint_state.joint_names")
    for k, item in enumerate(yaml_list(multi.get("transforms"), f"{where}.multi_dof_joint_state.transforms")):
        at = f"{where}.multi_dof_joint_state.transforms[{k}]"
        if not np.allclose(transform(item, at), np.eye(4), atol=1e-9):
            joint = names[k] if k < len(names) else "?"
            raise ConfigError(f"{at}: joint '{joint}' is away from the identity; moveplan plans in the URDF "
                              "root frame and cannot move a virtual joint")
    return joints, yaml_list(entry.get("attached_collision_objects"), f"{where}.attached_collision_objects")


def joint_positions(value: Any, where: str) -> dict[str, float]:
    """Return joint name -> position of a sensor_msgs/JointState."""
    entry = mapping(value, where)
    check_keys(entry, _JOINT_STATE_KEYS, where)
    names = string_list(entry.get("name"), f"{where}.name")
    positions = yaml_list(entry.get("position"), f"{where}.position")
    if len(positions) != len(names):
        raise ConfigError(f"{where}.position: {len(positions)} positions for {len(names)} names")
    if len(set(names)) != len(names):
        twice = next(name for name in names if names.count(name) > 1)
        raise ConfigError(f"{where}.name: joint '{twice}' is listed twice")
    return {name: coordinate(v, f"{where}.position[{i}]")
            for i, (name, v) in enumerate(zip(names, positions, strict=True))}


def known_joints(joints: dict[str, float], robot: Robot, where: str) -> dict[str, float]:
    """Return the joints that have a position in `robot`, after checking every name is a URDF joint.

    Fixed joints (a Panda's fingers in some URDFs) are known but have no position: left out.
    """
    for joint in joints:
        if joint not in robot.config.urdf_joints:
            raise UnknownName("joint", joint, where, robot.config.limits)
    return {j: v for j, v in joints.items() if robot.model.existJointName(j)}


def yaml_list(value: Any, where: str) -> list[Any]:
    """Return `value` if it is a list, [] if it is missing, else raise ConfigError at `where`."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError(f"{where}: expected a list, got {type(value).__name__}")
    return value


def string_list(value: Any, where: str) -> list[str]:
    """Return `value` if it is a list of strings ([] if missing), else raise ConfigError at `where`."""
    items = yaml_list(value, where)
    for i, item in enumerate(items):
        if not isinstance(item, str):
            raise ConfigError(f"{where}[{i}]: expected a name, got {item!r}")
    return items


def point(value: Any, where: str) -> list[float]:
    """Return [x, y, z] of a Point or Vector3 written as a list or a mapping (missing fields are 0)."""
    if isinstance(value, list):
        if len(value) != 3:
            raise ConfigError(f"{where}: expected [x, y, z], got {value!r}")
        return [coordinate(v, f"{where}[{i}]") for i, v in enumerate(value)]
    entry = mapping(value, where)
    check_keys(entry, {"x", "y", "z"}, where)
    return [coordinate(entry.get(axis, 0.0), f"{where}.{axis}") for axis in "xyz"]


def quaternion(value: Any, where: str) -> list[float] | None:
    """Return [x, y, z, w] of a Quaternion written as a list or a mapping; None means the identity.

    Missing fields take ROS 2's defaults (w = 1). All zeros is read as the identity, as MoveIt does.
    """
    if value is None:
        return None
    quat = _quaternion_values(value, where)
    if not any(quat):
        logger.warning("%s: quaternion of zeros read as the identity, as MoveIt does", where)
        return None
    return quat


def _quaternion_values(value: Any, where: str) -> list[float]:
    """Return [x, y, z, w] as written (the identity when missing)."""
    if value is None:
        return [0.0, 0.0, 0.0, 1.0]
    if isinstance(value, list):
        if len(value) != 4:
            raise ConfigError(f"{where}: expected [x, y, z, w], got {value!r}")
        return [coordinate(v, f"{where}[{i}]") for i, v in enumerate(value)]
    entry = mapping(value, where)
    check_keys(entry, {"x", "y", "z", "w"}, where)
    return [coordinate(entry.get(axis, 1.0 if axis == "w" else 0.0), f"{where}.{axis}") for axis in "xyzw"]


def pose(value: Any, where: str) -> NDArray[np.float64]:
    """Return the 4x4 transform of a geometry_msgs/Pose {position, orientation}; missing parts are identity."""
    entry = mapping(value, where)
    check_keys(entry, {"position", "orientation"}, where)
    xyz = point(entry.get("position", [0.0, 0.0, 0.0]), f"{where}.position")
    return pose_matrix(xyz, None, quaternion(entry.get("orientation"), f"{where}.orientation"), where)


def transform(value: Any, where: str) -> NDArray[np.float64]:
    """Return the 4x4 transform of a geometry_msgs/Transform {translation, rotation}."""
    entry = mapping(value, where)
    check_keys(entry, {"translation", "rotation"}, where)
    xyz = point(entry.get("translation", [0.0, 0.0, 0.0]), f"{where}.translation")
    return pose_matrix(xyz, None, quaternion(entry.get("rotation"), f"{where}.rotation"), where)


def is_empty_pose(value: Any, where: str) -> bool:
    """Return True for a pose left out, or written as all zeros (MoveIt's isEmpty)."""
    if value is None:
        return True
    entry = mapping(value, where)
    position = point(entry.get("position", [0.0, 0.0, 0.0]), f"{where}.position")
    orientation = _quaternion_values(entry.get("orientation"), f"{where}.orientation")
    return not any(position) and not any(orientation)


def attached_object(value: Any, where: str) -> tuple[str, dict[str, Any], tuple[str, ...]]:
    """Return a moveit_msgs/AttachedCollisionObject's link name, its object (as written) and its touch links."""
    entry = mapping(value, where)
    check_keys(entry, _ATTACHED_KEYS, where)
    link = entry.get("link_name")
    if not isinstance(link, str) or not link:
        raise ConfigError(f"{where}.link_name: expected a link name, got {link!r}")
    written = mapping(entry.get("object"), f"{where}.object")
    if not isinstance(written.get("id"), str) or not written["id"]:
        raise ConfigError(f"{where}.object.id: expected an object name, got {written.get('id')!r}")
    number(entry.get("weight", 0.0), f"{where}.weight", bound=MAX_MAGNITUDE)
    return link, written, tuple(string_list(entry.get("touch_links"), f"{where}.touch_links"))


def collision_object(value: Any, where: str, folder: Path, packages: PackagePath) -> ObjectMessage:
    """Return a moveit_msgs/CollisionObject's shapes, poses and subframes.

    Mesh files (`meshes[].resource`) resolve through `packages` (package://) or against `folder`.
    An object with no shapes is returned with no parts: only an attached object may be one.
    """
    entry = mapping(value, where)
    check_keys(entry, _OBJECT_KEYS, where)
    name = entry.get("id")
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{where}.id: expected an object name, got {name!r}")
    operation = entry.get("operation", 0)
    if isinstance(operation, bool) or operation not in _ADD:
        raise ConfigError(f"{where}.operation: only ADD (0) describes an object in a scene, got {operation!r} "
                          "(APPEND 1, REMOVE 2 and MOVE 3 edit a running scene)")
    if yaml_list(entry.get("planes"), f"{where}.planes"):
        raise ConfigError(f"{where}.planes: planes are not supported; use a thin box")
    shapes: list[Shape] = []
    shape_poses: list[NDArray[np.float64]] = []
    readers = (("primitives", "primitive_poses", _primitive),
               ("meshes", "mesh_poses", lambda item, at: _mesh(item, at, folder, packages)))
    for key, poses_key, read in readers:
        items = yaml_list(entry.get(key), f"{where}.{key}")
        poses = yaml_list(entry.get(poses_key), f"{where}.{poses_key}")
        if len(poses) != len(items):
            # MoveIt refuses such an object ("Number of primitive shapes does not match number of poses").
            raise ConfigError(f"{where}.{poses_key}: object '{name}' has {len(items)} {key} and {len(poses)} "
                              f"{poses_key}; give one pose per shape")
        shapes.extend(read(item, f"{where}.{key}[{i}]") for i, item in enumerate(items))
        shape_poses.extend(pose(p, f"{where}.{poses_key}[{i}]") for i, p in enumerate(poses))
    header_T_object = pose(entry.get("pose"), f"{where}.pose")
    if len(shapes) == 1 and is_empty_pose(entry.get("pose"), f"{where}.pose"):
        # MoveIt: an object with one shape and no pose takes the shape's pose as its own.
        header_T_object, shape_poses[0] = shape_poses[0], header_T_object
    parts = tuple((name if len(shapes) == 1 else f"{name}/{i}", shape, shape_T)
                  for i, (shape, shape_T) in enumerate(zip(shapes, shape_poses, strict=True)))
    sub_names = string_list(entry.get("subframe_names"), f"{where}.subframe_names")
    sub_poses = yaml_list(entry.get("subframe_poses"), f"{where}.subframe_poses")
    if len(sub_names) != len(sub_poses):
        raise ConfigError(f"{where}.subframe_poses: {len(sub_poses)} poses for {len(sub_names)} subframe_names")
    subframes = {sub: pose(p, f"{where}.subframe_poses[{i}]")
                 for i, (sub, p) in enumerate(zip(sub_names, sub_poses, strict=True))}
    return ObjectMessage(name, header_frame(entry, where, ""), header_T_object, parts, subframes)


def _primitive(value: Any, where: str) -> Shape:
    """Return the shape of a shape_msgs/SolidPrimitive."""
    entry = mapping(value, where)
    check_keys(entry, {"type", "dimensions", "polygon"}, where)
    kind_value = entry.get("type")
    kind = _PRIMITIVES.get(kind_value) if isinstance(kind_value, int) and not isinstance(kind_value, bool) else (
        kind_value.lower() if isinstance(kind_value, str) else None)
    if kind not in _DIMENSIONS:
        raise ConfigError(f"{where}.type: unknown primitive type {kind_value!r}; expected box (1), sphere (2), "
                          "cylinder (3) or cone (4)")
    dims = entry.get("dimensions")
    size = len(_DIMENSIONS[kind].split(","))
    if not isinstance(dims, list) or len(dims) != size:
        raise ConfigError(f"{where}.dimensions: a {kind} takes {size} number{'s' * (size > 1)} "
                          f"[{_DIMENSIONS[kind]}], got {dims!r}")
    values = [number(v, f"{where}.dimensions[{i}]", positive=True, bound=MAX_MAGNITUDE) for i, v in enumerate(dims)]
    if kind == "box":
        return Shape("box", tuple(values))
    if kind == "sphere":
        return Shape("sphere", (values[0],))
    height, radius = values
    if kind == "cone":
        logger.warning("%s: a cone is checked as the cylinder that encloses it", where)
    return Shape("cylinder", (radius, height))


def _mesh(value: Any, where: str, folder: Path, packages: PackagePath) -> Shape:
    """Return the mesh of a shape_msgs/Mesh: inline, or a file named by `resource` (robowflex's extension)."""
    entry = mapping(value, where)
    check_keys(entry, {"triangles", "vertices", "resource", "dimensions"}, where)
    if "resource" in entry or "dimensions" in entry:
        return _mesh_file(entry, where, folder, packages)
    vertices = [point(v, f"{where}.vertices[{i}]")
                for i, v in enumerate(yaml_list(entry.get("vertices"), f"{where}.vertices"))]
    triangles = []
    for i, item in enumerate(yaml_list(entry.get("triangles"), f"{where}.triangles")):
        at = f"{where}.triangles[{i}]"
        if isinstance(item, dict):
            triangle = mapping(item, at)
            check_keys(triangle, {"vertex_indices"}, at)
            item, at = triangle.get("vertex_indices"), f"{at}.vertex_indices"
        if not (isinstance(item, list) and len(item) == 3
                and all(isinstance(n, int) and not isinstance(n, bool) and 0 <= n < len(vertices) for n in item)):
            raise ConfigError(f"{at}: expected 3 indices into vertices (0 to {len(vertices) - 1}), got {item!r}")
        triangles.append(item)
    if not triangles:
        raise ConfigError(f"{where}: a mesh needs vertices and triangles, or a resource (a mesh file)")
    return Shape("mesh", vertices=np.array(vertices), triangles=np.array(triangles))


def _mesh_file(entry: dict[str, Any], where: str, folder: Path, packages: PackagePath) -> Shape:
    """Return a mesh given by file: `resource` (a path or a package:// URI), scaled by `dimensions`."""
    if "triangles" in entry or "vertices" in entry:
        raise ConfigError(f"{where}: give a resource (a mesh file) or triangles and vertices, not both")
    uri = entry.get("resource")
    if not isinstance(uri, str) or not uri.strip():
        raise ConfigError(f"{where}.resource: expected a mesh file path or package:// URI, got {uri!r}")
    scale = entry.get("dimensions", [1.0, 1.0, 1.0])
    if not isinstance(scale, list) or len(scale) != 3:
        raise ConfigError(f"{where}.dimensions: expected the scale [x, y, z] of the mesh, got {scale!r}")
    sx, sy, sz = (number(v, f"{where}.dimensions[{i}]", positive=True, bound=MAX_MAGNITUDE)
                  for i, v in enumerate(scale))
    if len(uri) > 4096 or "\0" in uri:
        raise ConfigError(f"{where}.resource: {uri[:60]!r}... is not a file name or package:// URI")
    path, package = packages.resolve_uri(uri.strip(), folder, f"{where}.resource")
    inside = f" (package '{package}' is {packages.find(package, where)})" if package else ""
    try:
        found = path.is_file()
    except OSError:
        found = False
    if not found:
        raise ConfigError(f"{where}.resource: mesh file not found: {str(path)[:200]}{inside}")
    return Shape("mesh", (), str(mesh_file(path, f"{where}.resource")), (sx, sy, sz))
