"""The commands as library calls: plan, execute, check and benchmark compose the districts below.

Modules: `plan` (plan, plan_to_file; one step's stages in `step`), `request` (PlanFlags,
resolve_request), `execute` (execute, check), `plan_files` (what every command reading a plan
needs: its config, its steps checked, its controller), `report` (the result document and the
executed file), `inspection` (inspect_file), `benchmark` (run_benchmark, summarize), `scene_export`
(export_scene: a scene as MoveIt's .scene), `plots/` (the --plot files). Nothing is imported
here, so that a command loads only what it runs (execute never loads OMPL).
"""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._checks import Problem
    from .benchmark import (
        ProblemFiles,
        Run,
        find_problems,
        plot_benchmark,
        read_runs,
        run_benchmark,
        shard,
        summarize,
        write_csv,
    )
    from .documents import (
        benchmark_document,
        failure_document,
        inspect_document,
        plan_document,
        plan_failure_document,
        robot_document,
        state_document,
    )
    from .execution import CheckRequest, ExecuteRequest, PlanExecution, check, execute
    from .inspection import Inspection, inspect_file
    from .plan import PlanResult, plan_to_file
    from .plots import check_plot_path, check_plotted, execute_plotted, write_plan_plot, write_tuning_plot
    from .report import check_document, execute_to_file, execution_document
    from .request import PlanFlags, RobotSource, check_planning_time
    from .robot_state import StateRequest, StateResult, state
    from .scene_export import SceneExport, check_scene_path, export_scene, scene_document
    from .session import (
        ExecutionSettings,
        cartesian_motion,
        check_execution,
        compose_scene,
        execute_motion,
        frame_in_root,
        motion_problem,
        plan_motion,
        session_plan,
        start_configuration,
        write_session,
    )
    from .tuning import TuneRequest, TuneResult, tune, tuning_document

__all__ = [
    "CheckRequest",
    "ExecuteRequest",
    "ExecutionSettings",
    "Inspection",
    "PlanExecution",
    "PlanFlags",
    "PlanResult",
    "Problem",
    "ProblemFiles",
    "RobotSource",
    "Run",
    "SceneExport",
    "StateRequest",
    "StateResult",
    "TuneRequest",
    "TuneResult",
    "benchmark_document",
    "cartesian_motion",
    "check",
    "check_document",
    "check_execution",
    "check_planning_time",
    "check_plot_path",
    "check_plotted",
    "check_scene_path",
    "compose_scene",
    "execute",
    "execute_motion",
    "execute_plotted",
    "execute_to_file",
    "export_scene",
    "execution_document",
    "failure_document",
    "find_problems",
    "frame_in_root",
    "inspect_document",
    "inspect_file",
    "motion_problem",
    "plan_document",
    "plan_failure_document",
    "plan_motion",
    "plan_to_file",
    "plot_benchmark",
    "robot_document",
    "read_runs",
    "run_benchmark",
    "scene_document",
    "session_plan",
    "start_configuration",
    "state",
    "state_document",
    "shard",
    "summarize",
    "tune",
    "tuning_document",
    "write_csv",
    "write_plan_plot",
    "write_session",
    "write_tuning_plot",
]

__getattr__ = lazy_exports(__name__, {
    "CheckRequest": "execution",
    "ExecuteRequest": "execution",
    "ExecutionSettings": "session",
    "Inspection": "inspection",
    "PlanExecution": "execution",
    "PlanFlags": "request",
    "PlanResult": "plan",
    "Problem": "_checks",
    "ProblemFiles": "benchmark",
    "RobotSource": "request",
    "Run": "benchmark",
    "SceneExport": "scene_export",
    "StateRequest": "robot_state",
    "StateResult": "robot_state",
    "TuneRequest": "tuning",
    "TuneResult": "tuning",
    "benchmark_document": "documents",
    "cartesian_motion": "session",
    "check": "execution",
    "check_document": "report",
    "check_execution": "session",
    "check_planning_time": "request",
    "check_plot_path": "plots",
    "check_plotted": "plots",
    "check_scene_path": "scene_export",
    "compose_scene": "session",
    "execute": "execution",
    "execute_motion": "session",
    "execute_plotted": "plots",
    "execute_to_file": "report",
    "export_scene": "scene_export",
    "execution_document": "report",
    "failure_document": "documents",
    "find_problems": "benchmark",
    "frame_in_root": "session",
    "inspect_document": "documents",
    "inspect_file": "inspection",
    "motion_problem": "session",
    "plan_document": "documents",
    "plan_failure_document": "documents",
    "plan_motion": "session",
    "plan_to_file": "plan",
    "plot_benchmark": "benchmark",
    "robot_document": "documents",
    "read_runs": "benchmark",
    "run_benchmark": "benchmark",
    "scene_document": "scene_export",
    "session_plan": "session",
    "start_configuration": "session",
    "state": "robot_state",
    "state_document": "documents",
    "shard": "benchmark",
    "summarize": "benchmark",
    "tune": "tuning",
    "tuning_document": "tuning",
    "write_csv": "benchmark",
    "write_plan_plot": "plots",
    "write_session": "session",
    "write_tuning_plot": "plots",
})
