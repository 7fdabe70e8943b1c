"""MoveGroupCommander: MoveIt 1 Noetic's Python API for one planning group, planning and executing in memory.

Names, arguments, defaults and return shapes are moveit_commander's (move_group.py): a target
is set, then plan() returns (success, RobotTrajectory, planning time, MoveItErrorCodes), go()
plans and executes, execute() runs a trajectory on the simulated controller, and the robot's
current state moves to where the execution ended. A motion is one step of `moveplan plan`
(core/pipeline/session.py); execution is `moveplan execute --fake`'s.
"""

from __future__ import annotations

import logging
import math
import numbers
import time
from collections.abc import Sequence
from typing import Any, cast

from ..core.config import (
    SHIFT_AXES,
    Goal,
    JointGoal,
    NamedGoal,
    PoseGoal,
    PositionGoal,
    ShiftGoal,
    StepSpec,
    pose_matrix,
)
from ..core.control import ExecutionSummary
from ..core.errors import NoPlan, UnknownName, UsageError
from ..core.pipeline import cartesian_motion, execute_motion, plan_motion
from ..core.planning import joint_target
from ..core.types import StepResult
from ._settings import PlanningSettings, real_number
from ._targets import finite_number, joint_goal, pose_goal
from ._world import current_world
from .conversions import matrix_to_pose, pose_to_list
from .msgs import JointState, MoveItErrorCodes, Pose, PoseStamped, RobotState, RobotTrajectory
from .scene import attach_existing, detach
from .trajectory import error_code, from_message, to_message
from .transformations import euler_from_quaternion

__all__ = ["MoveGroupCommander"]

logger = logging.getLogger(__name__)


class MoveGroupCommander(PlanningSettings):
    """Execution of simple commands for one planning group: targets, plan(), go(), execute().

    Args:
        name: The SRDF planning group.
        robot: Its RobotCommander; None (or MoveIt's robot_description string): the one created last.
        ns, wait_for_servers: MoveIt's; accepted and unused (there is no ROS graph to wait for).
    """

    def __init__(self, name: str, robot: Any = None, ns: str = "", wait_for_servers: float = 5.0) -> None:
        super().__init__()
        self._world = current_world(robot, f"MoveGroupCommander('{name}')")
        self._robot = self._world.robot(name)
        self._name = name
        self._eef = self._robot.group.tip
        self._reference = self._robot.root_link
        self._target: Goal | None = None
        self._start: dict[str, float] | None = None
        self._remembered: dict[str, list[float]] = {}
        self._last: ExecutionSummary | None = None

    # The group ---------------------------------------------------------------------------------

    def get_name(self) -> str:
        """Return the name of the group."""
        return self._name

    def get_active_joints(self) -> list[str]:
        """Return the group's active joints, in group order."""
        return list(self._robot.joint_names)

    def get_joints(self) -> list[str]:
        """Return the group's joints (its active joints: fixed ones take no values)."""
        return list(self._robot.joint_names)

    def get_variable_count(self) -> int:
        """Return the number of values a state of the group has."""
        return self._robot.dof

    def has_end_effector_link(self) -> bool:
        """Return True: a moveplan group always has a tip link."""
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
        """Return the group's current joint values, in group order, in [rad] or [m]."""
        return cast(list[float], self._robot.values(self._world.q).tolist())

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
        """Return the robot's current state: every movable joint's position."""
        names = self._world.joint_names()
        return RobotState(JointState(name=names, position=[self._world.joint_value(j) for j in names]))

    def set_start_state_to_current_state(self) -> None:
        """Plan from the current state again (the default); return None."""
        self._start = None

    def set_start_state(self, msg: RobotState) -> None:
        """Plan from the joint positions of a RobotState (joints it leaves out: current); return None."""
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

    # Targets ------------------------------------------------------------------------------------

    def get_joint_value_target(self) -> list[float]:
        """Return the joint values of a joint or named target (the current values for a pose target)."""
        current = self._robot.values(self._world.q)
        if isinstance(self._target, JointGoal | NamedGoal):
            target = joint_target(self._robot, self._target, current, "get_joint_value_target")
            return cast(list[float], target.tolist())
        return cast(list[float], current.tolist())

    def set_joint_value_target(self, arg1: Any, arg2: Any = None, arg3: Any = None) -> None:
        """Set a joint target: a list of all values, a dict joint: value, a JointState or (joint, value); return None.

        A Pose or PoseStamped (with an end-effector link as arg2 or arg3) sets a pose target
        instead, solved by the same inverse kinematics when planning. Joints a dict leaves out
        keep the values they have where the motion starts.
        """
        if isinstance(arg1, Pose | PoseStamped):
            link = next((a for a in (arg2, arg3) if isinstance(a, str)), "")
            self.set_pose_target(arg1, link)
            return
        if arg3 is not None:
            raise UsageError("set_joint_value_target: too many arguments")
        goal = joint_goal(arg1, arg2, self._robot.joint_names, "set_joint_value_target")
        joint_target(self._robot, goal, self._robot.values(self._world.q), "set_joint_value_target")
        self._target = goal

    def set_pose_target(self, pose: Any, end_effector_link: str = "") -> None:
        """Set a pose target for the end-effector (or `end_effector_link`); return None.

        `pose` is a Pose or a list [x, y, z, qx, qy, qz, qw] | [x, y, z, roll, pitch, yaw] in the
        pose reference frame, or a PoseStamped in its own frame (any link or scene frame).
        """
        link = self._link(end_effector_link or self._eef, "set_pose_target")
        self._target = pose_goal(pose, link, self._reference, "set_pose_target")

    def set_position_target(self, xyz: Sequence[float], end_effector_link: str = "") -> None:
        """Set a position target in the pose reference frame, any orientation; return None."""
        link = self._link(end_effector_link or self._eef, "set_position_target")
        if isinstance(xyz, str) or not hasattr(xyz, "__len__") or len(xyz) != 3:
            raise UsageError(f"set_position_target: expected [x, y, z], got {xyz!r}")
        goal = pose_goal([*xyz, 0.0, 0.0, 0.0], link, self._reference, "set_position_target")
        self._target = PositionGoal(xyz=goal.xyz, frame=goal.frame, link=link)

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
            self._target = ShiftGoal.of({SHIFT_AXES[axis]: float(value)}, "moveit")
            return
        pose = pose_to_list(self.get_current_pose(link).pose)
        if axis > 2:
            pose = pose[:3] + list(euler_from_quaternion(pose[3:]))
        pose[axis] += float(value)
        self._target = pose_goal(pose, link, self._robot.root_link, "shift_pose_target")

    def clear_pose_target(self, end_effector_link: str) -> None:
        """Drop a pose target of `end_effector_link`; return None."""
        target = self._target
        if isinstance(target, ShiftGoal) and end_effector_link in ("", self._robot.group.tip):
            self._target = None
        elif isinstance(target, PoseGoal) and (target.link or self._robot.group.tip) == end_effector_link:
            self._target = None

    def clear_pose_targets(self) -> None:
        """Drop any pose target; return None."""
        if isinstance(self._target, PoseGoal | ShiftGoal):
            self._target = None

    def get_named_targets(self) -> list[str]:
        """Return the names of the group's SRDF group states and of the values remembered."""
        states = self._world.config.srdf.group_states.get(self._name, {})
        return [*states, *(n for n in self._remembered if n not in states)]

    def get_named_target_values(self, target: str) -> dict[str, float]:
        """Return joint -> value of a remembered or SRDF named target."""
        if target in self._remembered:
            return dict(zip(self._robot.joint_names, self._remembered[target], strict=True))
        values = joint_target(self._robot, NamedGoal(target), self._robot.values(self._world.q), "named target")
        return dict(zip(self._robot.joint_names, values.tolist(), strict=True))

    def set_named_target(self, name: str) -> None:
        """Set a joint target by name: values remembered under it, else the SRDF group state; return None."""
        if name in self._remembered:
            self._target = JointGoal(tuple(self._remembered[name]))
            return
        goal = NamedGoal(name)
        joint_target(self._robot, goal, self._robot.values(self._world.q), "set_named_target")
        self._target = goal

    def remember_joint_values(self, name: str, values: Sequence[float] | None = None) -> None:
        """Remember `values` (default: the current ones) under `name`, a named target; return None."""
        goal = joint_goal(self.get_current_joint_values() if values is None else values, None,
                          self._robot.joint_names, "remember_joint_values")
        self._remembered[name] = list(goal.values)

    def get_remembered_joint_values(self) -> dict[str, list[float]]:
        """Return name -> joint values remembered."""
        return {name: list(values) for name, values in self._remembered.items()}

    def forget_joint_values(self, name: str) -> None:
        """Forget the values remembered under `name`; return None."""
        self._remembered.pop(name, None)

    # Planning and execution -----------------------------------------------------------------------

    def plan(self, joints: Any = None) -> tuple[bool, RobotTrajectory, float, MoveItErrorCodes]:
        """Return (success, trajectory, planning time [s], error code) of a plan to the target (or `joints`, set first).

        `joints` may be a name (remembered or SRDF), a Pose or PoseStamped, or joint values.
        A plan that fails returns (False, an empty trajectory, the time spent, the reason).
        """
        self._set_target(joints)
        step, error, seconds = self._plan_step()
        return error is None, to_message(step, self.get_planning_frame()), seconds, error_code(error)

    def go(self, joints: Any = None, wait: bool = True) -> bool:
        """Return True if planning to the target (or `joints`, set first) and executing the plan both succeeded."""
        if isinstance(joints, bool):
            wait, joints = joints, None
        success, trajectory, _, _ = self.plan(joints)
        return success and self.execute(trajectory, wait)

    def execute(self, plan_msg: Any, wait: bool = True) -> bool:
        """Return True if executing a trajectory on the simulated controller succeeded; the robot moves either way.

        The robot ends where the execution did (also on a path violation); a trajectory that
        does not start where the robot is gets refused and moves nothing. Executions are
        synchronous: `wait` is accepted and unused. get_execution_report() says what happened.
        """
        step = from_message(plan_msg, self._robot.joint_names, "execute")
        world = self._world
        start = {j: world.joint_value(j) for j in step.trajectory.joint_names}
        report = execute_motion(world.config, step.trajectory, start, world.execution, "execute")
        self._last = report.summary()
        if len(report.times_s):
            world.q = world.with_joints(dict(zip(report.joint_names, report.actual_positions[-1].tolist(),
                                                 strict=True)))
            world.record(self._name, step, self._last)
        if not report.ok:
            logger.info("execute: %s: %s", report.result.name, report.result.message)
        return report.ok

    def compute_cartesian_path(
        self, waypoints: Sequence[Any], eef_step: float, jump_threshold: float = 0.0, avoid_collisions: bool = True,
        path_constraints: Any = None,
    ) -> tuple[RobotTrajectory, float]:
        """Return (trajectory, fraction) of the end-effector moving in straight lines through `waypoints` in turn.

        Waypoints are Poses in the pose reference frame (or PoseStamped). The fraction is the
        part of the path achieved (MoveIt's). `eef_step` and `jump_threshold` are accepted:
        moveplan steps 5 mm / 0.05 rad and checks each interval as MoveIt >= 1.1.15 does.
        """
        if not avoid_collisions:
            raise UsageError("compute_cartesian_path: avoid_collisions=False is not supported: every moveplan "
                             "motion is certified collision-free (allow a contact with touch_links instead)")
        if path_constraints is not None:
            raise UsageError("compute_cartesian_path: path_constraints are not supported")
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
            logger.info("compute_cartesian_path: %s", exc)
            return to_message(None, self.get_planning_frame()), 0.0
        step, fraction = cartesian_motion(problem, goals, q, self._settings(), world.seed)
        return to_message(step, self.get_planning_frame()), fraction

    def stop(self) -> None:
        """Stop the current execution: executions are synchronous, so there is none; return None."""

    def get_execution_report(self) -> ExecutionSummary | None:
        """Return what the last execute() or go() of this group did (result, violations, margins), None before one."""
        return self._last

    def attach_object(self, object_name: str, link_name: str = "", touch_links: Sequence[str] = ()) -> bool:
        """Return True once the scene object `object_name` is attached to `link_name` (default: the end-effector)."""
        attach_existing(self._world, object_name, link_name or self._eef, touch_links or None,
                        f"attach_object('{object_name}')")
        return True

    def detach_object(self, name: str = "") -> bool:
        """Return True once the object `name` (or the objects of link `name`, or all for "") is detached."""
        return detach(self._world, name)

    # Helpers -----------------------------------------------------------------------------------------

    def _link(self, link: str, where: str) -> str:
        """Return `link` if the robot has it, else raise UnknownName naming `where`."""
        if link not in self._robot.link_names:
            raise UnknownName("link", link, f"{where} (the robot's links)", self._robot.link_names)
        return link

    def _set_target(self, joints: Any) -> None:
        """Set the target plan() and go() were given, as MoveIt does; None keeps the target set."""
        if joints is None:
            return
        if isinstance(joints, str):
            self.set_named_target(joints)
        elif isinstance(joints, Pose | PoseStamped):
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

    def _plan_step(self) -> tuple[StepResult | None, NoPlan | None, float]:
        """Return the step planned to the target, or the reason there is none, and the time spent [s]."""
        if self._target is None:
            raise UsageError("plan: no target: set one with set_joint_value_target, set_named_target, "
                             "set_pose_target or shift_pose_target")
        q = self._start_q()
        spec = StepSpec(_step_name(self._target), self._target)
        began = time.perf_counter()
        try:
            step = plan_motion(self._world.problem(self._robot, q), spec, q, self._settings(), self._world.seed)
        except NoPlan as exc:
            logger.info("plan: %s", exc)
            return None, exc, time.perf_counter() - began
        return step, None, step.planning_time_s


def _step_name(goal: Goal) -> str:
    """Return a step's name in a saved plan: the named target's name, else the kind of goal."""
    return goal.name if isinstance(goal, NamedGoal) else goal.kind
