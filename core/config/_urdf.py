"""What moveplan reads of a URDF: its joints with their limits, and its collision meshes' files."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError
from .fields import MAX_MAGNITUDE
from .xacro import PackagePath

__all__ = [
    "JOINT_TYPES", "MAX_DEGREES_OF_FREEDOM", "MAX_LINKS", "MOVABLE_JOINT_TYPES", "CollisionMesh", "UrdfJoint",
    "float_attr", "parse_urdf",
    "resolve_collision_meshes", "xml_root",
]

MOVABLE_JOINT_TYPES = ("revolute", "continuous", "prismatic")
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
"""The joint types urdfdom reads."""


@dataclass(frozen=True)
class UrdfJoint:
    """A joint as written in the URDF: type, parent and child links, limits (NaN when absent)."""

    name: str
    type: str
    parent: str
    child: str
    lower: float = math.nan
    upper: float = math.nan
    velocity: float = math.nan
    mimic: str = ""  # the joint this one follows (<mimic joint="..."/>), "" for none
    mimic_multiplier: float = 1.0  # value = multiplier * leader's value + offset
    mimic_offset: float = 0.0


@dataclass(frozen=True)
class CollisionMesh:
    """A collision mesh of a link: the URI the URDF gives and the file it resolves to."""

    link: str
    uri: str
    path: Path
    package: str = ""


def xml_root(text: str, path: Path) -> ET.Element:
    """Return the root element of an XML text read from `path`; ConfigError names the file."""
    try:
        return ET.fromstring(text)
    except ET.ParseError as exc:
        raise ConfigError(f"{path}: malformed XML: {exc}") from None


def float_attr(element: ET.Element, name: str, path: Path, default: float = math.nan) -> float:
    """Return an element's attribute as a float, `default` when it is absent."""
    text = element.get(name)
    if text is None:
        return default
    try:
        return float(text)
    except ValueError:
        raise ConfigError(f"{path}: <{element.tag}> {name}='{text}' is not a number") from None


MAX_LINKS = 256
"""Links a URDF may have: collision checks cost memory and time per pair of links; PR2 and TIAGo have
fewer than 100."""

MAX_DEGREES_OF_FREEDOM = 128
"""Joint coordinates a URDF may have (revolute, continuous and prismatic joints 1, planar 3, floating 6):
pinocchio's model data holds tables of their cube (32 bytes each), and a plan several of them: 67 MB
each at 128, 560 MB at 255, 32 GB at 1,000. A humanoid with two hands has about 80."""

_DEGREES_OF_FREEDOM = {"revolute": 1, "continuous": 1, "prismatic": 1, "planar": 3, "floating": 6}

# Attributes holding numbers in a URDF's links and joints: poses, axes, shapes, mesh scales, inertia.
_NUMERIC_ATTRIBUTES = frozenset({"xyz", "rpy", "size", "radius", "length", "scale", "value",
                                 "ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
# Joint numbers urdfdom refuses when not finite, in a message naming neither the joint nor the file (those
# of <limit> and <mimic> are read in _joint). Not bounded: a large gain or friction is valid URDF.
_FINITE_ATTRIBUTES = frozenset({"soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity", "damping",
                                "friction", "rising", "falling"})
_SHAPES = frozenset({"box", "cylinder", "sphere"})


def parse_urdf(text: str, path: Path) -> dict[str, UrdfJoint]:
    """Return the URDF's joints by name, in file order, checked as urdfdom checks a model.

    Every link and joint has a unique name, joints a known type and links that exist,
    limits finite numbers (velocity and effort given, as urdfdom requires), a movable joint a
    non-zero axis, a mimic joint a leader other than itself and no mimic loop; the links form
    one tree.
    """
    root = xml_root(text, path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not a URDF (root element is <{root.tag}>, expected <robot>)")
    links = _names(root.findall("link"), "link", path)
    if not links:
        raise ConfigError(f"{path}: defines no <link>; a URDF needs at least one")
    if len(links) > MAX_LINKS:
        raise ConfigError(f"{path}: {len(links):,} links; moveplan loads robots of at most {MAX_LINKS} links")
    _names(root.findall("joint"), "joint", path)
    freedom = sum(_DEGREES_OF_FREEDOM.get(joint.get("type", ""), 0) for joint in root.findall("joint"))
    if freedom > MAX_DEGREES_OF_FREEDOM:
        raise ConfigError(f"{path}: {freedom:,} degrees of freedom in its joints; moveplan loads robots of at most "
                          f"{MAX_DEGREES_OF_FREEDOM}")
    for element in (*root.findall("link"), *root.findall("joint")):
        _check_numbers(element, path)
    joints = {joint.name: joint for joint in (_joint(element, links, path) for element in root.findall("joint"))}
    _check_mimics(joints, path)
    _check_tree(joints, path, links)
    return joints


def _names(elements: list[ET.Element], what: str, path: Path) -> list[str]:
    """Return the names of URDF `<link>` or `<joint>` elements; ConfigError for a missing or repeated one."""
    names: list[str] = []
    seen: set[str] = set()
    for element in elements:
        name = element.get("name", "")
        if not name:
            raise ConfigError(f"{path}: a <{what}> has no name")
        if name in seen:
            raise ConfigError(f"{path}: {what} '{name}' is defined twice; names in a URDF are unique")
        seen.add(name)
        names.append(name)
    return names


def _joint(element: ET.Element, links: list[str], path: Path) -> UrdfJoint:
    """Return one `<joint>` element read as urdfdom reads it, checked."""
    name, kind = element.get("name", ""), element.get("type", "")
    if kind not in JOINT_TYPES:
        raise ConfigError(f"{path}: joint '{name}' has type '{kind}'; expected one of {', '.join(JOINT_TYPES)}")
    parent, child = element.find("parent"), element.find("child")
    if parent is None or child is None:
        raise ConfigError(f"{path}: joint '{name}' needs <parent> and <child>")
    for link in (parent.get("link", ""), child.get("link", "")):
        if link not in links:
            raise ConfigError(f"{path}: joint '{name}' names link '{link}', which is not defined")
    limit = element.find("limit")
    lower = upper = velocity = math.nan
    if limit is not None:
        where = f"joint '{name}' <limit>"
        lower, upper = _finite_attr(limit, "lower", path, where, 0.0), _finite_attr(limit, "upper", path, where, 0.0)
        velocity = _finite_attr(limit, "velocity", path, where)
        _finite_attr(limit, "effort", path, where)
    elif kind in ("revolute", "prismatic"):
        raise ConfigError(f"{path}: joint '{name}' is {kind} but has no <limit> (urdfdom requires one)")
    if kind in MOVABLE_JOINT_TYPES:
        _check_axis(element, name, path)
    mimic = element.find("mimic")
    leader, multiplier, offset = "", 1.0, 0.0
    if mimic is not None:
        leader = mimic.get("joint", "")
        where = f"joint '{name}' <mimic>"
        multiplier = _finite_attr(mimic, "multiplier", path, where, 1.0)
        offset = _finite_attr(mimic, "offset", path, where, 0.0)
    return UrdfJoint(name, kind, parent.get("link", ""), child.get("link", ""), lower, upper, velocity,
                     leader, multiplier, offset)


def _check_numbers(element: ET.Element, path: Path) -> None:
    """Raise ConfigError for a number of a link or joint that is not finite, too large, or a negative shape size.

    Poses, axes, shapes, mesh scales and inertia are bounded by MAX_MAGNITUDE. urdfdom refuses NaN
    with a log on stderr and a message naming nothing; a huge origin (1e300) loads and overflows the
    planner's geometry; a box or sphere of negative size loads and never collides.
    """
    owner = f"{element.tag} '{element.get('name', '')}'"
    for child in element.iter():
        for attribute in (_NUMERIC_ATTRIBUTES | _FINITE_ATTRIBUTES) & child.attrib.keys():
            text = child.attrib[attribute]
            for word in text.split():
                try:
                    value = float(word)
                except ValueError:
                    continue  # urdfdom's own message names a word that is no number
                if not math.isfinite(value):
                    problem = "is not a finite number"
                elif abs(value) > MAX_MAGNITUDE and attribute in _NUMERIC_ATTRIBUTES:
                    problem = f"is beyond moveplan's bound of {MAX_MAGNITUDE:g} (m, rad, kg)"
                elif value < 0 and child.tag in _SHAPES:
                    problem = "is negative; a shape's size is a length"
                else:
                    continue
                shown = text if len(text) <= 60 else f"{text[:57]}..."
                raise ConfigError(f"{path}: {owner} <{child.tag} {attribute}='{shown}'>: {word[:40]!r} {problem}")


def _finite_attr(element: ET.Element, name: str, path: Path, where: str, default: float | None = None) -> float:
    """Return an attribute as a finite float, `default` when absent (None: required, as urdfdom requires it)."""
    text = element.get(name)
    if text is None:
        if default is None:
            raise ConfigError(f"{path}: {where} has no {name} (urdfdom requires it)")
        return default
    value = float_attr(element, name, path)
    if not math.isfinite(value):
        raise ConfigError(f"{path}: {where} {name}='{text[:40]}' is not a finite number")
    return value


def _check_axis(element: ET.Element, name: str, path: Path) -> None:
    """Raise ConfigError unless a movable joint's `<axis xyz>` is three finite numbers, not all zero."""
    axis = element.find("axis")
    text = axis.get("xyz", "1 0 0") if axis is not None else "1 0 0"
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ConfigError(f"{path}: joint '{name}' <axis xyz='{text[:60]}'>: expected three finite numbers")
    if not any(values):
        # Normalised by the kinematics, a zero axis turns every pose below the joint into NaN.
        raise ConfigError(f"{path}: joint '{name}' <axis xyz='{text}'> has zero length; give the axis it turns about")


def _check_mimics(joints: dict[str, UrdfJoint], path: Path) -> None:
    """Raise ConfigError for a mimic joint whose leader is missing, itself, or part of a loop of mimics."""
    for joint in joints.values():
        if not joint.mimic:
            continue
        if joint.mimic not in joints:
            raise ConfigError(f"{path}: joint '{joint.name}' mimics joint '{joint.mimic}', which is not defined")
        chain = [joint.name]
        while joints[chain[-1]].mimic:
            chain.append(joints[chain[-1]].mimic)
            if chain[-1] in chain[:-1]:
                loop = " -> ".join(chain[chain.index(chain[-1]):])
                raise ConfigError(f"{path}: mimic joints follow each other in a loop ({loop}); "
                                  "a mimic joint follows a joint that moves on its own")
            if chain[-1] not in joints:
                break


def _check_tree(joints: dict[str, UrdfJoint], path: Path, links: list[str]) -> None:
    """Raise ConfigError unless the joints make one tree: one parent joint per link, no cycle, one root."""
    parent_joint: dict[str, UrdfJoint] = {}
    for joint in joints.values():
        if joint.child in parent_joint:
            raise ConfigError(f"{path}: link '{joint.child}' is the child of two joints, "
                              f"'{parent_joint[joint.child].name}' and '{joint.name}'; a URDF is a tree")
        parent_joint[joint.child] = joint
    done: set[str] = set()
    for start in parent_joint:
        seen: list[str] = []
        link = start
        while link in parent_joint and link not in done:
            if link in seen:
                loop = " -> ".join([*seen[seen.index(link):], link])
                raise ConfigError(f"{path}: link '{link}' is its own ancestor ({loop}); a URDF is a tree")
            seen.append(link)
            link = parent_joint[link].parent
        done.update(seen)
    roots = [link for link in links if link not in parent_joint]
    if len(roots) > 1:
        shown = ", ".join(roots[:5]) + (f", ... ({len(roots) - 5} more)" if len(roots) > 5 else "")
        raise ConfigError(f"{path}: {len(roots)} root links ({shown}); a URDF is one tree: attach each "
                          "to the others with a joint")


def resolve_collision_meshes(
    urdf: str, urdf_path: Path, package_paths: Sequence[Path]
) -> tuple[str, tuple[CollisionMesh, ...]]:
    """Return the URDF with collision mesh files resolved to absolute paths, and the meshes.

    Raises:
        ConfigError: A mesh whose package cannot be found or whose file does not exist;
            names the URDF, the link, the URI, the package and the search path.
    """
    root = xml_root(urdf, urdf_path)
    packages = PackagePath(tuple(package_paths))
    meshes = []
    for link in root.findall("link"):
        for mesh in link.findall("collision/geometry/mesh"):
            uri = mesh.get("filename", "")
            if not uri:
                raise ConfigError(f"{urdf_path}: link '{link.get('name', '')}': collision <mesh> has no filename")
            where = f"{urdf_path}: link '{link.get('name', '')}': collision mesh {uri}"
            path, package = packages.resolve_uri(uri, urdf_path.parent, where)
            if not path.is_file():
                inside = f" (package '{package}' is {packages.find(package, where)})" if package else ""
                raise ConfigError(f"{where}: file not found: {path}{inside}; search path: {packages.describe()}")
            mesh.set("filename", str(path.resolve()))
            meshes.append(CollisionMesh(link.get("name", ""), uri, path, package))
    return ET.tostring(root, encoding="unicode"), tuple(meshes)
