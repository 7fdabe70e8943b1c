"""`moveplan state`: where the robot is, or where a plan puts it: joint values and a link's pose in a frame."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .errors import exit_codes
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
    UrdfOpt,
    XacroArgOpt,
    robot_source,
    setup_logging,
)
from .parsing import parse_joints, parse_optional, parse_time

__all__ = ["state"]


def state(
    robot: Annotated[Path | None, typer.Option(help=ROBOT_HELP + " Not needed with --from.")] = None,
    group: Annotated[str | None, typer.Option(help="Planning group (default: the config's, or the plan's).")] = None,
    joints: Annotated[str | None, typer.Option(help="Joint values: 'q1,...,qn' or 'elbow_joint=-90deg,...'.")] = None,
    named: Annotated[str | None, typer.Option(help="An SRDF group_state.")] = None,
    from_plan: Annotated[Path | None, typer.Option("--from", help="A plan file: the state where it ends.")] = None,
    step: Annotated[str | None, typer.Option(help="With --from: where this step ends.")] = None,
    at: Annotated[str | None, typer.Option(help="With --from: seconds from the plan's (or --step's) start.")] = None,
    link: Annotated[str | None, typer.Option(help="Link whose pose to give (default: the group's tip).")] = None,
    frame: Annotated[str | None, typer.Option(help="Frame of the pose (default: the planning frame).")] = None,
    scene: Annotated[Path | None, typer.Option(help="Scene file, for its frames (default with --from: "
                                                    "the scene the plan embeds).")] = None,
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
    """Show a robot state: the group's joint values and a link's pose in a frame (lookup_transform)."""
    setup_logging(False, quiet)
    with exit_codes(as_json):
        from ..core.pipeline import StateRequest
        from ..core.pipeline import state as robot_state
        from . import render

        given = {"--package-path": package_path, "--xacro-arg": xacro_arg, "--urdf": urdf, "--srdf": srdf,
                 "--joint-limits": joint_limits, "--strict-limits": strict_limits, "--launch": launch,
                 "--launch-arg": launch_arg, "--strict": strict}
        if robot is None and (flags := [name for name, value in given.items() if value]):
            from ..core.errors import UsageError

            raise UsageError(f"{flags[0]} completes --robot: give --robot too (with --from alone, the plan's "
                             "embedded config is used as it is)")
        source = None if robot is None else robot_source(robot, package_path, xacro_arg, urdf, srdf, strict_limits,
                                                         joint_limits, launch, launch_arg, strict)
        result = robot_state(StateRequest(
            robot=source, group=group, joints=parse_optional(parse_joints, joints, "--joints"), named=named,
            plan=from_plan, step=step, at_s=parse_optional(parse_time, at, "--at"), link=link, frame=frame, scene=scene,
        ))
    render.state_summary(result, as_json, quiet)
