"""A plan file's services: the robot config it carries, its steps checked as goals, and the controller that runs it.

What every command reading a plan needs before it does its own work: execute and
check-tolerances, inspect, state --from, tune-pid, and plan's --start-from.
"""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from .. import bag as recording
from ..config import (
    CONFIG_FILE,
    ControllerConfig,
    RobotConfig,
    check_carried,
    default_controller,
    load_robot_config,
    parse_controllers,
)
from ..control import validate_goal, validate_goal_end
from ..errors import ConfigError, InputError, UsageError

if TYPE_CHECKING:
    from ..control import Plant

__all__ = [
    "MAX_PLAN_S", "configured_plant", "pick_controller", "plan_config", "plan_controller", "plant_settings",
    "read_valid_plan",
]

MAX_PLAN_S = 86_400.0
"""The longest plan read, in [s] from its first step's start to its last step's end: a day."""

_LOG = logging.getLogger(__name__)


def plan_config(plan: recording.PlanFile, source: Path) -> RobotConfig:
    """Return the robot config embedded in a plan file, read as data: no xacro, no substitution, no host file.

    Raises:
        InputError: The plan carries no config, carries xacro (written by an earlier moveplan:
            planned again, it carries the expanded files), or a config that names a file it
            does not carry or does not load; names the plan file.
    """
    if CONFIG_FILE not in plan.attachments:
        raise InputError(f"{source}: the plan carries no robot config ({CONFIG_FILE} attachment missing)")
    check_carried(plan.attachments, str(source))
    with tempfile.TemporaryDirectory(prefix="moveplan-") as folder:
        for name, data in plan.attachments.items():
            path = Path(folder) / name
            if not path.resolve().is_relative_to(Path(folder).resolve()):
                raise InputError(f"{source}: attachment name '{name}' points outside the config")
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(data)
            except OSError as exc:  # names such as "." or both "a" and "a/b"
                raise InputError(f"{source}: attachment name '{name}' is not a file name: {exc.strerror}") from None
        # Its warnings were given when the plan was made, and would name a temporary folder here.
        config_log = logging.getLogger("moveplan.core.config")
        level = config_log.level
        config_log.setLevel(logging.ERROR)
        try:
            return load_robot_config(folder, embedded=True)
        except ConfigError as exc:
            # The files are the plan's: named as it carries them, not by the temporary folder.
            message = str(exc).replace(f"{Path(folder).resolve()}/", "").replace(f"{folder}/", "")
            raise InputError(f"{source}: embedded config: {message}") from None
        finally:
            config_log.setLevel(level)


def read_valid_plan(path: Path) -> recording.PlanFile:
    """Return the plan file at `path`, each step checked as JTC validates a goal, the whole no longer than MAX_PLAN_S.

    Raises:
        InputError: The file is unreadable, or a step holds a NaN or infinite value or
            times that are not strictly increasing (the message names step, point and joint),
            or ends more than MAX_PLAN_S after the plan's start.

    """
    plan = recording.read_plan(path)
    for step in plan.steps:
        validate_goal(step.trajectory, f"{path}: step '{step.name}' on /planned_trajectory")
    origin = min((step.start_s for step in plan.steps), default=0.0)
    for step in plan.steps:
        end_s = step.start_s - origin + step.trajectory.duration_s
        if end_s > MAX_PLAN_S:
            raise InputError(
                f"{path}: step '{step.name}' ends {end_s:.6g} s after the plan's start, past the limit of "
                f"{MAX_PLAN_S:.0f} s (a day) on a plan's length (a time_from_start or log time written wrong?)")
    return plan


def pick_controller(
    controllers: Mapping[str, ControllerConfig], joints: Sequence[str], source: str, preferred: Sequence[str] = ()
) -> ControllerConfig:
    """Return the JointTrajectoryController that drives all of `joints`, chosen as MoveIt chooses.

    MoveIt's TrajectoryExecutionManager ranks the controllers that fit by whether moveit_controllers.yaml
    marks them `default: true` (`preferred`), then by fewest joints. Several left that differ
    (tolerances, gains, interfaces, rate) are an error: ros2_control activates only one of them,
    and which one the launch file spawns active is not in the files.
    """
    fitting = [c for c in controllers.values() if set(joints) <= set(c.joints)]
    if not fitting:
        why = "" if controllers else (" (the file gives no controller a JointTrajectoryController type: under "
                                      "controller_manager's ros__parameters, or in a launch file of its package "
                                      "that spawns it)")
        raise ConfigError(f"{source}: no JointTrajectoryController drives all of {', '.join(joints)}; "
                          f"controllers: {', '.join(controllers) or '(none)'}{why}")
    best = min((c.name not in preferred, len(c.joints)) for c in fitting)
    candidates = [c for c in fitting if (c.name not in preferred, len(c.joints)) == best]
    # The same joints listed in another order drive the robot the same way.
    settings = [replace(c, name="", joints=tuple(sorted(c.joints))) for c in candidates]
    if any(other != settings[0] for other in settings[1:]):
        names = ", ".join(f"'{c.name}'" for c in candidates)
        raise ConfigError(f"{source}: controllers {names} all drive {', '.join(joints)} with different settings; "
                          "keep one, mark one `default: true` in moveit_controllers.yaml, or pass "
                          "--controllers FILE holding one")
    return candidates[0]


def plan_controller(
    config: RobotConfig, plan: recording.PlanFile, path: Path, override: Path | None, substitute: bool = True,
    strict: bool = False,
) -> ControllerConfig:
    """Return the controller that executes the plan at `path`: from `override` (--controllers), else its own config.

    `substitute` False reads `override` as data: launch substitutions are left as text. `strict`
    (--strict) refuses a parameter `override`'s controller does not declare.

    Raises:
        InputError: A step the controller would refuse as a goal (a last point that still moves).
    """
    controller = _plan_controller(config, plan, path, override, substitute, strict)
    for step in plan.steps:
        validate_goal_end(step.trajectory, controller.allow_nonzero_velocity_at_trajectory_end,
                          f"{path}: step '{step.name}' for {controller.name}")
    return controller


def _plan_controller(
    config: RobotConfig, plan: recording.PlanFile, path: Path, override: Path | None, substitute: bool,
    strict: bool,
) -> ControllerConfig:
    joints = plan.steps[0].trajectory.joint_names
    if override is not None:
        # MoveIt's preference comes from its own controllers file, whichever file ros2_control reads.
        return pick_controller(parse_controllers(override, substitute=substitute, strict=strict), joints, str(override),
                               config.execution.default_controllers)
    if "controllers" not in config.sources:
        # A config without ros2_controllers.yaml (ABB's, most Setup Assistant packages before Humble): the
        # controller ros2_control would load with no parameters file, as users get from mock hardware.
        _LOG.warning("%s: the robot config has no ros2_controllers.yaml; executing with a "
                     "JointTrajectoryController at ros2_controllers' defaults (100 Hz, position interface, "
                     "no path or goal tolerances); --controllers FILE gives yours", path)
        return default_controller(joints)
    return pick_controller(config.controllers, joints, f"{path}: embedded {config.sources['controllers'].name}",
                           config.execution.default_controllers)


def plant_settings(config: RobotConfig, model: str | None,
                   params: Mapping[str, float] | None) -> tuple[str, dict[str, float]]:
    """Return the plant to execute on and its parameters: the flags', over the robot config's plant.

    The config's parameters apply when its model is the one used; --plant-param overrides them.
    """
    configured = config.plant
    chosen = model or (configured.model if configured is not None else "mirror")
    base = dict(configured.params) if configured is not None and configured.model == chosen else {}
    return chosen, {**base, **dict(params or {})}


def configured_plant(config: RobotConfig, model: str | None, params: Mapping[str, float] | None,
                     controller: ControllerConfig, continuous: Sequence[str]) -> Plant:
    """Return the plant to execute on (plant_settings), built for `controller`.

    Raises:
        ConfigError: The robot config's plant has a parameter its model does not take, or a bad value.
        UsageError: Likewise for the flags' (--plant, --plant-param).
    """
    from ..control import make_plant  # here: check-tolerances reads plan files and simulates nothing

    chosen, values = plant_settings(config, model, params)
    try:
        return make_plant(chosen, values, controller, continuous)
    except UsageError as exc:
        given = params or {}
        if config.plant is None or config.plant.model != chosen or all(k in given for k in config.plant.params):
            raise
        raise ConfigError(f"{config.name}: moveplan.yaml: plant: {exc}") from None
