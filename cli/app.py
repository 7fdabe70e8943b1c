"""The `moveplan` command line: parse flags, make one core call, render, exit with the documented code.

Heavy libraries (pinocchio, coal, ompl, mcap) are imported inside the
commands, so `moveplan --help` stays fast.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer

from . import scene_command, state_command, tune_command
from .errors import (
    GuardedGroup,
    all_or_none,
    check_outputs,
    description_inputs,
    exit_codes,
    handle_signals,
)
from .options import (
    ROBOT_HELP,
    JointLimitsOpt,
    JsonOpt,
    LaunchArgOpt,
    LaunchOpt,
    PackagePathOpt,
    QuietOpt,
    SrdfOpt,
    StrictLimitsOpt,
    StrictOpt,
    TimeoutOpt,
    UrdfOpt,
    VerboseOpt,
    XacroArgOpt,
    robot_source,
    setup_logging,
)
from .parsing import (
    MAX_SEED,
    parse_disturbance,
    parse_joint_values,
    parse_joints,
    parse_number,
    parse_optional,
    parse_params,
    parse_pose,
    parse_seeds,
    parse_shard,
    parse_shift,
    parse_time,
)

if TYPE_CHECKING:  # each command imports the core it runs, so that `moveplan --help` stays fast
    from ..core.control import RecordingStart
    from ..core.pipeline import PlanFlags
    from ..core.types import TimeSource

__all__ = ["app", "main"]

app = typer.Typer(
    name="moveplan",
    help="MoveIt-style planning and ros2_control execution checks from one command line: files in, files out.",
    epilog="Exit codes: 0 success, 1 internal error, 2 usage error, 3 bad input file, 4 no plan, "
           "5 tolerances violated. Reference (file formats, JSON keys, planning and execution rules): "
           "docs/ in the moveplan repository.",
    cls=GuardedGroup,  # a closed stdout or a signal outside a command's work exits quietly too
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # Plain click help: typer's rich help formatter costs ~0.1 s of start-up in every CI loop.
    rich_markup_mode=None,
)

def _print_version(value: bool) -> None:
    if value:
        from ..core.version import moveplan_version

        typer.echo(f"moveplan {moveplan_version()}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[bool, typer.Option(
        "--version", callback=_print_version, is_eager=True, help="Print moveplan's version and exit.")] = False,
) -> None:
    """MoveIt-style planning and ros2_control execution checks from one command line: files in, files out."""


@app.command()
def plan(
    task: Annotated[Path | None, typer.Argument(help="Task file (docs/formats.md).", show_default=False)] = None,
    output: Annotated[Path, typer.Option("--output", "-o", help="Plan file to write (.mcap).")] = Path("plan.mcap"),
    robot: Annotated[Path | None, typer.Option(help=ROBOT_HELP)] = None,
    scene: Annotated[Path | None, typer.Option(
        help="Scene file: frames and collision objects, or a MoveIt PlanningScene YAML.")] = None,
    motion_request: Annotated[Path | None, typer.Option(
        "--request", help="MoveIt MotionPlanRequest YAML: start state, goal, group, planner, scaling.")] = None,
    group: Annotated[str | None, typer.Option(help="Planning group (default: the config's).")] = None,
    start_joints: Annotated[str | None, typer.Option(help="Start joints: '0,-1.57,...' or 'joint=value'.")] = None,
    start_named: Annotated[str | None, typer.Option(help="Start at an SRDF group_state.")] = None,
    start_from: Annotated[Path | None, typer.Option(help="Start where a previous plan file ends.")] = None,
    joints: Annotated[str | None, typer.Option(help="Joint goal: 'q1,...,qn' or 'elbow_joint=1.2,...'.")] = None,
    named: Annotated[str | None, typer.Option(help="Goal: an SRDF group_state.")] = None,
    pose: Annotated[str | None, typer.Option(help="Tip goal: 'x,y,z[,roll,pitch,yaw | ,qx,qy,qz,qw]'.")] = None,
    frame: Annotated[str | None, typer.Option(help="Frame --pose is given in: a scene frame or robot link.")] = None,
    link: Annotated[str | None, typer.Option(help="Link --pose moves (default: the group's tip).")] = None,
    shift: Annotated[str | None, typer.Option(help="Move the tip from here: 'z=0.1' or 'x=0.05,yaw=0.3'.")] = None,
    shift_frame: Annotated[str | None, typer.Option(
        help="Axes of --shift: tool (default), base, moveit (shift_pose_target) or any frame.")] = None,
    linear: Annotated[bool, typer.Option("--linear", help="Move the tip along a straight line.")] = False,
    min_fraction: Annotated[str | None, typer.Option(help="With --linear: fail below this fraction (1).")] = None,
    planner: Annotated[str | None, typer.Option(
        help="OMPL geometric planner (default RRTConnect); Pilz's PTP (joint line), LIN (tool line), CIRC.")] = None,
    planning_time: Annotated[str | None, typer.Option(
        help="The search's budget per step, in seconds at 20,000 checked motions a second (not wall time).")] = None,
    timeout: TimeoutOpt = None,
    seed: Annotated[int | None, typer.Option(min=0, max=MAX_SEED, help="Random seed: same seed, same plan.")] = None,
    velocity_scaling: Annotated[str | None, typer.Option(help="Velocity limits' fraction, in [0.001, 1].")] = None,
    acceleration_scaling: Annotated[str | None, typer.Option(help="Acceleration limits' fraction, [0.001, 1].")] = None,
    package_path: PackagePathOpt = None,
    xacro_arg: XacroArgOpt = None,
    urdf: UrdfOpt = None,
    srdf: SrdfOpt = None,
    joint_limits: JointLimitsOpt = None,
    launch: LaunchOpt = None,
    launch_arg: LaunchArgOpt = None,
    strict_limits: StrictLimitsOpt = False,
    strict: StrictOpt = False,
    ros_distro: Annotated[str, typer.Option(help="Message layout to write: jazzy or humble.")] = "jazzy",
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    verbose: VerboseOpt = False,
) -> None:
    """Plan collision-free, time-parameterised motions and write them to MCAP."""
    setup_logging(verbose, quiet)
    from ..core.pipeline import plan_failure_document
    from . import render

    with exit_codes(as_json, plan_failure_document):
        check_outputs({"-o": output}, {"TASK": task, "--robot": robot, "--scene": scene, "--request": motion_request,
                                       "--start-from": start_from, **description_inputs(urdf, srdf, joint_limits)})
        flags = _plan_flags(locals())
        from ..core.pipeline import plan_to_file

        result = plan_to_file(task, flags, output, ros_distro)
    render.plan_summary(result, output, as_json, quiet)


def _plan_flags(args: dict[str, Any]) -> PlanFlags:
    """Return the plan command's flags as core's typed values; core checks the rules between them."""
    from ..core.config import MotionSettings, launch_arguments, parse_xacro_args
    from ..core.pipeline import PlanFlags

    def number(key: str) -> float | None:
        return parse_optional(parse_number, args[key], "--" + key.replace("_", "-"))

    return PlanFlags(
        robot=args["robot"], scene=args["scene"], request=args["motion_request"], group=args["group"],
        start_joints=parse_optional(parse_joints, args["start_joints"], "--start-joints"),
        start_named=args["start_named"], start_from=args["start_from"],
        joints=parse_optional(parse_joints, args["joints"], "--joints"), named=args["named"],
        pose=parse_optional(parse_pose, args["pose"], "--pose"), frame=args["frame"], link=args["link"],
        shift=parse_optional(parse_shift, args["shift"], "--shift"), shift_frame=args["shift_frame"],
        linear=args["linear"], min_fraction=number("min_fraction"),
        motion=MotionSettings(args["planner"], number("planning_time"), number("velocity_scaling"),
                              number("acceleration_scaling")),
        timeout=number("timeout"), seed=args["seed"],
        package_paths=tuple(args["package_path"] or ()),
        xacro_args=parse_xacro_args(args["xacro_arg"] or ()), urdf=args["urdf"], srdf=args["srdf"],
        strict_limits=args["strict_limits"], joint_limits=args["joint_limits"], launch=args["launch"],
        launch_args=launch_arguments(args["launch_arg"] or ()), strict=args["strict"],
    )


@app.command()
def execute(
    plan_file: Annotated[Path, typer.Argument(metavar="PLAN", help="Plan file written by moveplan plan.")],
    fake: Annotated[bool, typer.Option("--fake", help="Replay through a simulated controller (required).")] = False,
    output: Annotated[Path | None, typer.Option("--output", "-o", help="Write what happened to this .mcap.")] = None,
    plant: Annotated[str | None, typer.Option(help=(
        "Hardware model: mirror, lag or pid (default: the robot config's plant, else mirror)."))] = None,
    plant_param: Annotated[list[str] | None, typer.Option(help="Plant parameter k=v, e.g. tau=0.05.")] = None,
    disturb: Annotated[list[str] | None, typer.Option(help="Fault: 't=1.2,joint=elbow_joint,delta=0.05'.")] = None,
    start_joints: Annotated[str | None, typer.Option(help="Robot away from the plan start: 'joint=value'.")] = None,
    controllers: Annotated[Path | None, typer.Option(help="ros2_controllers.yaml overriding the plan's.")] = None,
    strict: StrictOpt = False,
    seed: Annotated[int, typer.Option(min=0, max=MAX_SEED, help="Seed for plant noise.")] = 0,
    ros_distro: Annotated[str, typer.Option(help="Controller-state layout to write: jazzy or humble.")] = "jazzy",
    ros2_controllers: Annotated[str, typer.Option(metavar="RELEASE", help=(
        "ros2_controllers release whose JointTrajectoryController is simulated: a distro (its newest "
        "release) or a version such as 4.35.0 (the blend before a late first point changed in 4.36.0)."))] = "jazzy",
    plot: Annotated[Path | None, typer.Option(metavar="FILE.png", help=(
        "Write a PNG: per joint reference and actual, the error against the tolerances, violations."))] = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    verbose: VerboseOpt = False,
) -> None:
    """Replay a plan through a simulated JointTrajectoryController and report every tolerance violation."""
    setup_logging(verbose, quiet)
    with exit_codes(as_json):
        from ..core.errors import UsageError

        if not fake:
            raise UsageError("only fake execution exists yet: add --fake to replay through a simulated controller")
        check_outputs({"-o": output, "--plot": plot}, {"PLAN": plan_file, "--controllers": controllers})
        from ..core.pipeline import ExecuteRequest
        from ..core.pipeline import execute as run
        from . import render

        if plot is not None:
            from ..core.pipeline import check_plot_path, execute_plotted

            check_plot_path(plot)

        request = ExecuteRequest(
            plan=plan_file, plant=plant, plant_params=parse_params(plant_param or [], "--plant-param"),
            disturbances=tuple(parse_disturbance(d) for d in disturb or []),
            start_joints=parse_joint_values(start_joints, "--start-joints") if start_joints else None,
            controllers=controllers, seed=seed, strict=strict, ros2_controllers=ros2_controllers,
        )
        if plot is not None:
            outcome = execute_plotted(request, plot, output, ros_distro)
        elif output is None:
            outcome = run(request)
        else:
            from ..core.pipeline import execute_to_file

            outcome = execute_to_file(request, output, ros_distro)
    render.execution_summary(outcome, output, as_json, quiet)
    raise typer.Exit(0 if outcome.ok else 5)


@app.command("check-tolerances")
def check_tolerances(
    plan_file: Annotated[Path | None, typer.Argument(metavar="PLAN", help="Plan file written by moveplan plan.")]
        = None,
    recording_file: Annotated[Path | None, typer.Argument(
        metavar="RECORDING", help="A ROS 2 bag with sensor_msgs/JointState: .mcap, .db3 or a bag folder.")] = None,
    manifest: Annotated[Path | None, typer.Option(metavar="FLEET.csv", help=(
        "Check many pairs instead of PLAN RECORDING: a CSV with columns plan, recording (paths relative to it, "
        "globs allowed); other columns are carried into the results."))] = None,
    jobs: Annotated[int | None, typer.Option(min=1, help=(
        "With --manifest: workers checking items at once (local: processes, default 1; ray: actors, default one "
        "per CPU of the cluster)."))] = None,
    engine: Annotated[str, typer.Option(help=(
        "With --manifest: local (processes on this machine) or ray (actors on the Ray cluster at --ray-address "
        "or RAY_ADDRESS)."))] = "local",
    ray_address: Annotated[str | None, typer.Option(help="With --engine ray: the cluster, HOST:PORT.")] = None,
    csv: Annotated[Path | None, typer.Option(metavar="RESULTS.csv", help=(
        "With --manifest: write a row per item as it is judged."))] = None,
    resume: Annotated[bool, typer.Option("--resume", help=(
        "With --manifest and --csv: skip pairs the CSV already judges (same file contents), add the rest."))] = False,
    html: Annotated[Path | None, typer.Option(metavar="REPORT.html", help=(
        "With --manifest: write one self-contained page: the summary, a sortable, filterable row per item, "
        "each opening its tracking errors."))] = None,
    topic: Annotated[str, typer.Option(help="JointState topic in the recording.")] = "/joint_states",
    controllers: Annotated[Path | None, typer.Option(help="ros2_controllers.yaml overriding the plan's.")] = None,
    strict: StrictOpt = False,
    start: Annotated[str, typer.Option(help="auto, a time [s] from the recording's start, or all.")] = "auto",
    time_source: Annotated[str, typer.Option(help="header (message stamps) or log (receive times).")] = "header",
    skip_damaged: Annotated[bool, typer.Option("--skip-damaged", help=(
        "Skip MCAP chunks failing their CRC or size checks, with a warning (JSON: skipped)."))] = False,
    plot: Annotated[Path | None, typer.Option(metavar="FILE.png", help=(
        "Write a PNG: per joint reference and actual, the error against the tolerances, violations "
        "(with --start all: the first failing cycle, else the first)."))] = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    verbose: VerboseOpt = False,
) -> None:
    """Check a recording (a ros2 bag of a real robot, or an executed file) against a plan's tolerances.

    Exit 0 within tolerances, 5 on a violation, 3 if the recording cuts the execution (with --start all,
    every execution) off before a verdict; with --start all, cut-off cycles are INCOMPLETE and not counted.
    With --manifest: exit 0 if every item passes, 3 if any could not be checked, else 5 on any violation.
    """
    setup_logging(verbose, quiet)
    with exit_codes(as_json):
        from ..core.errors import UsageError
        from ..core.pipeline import CheckRequest, check
        from . import render

        if time_source not in ("header", "log"):
            raise UsageError(f"--time-source: expected header or log, got '{time_source}'")
        source: TimeSource = "log" if time_source == "log" else "header"
        when: RecordingStart = ("auto" if start == "auto" else "all" if start == "all"
                                else parse_time(start, "--start (auto, all or seconds)"))
        if manifest is not None:
            if plan_file is not None or recording_file is not None or plot is not None:
                raise UsageError("--manifest checks the pairs it lists: give no PLAN, RECORDING or --plot with it")
            code = _check_fleet(manifest, (topic, controllers, when, source, skip_damaged, strict), jobs, csv, resume,
                                (engine, ray_address, html), as_json, quiet)
        else:
            if plan_file is None or recording_file is None:
                raise UsageError("check-tolerances needs PLAN and RECORDING, or --manifest FLEET.csv")
            if csv is not None or resume or jobs is not None or engine != "local" or ray_address is not None or html:
                raise UsageError("--jobs, --csv, --resume, --engine, --ray-address and --html go with --manifest")
            request = CheckRequest(plan_file, recording_file, topic, controllers, when, source, skip_damaged, strict)
            if plot is None:
                report = check(request)
            else:
                from ..core.pipeline import check_plot_path, check_plotted

                check_outputs({"--plot": plot}, {"PLAN": plan_file, "RECORDING": recording_file,
                                                 "--controllers": controllers})
                check_plot_path(plot)
                report = check_plotted(request, plot)
            render.check_summary(report, recording_file, as_json, quiet)
            # Cut off before any verdict: the check could not be done on this recording (bad input).
            code = 0 if report.ok else 5 if report.complete else 3
    raise typer.Exit(code)


def _check_fleet(manifest: Path, flags: tuple[Any, ...], jobs: int | None, csv: Path | None, resume: bool,
                 where: tuple[str, str | None, Path | None], as_json: bool, quiet: bool) -> int:
    """Check every pair a manifest lists, stream results to `csv`, print the batch's report; return its exit code."""
    from ..core.errors import UsageError
    from ..core.pipeline import (
        CheckFlags,
        ResultsFile,
        batch_exit_code,
        check_engine,
        check_html_path,
        check_items,
        judged_pairs,
        read_manifest,
        unresumed_items,
        write_fleet_html,
    )
    from . import render

    if resume and csv is None:
        raise UsageError("--resume reads and extends the results of --csv RESULTS.csv: give --csv")
    engine, ray_address, html = where
    check_engine(engine)
    if html is not None:
        check_html_path(html)
    items = read_manifest(manifest)
    check_outputs({"--csv": csv, "--html": html}, {"--manifest": manifest,
                                                   **{f"item {i.index}": i.recording for i in items},
                                                   **{f"plan {i.index}": i.plan for i in items}})
    judged = judged_pairs(csv) if resume and csv is not None else {}
    todo, resumed = unresumed_items(items, judged) if judged else (list(items), [])
    results_file = ResultsFile(csv, list(items[0].columns), append=resume) if csv is not None else None
    try:
        with render.fleet_progress(len(todo), quiet or as_json) as advance:
            def arrived(result: Any) -> None:
                if results_file is not None:
                    results_file.write(result)
                advance(result)

            settings = replace(CheckFlags(*flags), series_points=300 if html else 0, hashes=csv is not None)
            results = check_items(todo, settings, jobs, arrived, engine, ray_address)
    finally:
        if results_file is not None:
            results_file.close()
    if html is not None:
        write_fleet_html(html, manifest, results, resumed)
    render.fleet_report(results, resumed, as_json, quiet)
    return batch_exit_code([r.exit_code for r in results] + [int(r["exit_code"]) for r in resumed])


@app.command("robot")
def robot_info(
    config: Annotated[Path, typer.Argument(help=ROBOT_HELP)],
    package_path: PackagePathOpt = None,
    xacro_arg: XacroArgOpt = None,
    urdf: UrdfOpt = None,
    srdf: SrdfOpt = None,
    joint_limits: JointLimitsOpt = None,
    launch: LaunchOpt = None,
    launch_arg: LaunchArgOpt = None,
    strict_limits: StrictLimitsOpt = False,
    strict: StrictOpt = False,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
) -> None:
    """Show a robot config: groups, joints and limits with their sources, frames, named states, controllers."""
    setup_logging(False, quiet)
    with exit_codes(as_json):
        from . import render

        loaded = robot_source(config, package_path, xacro_arg, urdf, srdf, strict_limits, joint_limits, launch,
                              launch_arg, strict).load()
        loaded.collision_meshes()  # a missing mesh is reported here too, not only when planning
    render.robot_summary(loaded, as_json, quiet)


@app.command()
def inspect(
    file: Annotated[Path, typer.Argument(
        help="Any ROS 2 bag (.mcap, .db3 or a bag folder); plan files get a per-step summary.")],
    plot: Annotated[Path | None, typer.Option(metavar="FILE.png", help=(
        "Plan files: write a PNG of each joint's position, velocity and acceleration against its limits."))] = None,
    skip_damaged: Annotated[bool, typer.Option("--skip-damaged", help=(
        "Skip MCAP chunks failing their CRC or size checks, with a warning (JSON: skipped)."))] = False,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
) -> None:
    """Summarise a ROS 2 bag (MCAP, .db3 or a bag folder): topics, counts; a plan's step durations and peak rates."""
    setup_logging(False, quiet)
    with exit_codes(as_json):
        from ..core.pipeline import inspect_file
        from . import render

        if plot is not None:
            from ..core.pipeline import check_plot_path, write_plan_plot

            check_outputs({"--plot": plot}, {"FILE": file})
            check_plot_path(plot)
        inspection = inspect_file(file, skip_damaged)
        if plot is not None:
            write_plan_plot(inspection.plan, file, plot)
    render.inspect_summary(inspection, as_json, quiet)


@app.command()
def benchmark(
    problems: Annotated[list[Path], typer.Argument(
        help="Folders of sceneNNNN.yaml/requestNNNN.yaml pairs (searched recursively, links too), or task files.")],
    robot: Annotated[Path, typer.Option(help="Robot config the problems are for (as plan's --robot).")],
    planner: Annotated[list[str] | None, typer.Option(
        help="OMPL planner; repeatable or comma-separated (default: the config's).")] = None,
    seeds: Annotated[str, typer.Option(help="Seeds: '0-4' or '0,3,7'.")] = "0",
    count: Annotated[int | None, typer.Option(min=1, help="Only the first N problems of each folder.")] = None,
    planning_time: Annotated[str, typer.Option(
        help="Each search's budget, in seconds at 20,000 checked motions a second (not wall time).")] = "1.0",
    timeout: TimeoutOpt = None,
    jobs: Annotated[int | None, typer.Option(min=1, help=(
        "Workers, each taking the next (planner, seed, problem) run (local: processes, default 1, the cleanest "
        "times; ray: actors, default one per CPU of the cluster)."))] = None,
    engine: Annotated[str, typer.Option(help=(
        "local (processes on this machine) or ray (actors on the Ray cluster at --ray-address or RAY_ADDRESS)."))]
        = "local",
    ray_address: Annotated[str | None, typer.Option(help="With --engine ray: the cluster, HOST:PORT.")] = None,
    shard: Annotated[str | None, typer.Option(
        help="Run only shard K of N: every N-th problem from the K-th ('2/4'); merge the shards' --csv files "
             "with benchmark-merge.")] = None,
    exact_check: Annotated[bool, typer.Option(
        "--exact-check/--no-exact-check",
        help="Re-check every plan's certified states on the exact meshes (exact_valid); off: faster runs, "
             "exact_valid empty.")]
        = True,
    csv: Annotated[Path | None, typer.Option(help="Write one CSV row per run here.")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG of the time distributions here.")] = None,
    html: Annotated[Path | None, typer.Option(metavar="REPORT.html", help=(
        "Write one self-contained page: the summary, a sortable, filterable row per run, each opening its "
        "times."))] = None,
    package_path: PackagePathOpt = None,
    xacro_arg: XacroArgOpt = None,
    urdf: UrdfOpt = None,
    srdf: SrdfOpt = None,
    joint_limits: JointLimitsOpt = None,
    launch: LaunchOpt = None,
    launch_arg: LaunchArgOpt = None,
    strict_limits: StrictLimitsOpt = False,
    strict: StrictOpt = False,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
) -> None:
    """Plan many problems with several planners and seeds; report success, times, path quality, exact validity."""
    setup_logging(False, quiet)
    with exit_codes(as_json):
        from ..core.pipeline import (
            check_engine,
            check_planning_time,
            find_problems,
            run_benchmark,
        )
        from ..core.pipeline import shard as shard_of
        from . import render

        check_outputs({"--csv": csv, "--plot": plot, "--html": html},
                      {"PROBLEMS": problems, "--robot": robot, **description_inputs(urdf, srdf, joint_limits)})
        if html is not None:
            from ..core.pipeline import check_html_path

            check_html_path(html)
        if plot is not None:
            from ..core.pipeline import check_plot_path

            check_plot_path(plot)
        check_engine(engine)
        seed_list = parse_seeds(seeds)
        time_s = check_planning_time(parse_number(planning_time, "--planning-time"))
        timeout_s = parse_optional(parse_number, timeout, "--timeout")
        if timeout_s is not None:
            check_planning_time(timeout_s, "--timeout")
        found = find_problems(problems, count)
        if shard is not None:
            index, total = parse_shard(shard)
            found = shard_of(found, index, total)
        source = robot_source(robot, package_path, xacro_arg, urdf, srdf, strict_limits, joint_limits, launch,
                              launch_arg, strict)
        config = source.load()
        planners = [p.strip() for text in planner or [config.motion.planner] for p in text.split(",")]
        with render.benchmark_progress(len(found) * len(planners) * len(seed_list), quiet) as advance:
            runs = run_benchmark(source, found, planners, seed_list, time_s, jobs, advance, timeout_s, exact_check,
                                 engine, ray_address)
        rows = _benchmark_outputs(runs, csv, plot, html)
    render.benchmark_summary(runs, rows, as_json, quiet)


def _benchmark_outputs(runs: list[Any], csv: Path | None, plot: Path | None, html: Path | None) -> list[dict[str, Any]]:
    """Write the runs' CSV, plot and page that were asked for, all or none; return their summary rows."""
    from ..core.pipeline import plot_benchmark, summarize, write_benchmark_html, write_csv

    rows = summarize(runs)
    with all_or_none() as written:
        if csv is not None:
            write_csv(runs, csv)
            written.append(csv)
        if plot is not None:
            plot_benchmark(runs, plot)
            written.append(plot)
        if html is not None:
            write_benchmark_html(html, runs, rows)
            written.append(html)
    return rows


@app.command("benchmark-merge")
def benchmark_merge(
    runs: Annotated[list[Path], typer.Argument(help="The --csv files of benchmark runs (one benchmark's shards).")],
    csv: Annotated[Path | None, typer.Option(help="Write every run, one CSV row each, here.")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG of the time distributions here.")] = None,
    html: Annotated[Path | None, typer.Option(metavar="REPORT.html", help=(
        "Write one self-contained page: the summary, a sortable, filterable row per run."))] = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
) -> None:
    """Merge the runs of benchmark shards (their --csv files) into one summary, as benchmark prints it."""
    setup_logging(False, quiet)
    with exit_codes(as_json):
        from ..core.errors import InputError
        from ..core.pipeline import read_runs
        from . import render

        check_outputs({"--csv": csv, "--plot": plot, "--html": html}, {"RUNS": runs})
        if html is not None:
            from ..core.pipeline import check_html_path

            check_html_path(html)
        if plot is not None:
            from ..core.pipeline import check_plot_path

            check_plot_path(plot)
        merged = read_runs(runs)
        if not merged:
            raise InputError(f"{', '.join(map(str, runs))}: no benchmark run in these files")
        rows = _benchmark_outputs(merged, csv, plot, html)
    render.benchmark_summary(merged, rows, as_json, quiet)


app.command("state")(state_command.state)
app.command("scene")(scene_command.scene)
app.command("tune-pid")(tune_command.tune_pid)


def main() -> None:
    """Run the moveplan command line: SIGTERM and SIGHUP clean up and exit like Ctrl-C (128 + signal)."""
    handle_signals()
    app()


def run() -> NoReturn:
    """Run main() as the `moveplan` program: exit with its code, without the interpreter's teardown.

    Freeing every object numpy, pinocchio, OMPL and matplotlib made, one by one, took 50 ms of a
    plan and 160 ms of a plot. Nothing is lost: every file is closed by then, exit handlers run,
    and output is flushed; with another thread alive, or output that fails to flush, the
    interpreter exits as usual.
    """
    try:
        main()
        code = 0
    except SystemExit as exc:
        if not (exc.code is None or isinstance(exc.code, int)) or threading.active_count() > 1:
            raise
        code = exc.code or 0
    if threading.active_count() > 1:
        sys.exit(code)
    atexit._run_exitfuncs()
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
    except OSError:
        sys.exit(code)
    os._exit(code)


if __name__ == "__main__":
    run()
