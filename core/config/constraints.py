"""moveit_msgs/Constraints as path constraints: what every state of a motion must satisfy, read as MoveIt reads them.

- A joint constraint holds `joint_name` within [position - tolerance_below, position + tolerance_above].
- An orientation constraint holds `link_name`'s orientation within `absolute_*_axis_tolerance` [rad]
  of `orientation` (in `header.frame_id`), the error measured as MoveIt 1's
  kinematic_constraints::OrientationConstraint does: XYZ Euler angles (the default) or a
  rotation vector (`parameterization` 1) of R_target^T R_link.
- A position constraint holds the point `target_point_offset` (in the link's frame) of
  `link_name` inside one of `constraint_region`'s primitives (box, sphere, cylinder) at their
  poses in `header.frame_id`. Meshes as regions are refused.

Frames are placed where the motion starts. Weights are ignored (MoveIt's are for goal
sampling); visibility constraints are refused. The same reader serves a task file's step,
a MotionPlanRequest's `path_constraints` and MoveGroupCommander.set_path_constraints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..types import Shape, frozen_array
from .fields import MAX_MAGNITUDE, check_keys, mapping, number
from .ros_messages import header_frame, point, pose, quaternion, yaml_list

__all__ = ["ARC_POINTS", "ArcPoint", "JointBound", "OrientationBound", "PathConstraints", "PositionBound", "arc_point",
           "path_constraints"]

ARC_POINTS = ("interim", "center")
"""Names of Constraints that give Pilz's CIRC its third point instead of constraining the path."""

_KEYS = {"name", "joint_constraints", "position_constraints", "orientation_constraints", "visibility_constraints"}
_JOINT_KEYS = {"joint_name", "position", "tolerance_above", "tolerance_below", "weight"}
_ORIENTATION_KEYS = {"header", "orientation", "link_name", "absolute_x_axis_tolerance", "absolute_y_axis_tolerance",
                     "absolute_z_axis_tolerance", "parameterization", "weight"}
_POSITION_KEYS = {"header", "link_name", "target_point_offset", "constraint_region", "weight"}
_REGION_KEYS = {"primitives", "primitive_poses", "meshes", "mesh_poses"}
_PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder"}


@dataclass(frozen=True)
class JointBound:
    """A joint kept within [lower, upper] in [rad] or [m]."""

    joint: str
    lower: float
    upper: float


@dataclass(frozen=True)
class OrientationBound:
    """A link kept oriented as `quat` [x, y, z, w] in `frame`, each axis error within `tolerance` [rad]."""

    link: str
    frame: str
    quat: tuple[float, float, float, float]
    tolerance: tuple[float, float, float]
    rotation_vector: bool = False


@dataclass(frozen=True)
class PositionBound:
    """A point of a link (`offset` in its frame) kept inside one of `region`'s shapes, each at its pose in `frame`."""

    link: str
    frame: str
    offset: tuple[float, float, float]
    region: tuple[tuple[Shape, NDArray[np.float64]], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "region", tuple((shape, frozen_array(where, (4, 4), "region pose"))
                                                 for shape, where in self.region))


@dataclass(frozen=True)
class PathConstraints:
    """What every state of a motion must satisfy; `source` names where it was written, for messages."""

    joints: tuple[JointBound, ...] = ()
    orientations: tuple[OrientationBound, ...] = ()
    positions: tuple[PositionBound, ...] = ()
    source: str = ""

    def describe(self) -> dict[str, Any]:
        """Return the constraints as the plan JSON reports them."""
        return {"joints": [[b.joint, b.lower, b.upper] for b in self.joints],
                "orientations": [{"link": b.link, "frame": b.frame, "quat": list(b.quat),
                                  "tolerance": list(b.tolerance)} for b in self.orientations],
                "positions": [{"link": b.link, "frame": b.frame, "offset": list(b.offset),
                               "shapes": len(b.region)} for b in self.positions]}


@dataclass(frozen=True)
class ArcPoint:
    """Pilz's CIRC point: the arc passes through it ("interim") or turns about it ("center"); in `frame` [m]."""

    kind: str
    xyz: tuple[float, float, float]
    frame: str


def arc_point(value: Any, where: str) -> ArcPoint:
    """Return the point of a Constraints named "interim" or "center", as Pilz's CIRC reads it.

    The point is the first primitive pose of the one position constraint's region, in its header frame.

    Raises:
        ConfigError: Another name, or not exactly one position constraint with a region pose.
    """
    entry = mapping(value, where)
    check_keys(entry, _KEYS, where)
    name = entry.get("name")
    if name not in ARC_POINTS:
        raise ConfigError(f"{where}.name: Pilz's CIRC takes its point from constraints named 'interim' or 'center', "
                          f"got {name!r}")
    items = yaml_list(entry.get("position_constraints"), f"{where}.position_constraints")
    if len(items) != 1:
        raise ConfigError(f"{where}.position_constraints: CIRC's {name} point is one position constraint, got "
                          f"{len(items)}")
    item = mapping(items[0], f"{where}.position_constraints[0]")
    region = mapping(item.get("constraint_region"), f"{where}.position_constraints[0].constraint_region")
    poses = yaml_list(region.get("primitive_poses"), f"{where}.position_constraints[0].constraint_region"
                      ".primitive_poses")
    if not poses:
        raise ConfigError(f"{where}.position_constraints[0].constraint_region.primitive_poses: CIRC's {name} "
                          "point is the first pose's position; there is none")
    xyz = pose(poses[0], f"{where}.position_constraints[0].constraint_region.primitive_poses[0]")[:3, 3]
    frame = header_frame(item, f"{where}.position_constraints[0]", "")
    return ArcPoint(str(name), (float(xyz[0]), float(xyz[1]), float(xyz[2])), frame)


def path_constraints(value: Any, where: str) -> PathConstraints | None:
    """Return a moveit_msgs/Constraints mapping's constraints, None when it constrains nothing.

    Raises:
        ConfigError: A malformed constraint (names `where` and the key), a tolerance below 0,
            a mesh region, or a visibility constraint.
    """
    entry = mapping(value, where)
    check_keys(entry, _KEYS, where)
    if yaml_list(entry.get("visibility_constraints"), f"{where}.visibility_constraints"):
        raise ConfigError(f"{where}.visibility_constraints: not supported (they need a sensor model)")
    joints = tuple(_joint(item, f"{where}.joint_constraints[{k}]")
                   for k, item in enumerate(yaml_list(entry.get("joint_constraints"), f"{where}.joint_constraints")))
    orientations = tuple(
        _orientation(item, f"{where}.orientation_constraints[{k}]")
        for k, item in enumerate(yaml_list(entry.get("orientation_constraints"), f"{where}.orientation_constraints")))
    positions = tuple(
        _position(item, f"{where}.position_constraints[{k}]")
        for k, item in enumerate(yaml_list(entry.get("position_constraints"), f"{where}.position_constraints")))
    if not (joints or orientations or positions):
        return None
    return PathConstraints(joints, orientations, positions, where)


def _joint(value: Any, where: str) -> JointBound:
    """Return a moveit_msgs/JointConstraint as bounds."""
    entry = mapping(value, where)
    check_keys(entry, _JOINT_KEYS, where)
    name = entry.get("joint_name")
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{where}.joint_name: expected a joint name, got {name!r}")
    position = number(entry.get("position", 0.0), f"{where}.position", bound=MAX_MAGNITUDE)
    above, below = (_tolerance(entry, key, where) for key in ("tolerance_above", "tolerance_below"))
    return JointBound(name, position - below, position + above)


def _orientation(value: Any, where: str) -> OrientationBound:
    """Return a moveit_msgs/OrientationConstraint."""
    entry = mapping(value, where)
    check_keys(entry, _ORIENTATION_KEYS, where)
    link = _link(entry, where)
    quat = quaternion(entry.get("orientation"), f"{where}.orientation") or [0.0, 0.0, 0.0, 1.0]
    tolerance = tuple(_tolerance(entry, f"absolute_{axis}_axis_tolerance", where) for axis in "xyz")
    parameterization = entry.get("parameterization", 0)
    if parameterization not in (0, 1) or isinstance(parameterization, bool):
        raise ConfigError(f"{where}.parameterization: expected 0 (XYZ Euler angles) or 1 (rotation vector), "
                          f"got {parameterization!r}")
    return OrientationBound(link, header_frame(entry, where, ""), (quat[0], quat[1], quat[2], quat[3]),
                            (tolerance[0], tolerance[1], tolerance[2]), parameterization == 1)


def _position(value: Any, where: str) -> PositionBound:
    """Return a moveit_msgs/PositionConstraint."""
    entry = mapping(value, where)
    check_keys(entry, _POSITION_KEYS, where)
    link = _link(entry, where)
    offset = point(entry.get("target_point_offset", {}), f"{where}.target_point_offset")
    region = mapping(entry.get("constraint_region"), f"{where}.constraint_region")
    check_keys(region, _REGION_KEYS, f"{where}.constraint_region")
    if yaml_list(region.get("meshes"), f"{where}.constraint_region.meshes"):
        raise ConfigError(f"{where}.constraint_region.meshes: mesh regions are not supported; use primitives")
    primitives = yaml_list(region.get("primitives"), f"{where}.constraint_region.primitives")
    poses = yaml_list(region.get("primitive_poses"), f"{where}.constraint_region.primitive_poses")
    if not primitives or len(primitives) != len(poses):
        raise ConfigError(f"{where}.constraint_region: expected primitives, one pose each; got {len(primitives)} "
                          f"primitives and {len(poses)} poses")
    shapes = tuple((_primitive(item, f"{where}.constraint_region.primitives[{k}]"),
                    pose(poses[k], f"{where}.constraint_region.primitive_poses[{k}]"))
                   for k, item in enumerate(primitives))
    return PositionBound(link, header_frame(entry, where, ""), (offset[0], offset[1], offset[2]), shapes)


def _primitive(value: Any, where: str) -> Shape:
    """Return a region's shape_msgs/SolidPrimitive (box x, y, z; sphere radius; cylinder height, radius)."""
    entry = mapping(value, where)
    code = entry.get("type")
    kind = _PRIMITIVES.get(code) if isinstance(code, int) and not isinstance(code, bool) else None
    if kind is None:
        raise ConfigError(f"{where}.type: expected a box (1), sphere (2) or cylinder (3), got {entry.get('type')!r}")
    dims = entry.get("dimensions")
    size = {"box": 3, "sphere": 1, "cylinder": 2}[kind]
    if not isinstance(dims, list) or len(dims) != size:
        raise ConfigError(f"{where}.dimensions: a {kind} takes {size} numbers, got {dims!r}")
    values = [number(v, f"{where}.dimensions[{i}]", positive=True, bound=MAX_MAGNITUDE) for i, v in enumerate(dims)]
    if kind == "box":
        return Shape("box", tuple(values))
    if kind == "sphere":
        return Shape("sphere", tuple(values))
    return Shape("cylinder", (values[1], values[0]))


def _link(entry: dict[str, Any], where: str) -> str:
    """Return a constraint's link_name, checked to be a name."""
    link = entry.get("link_name")
    if not isinstance(link, str) or not link:
        raise ConfigError(f"{where}.link_name: expected a link name, got {link!r}")
    return link


def _tolerance(entry: dict[str, Any], key: str, where: str) -> float:
    """Return a tolerance >= 0 (MoveIt's default 0 where absent)."""
    value = number(entry.get(key, 0.0), f"{where}.{key}", bound=MAX_MAGNITUDE)
    if not value >= 0.0 or not math.isfinite(value):
        raise ConfigError(f"{where}.{key}: expected a tolerance >= 0, got {value!r}")
    return value
