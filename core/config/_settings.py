"""The settings beside the robot model: planning defaults and kinematics.yaml."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import ConfigError, UnknownName
from .fields import check_keys, load_yaml, mapping, number
from .srdf import Srdf

__all__ = ["COLLISION_MODES", "parse_kinematics", "planning_defaults"]

COLLISION_MODES = ("exact", "convex")  # robot meshes as triangle BVHs, or as their convex hulls
_PLANNING_KEYS = {"group", "planner", "planning_time", "collision"}


def planning_defaults(
    manifest: Path | None, top: dict[str, Any], ompl: Path | None, srdf: Srdf, srdf_path: Path
) -> tuple[dict[str, Any], Path]:
    """Return the planning defaults and the file that chose the group.

    Precedence: moveplan.yaml `planning` > ompl_planning.yaml (its first group section, and
    that group's `default_planner_config`) > the SRDF's first group, RRTConnect, 1 s, and
    `exact` collision geometry.
    """
    planning = mapping(top.get("planning"), f"{manifest}: planning")
    check_keys(planning, _PLANNING_KEYS, f"{manifest}: planning")
    for key in ("group", "planner", "collision"):
        if key in planning and not isinstance(planning[key], str):
            shown = repr(planning[key]) if len(repr(planning[key])) <= 60 else f"{repr(planning[key])[:57]}..."
            raise ConfigError(f"{manifest}: planning.{key}: expected a name, got {shown}")
    source = manifest if manifest is not None and "group" in planning else srdf_path
    if ompl is not None:
        group, planner = _ompl_defaults(ompl, srdf)
        if group and "group" not in planning:
            planning["group"], source = group, ompl
        if planner and "planner" not in planning and planning.get("group") == group:
            planning["planner"] = planner
    planning.setdefault("group", next(iter(srdf.groups), ""))
    planning.setdefault("planner", "RRTConnect")
    planning["planning_time"] = number(
        planning.get("planning_time", 1.0), f"{manifest}: planning.planning_time", positive=True
    )
    planning.setdefault("collision", "exact")
    if planning["collision"] not in COLLISION_MODES:
        raise ConfigError(f"{manifest}: planning.collision: expected one of {', '.join(COLLISION_MODES)}, "
                          f"got {planning['collision']!r}")
    return planning, source


def _ompl_defaults(path: Path, srdf: Srdf) -> tuple[str | None, str | None]:
    """Return the first SRDF group ompl_planning.yaml configures and its default planner (or None).

    MoveIt gives a group without a (known) `default_planner_config` RRTConnect; so does this.
    """
    top = mapping(load_yaml(path), str(path))
    group = next((key for key in top if key in srdf.groups), None)
    if group is None:
        return None, None
    section = mapping(top[group], f"{path}: {group}")
    default = section.get("default_planner_config")
    configs = mapping(top.get("planner_configs"), f"{path}: planner_configs")
    if not isinstance(default, str) or default not in configs:
        return group, None
    kind = mapping(configs[default], f"{path}: planner_configs.{default}").get("type", "")
    if not isinstance(kind, str) or not kind.startswith("geometric::"):
        raise ConfigError(f"{path}: planner_configs.{default}.type: expected geometric::<Planner>, got {kind!r}")
    return group, kind.removeprefix("geometric::")


def parse_kinematics(path: Path, srdf: Srdf) -> dict[str, dict[str, Any]]:
    """Return kinematics.yaml's settings per group (moveplan solves IK itself; they are reported)."""
    top = mapping(load_yaml(path), str(path))
    if "/**" in top:  # written as ROS 2 parameters: /**: ros__parameters: robot_description_kinematics:
        top = mapping(mapping(top["/**"], f"{path}: /**").get("ros__parameters"), f"{path}: /**.ros__parameters")
    if "robot_description_kinematics" in top:
        top = mapping(top["robot_description_kinematics"], f"{path}: robot_description_kinematics")
    result = {}
    for group, entry in top.items():
        if group not in srdf.groups:
            raise UnknownName("group", group, f"{path} (groups of {srdf.name})", srdf.groups)
        result[group] = mapping(entry, f"{path}: {group}")
    return result

