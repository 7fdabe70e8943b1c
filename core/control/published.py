"""The state a JointTrajectoryController publishes each cycle of an execution, as ros2_controllers fills it."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..config import ControllerConfig
from ..types import ControllerStates, PointSeries
from .controller import ExecutionReport
from .tolerances import velocity_error_computable

__all__ = ["controller_states"]

# Where each output interface's command goes in the controller state's `output` point.
_OUTPUT_FIELDS = {
    "position": "positions",
    "velocity": "velocities",
    "acceleration": "accelerations",
    "effort": "effort",
}


def controller_states(
    report: ExecutionReport,
    controller: ControllerConfig,
    stamps_ns: NDArray[np.int64],
    times_ns: NDArray[np.int64],
) -> ControllerStates:
    """Return the state messages a JTC publishes over `report`'s cycles.

    Filled as ros2_controllers fills them: reference = the sample at the cycle time
    (positions, velocities, accelerations); feedback = what the state interfaces read,
    velocities only with a velocity state interface; error positions = reference - feedback
    (shortest angle for continuous joints); velocity error only where JTC computes it,
    else 0 (see velocity_error_computable); output = the command written, in
    its interface's field. The plants model no acceleration state, read as 0.
    """
    if report.output_interface not in _OUTPUT_FIELDS:
        raise ValueError(
            f"output interface '{report.output_interface}' is not one of "
            f"{', '.join(_OUTPUT_FIELDS)}"
        )
    zeros = np.zeros_like(report.actual_positions)
    has_velocity = "velocity" in controller.state_interfaces
    # JTC reads acceleration states only together with velocity states.
    has_acceleration = has_velocity and "acceleration" in controller.state_interfaces
    velocity_error = report.reference_velocities - report.actual_velocities
    acceleration_error = report.reference_accelerations  # minus the acceleration read, 0
    computes_acceleration = "acceleration" in controller.command_interfaces
    return ControllerStates(
        joint_names=report.joint_names,
        stamps_ns=stamps_ns,
        times_from_start_ns=times_ns,
        reference=PointSeries(
            report.reference_positions,
            report.reference_velocities,
            report.reference_accelerations,
        ),
        feedback=PointSeries(
            report.actual_positions,
            report.actual_velocities if has_velocity else None,
            zeros if has_acceleration else None,
        ),
        error=PointSeries(
            report.error,
            (velocity_error if velocity_error_computable(controller) else zeros)
            if has_velocity
            else None,
            (acceleration_error if computes_acceleration else zeros) if has_acceleration else None,
        ),
        output=PointSeries(**{_OUTPUT_FIELDS[report.output_interface]: report.output}),
    )
