"""`moveplan scene`: write any scene moveplan reads as MoveIt's text `.scene` file, resolved against the robot."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape

from .errors import check_outputs, description_inputs, exit_codes
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
    VerboseOpt,
    XacroArgOpt,
    robot_source,
    setup_logging,
)
from .tables import console, emit, escape_controls

if TYPE_CHECKING:
    from ..core.pipeline import SceneExport

__all__ = ["scene"]


def scene(
    scene_file: Annotated[Path, typer.Argument(metavar="SCENE", help=(
        "Scene to write: a moveplan scene YAML, a MoveIt PlanningScene YAML or a .scene file."))],
    output: Annotated[Path, typer.Option("--output", "-o", help="The .scene file to write.")],
    robot: Annotated[Path, typer.Option(help=ROBOT_HELP + " Its links and frames place the scene's objects.")],
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
    verbose: VerboseOpt = False,
) -> None:
    """Write a scene as MoveIt's text .scene (RViz's Import reads it): world objects, poses in the planning frame."""
    setup_logging(verbose, quiet)
    with exit_codes(as_json):
        from ..core.pipeline import check_scene_path, export_scene

        check_scene_path(output)
        check_outputs({"-o": output}, {"SCENE": scene_file, "--robot": robot,
                                       **description_inputs(urdf, srdf, joint_limits)})
        source = robot_source(robot, package_path, xacro_arg, urdf, srdf, strict_limits, joint_limits, launch,
                              launch_arg, strict)
        result = export_scene(scene_file, source, output)
    _summary(result, as_json, quiet)


def _summary(result: SceneExport, as_json: bool, quiet: bool) -> None:
    """Print where the scene went and which objects it holds; or its JSON document."""
    from ..core.pipeline import scene_document

    if as_json:
        emit(scene_document(result))
        return
    if quiet:
        return
    count = len(result.objects)
    objects = f"{count} world object{'' if count == 1 else 's'}" + (f" ({', '.join(result.objects)})" if count else "")
    console.print(escape(escape_controls(f"wrote {result.output}: scene '{result.name}', {objects}, poses in "
                                         f"{result.robot}'s planning frame {result.planning_frame}")))
