"""ros2_control as MoveIt drives it: the JointTrajectoryController, simulated hardware, and its tolerances."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .check import (
        SCAN_ROWS,
        CheckReport,
        CycleCheck,
        RecordingStart,
        SampleSource,
        StepCheck,
        check_recording,
        uses_velocities,
    )
    from .controller import Disturbance, ExecutionReport, simulate
    from .goal_validation import validate_goal, validate_goal_end
    from .margins import merged_margins
    from .plants import (
        PLANTS,
        Plant,
        PlantFit,
        RecordedStep,
        fit_plant,
        make_plant,
        pid_gains,
        pid_interface,
        pid_parameters,
    )
    from .published import controller_states
    from .quality import JointTracking, merged_tracking
    from .releases import DEFAULT_RELEASE, fills_point_before
    from .results import ExecutionResult, ExecutionSummary, Violation
    from .step_tracking import recorded_tracking, sample_index, simulated_tracking
    from .tolerances import check_goal_joints, in_controller_order, position_error, unchecked_joints
    from .tuning import Gains, JointSetup, JointTuning, tune_joint

__all__ = [
    "DEFAULT_RELEASE",
    "PLANTS",
    "SCAN_ROWS",
    "CheckReport",
    "CycleCheck",
    "Disturbance",
    "ExecutionReport",
    "ExecutionResult",
    "ExecutionSummary",
    "Gains",
    "JointSetup",
    "JointTracking",
    "JointTuning",
    "Plant",
    "PlantFit",
    "RecordedStep",
    "RecordingStart",
    "SampleSource",
    "StepCheck",
    "Violation",
    "check_recording",
    "controller_states",
    "fills_point_before",
    "fit_plant",
    "check_goal_joints",
    "in_controller_order",
    "make_plant",
    "merged_margins",
    "merged_tracking",
    "pid_gains",
    "pid_interface",
    "pid_parameters",
    "position_error",
    "recorded_tracking",
    "sample_index",
    "simulate",
    "simulated_tracking",
    "tune_joint",
    "unchecked_joints",
    "uses_velocities",
    "validate_goal",
    "validate_goal_end",
]

__getattr__ = lazy_exports(__name__, {
    "DEFAULT_RELEASE": "releases",
    "PLANTS": "plants",
    "SCAN_ROWS": "check",
    "CheckReport": "check",
    "CycleCheck": "check",
    "Disturbance": "controller",
    "ExecutionReport": "controller",
    "ExecutionResult": "results",
    "ExecutionSummary": "results",
    "Gains": "tuning",
    "JointSetup": "tuning",
    "JointTracking": "quality",
    "JointTuning": "tuning",
    "Plant": "plants",
    "PlantFit": "plants",
    "RecordedStep": "plants",
    "RecordingStart": "check",
    "SampleSource": "check",
    "StepCheck": "check",
    "Violation": "results",
    "check_recording": "check",
    "controller_states": "published",
    "fills_point_before": "releases",
    "fit_plant": "plants",
    "check_goal_joints": "tolerances",
    "in_controller_order": "tolerances",
    "make_plant": "plants",
    "merged_margins": "margins",
    "merged_tracking": "quality",
    "pid_gains": "plants",
    "pid_interface": "plants",
    "pid_parameters": "plants",
    "position_error": "tolerances",
    "recorded_tracking": "step_tracking",
    "sample_index": "step_tracking",
    "simulate": "controller",
    "simulated_tracking": "step_tracking",
    "tune_joint": "tuning",
    "unchecked_joints": "tolerances",
    "uses_velocities": "check",
    "validate_goal": "goal_validation",
    "validate_goal_end": "goal_validation",
})
