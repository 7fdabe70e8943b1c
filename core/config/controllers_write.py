"""New PID gains written into a copy of a ros2_controllers.yaml: the file as it was, only the gains changed.

The text is edited where the gains stand (positions from the YAML parser), so comments, key
order, flow or block style and launch substitutions stay as the user wrote them. A gain the
file lacks is added beside the joint's others; a joint without gains, under `gains`; a
controller without `gains`, under its `ros__parameters`. Numbers are written with a decimal
point: ROS 2 refuses an integer for a double parameter.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import yaml

from ..errors import ConfigError
from ._substitutions import substitute

__all__ = ["tuned_controllers_text", "yaml_float"]

Edit = tuple[int, int, str]
"""Replace text[start:end] by the string."""


@dataclass(frozen=True)
class _Section:
    """A top-level section naming the controller: its ros__parameters node, and gains if any."""

    parameters: yaml.MappingNode
    gains: yaml.MappingNode | None
    wildcard: bool


def tuned_controllers_text(
    text: str, source: str, controller: str, gains: Mapping[str, Mapping[str, float]],
    launch_args: Mapping[str, str] | None = None,
) -> str:
    """Return `text` (a ros2_controllers.yaml read from `source`) with `controller`'s gains set to `gains`.

    `gains` maps joint -> gain key -> value. Keys with launch substitutions
    (`$(var tf_prefix)elbow_joint`) are matched as substituted with `launch_args`.

    Raises:
        ConfigError: The file has no section for the controller.
    """
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        raise ConfigError(f"{source}: not valid YAML: {exc}") from None
    args = launch_args or {}
    sections = _sections(root, controller, source, args)
    if not sections:
        raise ConfigError(f"{source}: no '{controller}: ros__parameters' section to write gains into")
    holders = [s for s in sections if s.gains is not None]
    missing = [j for j in gains if not any(isinstance(_child(s.gains, j, source, args), yaml.MappingNode)
                                           for s in holders)]
    entries = [f"{joint}: " + "{" + ", ".join(f"{k}: {yaml_float(v)}" for k, v in gains[joint].items()) + "}"
               for joint in missing]
    edits: list[Edit] = []
    if entries and holders:
        edits.append(_insert(text, cast(yaml.MappingNode, holders[-1].gains), "\n".join(entries)))
    elif entries:
        target = ([s for s in sections if not s.wildcard] or sections)[-1]
        edits.append(_insert(text, target.parameters, "gains:" + "".join("\n  " + e for e in entries)))
    for joint, values in gains.items():
        if joint not in missing:
            edits += _joint_edits(text, holders, joint, values, source, args)
    for start, end, new in sorted(edits, key=lambda e: (e[0], e[1]), reverse=True):
        text = text[:start] + new + text[end:]
    return text


def yaml_float(value: float) -> str:
    """Return `value` as a YAML float that PyYAML, yaml-cpp and rclcpp all read as a double."""
    if not math.isfinite(value):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf")
    text = f"{value:.6g}"
    mantissa, _, exponent = text.partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return f"{mantissa}e{exponent}" if exponent else mantissa


def _sections(root: yaml.Node | None, controller: str, source: str, args: Mapping[str, str]) -> list[_Section]:
    """Return, in file order, the sections whose ros__parameters apply to the node `controller`."""
    found: list[_Section] = []
    if not isinstance(root, yaml.MappingNode):
        return found
    for key, value in root.value:
        name = _name(key, source, args)
        if name is None or not _names_node(name, controller) or not isinstance(value, yaml.MappingNode):
            continue
        parameters = _child(value, "ros__parameters", source, args)
        if isinstance(parameters, yaml.MappingNode):
            gains = _child(parameters, "gains", source, args)
            found.append(_Section(parameters, gains if isinstance(gains, yaml.MappingNode) else None, "*" in name))
    return found


def _joint_edits(
    text: str, holders: list[_Section], joint: str, values: Mapping[str, float], source: str,
    args: Mapping[str, str],
) -> list[Edit]:
    """Return the edits that give `joint`, which has gains in some section, the gains `values`.

    Each value is set where rclcpp reads it last: the last section that gives it; a gain no
    section gives is added to the last section that has the joint.
    """
    entries = [e for e in (_child(s.gains, joint, source, args) for s in holders) if isinstance(e, yaml.MappingNode)]
    edits, missing = [], []
    for key, value in values.items():
        node = next((n for n in (_child(e, key, source, args) for e in reversed(entries)) if n is not None), None)
        if node is None:
            missing.append(f"{key}: {yaml_float(value)}")
        else:
            edits.append((node.start_mark.index, node.end_mark.index, yaml_float(value)))
    if missing:
        edits.append(_insert(text, entries[-1], "\n".join(missing)))
    return edits


def _insert(text: str, mapping: yaml.MappingNode, entry: str) -> Edit:
    """Return the edit adding `entry` (`key: value`, maybe several lines) at the end of `mapping`."""
    if mapping.flow_style:
        close = text.rindex("}", mapping.start_mark.index, mapping.end_mark.index)
        before = text[mapping.start_mark.index + 1 : close].strip()
        return close, close, (", " if before else "") + entry.replace("\n", ", ")
    if not mapping.value:
        raise ConfigError(f"line {mapping.start_mark.line + 1}: an empty block mapping cannot take gains")
    indent = " " * mapping.value[0][0].start_mark.column
    last = mapping.value[-1][1]
    at = text.find("\n", max(last.end_mark.index - 1, last.start_mark.index))
    if at < 0:
        at = len(text)
    lines = entry.split("\n")
    return at, at, "".join("\n" + indent + line for line in lines)


def _child(mapping: yaml.MappingNode | None, key: str, source: str, args: Mapping[str, str]) -> yaml.Node | None:
    """Return the value node of `key` in `mapping` (keys compared once substituted), None if absent."""
    if mapping is None:
        return None
    found = None
    for key_node, value in mapping.value:
        if _name(key_node, source, args) == key:
            found = value  # the last one wins, as the parser keeps it
    return found


def _name(node: yaml.Node, source: str, args: Mapping[str, str]) -> str | None:
    """Return a key's text with its launch substitutions made, None for a key that is not a string."""
    if not isinstance(node, yaml.ScalarNode):
        return None
    value = str(node.value)
    return substitute(value, Path(source), args) if "$(" in value else value


def _names_node(key: str, node: str) -> bool:
    """Return whether a top-level key applies to the node `node`, as controllers.parse_controllers reads it."""
    last = key.strip("/").rsplit("/", 1)[-1]
    return last == "**" or re.fullmatch(re.escape(last).replace(r"\*", "[^/]*"), node) is not None
