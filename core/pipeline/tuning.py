"""tune-pid pipeline: a plan and its controllers -> gains tuned joint by joint on the pid plant -> verified file.

Reads the plan and the controllers file (`--controllers`, else the one the plan embeds),
fits the plant to a recording if one is given, tunes each joint (core.control.tuning),
writes the controllers file with only the gains changed, and verifies it by executing the
plan through it under the same plant, as `execute --fake --plant pid --controllers` would.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np

from .. import bag as recording
from ..bag import staged_file
from ..config import ControllerConfig, read_input_text, tuned_controllers_text
from ..control import (
    Gains,
    JointSetup,
    JointTuning,
    PlantFit,
    RecordedStep,
    fit_plant,
    in_controller_order,
    pid_gains,
    pid_interface,
    pid_parameters,
    sample_index,
    tune_joint,
)
from ..errors import ConfigError, InputError, UsageError, known
from ._plan_files import plan_config, plan_controller, plant_settings, read_valid_plan
from .execution import (
    CheckedRecording,
    CheckRequest,
    ExecuteRequest,
    PlanExecution,
    check,
    execute,
)
from .report import execution_document, finite_numbers

__all__ = ["TuneRequest", "TuneResult", "tune", "tuning_document"]

_FIT_BEFORE_S = 0.2  # recorded samples kept before each aligned step start: the robot at rest, for the replay


@dataclass(frozen=True)
class TuneRequest:
    """What `moveplan tune-pid` was asked to do."""

    plan: Path
    output: Path
    controllers: Path | None = None
    joints: tuple[str, ...] = ()
    plant_params: Mapping[str, float] | None = None
    oscillations: int = 0
    recording: Path | None = None
    topic: str = "/joint_states"
    seed: int = 0
    plot: Path | None = None
    strict: bool = False  # --strict: a parameter the controller does not declare is an error


@dataclass(frozen=True)
class TuneResult:
    """The tuning: per joint its stages, the plant it ran on, the file written and its verification.

    Attributes:
        controller: The JointTrajectoryController tuned.
        source: The controllers file the gains came from (a plan's embedded file is named so).
        output: The file written.
        interface: velocity or effort.
        joints: Each tuned joint's stages and gains, in the controller's order.
        plant_params: The plant tuned on and verified with, as `--plant-param` keys.
        fit: The plant fitted to `--recording`, if one was given.
        verification: The plan executed with the tuned gains.
    """

    controller: str
    source: str
    output: Path
    interface: str
    joints: tuple[JointTuning, ...]
    plant_params: dict[str, float]
    fit: PlantFit | None
    verification: PlanExecution

    @property
    def ringing(self) -> list[str]:
        """Return the joints the verification names as ringing."""
        return [joint for joint, t in self.verification.tracking.items() if t.ringing]

    @property
    def ok(self) -> bool:
        """Return True if the verification passed its tolerances without a ringing joint."""
        return self.verification.ok and not self.ringing


def tune(request: TuneRequest, draw: Callable[[TuneResult, Path], None] | None = None) -> TuneResult:
    """Return the tuning of the plan's controller, its file written to `request.output` (and drawn to `request.plot`).

    The file is written whatever the verification finds (TuneResult.ok says). With
    `request.plot`, `draw` (tune_plot.write_tuning_plot) writes the plot before the gains file
    is renamed into place: if either fails, or a signal arrives, neither is left.

    Raises:
        InputError: The plan, the controllers file or the recording is unreadable or invalid,
            the controller does not command velocity or effort alone, or an output cannot be written.
        UsageError: An unknown joint in `joints`, a bad plant parameter, oscillations < 0.
    """
    if request.oscillations < 0:
        raise UsageError(f"--oscillations must be >= 0, got {request.oscillations}")
    plan = read_valid_plan(request.plan)
    config = plan_config(plan, request.plan)
    controller = plan_controller(config, plan, request.plan, request.controllers, strict=request.strict)
    continuous = np.array([config.limits[j].continuous if j in config.limits else False for j in controller.joints])
    text, source = _controllers_text(request, plan, config.sources.get("controllers"))
    try:
        interface = pid_interface(controller)
    except UsageError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    joints = _joints(request.joints, controller)
    params = plant_settings(config, "pid", request.plant_params)[1]  # the config's pid plant, if it has one
    values = pid_parameters(params, controller.joints)
    fit = None
    if request.recording is not None:
        fit = _fit(request, controller, interface, values, params, continuous)
        params = {**fit.plant_params(), **params}
        values = pid_parameters(params, controller.joints)
    tuned = tuple(_tune_joint(controller, joint, interface, values, request) for joint in joints)
    gains = {t.setup.joint: {k: v for k, v in t.gains.as_dict().items() if k != "ff_velocity_scale"} for t in tuned}
    written = tuned_controllers_text(text, source, controller.name, gains)
    drawn = False
    try:
        with staged_file(request.output, written.encode("utf-8")) as staged:
            verification = execute(ExecuteRequest(plan=request.plan, plant="pid", plant_params=params,
                                                  controllers=staged, seed=request.seed,
                                                  controllers_as_data=request.controllers is None))
            result = TuneResult(controller.name, source, request.output, interface, tuned, params, fit, verification)
            if request.plot is not None:
                assert draw is not None, "a plot asked for and nothing to draw it"
                draw(result, request.plot)
                drawn = True
    except BaseException:
        if drawn and request.plot is not None:
            request.plot.unlink(missing_ok=True)
        raise
    return result


def _controllers_text(request: TuneRequest, plan: recording.PlanFile, embedded: Path | None) -> tuple[str, str]:
    """Return the controllers file's text and how to name it: `--controllers`, else the plan's embedded file."""
    if request.controllers is not None:
        return read_input_text(request.controllers), str(request.controllers)
    if embedded is not None:
        for name, data in plan.attachments.items():
            if embedded.as_posix().endswith("/" + name):
                return data.decode("utf-8"), f"{request.plan}: embedded {name}"
    raise ConfigError(f"{request.plan}: the plan embeds no ros2_controllers.yaml to tune; give --controllers FILE")


def _joints(asked: Sequence[str], controller: ControllerConfig) -> tuple[str, ...]:
    """Return the joints to tune, in the controller's order (all of them when none are asked)."""
    for joint in asked:
        if joint not in controller.joints:
            raise UsageError(f"--joints: joint '{joint}' is not driven by controller '{controller.name}'; "
                             f"known: {known(controller.joints)}")
    return tuple(j for j in controller.joints if not asked or j in asked)


def _tune_joint(
    controller: ControllerConfig, joint: str, interface: str, values: Mapping[str, np.ndarray], request: TuneRequest
) -> JointTuning:
    """Return one joint tuned on its plant, from the controller's gains for it."""
    column = controller.joints.index(joint)
    start = Gains(**{key: float(controller.gains.get(joint, {}).get(key, 0.0)) for key in Gains().as_dict()})
    setup = JointSetup(joint, interface, 1.0 / controller.update_rate_hz, controller.goal_tolerance[joint],
                       {key: float(value[column]) for key, value in values.items()},
                       oscillations=request.oscillations, seed=request.seed)
    return tune_joint(setup, start)


def _fit(
    request: TuneRequest, controller: ControllerConfig, interface: str, values: Mapping[str, np.ndarray],
    params: Mapping[str, float], continuous: np.ndarray,
) -> PlantFit:
    """Return the plant fitted to the recording of the plan, the parameters the user gave held."""
    assert request.recording is not None
    steps: list[RecordedStep] = []

    def take(checked: CheckedRecording) -> None:
        steps.extend(_recorded_steps(checked))

    check(CheckRequest(request.plan, request.recording, request.topic, request.controllers), then=take)
    if not steps:
        raise InputError(f"{request.recording}: no execution of the plan found to fit the plant to")
    given = {key: values[key] for key in values if any(k == key or k.startswith(key + ".") for k in params)}
    return fit_plant(steps, interface, 1.0 / controller.update_rate_hz, pid_gains(controller), given, continuous)


def _recorded_steps(checked: CheckedRecording) -> list[RecordedStep]:
    """Return the recorded samples of each judged step, from a little before its aligned start to the next step."""
    report, samples = checked.report, checked.samples
    judged = report.steps or next((c.steps for c in report.cycles if c.complete), ())
    columns = [samples.names.index(j) for j in checked.controller.joints]
    steps = []
    for number, step in enumerate(judged):
        end = judged[number + 1].start_s if number + 1 < len(judged) else step.start_s + step.duration_s
        first, stop = sample_index(samples, step.start_s - _FIT_BEFORE_S), sample_index(samples, end)
        if stop - first < 3:
            continue
        hold = samples.read_positions(0, 1)[0][columns]  # where joints a partial goal leaves out stay
        trajectory = in_controller_order(checked.plan.steps[number].trajectory, checked.controller, hold)
        positions = samples.read_positions(first, stop)[:, columns]
        steps.append(RecordedStep(trajectory, samples.read_times(first, stop) - step.start_s, positions))
    return steps


def tuning_document(result: TuneResult, plot: Path | None = None) -> dict[str, Any]:
    """Return the tune-pid JSON document: per joint its stages and gains, the plant, the fit and the verification.

    Keys: ok, output, controller, source, interface, plant (the parameters tuned on), fit (null
    without --recording: rms_error [rad], fraction of the largest joint travel, travel,
    samples, shifts_s, joints {joint: {params, rms_error, travel, fraction}}), joints {joint:
    {start, gains, bump, load, stages [{stage, gains, response, chosen, note}]}}, verification
    (as execute --json), ringing (the joints the verification names), error (null); last plot,
    the figure drawn, if `plot` is given.
    """
    fit = None
    if result.fit is not None:
        fit = {"rms_error": result.fit.rms_error, "fraction": result.fit.fraction, "travel": result.fit.travel,
               "samples": result.fit.samples, "shifts_s": list(result.fit.shifts_s),
               "joints": {j.joint: {"params": j.params, "rms_error": j.rms_error, "travel": j.travel,
                                    "fraction": j.fraction} for j in result.fit.joints}}
    joints = {
        t.setup.joint: {
            "start": t.stages[0].gains.as_dict(), "gains": t.gains.as_dict(), "bump": t.setup.bump, "load": t.load,
            "stages": [{"stage": s.stage, "gains": s.gains.as_dict(), "response": s.response.as_dict(),
                        "chosen": s.chosen, "note": s.note} for s in t.stages],
        }
        for t in result.joints
    }
    document = {
        "ok": result.ok, "output": str(result.output), "controller": result.controller, "source": result.source,
        "interface": result.interface, "plant": result.plant_params, "fit": fit, "joints": joints,
        "verification": execution_document(result.verification), "ringing": result.ringing, "error": None,
    }
    if plot is not None:
        document["plot"] = str(plot)
    return cast("dict[str, Any]", finite_numbers(document))
