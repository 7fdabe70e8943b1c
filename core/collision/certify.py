"""Where to check a motion so that no point of the robot moves more than a distance between checks.

A joint turning by d [rad] moves a point at distance r from its origin by at most
r * |d|. `reach` bounds r for each group joint over every configuration: the joint
origins down the kinematic tree are a fixed distance apart, and each collision shape
lies within a fixed distance of its own joint. Summed over the joints, that bounds
how far any robot point (attached objects included) moves in a joint-space step, so
states placed by it certify a motion at a resolution given in metres, not radians.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..model.robot import Robot
from ..trajectory import peak_rates, sample, straight_states
from ..types import JointTrajectory

__all__ = ["farthest_point", "is_prismatic", "reach", "segment_states", "trajectory_states"]


def reach(robot: Robot, geometry: pin.GeometryModel) -> NDArray[np.float64]:
    """Return per group joint the largest distance [m] from its axis origin to any robot collision point.

    For a prismatic joint the answer is 1: a point moves as far as the joint.
    """
    model = robot.model
    extent = np.zeros(model.njoints)  # per joint: farthest point of the shapes it carries
    for obj in geometry.geometryObjects:
        if obj.parentJoint == 0:
            continue  # world objects do not move
        extent[obj.parentJoint] = max(extent[obj.parentJoint], farthest_point(obj))
    travel = np.zeros(model.njoints)  # how far a prismatic joint can push its children out
    for jid in range(1, model.njoints):
        if is_prismatic(model.joints[jid].shortname()):
            index = model.idx_qs[jid]
            travel[jid] = max(abs(model.lowerPositionLimit[index]), abs(model.upperPositionLimit[index]))
    # Farthest point below each joint, from the leaves up: a child's origin is a fixed offset away.
    below = extent.copy()
    for jid in range(model.njoints - 1, 0, -1):
        parent = model.parents[jid]
        if parent > 0:
            offset = np.linalg.norm(model.jointPlacements[jid].translation) + travel[jid]
            below[parent] = max(below[parent], offset + below[jid])
    out = []
    for name in robot.joint_names:
        jid = model.getJointId(name)
        out.append(1.0 if is_prismatic(model.joints[jid].shortname()) else below[jid])
    return np.array(out)


def is_prismatic(kind: str) -> bool:
    """Return True for pinocchio's prismatic joint models (JointModelPX/PY/PZ/PrismaticUnaligned)."""
    return kind in ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


def farthest_point(obj: pin.GeometryObject) -> float:
    """Return the largest distance from its joint's origin to a point of a collision shape."""
    geometry = obj.geometry
    geometry.computeLocalAABB()  # pinocchio has already scaled a mesh when it loaded it
    lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    placement = obj.placement
    points = corners @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
    return float(np.max(np.linalg.norm(points, axis=1)))


def segment_states(
    a: NDArray[np.float64], b: NDArray[np.float64], reach_m: NDArray[np.float64], step_m: float
) -> NDArray[np.float64]:
    """Return states from `a` to `b` (both included) along the straight segment, at most `step_m` of motion apart."""
    motion = float(np.abs(b - a) @ reach_m)
    return straight_states(a, b, max(1, int(np.ceil(motion / step_m))))


def trajectory_states(
    trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float
) -> NDArray[np.float64]:
    """Return states along the interpolated trajectory, at most `step_m` of robot motion apart.

    Between two samples dt apart a joint moves at most its peak speed times dt, and the
    peaks are exact for the controller's quintic segments.
    """
    knots = trajectory.times_s
    if len(knots) == 1:
        return np.asarray(trajectory.positions)
    speed = float(peak_rates(trajectory)[0] @ reach_m)  # [m/s], bounds every point's speed
    count = max(1, int(np.ceil(speed * (knots[-1] - knots[0]) / step_m)))
    times = np.linspace(knots[0], knots[-1], count + 1)
    positions, _, _ = sample(trajectory, times, derivatives=0)
    return positions
