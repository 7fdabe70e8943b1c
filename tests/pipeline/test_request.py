"""The plan command's options as typed flags: the rules between them, and precedence flag > request > task."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import ROOT

from moveplan.core.config.goals import JointGoal, NamedGoal, PoseGoal, ShiftGoal, StartFrom
from moveplan.core.config.motion import MotionSettings, Resolved, is_planning_time, is_scaling, layered, resolved
from moveplan.core.config.tasks import StepSpec, load_task
from moveplan.core.errors import UsageError
from moveplan.core.pipeline.request import PlanFlags, check_planning_time, resolve_request

REQUEST = ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda" / "request0001.yaml"
ROBOT = Path("robot")


def task_file(folder: Path, text: str) -> Path:
    path = folder / "task.yaml"
    path.write_text(text)
    return path


def test_pose_flag_becomes_one_step_with_the_frame_and_link_flags() -> None:
    flags = PlanFlags(pose=PoseGoal(xyz=(0.0, 0.0, 0.15), rpy=(3.0, 0.0, 0.0)), frame="object", link="tool0",
                      linear=True)
    assert flags.step == StepSpec("pose", PoseGoal((0.0, 0.0, 0.15), (3.0, 0.0, 0.0), None, "object", "tool0"),
                                  linear=True)


def test_shift_flag_moves_along_the_tool_unless_a_shift_frame_is_given() -> None:
    assert PlanFlags(shift=ShiftGoal(z=0.1)).step == StepSpec("shift", ShiftGoal(z=0.1, frame="tool"))
    along_base = PlanFlags(shift=ShiftGoal(z=0.1), shift_frame="base")
    assert along_base.step == StepSpec("shift", ShiftGoal(z=0.1, frame="base"))


def test_joint_and_named_flags_name_their_step_goal_and_the_state() -> None:
    assert PlanFlags(joints=JointGoal((0.0,) * 6)).step == StepSpec("goal", JointGoal((0.0,) * 6))
    assert PlanFlags(named="home").step == StepSpec("home", NamedGoal("home"))
    assert PlanFlags().step is None


def test_start_flags_become_typed_starts() -> None:
    assert PlanFlags(start_named="home").start == NamedGoal("home")
    assert PlanFlags(start_from=Path("p.mcap")).start == StartFrom(Path("p.mcap"))
    assert PlanFlags(start_joints=JointGoal.by_name({"elbow_joint": 1.0})).start == JointGoal((1.0,), ("elbow_joint",))
    assert PlanFlags().start is None


@pytest.mark.parametrize(("flags", "message"), [
    ({"named": "home", "joints": JointGoal((0.0,))}, "one goal flag, got --joints, --named"),
    ({"start_named": "home", "start_from": Path("p.mcap")}, "got --start-named, --start-from"),
    ({"named": "home", "frame": "object"}, "--frame goes with --pose"),
    ({"named": "home", "link": "tool0"}, "--link goes with --pose"),
    ({"pose": PoseGoal(), "shift_frame": "base"}, "--shift-frame goes with --shift"),
    ({"named": "home", "linear": True}, "--linear goes with --pose or --shift"),
    ({"named": "home", "min_fraction": 1.5}, r"--min-fraction: expected a number in \[0, 1\], got 1.5"),
    ({"named": "home", "motion": MotionSettings(planning_time=0.0)},
     r"--planning-time: expected a positive number of seconds .*, got 0"),
    ({"named": "home", "motion": MotionSettings(velocity_scaling=0.0)},
     r"--velocity-scaling: expected a factor in \[0.001, 1\], got 0"),
    ({"named": "home", "motion": MotionSettings(acceleration_scaling=1.5)}, r"--acceleration-scaling: .* got 1.5"),
])
def test_flags_that_break_a_rule_are_a_usage_error(flags: dict[str, object], message: str) -> None:
    with pytest.raises(UsageError, match=message):
        PlanFlags(**flags)  # type: ignore[arg-type]


def test_planning_time_check_names_the_flag() -> None:
    assert check_planning_time(0.5) == 0.5
    with pytest.raises(UsageError, match=r"--time: expected a positive number of seconds up to 1e\+06, got -1"):
        check_planning_time(-1.0, "--time")


def test_flag_wins_over_request_which_wins_over_task(tmp_path: Path) -> None:
    task = load_task(task_file(tmp_path, "robot: r\ngroup: arm\ndefaults: {planner: PRM, planning_time: 2, "
                                         "velocity_scaling: 0.2, acceleration_scaling: 0.3}\nseed: 7\n"))
    flags = PlanFlags(request=REQUEST, motion=MotionSettings(planner="RRTstar", velocity_scaling=0.5))
    request = resolve_request(task, flags)
    assert request.robot == tmp_path / "r"
    assert (request.motion.planner, request.motion.velocity_scaling) == ("RRTstar", 0.5)  # flags
    assert request.group == "panda_arm"  # request
    assert (request.motion.planning_time, request.motion.acceleration_scaling) == (60.0, 1.0)  # request
    assert request.seed == 7  # task
    assert request.steps[0].name == "request0001" and isinstance(request.steps[0].goal, JointGoal)


def test_task_settings_apply_where_no_flag_is_given(tmp_path: Path) -> None:
    task = load_task(task_file(tmp_path, "robot: r\nstart: {named: ready}\ndefaults: {planner: PRM}\n"
                                         "steps: [{named: home}]\n"))
    request = resolve_request(task, PlanFlags(robot=ROBOT, seed=3))
    assert (request.robot, request.motion.planner, request.seed, request.min_fraction) == (ROBOT, "PRM", 3, 1.0)
    assert request.start == NamedGoal("ready") and request.steps == task.steps


def test_start_flag_replaces_the_task_start_and_a_request_start_state_drops_it(tmp_path: Path) -> None:
    task = load_task(task_file(tmp_path, "robot: r\nstart: {named: ready}\n"))
    assert resolve_request(task, PlanFlags(named="home", start_named="home")).start == NamedGoal("home")
    assert resolve_request(task, PlanFlags(request=REQUEST)).start is None


def test_flag_goal_replaces_the_request_goal() -> None:
    request = resolve_request(None, PlanFlags(robot=ROBOT, request=REQUEST, named="ready"))
    assert request.steps == (StepSpec("ready", NamedGoal("ready")),)


@pytest.mark.parametrize(("flags", "message"), [
    (PlanFlags(named="home"), "has steps; give a goal by flag or by task, not both"),
    (PlanFlags(request=REQUEST), "has steps and .*request0001.yaml has goal_constraints"),
])
def test_task_steps_conflict_with_another_goal(tmp_path: Path, flags: PlanFlags, message: str) -> None:
    task = load_task(task_file(tmp_path, "robot: r\nsteps: [{named: home}]\n"))
    with pytest.raises(UsageError, match=message):
        resolve_request(task, flags)


def test_without_goal_or_robot_the_usage_error_says_how_to_give_one() -> None:
    with pytest.raises(UsageError, match="no goal: give --joints, --named, --pose, --shift, a --request"):
        resolve_request(None, PlanFlags(robot=ROBOT))
    with pytest.raises(UsageError, match="no robot: give --robot or a task file naming one"):
        resolve_request(None, PlanFlags(named="home"))


def test_one_rule_layers_the_motion_settings_each_from_the_first_place_that_sets_it() -> None:
    step = MotionSettings(velocity_scaling=0.1)
    flags = MotionSettings(planner="PRM", velocity_scaling=0.5)
    task = MotionSettings(planner="RRTstar", planning_time=3.0)
    assert layered(step, flags, task) == MotionSettings("PRM", 3.0, 0.1, None)
    defaults = Resolved("RRTConnect", 1.0, 0.2, 0.3)
    assert resolved(step, flags, task, defaults=defaults) == Resolved("PRM", 3.0, 0.1, 0.3)
    assert resolved(defaults=defaults) == defaults


def test_one_rule_says_which_scalings_and_planning_times_a_motion_is_planned_with() -> None:
    assert [is_scaling(f) for f in (1e-3, 1.0, 9e-4, 1.01, float("nan"))] == [True, True, False, False, False]
    assert [is_planning_time(t) for t in (1e-9, 1e6, 0.0, 1.1e6, float("nan"))] == [True, True, False, False, False]


def test_a_steps_own_scaling_wins_over_the_tasks_defaults(tmp_path: Path) -> None:
    task = load_task(task_file(tmp_path, "robot: r\ndefaults: {velocity_scaling: 0.2, planner: PRM}\n"
                                         "steps: [{named: home, velocity_scaling: 0.7}, {named: ready}]\n"))
    assert task.defaults == MotionSettings(planner="PRM", velocity_scaling=0.2)
    assert [s.motion for s in task.steps] == [MotionSettings(velocity_scaling=0.7), MotionSettings()]
