"""MoveGroupCommander: MoveIt 1 Noetic's Python API for one planning group, planning and executing in memory.

Names, arguments, defaults and return shapes are moveit_commander's (move_group.py): a target
is set, then plan() returns (success, RobotTrajectory, planning time, MoveItErrorCodes), go()
plans and executes, execute() runs a trajectory on the simulated controller, and the robot's
current state moves to where the execution ended. A motion is one step of `moveplan plan`
(core/pipeline/session.py); execution is `moveplan execute --fake`'s.

The joint target is MoveIt's joint state target: it starts at the model's default values, a
partial target (a dict, a joint name) changes only the joints it names, and it stays when a
pose target is set. A group's values are its variables, mimic joints included (a gripper's
`[0.035, 0.035]`); only the joints they follow are planned.
"""

from __future__ import annotations

import logging
import math
import numbers
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any, cast

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..core.config import (
    ARC_POINTS,
    PILZ_PLANNERS,
    SHIFT_AXES,
    Goal,
    JointGoal,
    NamedGoal,
    PoseGoal,
    PositionGoal,
    ShiftGoal,
    StepSpec,
    arc_point,
    default_position,
    parse_goal_tolerances,
    path_constraints,
    pose_matrix,
)
from ..core.control import ExecutionSummary
from ..core.errors import ConfigError, NoPlan, UnknownName, UsageError
from ..core.model import solve_ik
from ..core.pipeline import cartesian_motion, execute_motion, plan_motion
from ..core.planning import joint_target, tip_target
from ..core.timing import time_parameterize
from ..core.types import GoalTolerances, StepResult
from ._messages import state_message
from ._objects import attach_existing, detach
from ._settings import PlanningSettings, real_number, scaling
from ._targets import finite_number, joint_goal, pose_goal
from ._world import current_world
from .conversions import matrix_to_pose, pose_to_list
from .msgs import (
    Constraints,
    DeserializationError,
    JointState,
    MoveItErrorCodes,
    Pose,
    PoseStamped,
    RobotState,
    RobotTrajectory,
    plain,
)
from .trajectory import error_code, from_message, to_message
from .transformations import euler_from_quaternion

__all__ = ["MoveGroupCommander"]

logger = logging.getLogger(__name__)

# MoveIt's names of its time parameterizations; moveplan times each one with its own TOPP.
_RETIMING = ("iterative_time_parameterization", "iterative_spline_parameterization",
             "time_optimal_trajectory_generation")


class MoveGroupCommander(PlanningSettings):
    """Execution of simple commands for one planning group: targets, plan(), go(), execute().

    Args:
        name: The SRDF planning group.
        robot_description: Its RobotCommander; MoveIt's robot_description string, or None: the
            one created last (one is made from `$MOVEPLAN_ROBOT` if there is none).
        ns, wait_for_servers: MoveIt's; accepted and unused (there is no ROS graph to wait for).
    """

    def __init__(self, name: str, robot_description: Any = "robot_description", ns: str = "",
                 wait_for_servers: float = 5.0) -> None:
        super().__init__()
        self._world = current_world(robot_description, f"MoveGroupCommander('{name}')")
        self._robot = self._world.robot(name)
        self._name = name
        self._eef = self._robot.group.tip
        self._reference = self._robot.root_link
        defaults = [default_position(self._world.config.limits[j]) for j in self._robot.joint_names]
        self._joint_target = np.array(defaults)  # MoveIt's joint state target, the group's active joints
        self._named: str | None = None  # the named target the joint target was set from, for the step's name
        self._pose_targets: dict[str, Goal] = {}
        self._start: dict[str, float] | None = None
        self._remembered: dict[str, list[float]] = {}
        self._constraints: Constraints | None = None
        self._last: ExecutionSummary | None = None

    # The group ---------------------------------------------------------------------------------

    def get_name(self) -> str:
        """Return the name of the group."""
        return self._name

    def get_active_joints(self) -> list[str]:
        """Return the group's active joints (movable, not mimic), in group order."""
        return list(self._robot.joint_names)

    def get_joints(self) -> list[str]:
        """Return the group's joints, fixed and mimic ones included, as MoveIt lists them."""
        joints = self._world.config.urdf_joints
        above = {joint.child: name for name, joint in joints.items()}
        return [above[link] for link in self._robot.group.links]

    def get_variable_count(self) -> int:
        """Return the number of values a state of the group has (mimic joints included)."""
        return len(self._robot.variable_names)

    def has_end_effector_link(self) -> bool:
        """Return True if the group has a link pose targets move."""
        return bool(self._eef)

    def get_end_effector_link(self) -> str:
        """Return the link pose targets move: the group's tip unless set_end_effector_link changed it."""
        return self._eef

    def set_end_effector_link(self, link_name: str) -> None:
        """Make `link_name` the link pose targets move; return None."""
        self._eef = self._link(link_name, "set_end_effector_link")

    def get_pose_reference_frame(self) -> str:
        """Return the frame Pose and list targets and Cartesian waypoints are read in (default: the planning frame)."""
        return self._reference

    def set_pose_reference_frame(self, reference_frame: str) -> None:
        """Read Pose and list targets and waypoints in `reference_frame` (a link or scene frame); return None."""
        self._world.pose(reference_frame)
        self._reference = reference_frame

    def get_planning_frame(self) -> str:
        """Return the frame planning is done in: the URDF's root link."""
        return self._robot.root_link

    # The current state --------------------------------------------------------------------------

    def get_current_joint_values(self) -> list[float]:
        """Return the group's current values (mimic joints included), in group order, in [rad] or [m]."""
        return self._variables(self._robot.values(self._world.q))

    def get_current_pose(self, end_effector_link: str = "") -> PoseStamped:
        """Return the current pose of the end-effector (or `end_effector_link`), stamped in the planning frame."""
        link = self._link(end_effector_link or self._eef, "get_current_pose")
        stamped = PoseStamped(pose=matrix_to_pose(self._world.pose(link)))
        stamped.header.frame_id = self.get_planning_frame()
        return stamped

    def get_current_rpy(self, end_effector_link: str = "") -> list[float]:
        """Return [roll, pitch, yaw] in [rad] (fixed axes) of the end-effector's current orientation."""
        return list(euler_from_quaternion(pose_to_list(self.get_current_pose(end_effector_link).pose)[3:]))

    def get_current_state(self) -> RobotState:
        """Return the robot's current state: every movable joint's position, in the planning frame."""
        return state_message(self._world)

    def get_current_state_bounded(self) -> RobotState:
        """Return the current state with every joint within its limits (MoveIt's)."""
        return self.enforce_bounds(self.get_current_state())

    def set_start_state_to_current_state(self) -> None:
        """Plan from the current state again (the default); return None."""
        self._start = None

    def set_start_state(self, msg: RobotState) -> None:
        """Plan from the joint positions of a RobotState (joints it leaves out: current; none: the current state)."""
        if not isinstance(msg, RobotState):
            raise UsageError(f"set_start_state: expected a RobotState, got {type(msg).__name__}")
        state = msg.joint_state
        if len(state.name) != len(state.position):
            raise UsageError(f"set_start_state: joint_state has {len(state.name)} names and {len(state.position)} "
                             "positions")
        names = self._world.joint_names()
        for joint in state.name:
            if joint not in names:
                raise UnknownName("joint", joint, "set_start_state (the robot's movable joints)", names)
        pairs = zip(state.name, state.position, strict=True)
        self._start = {str(n): finite_number(v, f"set_start_state: {n}") for n, v in pairs}

    def enforce_bounds(self, robot_state_msg: RobotState) -> RobotState:
        """Return a copy of a RobotState with every joint position clamped into its limits.

        Raises:
            DeserializationError: The state names no joints (MoveIt cannot read it either).
            UnknownName: A joint the robot does not have.
        """
        state = getattr(robot_state_msg, "joint_state", None)
        if state is None or not state.name:
            raise DeserializationError("enforce_bounds: the RobotState names no joints")
        if len(state.name) != len(state.position):
            raise UsageError(f"enforce_bounds: joint_state has {len(state.name)} names and {len(state.position)} "
                             "positions")
        limits = self._world.config.limits
        out = RobotState(JointState(state.header, list(state.name), [], list(state.velocity), list(state.effort)))
        out.multi_dof_joint_state = robot_state_msg.multi_dof_joint_state
        out.attached_collision_objects = list(robot_state_msg.attached_collision_objects)
        out.is_diff = robot_state_msg.is_diff
        for name, value in zip(state.name, state.position, strict=True):
            if name not in limits:
                raise UnknownName("joint", str(name), "enforce_bounds (the robot's movable joints)", limits)
            limit, number = limits[name], finite_number(value, f"enforce_bounds: {name}")
            out.joint_state.position.append(number if limit.continuous else min(max(number, limit.lower),
                                                                                  limit.upper))
        return out

    def get_jacobian_matrix(self, joint_values: Sequence[float], reference_point: Sequence[float] | None = None,
                            use_quaternion_representation: bool = False) -> NDArray[np.float64]:
        """Return the 6 x n Jacobian of the end-effector at the group's `joint_values`, in the planning frame.

        Rows: linear velocity of `reference_point` (in the end-effector's frame, default its
        origin), then angular velocity; one column per active joint (a mimic joint's motion is
        added to its leader's column), as MoveIt's RobotState::getJacobian.
        """
        if use_quaternion_representation:
            raise UsageError("get_jacobian_matrix: use_quaternion_representation is not supported")
        values = self._active(joint_values, "get_jacobian_matrix")
        robot = self._robot
        q = robot.configuration(values, self._world.q)
        model, data = robot.model, robot.data
        frame = model.getFrameId(self._eef)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        full = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
        if reference_point is not None:
            offset = data.oMf[frame].rotation @ np.asarray([float(v) for v in reference_point][:3])
            full[:3] -= pin.skew(offset) @ full[3:]  # v_point = v_origin + w x offset
        columns = [model.idx_vs[model.getJointId(j)] for j in robot.joint_names]
        jacobian: NDArray[np.float64] = np.array(full[:, columns], dtype=float)
        for mimic in robot.mimics:
            jacobian[:, mimic.leader] += mimic.multiplier * full[:, model.idx_vs[model.getJointId(mimic.joint)]]
        return jacobian

    def get_random_joint_values(self) -> list[float]:
        """Return random values of the group within its limits (seeded by the RobotCommander's seed)."""
        return self._variables(self._random_values())

    def get_random_pose(self, end_effector_link: str = "") -> PoseStamped:
        """Return the end-effector's pose at random joint values, stamped in the planning frame."""
        link = self._link(end_effector_link or self._eef, "get_random_pose")
        q = self._robot.configuration(self._random_values(), self._world.q)
        stamped = PoseStamped(pose=matrix_to_pose(self._world.pose(link, q)))
        stamped.header.frame_id = self.get_planning_frame()
        return stamped

    # Targets ------------------------------------------------------------------------------------

    def get_joint_value_target(self) -> list[float]:
        """Return the joint target (MoveIt's joint state target: it stays when a pose target is set)."""
        return self._variables(self._joint_target)

    def set_joint_value_target(self, arg1: Any, arg2: Any = None, arg3: Any = None) -> None:
        """Set the joint target: all values, a dict joint: value, a JointState, a RobotState or (joint, value).

        A partial target changes only the joints it names, as in MoveIt. A Pose or PoseStamped
        (with an end-effector link as arg2 or arg3) sets the joint target to an inverse
        kinematics solution for it, from where the motion starts, as MoveIt does; return None.
        """
        if isinstance(arg1, Pose | PoseStamped):
            link = next((a for a in (arg2, arg3) if isinstance(a, str) and a), self._eef)
            self._set_joints(self._solve(pose_goal(arg1, self._link(link, "set_joint_value_target"),
                                                   self._reference, "set_joint_value_target")))
            return
        if arg3 is not None:
            raise UsageError("set_joint_value_target: too many arguments")
        if isinstance(arg1, RobotState):
            arg1 = arg1.joint_state
        goal = joint_goal(arg1, arg2, self._robot.variable_names, "set_joint_value_target")
        if goal.joints is None:  # every variable: mimic joints follow their leaders
            goal = JointGoal.by_name(dict(zip(self._robot.variable_names, goal.values, strict=True)))
        self._set_joints(joint_target(self._robot, goal, self._joint_target, "set_joint_value_target"))

    def set_pose_target(self, pose: Any, end_effector_link: str = "") -> None:
        """Set a pose target for the end-effector (or `end_effector_link`); return None.

        `pose` is a Pose or a list [x, y, z, qx, qy, qz, qw] | [x, y, z, roll, pitch, yaw] in the
        pose reference frame, or a PoseStamped in its own frame (any link or scene frame). One pose
        target per end-effector link: a second link's target joins the first (both are reached).
        """
        link = self._link(end_effector_link or self._eef, "set_pose_target")
        self._set_pose(link, pose_goal(pose, link, self._reference, "set_pose_target"))

    def set_pose_targets(self, poses: Sequence[Any], end_effector_link: str = "") -> None:
        """Set a pose target from a list of one pose (MoveIt plans to any of several; one is what moveplan takes)."""
        if isinstance(poses, str) or not hasattr(poses, "__len__") or len(poses) != 1:
            raise UsageError("set_pose_targets: moveplan takes one pose per end-effector link; give a list of one")
        self.set_pose_target(poses[0], end_effector_link)

    def set_position_target(self, xyz: Sequence[float], end_effector_link: str = "") -> None:
        """Set a position target in the pose reference frame, any orientation; return None."""
        link = self._link(end_effector_link or self._eef, "set_position_target")
        if isinstance(xyz, str) or not hasattr(xyz, "__len__") or len(xyz) != 3:
            raise UsageError(f"set_position_target: expected [x, y, z], got {xyz!r}")
        goal = pose_goal([*xyz, 0.0, 0.0, 0.0], link, self._reference, "set_position_target")
        self._set_pose(link, PositionGoal(xyz=goal.xyz, frame=goal.frame, link=link))

    def set_rpy_target(self, rpy: Sequence[float], end_effector_link: str = "") -> None:
        """Set a pose target: the current position, orientation [roll, pitch, yaw] (fixed axes); return None."""
        self._set_orientation(rpy, 3, end_effector_link, "set_rpy_target: expected [roll, pitch, yaw]")

    def set_orientation_target(self, q: Sequence[float], end_effector_link: str = "") -> None:
        """Set a pose target: the current position, orientation the quaternion [x, y, z, w]; return None."""
        self._set_orientation(q, 4, end_effector_link, "set_orientation_target: expected a quaternion [x, y, z, w]")

    def set_random_target(self) -> None:
        """Set the joint target to random values within the limits; return None."""
        self._set_joints(self._random_values())

    def shift_pose_target(self, axis: int, value: float, end_effector_link: str = "") -> None:
        """Set a pose target `value` away from the current pose along `axis` 0..5 (x, y, z, r, p, y); return None.

        As MoveIt does it: x, y, z move along the planning frame's axes, and the angles add to the
        pose's fixed-axis roll, pitch and yaw (roll turns about the tool's own x axis, yaw about
        the planning frame's z axis). The pose is read where the motion starts.
        """
        if isinstance(axis, bool) or not isinstance(axis, numbers.Integral) or not 0 <= axis < len(SHIFT_AXES):
            raise UsageError(f"shift_pose_target: an axis value between 0 and 5 expected, got {axis!r}")
        value = real_number(value, "shift_pose_target")
        link = self._link(end_effector_link or self._eef, "shift_pose_target")
        if link == self._robot.group.tip:
            self._set_pose(link, ShiftGoal.of({SHIFT_AXES[axis]: float(value)}, "moveit"))
            return
        pose = pose_to_list(self.get_current_pose(link).pose)
        if axis > 2:
            pose = pose[:3] + list(euler_from_quaternion(pose[3:]))
        pose[axis] += float(value)
        self._set_pose(link, pose_goal(pose, link, self._robot.root_link, "shift_pose_target"))

    def clear_pose_target(self, end_effector_link: str) -> None:
        """Drop the pose target of `end_effector_link`; return None."""
        self._pose_targets.pop(end_effector_link or self._eef, None)

    def clear_pose_targets(self) -> None:
        """Drop every pose target (the joint target is what plans next); return None."""
        self._pose_targets.clear()

    def get_named_targets(self) -> list[str]:
        """Return the names of the group's SRDF group states and of the values remembered."""
        states = self._world.config.srdf.group_states.get(self._name, {})
        return [*states, *(n for n in self._remembered if n not in states)]

    def get_named_target_values(self, target: str) -> dict[str, float]:
        """Return joint -> value of a remembered or SRDF named target."""
        if target in self._remembered:
            return dict(zip(self._robot.variable_names, self._remembered[target], strict=True))
        values = joint_target(self._robot, NamedGoal(target), self._robot.values(self._world.q), "named target")
        return dict(zip(self._robot.variable_names, self._variables(values), strict=True))

    def set_named_target(self, name: str) -> None:
        """Set the joint target by name: values remembered under it, else the SRDF group state; return None."""
        if name in self._remembered:
            self.set_joint_value_target(self._remembered[name])
        else:
            self._set_joints(joint_target(self._robot, NamedGoal(name), self._joint_target, "set_named_target"))
        self._named = name

    def remember_joint_values(self, name: str, values: Sequence[float] | None = None) -> None:
        """Remember `values` (default: the current ones) under `name`, a named target; return None."""
        goal = joint_goal(self.get_current_joint_values() if values is None else values, None,
                          self._robot.variable_names, "remember_joint_values")
        self._remembered[name] = list(goal.values)

    def get_remembered_joint_values(self) -> dict[str, list[float]]:
        """Return name -> joint values remembered."""
        return {name: list(values) for name, values in self._remembered.items()}

    def forget_joint_values(self, name: str) -> None:
        """Forget the values remembered under `name`; return None."""
        self._remembered.pop(name, None)

    def set_path_constraints(self, value: Any) -> None:
        """Plan every motion within `value`, a moveit_msgs Constraints (None clears them); return None.

        Joint constraints narrow the joints' ranges; orientation and position constraints are
        checked on every state the search and the certification check (MoveIt's rejection
        sampling: a tight orientation tolerance makes a hard search). Checked when planning.
        """
        if value is None:
            self.clear_path_constraints()
            return
        if isinstance(value, str):
            raise UsageError(f"set_path_constraints('{value}'): constraints by name come from MoveIt's warehouse "
                             "database, which moveplan does not have; give a Constraints message")
        if not isinstance(value, Constraints):
            raise UsageError(f"set_path_constraints: expected a moveit_msgs Constraints, got {type(value).__name__}")
        self._constraints = value

    def get_path_constraints(self) -> Constraints:
        """Return the path constraints set (an empty Constraints when none)."""
        return self._constraints or Constraints()

    def clear_path_constraints(self) -> None:
        """Plan without path constraints again; return None."""
        self._constraints = None

    def allow_replanning(self, value: bool) -> None:
        """Accept MoveIt's replanning switch: a moveplan motion is planned once and certified; return None."""

    def allow_looking(self, value: bool) -> None:
        """Accept MoveIt's sensor-looking switch: there is no sensor to turn; return None."""

    def set_workspace(self, ws: Sequence[float]) -> None:
        """Accept MoveIt's workspace bounds (for a mobile base; joint limits bound the search here); return None."""
        if isinstance(ws, str) or not hasattr(ws, "__len__") or len(ws) not in (0, 4, 6):
            raise UsageError(f"set_workspace: expected [minx, miny, maxx, maxy] or [minx, miny, minz, maxx, maxy, "
                             f"maxz], got {ws!r}")

    def set_support_surface_name(self, value: str) -> None:
        """Accept the support surface name MoveIt's place pipeline uses (there is no place pipeline); return None."""

    def get_known_constraints(self) -> list[str]:
        """Return the names of stored constraints: none (MoveIt keeps them in a warehouse database)."""
        return []

    # Planning and execution -----------------------------------------------------------------------

    def plan(self, joints: Any = None) -> tuple[bool, RobotTrajectory, float, MoveItErrorCodes]:
        """Return (success, trajectory, planning time [s], error code) of a plan to the target (or `joints`, set first).

        `joints` may be a name (remembered or SRDF), a JointState, a Pose or PoseStamped, or
        joint values. A plan that fails returns (False, an empty trajectory, the time spent, the reason).
        """
        self._set_target(joints)
        step, error, seconds = self._plan_step()
        return error is None, to_message(step, self.get_planning_frame()), seconds, \
            error_code(error, pilz=self._resolved().planner in PILZ_PLANNERS)

    def go(self, joints: Any = None, wait: bool = True) -> bool:
        """Return True if planning to the target (or `joints`, set first) and executing the plan both succeeded."""
        if isinstance(joints, bool):
            wait, joints = joints, None
        success, trajectory, _, _ = self.plan(joints)
        return success and self.execute(trajectory, wait)

    def execute(self, plan_msg: Any, wait: bool = True, tolerances: Any = None) -> bool:
        """Return True if executing a trajectory on the simulated controller succeeded; the robot moves either way.

        The robot ends where the execution did (also on a path violation); a trajectory that
        does not start where the robot is gets refused and moves nothing. Executions are
        synchronous: `wait` is accepted and unused. get_execution_report() says what happened.

        `tolerances` (moveplan's, not MoveIt's: MoveIt 2 sends none) are those the
        FollowJointTrajectory goal carries to the controller: a control_msgs goal (its
        path_tolerance, goal_tolerance and goal_time_tolerance) or a mapping of those keys,
        as a task step's `tolerances`. They replace the controller's for this execution and
        travel with it into a saved plan, where check-tolerances applies them.
        """
        step = from_message(plan_msg, self._robot.joint_names, "execute")
        if tolerances is not None:
            step = replace(step, tolerances=_goal_tolerances(tolerances))
        world = self._world
        start = {j: world.joint_value(j) for j in step.trajectory.joint_names}
        report = execute_motion(world.config, step.trajectory, start, world.execution, "execute", step.tolerances)
        self._last = report.summary()
        if len(report.times_s):
            ended = world.with_joints(dict(zip(report.joint_names, report.actual_positions[-1].tolist(), strict=True)))
            world.q = self._robot.configuration(self._robot.values(ended), ended)  # mimic joints follow
            world.record(self._name, step, self._last)
        if not report.ok:
            logger.warning("execute: %s: %s", report.result.name, report.result.message)
        return report.ok

    def retime_trajectory(self, ref_state_in: Any, traj_in: Any, velocity_scaling_factor: float = 1.0,
                          acceleration_scaling_factor: float = 1.0,
                          algorithm: str = "iterative_time_parameterization") -> RobotTrajectory:
        """Return `traj_in`'s path timed anew within the scaled limits (an empty trajectory for an unknown algorithm).

        MoveIt's three algorithms (iterative_time_parameterization, iterative_spline_parameterization,
        time_optimal_trajectory_generation) all time it with moveplan's TOPP: near time-optimal,
        from rest to rest, through the trajectory's points.
        """
        velocity = scaling(velocity_scaling_factor, "retime_trajectory: velocity_scaling_factor")
        acceleration = scaling(acceleration_scaling_factor, "retime_trajectory: acceleration_scaling_factor")
        if algorithm not in _RETIMING:
            logger.warning("retime_trajectory: unknown time parameterization algorithm '%s'; known: %s", algorithm,
                           ", ".join(_RETIMING))
            return RobotTrajectory()
        given = from_message(traj_in, self._robot.joint_names, "retime_trajectory").trajectory
        order = [given.joint_names.index(j) for j in self._robot.joint_names if j in given.joint_names]
        names = tuple(given.joint_names[i] for i in order)
        index = [self._robot.joint_names.index(j) for j in names]
        timed = time_parameterize(names, given.positions[:, order], self._robot.max_velocity[index] * velocity,
                                  self._robot.max_acceleration[index] * acceleration)
        step = StepResult(name="retimed", goal={"trajectory": {"points": len(given.times_s)}}, planner="given",
                          planning_time_s=0.0, trajectory=timed, scaling=(velocity, acceleration))
        return to_message(step, self.get_planning_frame())

    def compute_cartesian_path(
        self, waypoints: Sequence[Any], eef_step: float, *args: Any, **kwargs: Any,
    ) -> tuple[RobotTrajectory, float]:
        """Return (trajectory, fraction) of the end-effector moving in straight lines through `waypoints` in turn.

        Both of MoveIt's signatures: (waypoints, eef_step, avoid_collisions=True,
        path_constraints=None) since 1.1.15, and (waypoints, eef_step, jump_threshold,
        avoid_collisions=True, path_constraints=None) before; a bool third argument is
        avoid_collisions. Waypoints are Poses in the pose reference frame (or PoseStamped). The
        fraction is the part of the path achieved (MoveIt's). moveplan steps 5 mm / 0.05 rad and
        checks each interval as MoveIt >= 1.1.15 does, whatever `eef_step` and `jump_threshold` say.
        """
        avoid_collisions, path_constraints = _cartesian_arguments(args, kwargs)
        if not avoid_collisions:
            raise UsageError("compute_cartesian_path: avoid_collisions=False is not supported: every moveplan "
                             "motion is certified collision-free (allow a contact with touch_links instead)")
        if path_constraints is not None and not isinstance(path_constraints, Constraints):
            raise UsageError(f"compute_cartesian_path: path_constraints: expected a moveit_msgs Constraints, got "
                             f"{type(path_constraints).__name__}")
        if path_constraints is not None and _constraining(path_constraints):
            raise UsageError("compute_cartesian_path: path constraints on a straight line are not supported; the "
                             "line fixes the tool's path already")
        if isinstance(eef_step, bool) or not isinstance(eef_step, numbers.Real) or not 0.0 < eef_step < math.inf:
            raise UsageError(f"compute_cartesian_path: eef_step must be a positive distance in [m], got {eef_step!r}")
        if isinstance(waypoints, str) or not hasattr(waypoints, "__len__"):
            raise UsageError(f"compute_cartesian_path: waypoints: expected a list of poses, got {waypoints!r}")
        if not waypoints:
            raise UsageError("compute_cartesian_path: no waypoints: give the poses the end-effector goes through")
        q = self._start_q()
        where = "compute_cartesian_path: waypoints"
        goals = [self._in_root(pose_goal(point, self._eef, self._reference, f"{where}[{k}]"), q)
                 for k, point in enumerate(waypoints)]
        world = self._world
        try:
            problem = world.problem(self._robot, q)
        except NoPlan as exc:  # two parts that never move touch: no state is free
            logger.warning("compute_cartesian_path: %s", exc)
            return to_message(None, self.get_planning_frame()), 0.0
        step, fraction = cartesian_motion(problem, goals, q, self._settings(), world.seed)
        if fraction < 1.0:
            logger.warning("compute_cartesian_path: %.1f%% of the path achieved", 100.0 * fraction)
        return to_message(step, self.get_planning_frame()), fraction

    def stop(self) -> None:
        """Stop the current execution: executions are synchronous, so there is none; return None."""

    def get_execution_report(self) -> ExecutionSummary | None:
        """Return what the last execute() or go() of this group did (result, violations, margins), None before one."""
        return self._last

    def attach_object(self, object_name: str, link_name: str = "", touch_links: Sequence[str] = ()) -> bool:
        """Return True once the scene object `object_name` is attached to `link_name` (default: the end-effector).

        `touch_links` default to the link it is attached to, as MoveIt's attachObject sets them.
        """
        attach_existing(self._world, object_name, link_name or self._eef, touch_links or None,
                        f"attach_object('{object_name}')")
        return True

    def detach_object(self, name: str = "") -> bool:
        """Return True once the object `name` (or the objects of link `name`, or all for "") is detached."""
        return detach(self._world, name)

    def pick(self, object_name: str, *args: Any, **kwargs: Any) -> None:
        """Raise UsageError: MoveIt's pick pipeline (grasp generation) is not part of moveplan."""
        raise UsageError(f"pick('{object_name}'): MoveIt's pick and place pipeline is not supported; move to the "
                         "object, attach it (attach_object) and move on, as pick and place scripts do step by step")

    def place(self, object_name: str, *args: Any, **kwargs: Any) -> None:
        """Raise UsageError: MoveIt's place pipeline is not part of moveplan."""
        raise UsageError(f"place('{object_name}'): MoveIt's pick and place pipeline is not supported; move, then "
                         "detach_object")

    # Helpers -----------------------------------------------------------------------------------------

    def _link(self, link: str, where: str) -> str:
        """Return `link` if the robot has it, else raise UnknownName naming `where`."""
        if link not in self._robot.link_names:
            raise UnknownName("link", link, f"{where} (the robot's links)", self._robot.link_names)
        return link

    def _variables(self, values: NDArray[np.float64]) -> list[float]:
        """Return the group's variables (mimic joints included) for active joint values."""
        q = self._robot.configuration(values, self._world.q)
        return [self._world.joint_value(j, q) for j in self._robot.variable_names]

    def _active(self, values: Any, where: str) -> NDArray[np.float64]:
        """Return the active joint values in a list of all the group's variables."""
        goal = joint_goal(values, None, self._robot.variable_names, where)
        by_name = dict(zip(self._robot.variable_names, goal.values, strict=True))
        return np.array([by_name[j] for j in self._robot.joint_names])

    def _random_values(self) -> NDArray[np.float64]:
        """Return random active joint values within the limits (a continuous joint in [-pi, pi])."""
        robot = self._robot
        lower = np.where(robot.continuous, -np.pi, robot.lower)
        upper = np.where(robot.continuous, np.pi, robot.upper)
        return np.asarray(self._world.rng.uniform(lower, upper), dtype=float)

    def _set_joints(self, values: NDArray[np.float64]) -> None:
        """Make `values` the joint target, and joint values the target planned next."""
        self._joint_target = np.array(values, dtype=float)
        self._pose_targets.clear()
        self._named = None

    def _set_orientation(self, orientation: Any, size: int, link: str, expected: str) -> None:
        """Set a pose target at the link's current position with `orientation` (rpy or quaternion)."""
        where = expected.split(":")[0]
        if isinstance(orientation, str) or not hasattr(orientation, "__len__") or len(orientation) != size:
            raise UsageError(f"{expected}, got {orientation!r}")
        link = self._link(link or self._eef, where)
        position = pose_to_list(self.get_current_pose(link).pose)[:3]
        self._set_pose(link, pose_goal([*position, *orientation], link, self._robot.root_link, where))

    def _set_pose(self, link: str, goal: Goal) -> None:
        """Make `goal` the pose target of `link` (the others stay: one target per end-effector link)."""
        self._pose_targets[link] = goal

    def _solve(self, goal: PoseGoal) -> NDArray[np.float64]:
        """Return collision-free group values putting the goal's link at its pose, nearest where the motion starts."""
        q = self._start_q()
        problem = self._world.problem(self._robot, q)
        link, pose = tip_target(self._robot, problem.scene, goal, q, "set_joint_value_target")
        solution = solve_ik(self._robot, pose, link, self._robot.values(q), base=problem.checks.base,
                            seed=self._world.seed, is_free=problem.checks.state_free,
                            colliding_pair=problem.checks.checker.colliding_pair)
        return solution.values

    def _set_target(self, joints: Any) -> None:
        """Set the target plan() and go() were given, as MoveIt does; None keeps the target set."""
        if joints is None:
            return
        if isinstance(joints, str):
            self.set_named_target(joints)
        elif isinstance(joints, Pose | PoseStamped):  # MoveIt 1 solves a PoseStamped's IK at once: same place
            self.set_pose_target(joints)
        else:
            self.set_joint_value_target(joints)

    def _start_q(self) -> Any:
        """Return the configuration a motion starts from: the start state set, else the current one."""
        return self._world.with_joints(self._start) if self._start else self._world.q.copy()

    def _in_root(self, goal: PoseGoal, q: Any) -> PoseGoal:
        """Return a pose goal expressed in the planning frame, its frame placed with the robot at `q`."""
        root_T_frame = self._world.pose(goal.frame or self._robot.root_link, q)
        pose = matrix_to_pose(root_T_frame @ pose_matrix(goal.xyz, goal.rpy, goal.quat, "waypoint"))
        _, _, _, *quat = pose_to_list(pose)
        return PoseGoal(xyz=(pose.position.x, pose.position.y, pose.position.z), quat=(quat[0], quat[1], quat[2],
                        quat[3]), link=goal.link)

    def _goal(self) -> Goal:
        """Return the goal planned next: the pose target(s) if any, else the joint target."""
        if len(self._pose_targets) > 1:  # one pose target per end-effector link, reached together
            first, *others = self._pose_targets.values()
            if not all(isinstance(goal, PoseGoal) for goal in (first, *others)):
                raise UsageError("plan: a shift_pose_target of the tip cannot join pose targets of other links; set "
                                 "the tip's target with set_pose_target")
            return replace(cast(PoseGoal, first), also=tuple(cast(PoseGoal, g) for g in others))
        if self._pose_targets:
            return next(iter(self._pose_targets.values()))
        if self._named is not None and self._named not in self._remembered:
            return NamedGoal(self._named)
        return JointGoal(tuple(float(v) for v in self._joint_target))

    def _plan_step(self) -> tuple[StepResult | None, NoPlan | None, float]:
        """Return the step planned to the target, or the reason there is none, and the time spent [s]."""
        goal = self._goal()
        constraints, arc = None, None
        if self._constraints is not None and self._constraints.name in ARC_POINTS and \
                self._resolved().planner == "CIRC":  # Pilz's CIRC reads its point from the path constraints
            arc = arc_point(plain(self._constraints), "set_path_constraints")
        elif self._constraints is not None:
            constraints = path_constraints(plain(self._constraints), "set_path_constraints")
        q = self._start_q()
        spec = StepSpec(_step_name(goal), goal, constraints=constraints, arc=arc)
        began = time.perf_counter()
        try:
            step = plan_motion(self._world.problem(self._robot, q), spec, q, self._settings(), self._world.seed)
        except NoPlan as exc:
            logger.warning("plan: %s", exc)
            return None, exc, time.perf_counter() - began
        return step, None, step.planning_time_s


def _goal_tolerances(value: Any) -> GoalTolerances:
    """Return the tolerances of a control_msgs FollowJointTrajectory goal, or of a mapping of its three fields.

    Raises:
        UsageError: Neither, or a field that is no list of JointTolerance (name, position,
            velocity, acceleration) or no duration; the message begins with "execute: tolerances".
    """
    if hasattr(value, "path_tolerance") or hasattr(value, "goal_tolerance"):
        def joints(items: Any) -> list[dict[str, Any]]:
            keys = ("name", "position", "velocity", "acceleration")
            return [{key: getattr(item, key) for key in keys if hasattr(item, key)} for item in items or ()]
        seconds = getattr(value, "goal_time_tolerance", 0.0)
        value = {"path_tolerance": joints(getattr(value, "path_tolerance", ())),
                 "goal_tolerance": joints(getattr(value, "goal_tolerance", ())),
                 "goal_time_tolerance": seconds.to_sec() if hasattr(seconds, "to_sec") else seconds}
    try:
        return parse_goal_tolerances(value, "execute: tolerances")
    except ConfigError as exc:
        raise UsageError(str(exc)) from exc


def _step_name(goal: Goal) -> str:
    """Return a step's name in a saved plan: the named target's name, else the kind of goal."""
    return goal.name if isinstance(goal, NamedGoal) else goal.kind


def _constraining(constraints: Constraints) -> bool:
    """Return True if a Constraints message constrains anything."""
    return bool(constraints.joint_constraints or constraints.position_constraints
                or constraints.orientation_constraints or constraints.visibility_constraints)


def _cartesian_arguments(args: tuple[Any, ...], kwargs: dict[str, Any]) -> tuple[bool, Any]:
    """Return (avoid_collisions, path_constraints) of compute_cartesian_path's arguments after eef_step.

    Raises:
        UsageError: Too many or unknown arguments, or a jump_threshold that is no number >= 0.
    """
    unknown = set(kwargs) - {"jump_threshold", "avoid_collisions", "path_constraints"}
    if unknown:
        raise UsageError(f"compute_cartesian_path: unknown argument {', '.join(sorted(unknown))}")
    rest = list(args)
    if rest and not isinstance(rest[0], bool):  # MoveIt < 1.1.15: jump_threshold third
        kwargs.setdefault("jump_threshold", rest.pop(0))
    names = ["avoid_collisions", "path_constraints"]
    if len(rest) > len(names):
        raise UsageError(f"compute_cartesian_path: {len(args) + 2} positional arguments; at most 5")
    for name, value in zip(names, rest, strict=False):
        if name in kwargs:
            raise UsageError(f"compute_cartesian_path: {name} given twice")
        kwargs[name] = value
    jump = kwargs.get("jump_threshold", 0.0)
    if isinstance(jump, bool) or not isinstance(jump, numbers.Real) or not 0.0 <= float(jump) < math.inf:
        raise UsageError(f"compute_cartesian_path: jump_threshold must be a number >= 0, got {jump!r}")
    avoid = kwargs.get("avoid_collisions", True)
    if not isinstance(avoid, bool | np.bool_ | int):
        raise UsageError(f"compute_cartesian_path: avoid_collisions must be True or False, got {avoid!r}")
    return bool(avoid), kwargs.get("path_constraints")
