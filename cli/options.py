"""What several commands share: the robot config's options, --json/--quiet/--verbose, and logging to stderr."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:  # imported by the command that loads a robot: `moveplan --help` loads no config code
    from ..core.pipeline import RobotSource

__all__ = [
    "ROBOT_HELP", "JsonOpt", "LaunchArgOpt", "LaunchOpt", "PackagePathOpt", "QuietOpt", "SrdfOpt", "StrictLimitsOpt",
    "StrictOpt", "TimeoutOpt", "UrdfOpt", "VerboseOpt", "XacroArgOpt", "robot_source", "setup_logging",
]

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON document on stdout, nothing else.")]
QuietOpt = Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")]
VerboseOpt = Annotated[bool, typer.Option("--verbose", "-v", help="Log what happens to stderr.")]
PackagePathOpt = Annotated[list[Path] | None, typer.Option(
    help="Folder searched for $(find pkg) and package:// URIs; repeatable.")]
XacroArgOpt = Annotated[list[str] | None, typer.Option(help="xacro argument name:=value; repeatable.")]
UrdfOpt = Annotated[str | None, typer.Option(
    "--urdf", metavar="FILE|package://PKG/PATH", help="URDF (or .xacro) to load, whatever the config names.")]
SrdfOpt = Annotated[str | None, typer.Option(
    "--srdf", metavar="FILE|package://PKG/PATH", help="SRDF (or .srdf.xacro) to load, whatever the config names.")]
JointLimitsOpt = Annotated[str | None, typer.Option(
    "--joint-limits", metavar="FILE|package://PKG/PATH",
    help="MoveIt's joint_limits.yaml to load (where a vendor keeps it), whatever the config has.")]
LaunchOpt = Annotated[str | None, typer.Option(
    "--launch", metavar="FILE|package://PKG/PATH",
    help="The MoveIt package's launch file to read the robot from (read, never run; default: all of launch/).")]
LaunchArgOpt = Annotated[list[str] | None, typer.Option(
    "--launch-arg", metavar="NAME:=VALUE", help="Launch argument, as ros2 launch takes it; repeatable.")]
StrictOpt = Annotated[bool, typer.Option(
    "--strict", help="A parameter a controller does not declare (in ros2_controllers.yaml) is an error, "
                     "not a warning.")]
StrictLimitsOpt = Annotated[bool, typer.Option(
    "--strict-limits", help="An acceleration limit missing in the config is an error instead of the documented "
                            "default.")]
TimeoutOpt = Annotated[str | None, typer.Option(
    metavar="SECONDS", help="Wall-clock safety limit of each search (default: 20 x the planning time, at least 60 s); "
                            "the planning time is a budget of work, the same at any load.")]
ROBOT_HELP = ("Robot config: a moveplan.yaml or its folder, a MoveIt config package, a URDF or SRDF file, "
               "or a shipped name.")


class _Format(logging.Formatter):
    """`moveplan: LEVEL: message`, and `moveplan: message` for a notice of one-time work (INFO)."""

    def format(self, record: logging.LogRecord) -> str:
        text = super().format(record)
        return f"moveplan: {text}" if record.levelno == logging.INFO else f"moveplan: {record.levelname}: {text}"


def setup_logging(verbose: bool, quiet: bool) -> None:
    """Send log records to stderr as `moveplan: ...`: debug with --verbose, errors only with --quiet."""
    level = logging.DEBUG if verbose else logging.ERROR if quiet else logging.WARNING
    logging.basicConfig(level=level)
    for handler in logging.getLogger().handlers:
        handler.setFormatter(_Format("%(message)s"))
    if not quiet and not verbose:
        # Seconds of one-time work (sphere fitting, distance tables) are announced, not left silent.
        logging.getLogger("moveplan.core.collision._cache").setLevel(logging.INFO)


def robot_source(
    robot: Path, package_path: list[Path] | None, xacro_arg: list[str] | None, urdf: str | None, srdf: str | None,
    strict_limits: bool, joint_limits: str | None = None, launch: str | None = None,
    launch_arg: list[str] | None = None, strict: bool = False,
) -> RobotSource:
    """Return what loads the robot config: --robot and the flags that complete it, as core's typed value."""
    from ..core.config import launch_arguments, parse_xacro_args
    from ..core.pipeline import RobotSource

    return RobotSource(robot, tuple(package_path or ()), parse_xacro_args(xacro_arg or ()), urdf, srdf, strict_limits,
                       joint_limits, launch, launch_arguments(launch_arg or ()), strict)
