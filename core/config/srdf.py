"""What moveplan reads of an SRDF: planning groups, named states and disabled collision pairs."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError, UnknownName
from .urdf import MOVABLE_JOINT_TYPES, UrdfJoint, float_attr, xml_root

__all__ = ["Group", "Srdf", "parse_srdf"]


@dataclass(frozen=True)
class Group:
    """A planning group: its active joints in order, base and tip links."""

    name: str
    joints: tuple[str, ...]
    base: str
    tip: str


@dataclass(frozen=True)
class Srdf:
    """What moveplan uses of an SRDF: groups, named states and disabled collision pairs."""

    name: str
    groups: dict[str, Group]
    group_states: dict[str, dict[str, dict[str, float]]]
    disabled_pairs: frozenset[frozenset[str]]


def parse_srdf(text: str, path: Path, joints: dict[str, UrdfJoint]) -> Srdf:
    """Return the SRDF's groups, named states and disabled pairs, checked against the URDF's joints."""
    root = xml_root(text, path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not an SRDF (root element is <{root.tag}>, expected <robot>)")
    groups = _groups(root.findall("group"), path, joints)
    states = _group_states(root.findall("group_state"), path, joints, groups)
    disabled = frozenset(
        frozenset((e.get("link1", ""), e.get("link2", ""))) for e in root.findall("disable_collisions")
    )
    return Srdf(root.get("name", ""), groups, states, disabled)


def _groups(elements: list[ET.Element], path: Path, joints: dict[str, UrdfJoint]) -> dict[str, Group]:
    """Return the groups in file order: chains, joints and subgroups, reduced to their movable joints."""
    movable = [j.name for j in joints.values() if j.type in MOVABLE_JOINT_TYPES]
    groups: dict[str, Group] = {}
    for element in elements:
        name = element.get("name", "")
        names: list[str] = []
        base = tip = ""
        for chain in element.findall("chain"):
            base, tip = chain.get("base_link", ""), chain.get("tip_link", "")
            names += _chain(path, joints, base, tip)
        for joint in element.findall("joint"):
            jname = joint.get("name", "")
            if jname not in joints:
                raise UnknownName("joint", jname, f"{path} group '{name}'", joints)
            names.append(jname)
        for sub in element.findall("group"):
            sub_name = sub.get("name", "")
            if sub_name not in groups:
                raise UnknownName("group", sub_name, f"{path} group '{name}'", groups)
            names += groups[sub_name].joints
        active = tuple(n for n in dict.fromkeys(names) if n in movable)
        if not base and active:
            base, tip = joints[active[0]].parent, joints[active[-1]].child
        groups[name] = Group(name, active, base, tip)
    if not groups:
        raise ConfigError(f"{path}: defines no <group>")
    return groups


def _group_states(
    elements: list[ET.Element], path: Path, joints: dict[str, UrdfJoint], groups: dict[str, Group]
) -> dict[str, dict[str, dict[str, float]]]:
    """Return group -> state name -> joint values of the SRDF's <group_state> elements."""
    states: dict[str, dict[str, dict[str, float]]] = {g: {} for g in groups}
    for element in elements:
        group, name = element.get("group", ""), element.get("name", "")
        if group not in groups:
            raise UnknownName("group", group, f"{path} group_state '{name}'", groups)
        values: dict[str, float] = {}
        for joint in element.findall("joint"):
            jname = joint.get("name", "")
            if jname not in joints:
                raise UnknownName("joint", jname, f"{path} group_state '{name}'", joints)
            value = float_attr(joint, "value", path, 0.0)
            if not math.isfinite(value):
                raise ConfigError(f"{path}: group_state '{name}' joint '{jname}': value='{joint.get('value')}' "
                                  "is not a finite number")
            values[jname] = value
        states[group][name] = values
    return states


def _chain(path: Path, joints: dict[str, UrdfJoint], base: str, tip: str) -> list[str]:
    """Return the joints from `base` to `tip`, in order."""
    parent_joint = {j.child: j for j in joints.values()}
    links = {j.child for j in joints.values()} | {j.parent for j in joints.values()}
    for link in (base, tip):
        if link not in links:
            raise UnknownName("link", link, str(path), links)
    chain: list[str] = []
    link = tip
    while link != base:
        if link not in parent_joint:
            raise ConfigError(f"{path}: chain: '{tip}' does not descend from '{base}'")
        joint = parent_joint[link]
        chain.append(joint.name)
        link = joint.parent
    return chain[::-1]
