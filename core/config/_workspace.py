"""ROS packages on disk: a package.xml's name, the packages below a folder, the colcon workspace around a config.

Packages are found as colcon finds them in a workspace's src/ folder: every folder holding a
package.xml is a package, and its subfolders are its own (not searched further); hidden
folders, build/, install/, log/ and folders marked COLCON_IGNORE, AMENT_IGNORE or
CATKIN_IGNORE are skipped, and folders that cannot be read with a warning. The walk is bounded
(MAX_DEPTH levels, MAX_FOLDERS folders) and done once per folder and process.
"""

from __future__ import annotations

import functools
import logging
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from types import MappingProxyType

__all__ = ["MAX_DEPTH", "MAX_FOLDERS", "duplicate_packages", "package_name", "packages_under", "workspace_src"]

_log = logging.getLogger(__name__)

MAX_DEPTH = 8
"""Levels below a search folder where packages are looked for (ros2_kortex nests them three deep)."""

MAX_FOLDERS = 5_000
"""Folders one search folder's walk may read: a search folder that is a home directory must not stall a run."""

_SKIPPED = frozenset({"build", "install", "log"})
# REP 144 asks for [a-z][a-z0-9_]*; real packages also use capitals, dots and dashes. Bounded, so that a
# name from a package.xml makes a file name (config/<name>.srdf) the system accepts.
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,199}")
_IGNORE_MARKERS = ("COLCON_IGNORE", "CATKIN_IGNORE", "AMENT_IGNORE")


def package_name(folder: Path, warn: bool = False) -> str | None:
    """Return the name a folder's package.xml gives, or None (no, unreadable or malformed package.xml).

    With `warn`, a package.xml that gives no usable name is logged as a warning naming it: colcon
    refuses such a workspace, moveplan only skips the package.
    """
    manifest = folder / "package.xml"
    try:
        if not manifest.is_file():
            return None
        name = (ET.parse(manifest).getroot().findtext("name") or "").strip()
    except (ET.ParseError, OSError) as exc:
        problem = f"cannot be read ({exc})"
    else:
        if _NAME.fullmatch(name):
            return name
        problem = "has no <name>" if not name else f"names the package {name[:40]!r}, not a package name"
    if warn:
        _log.warning("%s %s; its package is skipped", manifest, problem)
    return None


def workspace_src(folder: Path) -> Path | None:
    """Return the workspace folder `folder` lies in, whose packages it may use, or None.

    In a colcon workspace's sources, the nearest ancestor named `src`. In a built but unsourced
    workspace, the install folder: a package installs to `install/<pkg>/share/<pkg>` (or
    `install/share/<pkg>` merged), and colcon writes `local_setup.sh` at the install folder's top.
    """
    for parent in folder.resolve().parents:
        if parent.name == "src":
            return parent
        if parent.name == "share":
            prefix = parent.parent
            for install in (prefix.parent, prefix):  # isolated, then merged
                if (install / "local_setup.sh").is_file():
                    return install
            return None
    return None


def packages_under(folder: Path) -> MappingProxyType[str, Path]:
    """Return package name -> folder for every package below `folder` (the first of a name, in sorted order)."""
    return _packages(folder)[0]


def duplicate_packages(folder: Path) -> MappingProxyType[str, tuple[Path, ...]]:
    """Return package name -> its folders, for the names that more than one package below `folder` gives."""
    return _packages(folder)[1]


@functools.lru_cache(maxsize=128)
def _packages(folder: Path) -> tuple[MappingProxyType[str, Path], MappingProxyType[str, tuple[Path, ...]]]:
    """Return the packages below `folder` by name, and the names given by several (different) folders."""
    found: dict[str, list[Path]] = {}
    budget = [MAX_FOLDERS]
    for package in _walk(folder, MAX_DEPTH, budget):
        name = package_name(package, warn=True)
        folders = found.setdefault(name, []) if name is not None else []
        # A link to a package inside the same tree is that package, not a second one.
        if name is not None and not any(_same(package, other) for other in folders):
            folders.append(package)
    if budget[0] <= 0:
        _log.warning("%s: stopped looking for packages after %d folders", folder, MAX_FOLDERS)
    first = {name: folders[0] for name, folders in found.items()}
    twice = {name: tuple(folders) for name, folders in found.items() if len(folders) > 1}
    return MappingProxyType(first), MappingProxyType(twice)


def _same(one: Path, other: Path) -> bool:
    try:
        return one.samefile(other)
    except OSError:
        return False


def _walk(folder: Path, depth: int, budget: list[int]) -> list[Path]:
    """Return the package folders below `folder`, depth first in sorted order, within `depth` levels and `budget`."""
    if depth == 0 or budget[0] <= 0:
        return []
    budget[0] -= 1
    try:
        children = sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith("."))
    except OSError as exc:
        # Another user's folder in a shared workspace must not stop a run that needs none of its packages.
        _log.warning("%s: cannot be read (%s); packages in it are not looked at", folder, exc.strerror or exc)
        return []
    packages: list[Path] = []
    for child in children:
        if child.name in _SKIPPED:
            continue
        try:
            ignored = any((child / marker).exists() for marker in _IGNORE_MARKERS)
            package = not ignored and (child / "package.xml").is_file()
        except OSError as exc:  # a folder that may be listed but not entered
            _log.warning("%s: cannot be read (%s); packages in it are not looked at", child, exc.strerror or exc)
            continue
        if package:
            packages.append(child)  # a package: its subfolders are its own, not other packages
        elif not ignored:
            packages.extend(_walk(child, depth - 1, budget))
    return packages
