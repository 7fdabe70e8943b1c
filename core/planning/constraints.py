"""Path constraints decided on group values: joint bounds, a link's orientation, a link point inside a region.

Frames are placed where the motion starts (a frame on a moving link stays where it was). The
orientation error is MoveIt 1's (kinematic_constraints::OrientationConstraint::decide): the
rotation R_target^T R_link as intrinsic XYZ Euler angles, each folded into [0, pi/2] as
MoveIt folds them, or as a rotation vector.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..config import PathConstraints
from ..errors import UnknownName
from ..model import Robot, Scene
from ..rotations import matrix_from_quaternion, rotation_vector

__all__ = ["PathCheck"]


@dataclass(frozen=True)
class _Orientation:
    link: str
    target_inv: NDArray[np.float64]  # R_target^T in the planning frame
    tolerance: NDArray[np.float64]
    rotation_vector: bool


@dataclass(frozen=True)
class _Position:
    link: str
    offset: NDArray[np.float64]
    regions: tuple[tuple[str, tuple[float, ...], NDArray[np.float64]], ...]  # kind, dims, shape_T_root


class PathCheck:
    """Whether group values satisfy path constraints, with the joint bounds they narrow the search to."""

    def __init__(self, robot: Robot, scene: Scene, constraints: PathConstraints, q: NDArray[np.float64]) -> None:
        self.robot, self.base, self.source = robot, q, constraints.source
        self.lower, self.upper = np.array(robot.lower), np.array(robot.upper)
        self._others: list[tuple[str, float, float]] = []  # joints outside the group: they keep their start
        for bound in constraints.joints:
            if bound.joint in robot.joint_names:
                i = robot.joint_names.index(bound.joint)
                self.lower[i], self.upper[i] = max(self.lower[i], bound.lower), min(self.upper[i], bound.upper)
            elif bound.joint in robot.config.limits:
                self._others.append((bound.joint, bound.lower, bound.upper))
            else:
                raise UnknownName("joint", bound.joint, f"{constraints.source} (joint constraints)",
                                  robot.config.limits)
        self._orientations = tuple(
            _Orientation(self._link(b.link),
                         (self._frame(scene, b.frame, q)[:3, :3] @ matrix_from_quaternion(b.quat)).T,
                         np.array(b.tolerance), b.rotation_vector)
            for b in constraints.orientations)
        self._positions = tuple(
            _Position(self._link(b.link), np.array(b.offset),
                      tuple((shape.kind, shape.dims, np.asarray(np.linalg.inv(self._frame(scene, b.frame, q) @ shape_T),
                                                                dtype=float))
                            for shape, shape_T in b.region))
            for b in constraints.positions)

    def satisfied(self, values: NDArray[np.float64]) -> bool:
        """Return True if group values satisfy every constraint."""
        return self.violation(values) is None

    def violation(self, values: NDArray[np.float64]) -> str | None:
        """Return which constraint group values violate and by how much, None if they satisfy all."""
        below, above = values < self.lower - 1e-9, values > self.upper + 1e-9
        if below.any() or above.any():
            i = int(np.flatnonzero(below | above)[0])
            return (f"joint '{self.robot.joint_names[i]}' at {values[i]:.6g} outside [{self.lower[i]:.6g}, "
                    f"{self.upper[i]:.6g}]")
        if not (self._orientations or self._positions or self._others):
            return None
        q = self.robot.configuration(values, self.base)
        for joint, lower, upper in self._others:
            value = float(q[self.robot.model.idx_qs[self.robot.model.getJointId(joint)]])
            if not lower <= value <= upper:
                return f"joint '{joint}' at {value:.6g} outside [{lower:.6g}, {upper:.6g}] (it is not in the group)"
        for orientation in self._orientations:
            error = _orientation_error(orientation, self.robot.frame_pose(q, orientation.link)[:3, :3])
            if (error > orientation.tolerance + 1e-9).any():
                return (f"orientation of '{orientation.link}' off by {np.round(error, 6).tolist()} rad (tolerances "
                        f"{orientation.tolerance.tolist()})")
        for position in self._positions:
            link_T = self.robot.frame_pose(q, position.link)
            point = link_T[:3, :3] @ position.offset + link_T[:3, 3]
            if not any(_inside(kind, dims, (shape_T_root[:3, :3] @ point + shape_T_root[:3, 3]))
                       for kind, dims, shape_T_root in position.regions):
                return f"point of '{position.link}' at {np.round(point, 6).tolist()} outside its region"
        return None

    def edge(self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float) -> bool:
        """Return True if the states of the straight edge a-b, `resolution` [rad or m] apart, all satisfy."""
        count = max(1, math.ceil(float(np.max(np.abs(b - a))) / resolution))
        return all(self.satisfied(a + (b - a) * (k / count)) for k in range(1, count + 1))

    def _link(self, link: str) -> str:
        """Return `link` if the robot has it, else raise UnknownName."""
        if not self.robot.model.existFrame(link):
            raise UnknownName("link", link, f"{self.source} (path constraints)", self.robot.link_names)
        return link

    def _frame(self, scene: Scene, frame: str, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return `root_T_frame` of a constraint's header frame, placed with the robot at `q`."""
        anchor, anchor_T_frame = scene.anchor(frame or self.robot.root_link, self.robot)
        return self.robot.frame_pose(q, anchor) @ anchor_T_frame


def _orientation_error(bound: _Orientation, rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the per-axis error [rad] of a link rotation from the constraint's, as MoveIt measures it."""
    diff = bound.target_inv @ rotation
    if bound.rotation_vector:
        return np.abs(rotation_vector(diff))
    # Eigen's eulerAngles(0, 1, 2): intrinsic X-Y-Z, first angle in [0, pi]; MoveIt then folds each angle.
    x = math.atan2(diff[1, 2] * -1.0, diff[2, 2])
    y = math.atan2(diff[0, 2], math.hypot(diff[0, 0], diff[0, 1]))
    z = math.atan2(-diff[0, 1], diff[0, 0])
    return np.array([min(abs(a), math.pi - abs(a)) for a in (x, y, z)])


def _inside(kind: str, dims: tuple[float, ...], p: NDArray[np.float64]) -> bool:
    """Return True if point `p`, in a shape's frame, lies inside the shape."""
    if kind == "box":
        return bool(np.all(np.abs(p) <= np.asarray(dims) / 2.0))
    if kind == "sphere":
        return float(np.linalg.norm(p)) <= dims[0]
    radius, height = dims
    return math.hypot(p[0], p[1]) <= radius and abs(p[2]) <= height / 2.0
