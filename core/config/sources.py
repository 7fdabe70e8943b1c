"""Where a robot config's files come from: a --robot argument, a moveplan.yaml, or a folder without one.

- A moveplan.yaml names them (relative to itself, or `package://pkg/...`); a URDF or
  SRDF ending in .xacro is expanded with its `xacro_args`, overridden by --xacro-arg.
- A folder without moveplan.yaml is a MoveIt config package (or a plain folder): the
  SRDF is the one *.srdf(.xacro) in the first of config/, srdf/, the folder that has
  any; the URDF the one *.urdf(.xacro) in the first of config/, urdf/, the folder
  (several: the one named like the SRDF); joint_limits.yaml, kinematics.yaml,
  ros2_controllers.yaml, moveit_controllers.yaml, initial_positions.yaml and
  ompl_planning.yaml by name, in config/ before the folder. More than one candidate
  is an error that asks for a moveplan.yaml.
- `$(find pkg)` and `package://pkg` search, in order: the config folder,
  moveplan.yaml `package_paths`, --package-path, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH
  shares, and Python-installed (cmeel) package shares (core/config/xacro.py finds them).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import ConfigError, known
from .fields import check_keys, load_yaml, mapping, string_list
from .xacro import PackagePath

__all__ = [
    "CONFIG_FILE", "FILE_KEYS", "discover", "manifest_files", "read_manifest", "resolve_config_path",
    "search_path", "shipped_configs", "stem",
]

CONFIG_FILE = "moveplan.yaml"
FILE_KEYS = ("urdf", "srdf", "joint_limits", "kinematics", "controllers", "moveit_controllers", "initial_positions")
_MOVEPLAN_KEYS = {*FILE_KEYS, "name", "planning", "package_paths", "xacro_args"}
# A folder without moveplan.yaml: a MoveIt config package keeps these in config/, a plain folder
# beside the URDF; config/ is searched first.
_PACKAGE_FILES = {
    "joint_limits": "joint_limits.yaml",
    "kinematics": "kinematics.yaml",
    "controllers": "ros2_controllers.yaml",
    "moveit_controllers": "moveit_controllers.yaml",
    "initial_positions": "initial_positions.yaml",
    "ompl_planning": "ompl_planning.yaml",
}
_SRDF_FOLDERS = ("config", "srdf", ".")
_URDF_FOLDERS = ("config", "urdf", ".")


def resolve_config_path(robot: str | Path) -> Path:
    """Return what a --robot argument names: a moveplan.yaml, or a folder to read without one.

    A bare name such as `ur10e` names a config shipped with moveplan. A folder holding a
    moveplan.yaml means that file; a folder without one is read as a MoveIt config package
    (or a plain folder holding a URDF and an SRDF) if it holds an SRDF.
    """
    path = Path(robot)
    shipped = Path(str(resources.files("moveplan.configs"))) / str(robot)
    if not path.exists() and path.name == str(robot) and (shipped / CONFIG_FILE).is_file():
        path = shipped
    if path.is_dir():
        if (path / CONFIG_FILE).is_file():
            return path / CONFIG_FILE
        if any(_candidates(path / sub, (".srdf", ".srdf.xacro")) for sub in _SRDF_FOLDERS):
            return path
        raise ConfigError(f"{robot}: no robot config: no {CONFIG_FILE}, and no *.srdf in config/, srdf/ "
                          "or the folder itself (a MoveIt config package)")
    if not path.is_file():
        raise ConfigError(f"{robot}: robot config not found (expected a {CONFIG_FILE}, a folder holding one, "
                          f"a MoveIt config package, or a shipped config: {known(shipped_configs())})")
    return path


def shipped_configs() -> list[str]:
    """Return the names of the robot configs shipped with moveplan."""
    folder = Path(str(resources.files("moveplan.configs")))
    return sorted(p.name for p in folder.iterdir() if (p / CONFIG_FILE).is_file())


def search_path(root: Path, package_paths: Sequence[Path] = (), extra: Sequence[Path] = ()) -> tuple[Path, ...]:
    """Return the folders searched for ROS packages, in order (first match wins).

    The config folder, moveplan.yaml's `package_paths` (`extra`), --package-path, then
    ROS_PACKAGE_PATH, then the `share` folder of each AMENT_PREFIX_PATH entry (a sourced
    ROS 2 workspace), then the share folders of Python-installed (cmeel) packages such as
    example-robot-data.
    """
    env = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    ament = [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    cmeel = [Path(p) / "cmeel.prefix" / "share" for p in sys.path if p]
    cmeel = [p for p in cmeel if p.is_dir()]
    return tuple(dict.fromkeys((root, *extra, *package_paths, *env, *ament, *cmeel)))


def read_manifest(manifest: Path) -> tuple[dict[str, Any], tuple[Path, ...]]:
    """Return a moveplan.yaml's checked content and its `package_paths`, relative to its folder."""
    top = mapping(load_yaml(manifest), str(manifest))
    check_keys(top, _MOVEPLAN_KEYS, str(manifest))
    folders = string_list(top.get("package_paths"), f"{manifest}: package_paths", "folder names")
    return top, tuple(manifest.parent / p for p in folders)


def manifest_files(manifest: Path, top: dict[str, Any], packages: PackagePath) -> dict[str, Path]:
    """Return setting -> file for the files moveplan.yaml names (relative to it, or package://)."""
    root = manifest.parent
    paths: dict[str, Path] = {}
    for key in FILE_KEYS:
        if key not in top:
            if key in ("urdf", "srdf"):
                raise ConfigError(f"{manifest}: missing key '{key}'")
            continue
        value = top[key]
        if not isinstance(value, str):
            raise ConfigError(f"{manifest}: {key}: expected a file name, got {value!r}")
        file = packages.resolve_uri(value, root, f"{manifest}: {key}")[0] if "://" in value else root / value
        if not file.is_file():
            raise ConfigError(f"{manifest}: {key}: file not found: {file}")
        paths[key] = file
    return paths


def discover(root: Path) -> dict[str, Path]:
    """Return setting -> file for a folder without moveplan.yaml (see the module's loading rules)."""
    paths = {"srdf": _one(root, _SRDF_FOLDERS, (".srdf", ".srdf.xacro"), "SRDF")}
    paths["urdf"] = _one(root, _URDF_FOLDERS, (".urdf", ".urdf.xacro"), "URDF", prefer=stem(paths["srdf"]))
    for setting, name in _PACKAGE_FILES.items():
        for sub in ("config", "."):
            if (root / sub / name).is_file():
                paths[setting] = root / sub / name
                break
    return paths


def stem(path: Path) -> str:
    """Return a robot file's name without .xacro and its format suffix: panda.urdf.xacro -> panda."""
    name = path.name.removesuffix(".xacro")
    return name.rsplit(".", 1)[0]


def _candidates(folder: Path, suffixes: tuple[str, ...]) -> list[Path]:
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.is_file() and p.name.endswith(suffixes))


def _one(root: Path, folders: tuple[str, ...], suffixes: tuple[str, str], kind: str, prefer: str = "") -> Path:
    """Return the one `kind` file in the first of `folders` that has any; `prefer` breaks ties by stem."""
    for sub in folders:
        found = _candidates(root / sub, suffixes)
        if len(found) > 1:
            found = [p for p in found if stem(p) == prefer] or found
        if len(found) == 1:
            return found[0]
        if found:
            raise ConfigError(f"{root / sub}: several {kind} files ({', '.join(p.name for p in found)}); "
                              f"write a {CONFIG_FILE} that names one")
    where = ", ".join(f"{s}/" for s in folders if s != ".")
    raise ConfigError(f"{root}: no {kind} file (*{suffixes[0]} or *{suffixes[1]}) in {where} or the folder "
                      f"itself; write a {CONFIG_FILE} that names one (urdf: package://pkg/urdf/robot.urdf.xacro)")
