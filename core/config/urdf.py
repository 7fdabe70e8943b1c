"""What moveplan reads of a URDF: its joints with their limits, and its collision meshes' files."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError
from .xacro import PackagePath

__all__ = [
    "MOVABLE_JOINT_TYPES", "CollisionMesh", "UrdfJoint", "float_attr", "parse_urdf", "resolve_collision_meshes",
    "xml_root",
]

MOVABLE_JOINT_TYPES = ("revolute", "continuous", "prismatic")


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


def parse_urdf(text: str, path: Path) -> dict[str, UrdfJoint]:
    """Return the URDF's joints by name, in file order; every link they name must be defined."""
    root = xml_root(text, path)
    if root.tag != "robot":
        raise ConfigError(f"{path}: not a URDF (root element is <{root.tag}>, expected <robot>)")
    links = {link.get("name", "") for link in root.findall("link")}
    joints: dict[str, UrdfJoint] = {}
    for element in root.findall("joint"):
        name = element.get("name", "")
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise ConfigError(f"{path}: joint '{name}' needs <parent> and <child>")
        for link in (parent.get("link", ""), child.get("link", "")):
            if link not in links:
                raise ConfigError(f"{path}: joint '{name}' names link '{link}', which is not defined")
        limit = element.find("limit")
        lower = upper = velocity = math.nan
        if limit is not None:
            lower = float_attr(limit, "lower", path, 0.0)
            upper = float_attr(limit, "upper", path, 0.0)
            velocity = float_attr(limit, "velocity", path)
        mimic = element.find("mimic")
        leader, multiplier, offset = "", 1.0, 0.0
        if mimic is not None:
            leader = mimic.get("joint", "")
            multiplier, offset = float_attr(mimic, "multiplier", path, 1.0), float_attr(mimic, "offset", path, 0.0)
        joints[name] = UrdfJoint(
            name, element.get("type", ""), parent.get("link", ""), child.get("link", ""),
            lower, upper, velocity, leader, multiplier, offset,
        )
    for joint in joints.values():
        if joint.mimic and joint.mimic not in joints:
            raise ConfigError(f"{path}: joint '{joint.name}' mimics joint '{joint.mimic}', which is not defined")
    _check_tree(joints, path)
    return joints


def _check_tree(joints: dict[str, UrdfJoint], path: Path) -> None:
    """Raise ConfigError unless the joints make a tree: one parent joint per link, no link its own ancestor."""
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
            where = f"{urdf_path}: link '{link.get('name', '')}': collision mesh {uri}"
            path, package = packages.resolve_uri(uri, urdf_path.parent, where)
            if not path.is_file():
                inside = f" (package '{package}' is {packages.find(package, where)})" if package else ""
                raise ConfigError(f"{where}: file not found: {path}{inside}; search path: {packages.describe()}")
            mesh.set("filename", str(path.resolve()))
            meshes.append(CollisionMesh(link.get("name", ""), uri, path, package))
    return ET.tostring(root, encoding="unicode"), tuple(meshes)
