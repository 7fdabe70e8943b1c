"""ROS packages on disk: a package.xml's name, the packages below a folder, the colcon workspace around a config.

Packages are found as colcon finds them in a workspace's src/ folder: every folder holding a
package.xml is a package, and its subfolders are its own (not searched further); hidden
folders, build/, install/, log/ and folders marked COLCON_IGNORE, AMENT_IGNORE or
CATKIN_IGNORE are skipped. The walk is bounded (MAX_DEPTH levels, MAX_FOLDERS folders) and
done once per folder and process.
"""

from __future__ import annotations

import functools
import logging
import xml.etree.ElementTree as ET
from pathlib import Path
from types import MappingProxyType

__all__ = ["MAX_DEPTH", "MAX_FOLDERS", "package_name", "packages_under", "workspace_src"]

_log = logging.getLogger(__name__)

MAX_DEPTH = 8
"""Levels below a search folder where packages are looked for (ros2_kortex nests them three deep)."""

MAX_FOLDERS = 5_000
"""Folders one search folder's walk may read: a search folder that is a home directory must not stall a run."""

_SKIPPED = frozenset({"build", "install", "log"})
_IGNORE_MARKERS = ("COLCON_IGNORE", "CATKIN_IGNORE", "AMENT_IGNORE")


def package_name(folder: Path) -> str | None:
    """Return the name a folder's package.xml gives, or None (no or unreadable package.xml)."""
    manifest = folder / "package.xml"
    if not manifest.is_file():
        return None
    try:
        name = ET.parse(manifest).getroot().findtext("name")
    except (ET.ParseError, OSError):
        return None
    return name.strip() if name else None


def workspace_src(folder: Path) -> Path | None:
    """Return the nearest ancestor of `folder` named `src` (a colcon workspace's source folder), or None."""
    for parent in folder.resolve().parents:
        if parent.name == "src":
            return parent
    return None


@functools.lru_cache(maxsize=128)
def packages_under(folder: Path) -> MappingProxyType[str, Path]:
    """Return package name -> folder for every package below `folder` (the first of a name, in sorted order)."""
    found: dict[str, Path] = {}
    budget = [MAX_FOLDERS]
    for package in _walk(folder, MAX_DEPTH, budget):
        name = package_name(package)
        if name is not None:
            found.setdefault(name, package)
    if budget[0] <= 0:
        _log.warning("%s: stopped looking for packages after %d folders", folder, MAX_FOLDERS)
    return MappingProxyType(found)


def _walk(folder: Path, depth: int, budget: list[int]) -> list[Path]:
    """Return the package folders below `folder`, depth first in sorted order, within `depth` levels and `budget`."""
    if depth == 0 or budget[0] <= 0:
        return []
    budget[0] -= 1
    try:
        children = sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith("."))
    except OSError:
        return []
    packages: list[Path] = []
    for child in children:
        if child.name in _SKIPPED or any((child / marker).exists() for marker in _IGNORE_MARKERS):
            continue
        if (child / "package.xml").is_file():
            packages.append(child)  # a package: its subfolders are its own, not other packages
        else:
            packages.extend(_walk(child, depth - 1, budget))
    return packages
