"""What moveplan reads of an SRDF: planning groups, named states and disabled collision pairs.

Groups are made as MoveIt makes its JointModelGroups (srdfdom Model::loadGroups, moveit_core
RobotModel::addJointModelGroup): a `<chain>` adds the joints from its base link to its tip link,
a `<joint>` that joint, a `<link>` the joint above that link, a `<group>` every joint of that
group, defined before or after it. The joints are then put in MoveIt's order: depth-first
through the URDF tree, the joints below a link in the order of their names (urdfdom's).

The SRDF's `<virtual_joint>` is the joint above the URDF's root link; groups and group states
may name it. moveplan plans fixed-base arms: a fixed virtual joint adds nothing to a group,
and a floating or planar one (or a URDF floating or planar joint) is kept aside in
`Group.base_joints`, so that the file loads and only planning with such a group is an error
(`Srdf.plannable`).
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import ConfigError, UnknownName, known
from ._urdf import MOVABLE_JOINT_TYPES, UrdfJoint, float_attr, xml_root

__all__ = ["VIRTUAL_JOINT_TYPES", "Group", "Srdf", "VirtualJoint", "parse_srdf"]

_log = logging.getLogger(__name__)

VIRTUAL_JOINT_TYPES = ("fixed", "floating", "planar")
_BASE_JOINT_TYPES = ("floating", "planar")


@dataclass(frozen=True)
class VirtualJoint:
    """An SRDF `<virtual_joint>`: how the robot's root link hangs from a frame outside the robot."""

    name: str
    type: str
    parent_frame: str
    child_link: str


@dataclass(frozen=True)
class Group:
    """A planning group: its movable joints in MoveIt's order, base and tip links.

    Attributes:
        joints: Its revolute, continuous and prismatic joints (mimic joints included),
            depth-first through the URDF tree.
        base_joints: Its floating and planar joints (joint -> type): a virtual joint that
            moves the whole robot, or URDF ones. moveplan does not plan them.
        links: Its links, MoveIt's JointModelGroup link models: the child link of each of its
            joints, fixed ones included, depth-first through the URDF tree.
    """

    name: str
    joints: tuple[str, ...]
    base: str
    tip: str
    base_joints: dict[str, str] = field(default_factory=dict)
    links: tuple[str, ...] = ()


@dataclass(frozen=True)
class Srdf:
    """What moveplan uses of an SRDF: groups, named states, disabled collision pairs and virtual joints."""

    name: str
    groups: dict[str, Group]
    group_states: dict[str, dict[str, dict[str, float]]]
    disabled_pairs: frozenset[frozenset[str]]
    virtual_joints: dict[str, VirtualJoint] = field(default_factory=dict)

    def plannable(self, name: str, source: Path | str) -> Group:
        """Return group `name` if moveplan can plan with it: no floating or planar joint moves its base.

        Raises:
            UnknownName: No such group in the SRDF at `source`.
            ConfigError: The group holds a floating or planar joint; names the group, the
                joint and the groups moveplan can plan with.
        """
        if name not in self.groups:
            raise UnknownName("group", name, str(source), self.groups)
        group = self.groups[name]
        if not group.base_joints:
            return group
        joint, kind = next(iter(group.base_joints.items()))
        what = f"{kind} virtual joint" if joint in self.virtual_joints else f"{kind} joint"
        usable = [g.name for g in self.groups.values() if g.joints and not g.base_joints]
        raise ConfigError(f"{source}: group '{name}' moves the robot's base through its {what} '{joint}'; "
                          f"moveplan plans fixed-base arms: plan with a group without it ({known(usable)})")


def parse_srdf(text: str, path: Path, joints: dict[str, UrdfJoint]) -> Srdf:
    """Return the SRDF's groups, named states and disabled pairs, checked against the URDF's joints."""
    root = xml_root(text, path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not an SRDF (root element is <{root.tag}>, expected <robot>)")
    virtual = _virtual_joints(root.findall("virtual_joint"), path, joints)
    tree = _Tree(joints, virtual, path)
    groups = _with_end_effector_tips(_groups(root.findall("group"), tree), root.findall("end_effector"), tree,
                                     {e.get("name", "").strip() for e in root.findall("group") if e.find("chain")
                                      is not None})
    states = _group_states(root.findall("group_state"), tree, groups)
    disabled = frozenset(
        frozenset((e.get("link1", ""), e.get("link2", ""))) for e in root.findall("disable_collisions")
    )
    return Srdf(root.get("name", ""), groups, states, disabled, virtual)


def _with_end_effector_tips(
    groups: dict[str, Group], end_effectors: list[ET.Element], tree: _Tree, chains: set[str]
) -> dict[str, Group]:
    """Return the groups with MoveIt's tip where no chain names it.

    The tip is the parent link of the group's end effector, else the group's last link, trailing
    fixed joints included: MoveGroupInterface's end-effector link.
    """
    parents: dict[str, str] = {}
    for element in end_effectors:
        owner, link = (element.get("parent_group") or "").strip(), (element.get("parent_link") or "").strip()
        if owner in groups and link in tree.links:
            parents.setdefault(owner, link)
    result: dict[str, Group] = {}
    for name, group in groups.items():
        tip = group.tip if name in chains else parents.get(name) or (group.links[-1] if group.links else group.tip)
        result[name] = group if tip == group.tip else replace(group, tip=tip)
    return result


def _name(element: ET.Element, attribute: str, path: Path, what: str) -> str:
    """Return an attribute naming something, trimmed as srdfdom trims it; ConfigError when it is missing."""
    value = (element.get(attribute) or "").strip()
    if not value:
        raise ConfigError(f"{path}: {what}: <{element.tag}> has no {attribute}")
    return value


def _virtual_joints(elements: list[ET.Element], path: Path, joints: dict[str, UrdfJoint]) -> dict[str, VirtualJoint]:
    """Return the SRDF's virtual joints by name, read as srdfdom reads them.

    srdfdom skips a virtual joint without a name, child link or parent frame, or whose child is
    not a URDF link, and takes an unknown type as fixed, logging an error: real configs carry
    such joints (ABB's IRB 1200 SRDF names none), so this warns and does the same.
    """
    links = {j.child for j in joints.values()} | {j.parent for j in joints.values()}
    virtual: dict[str, VirtualJoint] = {}
    for element in elements:
        name, child, parent = ((element.get(key) or "").strip() for key in ("name", "child_link", "parent_frame"))
        kind = (element.get("type") or "").strip().lower()
        problem = ("has no name" if not name else "has no child_link" if not child
                   else f"attaches to '{child}', which is not a URDF link" if child not in links
                   else "has no parent_frame" if not parent else "")
        if problem:
            shown = f"virtual joint '{name}'" if name else "a <virtual_joint>"
            _log.warning("%s: %s %s; skipped, as MoveIt skips it", path, shown, problem)
            continue
        if kind not in VIRTUAL_JOINT_TYPES:
            _log.warning("%s: virtual joint '%s': type '%s' is not one of %s; taken as fixed, as MoveIt takes it",
                         path, name, kind, ", ".join(VIRTUAL_JOINT_TYPES))
            kind = "fixed"
        virtual[name] = VirtualJoint(name, kind, parent, child)
    return virtual


class _Tree:
    """The URDF tree as MoveIt builds it: each link's parent joint, and the joints' depth-first order."""

    def __init__(self, joints: dict[str, UrdfJoint], virtual: dict[str, VirtualJoint], path: Path) -> None:
        self.joints, self.virtual, self.path = joints, virtual, path
        self.above = {j.child: j for j in joints.values()}
        self.links = set(self.above) | {j.parent for j in joints.values()}
        roots = sorted(self.links - set(self.above))
        # MoveIt takes the first virtual joint on the root link; it warns about and skips the others.
        at_root = [v for v in virtual.values() if v.child_link in roots][:1]
        for other in [v for v in virtual.values() if v not in at_root]:
            _log.warning("%s: virtual joint '%s' is skipped, as MoveIt skips it: only the first one on the URDF "
                         "root link (%s) counts", path, other.name, ", ".join(roots))
        self.parent_joint = {link: j.name for link, j in self.above.items()}
        self.parent_joint.update({v.child_link: v.name for v in at_root})
        self.order = _depth_first(joints, roots, at_root[0] if at_root else None)
        self.movable = {j.name for j in joints.values() if j.type in MOVABLE_JOINT_TYPES}
        # joint -> type of the joints that move the robot's base; MoveIt has no other virtual joint
        self.base_kinds = {j.name: j.type for j in joints.values() if j.type in _BASE_JOINT_TYPES}
        self.base_kinds.update({v.name: v.type for v in at_root if v.type in _BASE_JOINT_TYPES})

    def is_joint(self, name: str) -> bool:
        """Return whether a group or group state may name `name`: a URDF or a virtual joint (srdfdom)."""
        return name in self.joints or name in self.virtual

    def chain(self, base: str, tip: str, where: str) -> set[str]:
        """Return the joints of a `<chain>`, as MoveIt collects them (also through a common ancestor)."""
        for link in (base, tip):
            if link not in self.links:
                raise UnknownName("link", link, where, self.links)
        up_from_tip = self._ancestors(tip)
        if base in up_from_tip:
            return self._parent_joints(up_from_tip[: up_from_tip.index(base)])
        if tip in self._ancestors(base):
            # MoveIt would collect the same joints and take `base` as the tip: pose goals would then move the base.
            raise ConfigError(f"{where}: chain base_link '{base}' is below tip_link '{tip}' (given tip-to-base?): "
                              "swap base_link and tip_link")
        # base is not above tip (a chain from one gripper to another): MoveIt walks up from base to
        # the first link on tip's path and, as it does, keeps that link's own parent joint too.
        up_from_base = self._ancestors(base)
        on_tip_path = {link: i for i, link in enumerate(up_from_tip)}
        meet = next((i for i, link in enumerate(up_from_base) if link in on_tip_path), None)
        if meet is None:
            raise ConfigError(f"{where}: links '{base}' and '{tip}' do not form a chain (no common ancestor)")
        common = on_tip_path[up_from_base[meet]]
        return self._parent_joints(up_from_tip[: common + 1] + up_from_base[:meet])

    def link_joint(self, link: str, where: str) -> set[str]:
        """Return the joint above `link` (none above a root without a virtual joint)."""
        if link not in self.links:
            raise UnknownName("link", link, where, self.links)
        return self._parent_joints([link])

    def _ancestors(self, link: str) -> list[str]:
        """Return `link` and the links above it, up to the root."""
        path = [link]
        while path[-1] in self.above:
            path.append(self.above[path[-1]].parent)
        return path

    def _parent_joints(self, links: Iterable[str]) -> set[str]:
        """Return the joints above `links`."""
        return {self.parent_joint[link] for link in links if link in self.parent_joint}


def _depth_first(joints: dict[str, UrdfJoint], roots: list[str], root_joint: VirtualJoint | None) -> dict[str, int]:
    """Return joint -> index in MoveIt's order: the virtual joint, then depth-first, siblings by name."""
    below: dict[str, list[str]] = {}
    for joint in sorted(joints):
        below.setdefault(joints[joint].parent, []).append(joint)
    order: dict[str, int] = {root_joint.name: 0} if root_joint is not None else {}
    stack = [j for root in reversed(roots) for j in reversed(below.get(root, []))]
    while stack:
        joint = stack.pop()
        order[joint] = len(order)
        stack.extend(reversed(below.get(joints[joint].child, [])))
    return order


def _groups(elements: list[ET.Element], tree: _Tree) -> dict[str, Group]:
    """Return the groups in file order, each reduced to its movable joints and its base joints."""
    path = tree.path
    own: dict[str, set[str]] = {}
    subgroups: dict[str, list[str]] = {}
    chains: dict[str, tuple[str, str]] = {}
    for element in elements:
        name = _name(element, "name", path, "group")
        if name in own:
            raise ConfigError(f"{path}: group '{name}' is defined twice")
        own[name], subgroups[name] = _members(element, name, tree), []
        for sub in element.findall("group"):
            subgroups[name].append(_name(sub, "name", path, f"group '{name}'"))
        for chain in element.findall("chain"):
            chains[name] = (chain.get("base_link", "").strip(), chain.get("tip_link", "").strip())
    if not own:
        raise ConfigError(f"{path}: defines no <group>")
    members = _with_subgroups(own, subgroups, path)
    return {name: _group(name, members[name], chains.get(name), tree) for name in own}


def _members(element: ET.Element, name: str, tree: _Tree) -> set[str]:
    """Return the joints a group's own `<chain>`, `<joint>` and `<link>` elements name."""
    where = f"{tree.path} group '{name}'"
    joints: set[str] = set()
    for chain in element.findall("chain"):
        joints |= tree.chain(_name(chain, "base_link", tree.path, f"group '{name}'"),
                             _name(chain, "tip_link", tree.path, f"group '{name}'"), where)
    for joint in element.findall("joint"):
        jname = _name(joint, "name", tree.path, f"group '{name}'")
        if not tree.is_joint(jname):
            raise UnknownName("joint", jname, where, [*tree.joints, *tree.virtual])
        joints.add(jname)
    for link in element.findall("link"):
        joints |= tree.link_joint(_name(link, "name", tree.path, f"group '{name}'"), where)
    return joints


def _with_subgroups(own: dict[str, set[str]], subgroups: dict[str, list[str]], path: Path) -> dict[str, set[str]]:
    """Return each group's joints with those of its subgroups, in any order of definition (MoveIt's passes)."""
    for name, subs in subgroups.items():
        for sub in subs:
            if sub not in own:
                raise UnknownName("group", sub, f"{path} group '{name}'", own)
    members: dict[str, set[str]] = {}
    waiting = {name: set(subs) for name, subs in subgroups.items()}
    ready = [name for name, subs in waiting.items() if not subs]
    users: dict[str, list[str]] = {}
    for name, pending in waiting.items():
        for sub in pending:
            users.setdefault(sub, []).append(name)
    while ready:
        name = ready.pop()
        members[name] = own[name].union(*(members[sub] for sub in subgroups[name]))
        for user in users.get(name, []):
            waiting[user].discard(name)
            if not waiting[user]:
                ready.append(user)
    stuck = [name for name in own if name not in members]
    if len(stuck) == 1:
        raise ConfigError(f"{path}: group '{stuck[0]}' includes itself as a subgroup; a group cannot contain itself")
    if stuck:
        raise ConfigError(f"{path}: groups {', '.join(stuck)} include each other as subgroups; "
                          "a group cannot contain itself")
    return members


def _group(name: str, members: set[str], chain: tuple[str, str] | None, tree: _Tree) -> Group:
    """Return a group from its joints: movable ones in MoveIt's order, floating and planar ones aside."""
    active = tuple(sorted(members & tree.movable, key=tree.order.__getitem__))
    moving_base = sorted(tree.base_kinds.keys() & members, key=tree.order.__getitem__)
    base_joints = {joint: tree.base_kinds[joint] for joint in moving_base}
    base, tip = chain or ("", "")
    if not base and active:
        base, tip = tree.joints[active[0]].parent, tree.joints[active[-1]].child
    links = tuple(tree.joints[j].child for j in sorted(members & tree.joints.keys(), key=tree.order.__getitem__))
    return Group(name, active, base, tip, base_joints, links)


def _group_states(
    elements: list[ET.Element], tree: _Tree, groups: dict[str, Group]
) -> dict[str, dict[str, dict[str, float]]]:
    """Return group -> state name -> joint values of the SRDF's <group_state> elements.

    Values of floating and planar joints (several numbers each) are checked, not kept:
    moveplan does not plan them.
    """
    path = tree.path
    states: dict[str, dict[str, dict[str, float]]] = {g: {} for g in groups}
    for element in elements:
        group, name = element.get("group", "").strip(), element.get("name", "").strip()
        if group not in groups:
            raise UnknownName("group", group, f"{path} group_state '{name}'", groups)
        if name in states[group]:
            _log.warning("%s: group_state '%s' of group '%s' is defined twice; the last one counts, as in MoveIt",
                         path, name, group)
        states[group][name] = _state_values(element, name, tree, groups[group])
    return states


def _state_values(element: ET.Element, name: str, tree: _Tree, group: Group) -> dict[str, float]:
    """Return joint -> value of one `<group_state>`; values of joints outside the group are checked, then dropped.

    MoveIt (RobotModel::buildGroupStates) logs an error for a joint the group does not have
    and keeps the state's other values: so does this, with a warning.
    """
    path = tree.path
    values: dict[str, float] = {}
    outside: list[str] = []
    for joint in element.findall("joint"):
        jname = joint.get("name", "").strip()
        if not tree.is_joint(jname):
            raise UnknownName("joint", jname, f"{path} group_state '{name}'", [*tree.joints, *tree.virtual])
        where = f"{path}: group_state '{name}' joint '{jname}'"
        if jname in tree.virtual or tree.joints[jname].type in _BASE_JOINT_TYPES:
            _numbers(joint.get("value", ""), where)
            continue
        value = float_attr(joint, "value", path, 0.0)
        if not math.isfinite(value):
            raise ConfigError(f"{where}: value='{joint.get('value')}' is not a finite number")
        if jname in tree.movable and jname not in group.joints:
            outside.append(jname)
            continue
        values[jname] = value
    if outside:
        _log.warning("%s: group_state '%s' gives joints that group '%s' does not have: %s; ignored, as MoveIt "
                     "ignores them", path, name, group.name, ", ".join(outside))
    return values


def _numbers(text: str, where: str) -> list[float]:
    """Return the whitespace-separated finite numbers of a multi-variable joint's value."""
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        values = [math.nan]
    if not all(math.isfinite(v) for v in values):
        raise ConfigError(f"{where}: value='{text}' is not a list of finite numbers")
    return values
