"""Where the robot starts when nothing says otherwise: where mock hardware and MoveIt start it.

Each movable joint takes the first of:

1. the `initial_value` of the position state interface of the joint's `<ros2_control>` entry
   in the (expanded) URDF, or the older joint parameter `initial_position`: where
   ros2_control's mock_components/GenericSystem starts;
2. initial_positions.yaml, which a MoveIt config's xacro normally feeds into those initial
   values: it speaks for a URDF without them;
3. a MoveIt 1 config's fake_controllers.yaml `initial:` list (group and SRDF named state, in
   order), where MoveIt 1's fake controllers start the robot;
4. MoveIt's default state (RobotState::setToDefaultValues): 0 where the joint's limits allow
   it, else the middle of its range.

The URDF wins over initial_positions.yaml because it is what the hardware reads; where the two
disagree, a warning names the joints. A mimic joint follows its leader, as in MoveIt's
RobotState. Whether a start lies within the limits is checked where a plan starts.
"""

from __future__ import annotations

import logging
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError, UnknownName
from ._urdf import UrdfJoint, xml_root
from .fields import MAX_MAGNITUDE, coordinate, load_yaml, mapping
from .limits import JointLimit

__all__ = ["DEFAULT_STATE", "InitialState", "default_position", "fake_controllers_initial", "initial_state",
           "parse_initial_positions", "ros2_control_initial_positions"]

logger = logging.getLogger(__name__)

# What std::stod, which GenericSystem parses the value with, reads whole: no "1_000", "0x10" or "infinity".
_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")

DEFAULT_STATE = "MoveIt's default state (0, or the middle of the joint's limits)"
"""InitialState.sources value of a joint that neither the URDF nor initial_positions.yaml places."""


@dataclass(frozen=True)
class InitialState:
    """Where every movable joint starts, in [rad] or [m], and where each value comes from.

    Attributes:
        positions: Joint -> start value, for every movable URDF joint.
        sources: Joint -> where its value comes from, worded to follow "from": the URDF's
            `<ros2_control>` initial_value, initial_positions.yaml (its path), the joint it
            mimics, or DEFAULT_STATE.
    """

    positions: dict[str, float]
    sources: dict[str, str]


def initial_state(
    urdf_text: str,
    urdf_path: Path,
    joints: dict[str, UrdfJoint],
    limits: dict[str, JointLimit],
    positions_path: Path | None,
    named: tuple[dict[str, float], Path] | None = None,
) -> InitialState:
    """Return where every movable joint starts (see the module's precedence), with the source of each value.

    `named` is fake_controllers_initial's joint values and the file they come from.
    """
    hardware = ros2_control_initial_positions(urdf_text, urdf_path)
    from_file = parse_initial_positions(positions_path, limits) if positions_path is not None else {}
    _warn_disagreements(hardware, from_file, urdf_path, positions_path)
    positions: dict[str, float] = {}
    sources: dict[str, str] = {}
    for name, limit in limits.items():
        if name in hardware:
            positions[name], sources[name] = hardware[name], f"the <ros2_control> initial_value in {urdf_path}"
        elif name in from_file:
            positions[name], sources[name] = from_file[name], str(positions_path)
        elif named is not None and name in named[0]:
            positions[name], sources[name] = named[0][name], f"the initial poses of {named[1]}"
        else:
            positions[name], sources[name] = default_position(limit), DEFAULT_STATE
    for name in limits:
        joint = joints[name]
        # One level only: a leader that is itself a mimic joint, or does not move, leaves the joint as it is.
        if joint.mimic in positions and not joints[joint.mimic].mimic:
            positions[name] = joint.mimic_multiplier * positions[joint.mimic] + joint.mimic_offset
            sources[name] = f"joint '{joint.mimic}', which it mimics"
    _warn_ignored(hardware, positions, joints, limits, urdf_path)
    return InitialState(positions, sources)


def _warn_ignored(
    hardware: dict[str, float], positions: dict[str, float], joints: dict[str, UrdfJoint],
    limits: dict[str, JointLimit], urdf_path: Path,
) -> None:
    """Warn about `<ros2_control>` initial values moveplan does not start from: unknown joints, mimic joints."""
    unknown = sorted(set(hardware) - set(joints))
    if unknown:
        logger.warning("%s: <ros2_control> gives initial values of joints the URDF does not have: %s; ignored",
                       urdf_path, ", ".join(unknown))
    fixed = sorted(set(hardware) & set(joints) - set(limits))
    if fixed:
        logger.debug("%s: <ros2_control> initial values of joints that do not move ignored: %s",
                     urdf_path, ", ".join(fixed))
    differ = [f"{name} ({hardware[name]:g}, follows as {positions[name]:g})" for name in sorted(hardware)
              if name in limits and joints[name].mimic and abs(hardware[name] - positions[name]) > 1e-9]
    if differ:
        logger.warning("%s: <ros2_control> initial values of mimic joints ignored: %s; a mimic joint follows "
                       "its leader, as in MoveIt", urdf_path, ", ".join(differ))


def default_position(limit: JointLimit) -> float:
    """Return MoveIt's default value of a joint in [rad] or [m]: 0 if within its limits, else the middle."""
    if limit.continuous or not math.isfinite(limit.lower + limit.upper) or limit.lower <= 0.0 <= limit.upper:
        return 0.0
    return (limit.lower + limit.upper) / 2.0


def ros2_control_initial_positions(urdf_text: str, urdf_path: Path) -> dict[str, float]:
    """Return joint -> the initial position the URDF's `<ros2_control>` tags give mock hardware.

    Read as GenericSystem reads it: the `initial_value` parameter of the joint's `position`
    state interface, else the joint's `initial_position` parameter (the older form); an empty
    value is no value. The first `<ros2_control>` naming a joint wins.
    """
    values: dict[str, float] = {}
    for system in xml_root(urdf_text, urdf_path).findall("ros2_control"):
        for joint in system.findall("joint"):
            name = joint.get("name", "")
            text = _initial_position_text(joint)
            if text and name not in values:
                where = f"{urdf_path}: <ros2_control name=\"{system.get('name', '')}\"> joint '{name}'"
                values[name] = _finite(text, where)
    return values


def parse_initial_positions(path: Path, limits: dict[str, JointLimit]) -> dict[str, float]:
    """Return initial_positions.yaml's joint -> value, for joints that have limits (the movable ones)."""
    top = mapping(load_yaml(path), str(path))
    values = mapping(top.get("initial_positions", top), f"{path}: initial_positions")
    result = {}
    for joint, value in values.items():
        if joint not in limits:
            raise UnknownName("joint", joint, f"{path}: initial_positions", limits)
        result[joint] = coordinate(value, f"{path}: initial_positions.{joint}")
    return result


def fake_controllers_initial(path: Path, group_states: dict[str, dict[str, dict[str, float]]],
                             limits: dict[str, JointLimit]) -> dict[str, float]:
    """Return joint -> value of a MoveIt 1 fake_controllers.yaml's `initial:` poses (SRDF named states, in order).

    Raises:
        ConfigError: An entry that is no {group, pose} mapping; UnknownName: a group or pose the SRDF lacks.
    """
    top = mapping(load_yaml(path), str(path))
    entries = top.get("initial") or []
    if not isinstance(entries, list):
        raise ConfigError(f"{path}: initial: expected a list of {{group: ..., pose: ...}}, got {entries!r}")
    values: dict[str, float] = {}
    for k, entry in enumerate(entries):
        item = mapping(entry, f"{path}: initial[{k}]")
        group, pose = str(item.get("group", "")), str(item.get("pose", ""))
        if group not in group_states:
            raise UnknownName("group with named states", group, f"{path}: initial[{k}].group", group_states)
        if pose not in group_states[group]:
            raise UnknownName("named state", pose, f"{path}: initial[{k}].pose", group_states[group])
        values.update({j: v for j, v in group_states[group][pose].items() if j in limits})
    return values


def _initial_position_text(joint: ET.Element) -> str:
    """Return the text of a `<ros2_control>` joint's initial position parameter, "" when it has none."""
    for interface in joint.findall("state_interface"):
        if interface.get("name") == "position":
            for param in interface.findall("param"):
                if param.get("name") == "initial_value" and (param.text or "").strip():
                    return (param.text or "").strip()
    for param in joint.findall("param"):
        if param.get("name") == "initial_position":
            return (param.text or "").strip()
    return ""


def _finite(text: str, where: str) -> float:
    """Return `text` as a finite number within MAX_MAGNITUDE; ConfigError names `where` otherwise."""
    shown = text if len(text) <= 40 else f"{text[:37]}... ({len(text)} characters)"
    if text.lower() in ("nan", "inf", "+inf", "-inf", "infinity", "+infinity", "-infinity"):
        raise ConfigError(f"{where}: initial value '{shown}' is not a finite number")
    if not _NUMBER.fullmatch(text):
        raise ConfigError(f"{where}: initial value '{shown}' is not a number")
    value = float(text)
    if not abs(value) <= MAX_MAGNITUDE:
        raise ConfigError(f"{where}: initial value '{shown}' is out of range; values are limited to "
                          f"|value| <= {MAX_MAGNITUDE:,.0f}")
    return value


def _warn_disagreements(
    hardware: dict[str, float], from_file: dict[str, float], urdf_path: Path, positions_path: Path | None
) -> None:
    """Warn about joints whose URDF initial value and initial_positions.yaml value differ."""
    differ = [f"{joint} ({hardware[joint]:g}, not {value:g})" for joint, value in from_file.items()
              if joint in hardware and abs(hardware[joint] - value) > 1e-9]
    if differ:
        logger.warning("%s: <ros2_control> initial values differ from %s for %s; starting from the URDF's, "
                       "where mock hardware starts", urdf_path, positions_path, ", ".join(differ))
