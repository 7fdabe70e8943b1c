"""The simulated JointTrajectoryController loop, with MoveIt's execution checks around it.

One execution as ros2_controllers' Jazzy-era JTC runs a FollowJointTrajectory
goal that MoveIt's TrajectoryExecutionManager sent: MoveIt first compares the
start state with the plan's first point, then the controller cycles at its
update rate; each cycle it reads the state, samples the reference at the cycle
time ("desired", used for the tolerance checks) and one period later (the
command it writes), and checks path and goal tolerances. MoveIt stops the
execution when it runs longer than its duration monitor allows. Simulated time
runs as fast as the computer does.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..config import ControllerConfig, ExecutionConfig
from ..errors import InputError, UsageError, known
from ..trajectory import PointBefore, sample
from ..types import GoalTolerances, JointTrajectory, frozen_array
from ._judging import judge
from ._moveit_checks import Timeout, check_start_state, expected_duration_s
from .plants import Plant
from .results import (
    GOAL_TOLERANCE_VIOLATED,
    PATH_TOLERANCE_VIOLATED,
    TIMED_OUT,
    ExecutionResult,
    ExecutionSummary,
    ToleranceReport,
    Violation,
)
from .tolerances import (
    SegmentTolerances,
    goal_segment_tolerances,
    in_controller_order,
    position_error,
    segment_tolerances,
    velocity_error_computable,
)

__all__ = [
    "DEFAULT_MAX_CYCLES", "MAX_CYCLES_ENV", "WAIT_LIMIT_S", "Disturbance", "ExecutionReport", "max_control_cycles",
    "simulate",
]

_FIRST_CHUNK = 256
# Cycle times sampled at a time: the spline's temporaries (a dozen arrays) stay this size.
_SAMPLE_BLOCK = 16_384

# Three (K, n) arrays per cycle and joint: positions, velocities, and accelerations or outputs.
_PerCycle = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]

WAIT_LIMIT_S = 10.0
"""How long after the last point the simulation waits at least when nothing else ends it, in [s].

With constraints.goal_time 0 a Jazzy JTC waits for the goal tolerance forever
(ros2_controllers#548); 10 s is the goal_time default newer JTC versions adopted.
"""

MAX_CYCLES_ENV = "MOVEPLAN_MAX_CONTROL_CYCLES"
"""The environment variable that sets the most control cycles one trajectory's simulation may take."""

DEFAULT_MAX_CYCLES = 1_000_000
"""Control cycles one trajectory's simulation may take without MOVEPLAN_MAX_CONTROL_CYCLES: 2.8 h at 100 Hz,
16 min at 1 kHz. The simulation keeps a trajectory's samples, ~1 kB a cycle (a 24 min step at 500 Hz
peaked at 630 MB): a plan of a day at 1 kHz would need 90 GB."""


@dataclass(frozen=True)
class Disturbance:
    """A bump: at `time_s` [s] after the start, `joint`'s position moves by `delta` [rad] or [m]."""

    time_s: float
    joint: str
    delta: float


_SERIES = (
    "reference_positions", "reference_velocities", "reference_accelerations",
    "actual_positions", "actual_velocities", "output", "error",
)


@dataclass(frozen=True)
class ExecutionReport:
    """What a simulated execution did: its verdict and, per control cycle, the controller's state.

    Attributes:
        ok: True if the goal succeeded.
        result: How it ended (FollowJointTrajectory or MoveIt code, name and message).
        violations: The failed checks on the cycle it ended.
        margins: Per joint with a nonzero tolerance, the smallest tolerance - |error| in [rad].
        duration_s: Simulated time until the result in [s].
        joint_names: Column order of the arrays (the controller's joint order).
        times_s: Cycle times from the start in [s], shape (K,); K = 0 if it never started.
        reference_positions: What the controller sampled at each cycle ("desired"), (K, n);
            reference_velocities and reference_accelerations likewise.
        actual_positions: Measured positions, (K, n); actual_velocities likewise.
        output: Value written to the plant's command interface each cycle, (K, n).
        output_interface: That interface: position, velocity or effort.
        error: reference - actual positions (shortest angle for continuous joints), (K, n).
    """

    ok: bool
    result: ExecutionResult
    violations: tuple[Violation, ...]
    margins: dict[str, float]
    duration_s: float
    joint_names: tuple[str, ...]
    times_s: NDArray[np.float64]
    reference_positions: NDArray[np.float64]
    reference_velocities: NDArray[np.float64]
    reference_accelerations: NDArray[np.float64]
    actual_positions: NDArray[np.float64]
    actual_velocities: NDArray[np.float64]
    output: NDArray[np.float64]
    error: NDArray[np.float64]
    output_interface: str = "position"

    def __post_init__(self) -> None:
        times = frozen_array(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        shape = (len(times), len(self.joint_names))
        for name in _SERIES:
            object.__setattr__(self, name, frozen_array(getattr(self, name), shape, name))

    def summary(self) -> ExecutionSummary:
        """Return the verdict without the per-cycle samples: what a plan's execution keeps of a step."""
        return ExecutionSummary(self.ok, self.result, self.violations, self.margins, self.duration_s,
                                self.joint_names, len(self.times_s), self.output_interface)

    def cycles(self, start: int, stop: int) -> ExecutionReport:
        """Return the report restricted to cycles [start, stop), same verdict: a block of them to write."""
        rows = slice(start, stop)
        return replace(self, times_s=self.times_s[rows], **{name: getattr(self, name)[rows] for name in _SERIES})


def simulate(
    trajectory: JointTrajectory,
    controller: ControllerConfig,
    execution: ExecutionConfig,
    plant: Plant,
    *,
    continuous_joints: Iterable[str] = (),
    start_positions: npt.ArrayLike | None = None,
    disturbances: Sequence[Disturbance] = (),
    seed: int = 0,
    fill_point_before: bool = True,
    goal_tolerances: GoalTolerances | None = None,
) -> ExecutionReport:
    """Return the report of executing `trajectory` through the controller on `plant`.

    Args:
        trajectory: The plan's trajectory; its joints must be the controller's, in any order.
        controller: The JointTrajectoryController's parameters (rate, interfaces, constraints).
        execution: MoveIt's trajectory_execution settings.
        plant: The simulated hardware, built for the controller's joints in their order.
        continuous_joints: Names of URDF continuous joints (errors wrap around).
        start_positions: Where the robot is when the goal is sent, in the controller's joint
            order; None = exactly at the trajectory's first point.
        disturbances: Bumps applied to the actual positions during the execution.
        seed: Seeds the plant's randomness (measurement noise).
        fill_point_before: The blend before a first point after time 0 has the trajectory's spline
            degree, as ros2_controllers has done since PR #2043 (releases.py); False: as before it.
        goal_tolerances: Tolerances the goal carries, replacing the controller's for it
            (tolerances.goal_segment_tolerances).
    """
    hold = None if start_positions is None else np.asarray(start_positions, dtype=np.float64)
    if hold is not None and len(hold) != len(controller.joints):
        hold = None  # the trajectory's joints only: no joint is left out to hold
    trajectory = in_controller_order(trajectory, controller, hold)
    joints = trajectory.joint_names
    names = set(continuous_joints)
    continuous = np.array([j in names for j in joints])
    first = trajectory.positions[0]
    start = first
    if start_positions is not None:
        start = frozen_array(start_positions, first.shape, "start_positions")
    refused = check_start_state(joints, start, first, execution.allowed_start_tolerance, continuous)
    if refused is not None:
        return _not_started(refused, joints, plant.interface)

    dt = 1.0 / controller.update_rate_hz
    tolerances = goal_segment_tolerances(segment_tolerances(controller), goal_tolerances)
    timeout = _timeout(trajectory.duration_s, tolerances.goal_time_s, execution)
    horizon_s = _horizon_s(trajectory.duration_s, tolerances.goal_time_s, timeout)
    cycles, limit = horizon_s / dt, max_control_cycles()
    if not cycles <= limit:  # counted before the grid is built: a margin of 1e12 s would ask for terabytes
        raise InputError(f"a {trajectory.duration_s:.6g} s trajectory watched for up to {horizon_s:.6g} s (goal time, "
                         f"MoveIt's duration monitor) at {controller.update_rate_hz:g} Hz is {cycles:,.0f} control "
                         f"cycles; moveplan simulates at most {limit:,} per trajectory ({MAX_CYCLES_ENV} raises the "
                         "limit; memory grows ~1 kB a cycle)")
    grid = _time_grid(horizon_s, dt)
    bumps = _bumps(disturbances, joints, grid[:-1], dt)
    p0, v0 = plant.reset(start, seed)
    if np.any(bumps[0]):
        p0, v0 = plant.displace(bumps[0])
    initial_output = plant.last_output.copy()
    before = _point_before(controller, p0, v0, trajectory if fill_point_before else None)
    reference = _reference(trajectory, grid, before, continuous)
    verdict_of = _judge_cycles(trajectory, controller, tolerances, grid, reference, timeout, continuous)
    actual_p, actual_v, output, verdict = _run(plant, reference, bumps, (p0, v0), dt, verdict_of)
    return _executed(verdict, joints, grid, reference, (actual_p, actual_v, output), initial_output, continuous,
                     plant.interface)


def _executed(
    verdict: ToleranceReport,
    joints: tuple[str, ...],
    grid: NDArray[np.float64],
    reference: _PerCycle,
    measured: _PerCycle,
    initial_output: NDArray[np.float64],
    continuous: NDArray[np.bool_],
    interface: str,
) -> ExecutionReport:
    """Return the report of an execution that ran: its cycles up to the one that decided."""
    actual_p, actual_v, output = measured
    ref_p, ref_v, ref_a = reference
    end = verdict.end_index + 1
    return ExecutionReport(
        ok=verdict.ok,
        result=verdict.result,
        violations=verdict.violations,
        margins=verdict.margins,
        duration_s=float(grid[end - 1]),
        joint_names=joints,
        times_s=grid[:end],
        reference_positions=ref_p[:end],
        reference_velocities=ref_v[:end],
        reference_accelerations=ref_a[:end],
        actual_positions=actual_p[:end],
        actual_velocities=actual_v[:end],
        output=_hold_on_abort(output[:end], initial_output, verdict.result.code),
        error=position_error(ref_p[:end], actual_p[:end], continuous),
        output_interface=interface,
    )


def _reference(
    trajectory: JointTrajectory, grid: NDArray[np.float64], point_before: PointBefore, continuous: NDArray[np.bool_]
) -> _PerCycle:
    """Return what the controller samples at each cycle time of `grid`: positions, velocities, accelerations.

    Sampled in blocks into arrays of the grid's length: the spline's temporaries (a dozen
    arrays per sample) then stay a block's size however long the step.
    """
    shape = (len(grid), len(trajectory.joint_names))
    reference = (np.empty(shape), np.empty(shape), np.empty(shape))
    for first in range(0, len(grid), _SAMPLE_BLOCK):
        rows = slice(first, first + _SAMPLE_BLOCK)
        block = sample(trajectory, grid[rows], point_before=point_before, continuous=continuous)
        for values, sampled in zip(reference, block, strict=True):
            values[rows] = sampled
    return reference


def _judge_cycles(
    trajectory: JointTrajectory,
    controller: ControllerConfig,
    tolerances: SegmentTolerances,
    grid: NDArray[np.float64],
    reference: _PerCycle,
    timeout: Timeout,
    continuous: NDArray[np.bool_],
) -> Callable[[NDArray[np.float64], NDArray[np.float64]], ToleranceReport]:
    """Return the verdict on the first K cycles of `grid`, given the K states read so far."""
    ref_p, ref_v, _ = reference
    velocities = velocity_error_computable(controller)

    def verdict_of(actual_p: NDArray[np.float64], actual_v: NDArray[np.float64]) -> ToleranceReport:
        k = len(actual_p)
        return judge(
            tolerances, grid[:k], ref_p[:k], actual_p,
            # Jazzy's update() takes the segment from its second sample: the command's, at t + dt.
            before_last_point=grid[1 : k + 1] < trajectory.duration_s,
            last_point_s=trajectory.duration_s,
            timeout=timeout,
            reference_velocities=ref_v[:k] if velocities else None,
            actual_velocities=actual_v if velocities else None,
            continuous=continuous,
        )

    return verdict_of


def _run(
    plant: Plant,
    reference: _PerCycle,
    bumps: NDArray[np.float64],
    initial: tuple[NDArray[np.float64], NDArray[np.float64]],
    dt: float,
    verdict_of: Callable[[NDArray[np.float64], NDArray[np.float64]], ToleranceReport],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], ToleranceReport]:
    """Return actual positions, velocities, outputs and the verdict, running the plant till decided.

    Cycle k reads the state, is checked against the sample at grid[k] and writes the sample at
    grid[k + 1]; bump k + 1 moves the joints before cycle k + 1 reads them. The plant runs in
    growing chunks, so an execution that ends early does not simulate the rest of the horizon.
    """
    ref_p, ref_v, ref_a = reference
    count, n = len(ref_p) - 1, ref_p.shape[1]
    after = np.vstack((bumps[1:], np.zeros_like(bumps[:1])))
    # Filled chunk by chunk, no copies of what came before: row k + 1 of the states is what
    # command k leads to, which cycle k + 1 reads.
    actual_p, actual_v, output = np.empty((count + 1, n)), np.empty((count + 1, n)), np.empty((count, n))
    actual_p[0], actual_v[0] = initial
    done, size = 0, _FIRST_CHUNK
    while True:
        stop = min(count, done + size)
        # A diverging plant (unstable gains) overflows; the verdict comes from the cycles before.
        with np.errstate(over="ignore", invalid="ignore"):
            measured_p, measured_v, outputs = plant.run(ref_p[done + 1 : stop + 1], ref_v[done + 1 : stop + 1],
                                                        ref_a[done + 1 : stop + 1], dt, after[done:stop])
        actual_p[done + 1 : stop + 1], actual_v[done + 1 : stop + 1], output[done:stop] = (
            measured_p, measured_v, outputs)
        verdict = verdict_of(actual_p[:stop], actual_v[:stop])
        # On a partial series, a TIMED_OUT verdict at its last cycle only means "not decided yet".
        if stop == count or verdict.result.code != TIMED_OUT or verdict.end_index < stop - 1:
            return actual_p[:stop], actual_v[:stop], output[:stop], verdict
        done, size = stop, 2 * size


def max_control_cycles() -> int:
    """Return the most control cycles one trajectory's simulation may take: MOVEPLAN_MAX_CONTROL_CYCLES, else 1e6.

    Raises:
        UsageError: The variable is set to something that is not a positive integer.

    """
    text = os.environ.get(MAX_CYCLES_ENV, "").strip()
    if not text:
        return DEFAULT_MAX_CYCLES
    if not text.isdigit() or int(text) == 0:
        raise UsageError(f"{MAX_CYCLES_ENV}={text[:40]!r}: expected a positive number of control cycles")
    return int(text)


def _horizon_s(duration_s: float, goal_time_s: float, timeout: Timeout) -> float:
    """Return the last time [s] at which a cycle can decide the execution's verdict."""
    return min(timeout.time_s, duration_s + goal_time_s) if goal_time_s > 0.0 else timeout.time_s


def _time_grid(horizon_s: float, dt: float) -> NDArray[np.float64]:
    """Return cycle times [s] through the last cycle that can decide (at `horizon_s`), plus one for its command."""
    # Two cycles past the deciding time, so rounding never cuts the cycle that decides.
    return np.asarray(np.arange(math.floor(horizon_s / dt) + 3) * dt, dtype=np.float64)


def _timeout(duration_s: float, goal_time_s: float, execution: ExecutionConfig) -> Timeout:
    """Return when to give up: at MoveIt's duration monitor, else at the simulation's hard stop."""
    expected = expected_duration_s(duration_s, execution)
    if execution.execution_duration_monitoring:
        return Timeout(expected, (
            f"Controller is taking too long to execute trajectory (the expected upper bound for "
            f"the trajectory execution was {expected:.6f} seconds). Stopping trajectory."
        ))
    hard_stop = max(expected, duration_s + WAIT_LIMIT_S)
    waits = "forever" if goal_time_s == 0.0 else f"{goal_time_s:g} s"
    return Timeout(hard_stop, (
        f"simulation stopped at {hard_stop:.6f} s without a result: the controller was still "
        f"waiting for the goal tolerance (goal time {goal_time_s:g}: it waits {waits}) and MoveIt's "
        "execution_duration_monitoring is off"
    ))


def _bumps(
    disturbances: Sequence[Disturbance],
    joints: tuple[str, ...],
    times_s: NDArray[np.float64],
    dt: float,
) -> NDArray[np.float64]:
    """Return per cycle and joint the displacement applied before that cycle's state is read."""
    bumps = np.zeros((len(times_s), len(joints)))
    for disturbance in disturbances:
        if disturbance.joint not in joints:
            raise UsageError(
                f"disturbance names joint '{disturbance.joint}', which the trajectory does not "
                f"have; known: {known(joints)}"
            )
        if not disturbance.time_s >= 0.0:
            raise UsageError(f"disturbance time must be >= 0 s, got {disturbance.time_s}")
        # The first cycle at or after the time; the tolerance absorbs k * dt rounding.
        k = math.ceil(disturbance.time_s / dt - 1e-9)
        if k < len(times_s):
            bumps[k, joints.index(disturbance.joint)] += disturbance.delta
    return bumps


def _point_before(controller: ControllerConfig, positions: NDArray[np.float64],
                  velocities: NDArray[np.float64], filled_like: JointTrajectory | None = None) -> PointBefore:
    """Return the state JTC blends from: the fields it reads are those of its state interfaces.

    With `filled_like` (ros2_controllers' trajectory.cpp set_point_before_trajectory_msg, since
    PR #2043), a field the state lacks but the trajectory's points carry is zero.
    """
    has_velocity = "velocity" in controller.state_interfaces
    has_acceleration = has_velocity and "acceleration" in controller.state_interfaces
    zeros = np.zeros_like(positions)
    if filled_like is not None:
        return PointBefore(
            positions,
            velocities if has_velocity else zeros if filled_like.has_velocities else None,
            zeros if has_acceleration or filled_like.has_accelerations else None,
        )
    # The plants start at rest and model no acceleration state: read as 0.
    return PointBefore(positions, velocities if has_velocity else None, zeros if has_acceleration else None)


def _hold_on_abort(
    output: NDArray[np.float64], initial: NDArray[np.float64], code: int
) -> NDArray[np.float64]:
    """Return the outputs without the aborting cycle's command: JTC checks before it writes."""
    if code not in (PATH_TOLERANCE_VIOLATED, GOAL_TOLERANCE_VIOLATED):
        return output
    held = output.copy()
    held[-1] = held[-2] if len(held) > 1 else initial
    return held


def _not_started(
    refused: ToleranceReport, joints: tuple[str, ...], interface: str
) -> ExecutionReport:
    empty = np.zeros((0, len(joints)))
    return ExecutionReport(
        ok=False, result=refused.result, violations=refused.violations, margins={},
        duration_s=0.0, joint_names=joints, times_s=np.zeros(0), reference_positions=empty,
        reference_velocities=empty, reference_accelerations=empty, actual_positions=empty,
        actual_velocities=empty, output=empty, error=empty, output_interface=interface,
    )
