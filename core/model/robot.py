"""Robot model: pinocchio kinematics of a robot config, seen through one planning group.

A robot state is a pinocchio configuration vector `q` (all joints); the planner
works on the group's joint values (`values`, one per active joint, in [rad] or
[m]). Joints outside the group keep their values from the start state. A mimic
joint is not active: it follows its leader (value = multiplier * leader + offset)
wherever the leader is set, as MoveIt's RobotState.updateMimicJoints does.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import NDArray

from .._kept import kept
from ..config import Group, RobotConfig, UrdfJoint
from ..errors import ConfigError, UnknownName
from ..rotations import tf_poses
from ..types import Frame, TfSamples
from ._joint_transforms import JointTable, joint_poses, joint_table

__all__ = ["Mimic", "Robot"]


@dataclass(frozen=True)
class Mimic:
    """A joint that follows one of the group's active joints: q[q_index] = multiplier * values[leader] + offset."""

    joint: str
    leader: int  # position of the leader in the group's values
    q_index: int
    multiplier: float
    offset: float


class Robot:
    """Kinematic model of `config` with one active planning group."""

    def __init__(self, config: RobotConfig, group: str | None = None) -> None:
        self.config = config
        self.group: Group = config.group(group)
        config.srdf.plannable(self.group.name, config.srdf_path)  # a floating or planar base: refused
        # Per URDF text, once per process: a benchmark makes a Robot per problem.
        facts = kept(_URDFS, config.urdf, lambda: _urdf_facts(config))
        self.model = facts.model  # shared per process: never modify
        self.data = self.model.createData()
        joints = config.urdf_joints
        # The group's variables (MoveIt's) include its mimic joints; its active joints, which are planned, do not.
        self.variable_names: tuple[str, ...] = self.group.joints
        self.joint_names: tuple[str, ...] = tuple(j for j in self.group.joints if not joints[j].mimic)
        if not self.joint_names:
            raise ConfigError(f"{config.srdf_path}: group '{self.group.name}' has no movable joints")
        _check_group(config, self.group)
        limits = [config.limits[j] for j in self.joint_names]
        self.lower = _readonly([lim.lower for lim in limits])
        self.upper = _readonly([lim.upper for lim in limits])
        self.max_velocity = _readonly([lim.max_velocity for lim in limits])
        self.max_acceleration = _readonly([lim.max_acceleration for lim in limits])
        self.continuous = np.array([lim.continuous for lim in limits])
        ids = [self.model.getJointId(j) for j in self.joint_names]
        self.q_index = np.array([self.model.idx_qs[i] for i in ids])
        # Worked out once: a search places thousands of edges' states in configurations.
        self._plain = np.flatnonzero(~self.continuous)
        self._turning = np.flatnonzero(self.continuous)
        self._plain_q, self._turning_q = self.q_index[self._plain], self.q_index[self._turning]
        self.link_names = facts.link_names
        self.mimics = tuple(
            Mimic(j.name, self.joint_names.index(j.mimic), int(self.model.idx_qs[self.model.getJointId(j.name)]),
                  j.mimic_multiplier, j.mimic_offset)
            for j in joints.values() if j.mimic in self.joint_names and self.model.existJointName(j.name))
        self._moving, self._moving_frames, self._joint_table = facts.moving, facts.moving_frames, facts.joint_table

    @property
    def dof(self) -> int:
        """Return the number of active joints in the group."""
        return len(self.joint_names)

    def configuration(self, values: npt.ArrayLike, base: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Return the pinocchio configuration with the group at `values`, other joints from `base`."""
        return self.configurations(np.asarray(values, dtype=float)[None, :], base)[:, 0]

    def configurations(
        self, values: NDArray[np.float64], base: NDArray[np.float64] | None = None
    ) -> NDArray[np.float64]:
        """Return configurations, shape (nq, k), for group values of shape (k, dof)."""
        base = self.neutral() if base is None else base
        q = np.repeat(base[:, None], len(values), axis=1)
        if len(self._turning):
            q[self._plain_q, :] = values[:, self._plain].T
            # A continuous joint is stored by pinocchio as (cos, sin).
            q[self._turning_q, :] = np.cos(values[:, self._turning]).T
            q[self._turning_q + 1, :] = np.sin(values[:, self._turning]).T
        else:
            q[self._plain_q, :] = values.T
        for mimic in self.mimics:
            q[mimic.q_index, :] = mimic.multiplier * values[:, mimic.leader] + mimic.offset
        return q

    def values(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the group's joint values in configuration `q`."""
        out: NDArray[np.float64] = q[self.q_index].astype(float)
        cont = self.continuous
        out[cont] = np.arctan2(q[self.q_index[cont] + 1], q[self.q_index[cont]])
        return out

    def neutral(self) -> NDArray[np.float64]:
        """Return the configuration where the robot starts when no start is given (RobotConfig.initial_positions)."""
        q = np.array(pin.neutral(self.model))
        for joint, value in self.config.initial_positions.items():
            q = self.set_joint(q, joint, value)
        return q

    def set_joint(self, q: NDArray[np.float64], joint: str, value: float) -> NDArray[np.float64]:
        """Return a copy of `q` with one joint set to `value`."""
        if not self.model.existJointName(joint):
            raise UnknownName("joint", joint, str(self.config.urdf_path), self.config.limits)
        jid = self.model.getJointId(joint)
        q = q.copy()
        index = self.model.idx_qs[jid]
        if self.model.nqs[jid] == 2:
            q[index : index + 2] = np.cos(value), np.sin(value)
        else:
            q[index] = value
        return q

    def frame_pose(self, q: NDArray[np.float64], frame: str) -> NDArray[np.float64]:
        """Return `root_T_frame`, the 4x4 pose of a link or frame in the URDF root frame."""
        if not self.model.existFrame(frame):
            raise UnknownName("link", frame, str(self.config.urdf_path), self.link_names)
        fid = self.model.getFrameId(frame)
        pin.framesForwardKinematics(self.model, self.data, q)
        return np.array(self.data.oMf[fid].homogeneous)

    def fixed_frames(self) -> tuple[Frame, ...]:
        """Return `parent_T_child` of every fixed URDF joint, as robot_state_publisher latches them."""
        pin.framesForwardKinematics(self.model, self.data, self.neutral())
        joints = [j for j in self.config.urdf_joints.values() if j.type == "fixed"]
        return tuple(Frame(j.child, j.parent, self._relative(j.parent, j.child)) for j in joints)

    def tf_samples(
        self, times_s: NDArray[np.float64], values: NDArray[np.float64], base: NDArray[np.float64]
    ) -> TfSamples:
        """Return `parent_T_child` of every moving URDF joint for group values (M, dof) at `times_s`, as /tf poses."""
        moving = self._moving
        q = self.configurations(np.asarray(values, dtype=float), base)
        if self._joint_table is not None:
            poses = joint_poses(self._joint_table, q)
        else:  # a joint kind not written out: pinocchio's own inverse and product, sample by sample
            rows = np.empty((len(values), len(moving), 4, 4))
            frames, pairs = self.data.oMf, self._moving_frames
            for k, column in enumerate(q.T):
                pin.framesForwardKinematics(self.model, self.data, column)
                rows[k] = [(frames[parent].inverse() * frames[child]).homogeneous for parent, child in pairs]
            poses = tf_poses(rows)
        return TfSamples(times_s, tuple(j.parent for j in moving), tuple(j.child for j in moving), poses)

    def _relative(self, parent: str, child: str) -> NDArray[np.float64]:
        """Return `parent_T_child` from the last forward kinematics."""
        frames = self.data.oMf
        root_T_parent, root_T_child = frames[self.model.getFrameId(parent)], frames[self.model.getFrameId(child)]
        return np.array((root_T_parent.inverse() * root_T_child).homogeneous)

    @property
    def root_link(self) -> str:
        """Return the URDF root link, the planning frame."""
        return str(self.model.frames[1].name) if len(self.model.frames) > 1 else "world"


def _check_group(config: RobotConfig, group: Group) -> None:
    """Raise ConfigError for a group joint moveplan cannot plan: a continuous mimic pair, a joint that cannot move.

    A joint with lower == upper would divide by its zero range in the collision tables.
    """
    where = f"{config.urdf_path}: group '{group.name}'"
    for joint in config.urdf_joints.values():
        if joint.mimic in group.joints and "continuous" in (joint.type, config.urdf_joints[joint.mimic].type):
            raise ConfigError(f"{where}: joint '{joint.name}' mimics '{joint.mimic}' and one of them is "
                              "continuous; moveplan follows a leader with revolute or prismatic joints only")
    for name in group.joints:
        limit = config.limits[name]
        if not config.urdf_joints[name].mimic and not limit.continuous and limit.lower == limit.upper:
            raise ConfigError(f"{where}: joint '{name}' has lower limit = upper limit ({limit.lower:g}), so it "
                              "cannot move; make it a fixed joint in the URDF, or widen its limits")


def _readonly(values: list[float]) -> NDArray[np.float64]:
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class _UrdfFacts:
    """What a Robot reads of its URDF alone: pinocchio's model, link names, moving joints and their /tf table."""

    model: pin.Model
    link_names: tuple[str, ...]
    moving: tuple[UrdfJoint, ...]  # what /tf carries
    moving_frames: tuple[tuple[int, int], ...]  # each moving joint's parent and child frame ids
    joint_table: JointTable | None


_URDFS: dict[str, _UrdfFacts] = {}


def _urdf_facts(config: RobotConfig) -> _UrdfFacts:
    """Return the model of the config's URDF, its link names, moving joints, their frames and their /tf table."""
    model = _parsed(config)
    moving = tuple(j for j in config.urdf_joints.values() if j.type != "fixed")
    frames = tuple((model.getFrameId(j.parent), model.getFrameId(j.child)) for j in moving)
    return _UrdfFacts(model, tuple(f.name for f in model.frames if f.type == pin.FrameType.BODY), moving, frames,
                      joint_table(model, frames))


def _parsed(config: RobotConfig) -> pin.Model:
    """Return pinocchio's model of the config's URDF; ConfigError names the file and urdfdom's complaint."""
    error: Exception | None = None
    with _stderr_of_c_code() as log:
        try:
            model = pin.buildModelFromXML(config.urdf)
        except (RuntimeError, ValueError) as exc:
            error = exc
    # urdfdom says what is wrong only in its log (the exception names nothing), and logs an element it
    # drops (a collision shape it cannot read) yet loads the rest: a robot missing a shape.
    errors = list(dict.fromkeys(line.removeprefix("Error:").strip() for line in log if line.startswith("Error:")))
    if error is not None:
        raise ConfigError(f"{config.urdf_path}: pinocchio cannot load the URDF: {_joined(errors) or error}")
    if errors:
        raise ConfigError(f"{config.urdf_path}: urdfdom cannot read part of the URDF: {_joined(errors)}")
    return model


def _joined(errors: list[str]) -> str:
    """Return urdfdom's first error messages on one line: the first says what, the next which link or joint."""
    text = "; ".join(errors[:2])
    return text if len(text) <= 400 else f"{text[:397]}..."


@contextlib.contextmanager
def _stderr_of_c_code() -> Iterator[list[str]]:
    """Yield a list that gets the lines C++ code (urdfdom's log) wrote on file descriptor 2 meanwhile, not shown."""
    sys.stderr.flush()
    saved = os.dup(2)
    lines: list[str] = []
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            lines.extend(sink.read(65536).decode("utf-8", "replace").splitlines())
