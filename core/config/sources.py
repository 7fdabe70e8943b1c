"""Where a robot config's files come from: a --robot argument, a moveplan.yaml, a MoveIt config package, a lone file.

- A moveplan.yaml names them (relative to itself, or `package://pkg/...`); a URDF or
  SRDF ending in .xacro is expanded with its `xacro_args`, overridden by --xacro-arg.
- A folder without moveplan.yaml is a MoveIt config package (or a plain folder). Its URDF
  and SRDF are the ones MoveItConfigsBuilder would load (core/config/_setup_assistant.py:
  `config/<robot name>.urdf.xacro`, `.setup_assistant`, `config/<robot name>.srdf`), else
  the one *.srdf(.xacro) in the first of config/, srdf/, the folder that has any, and the one
  URDF in the first of config/, urdf/, robots/, the folder (*.urdf(.xacro); in urdf/ and
  robots/ also *.xacro). Among several candidates, `*_macro*` files and files another
  candidate includes are not robots; of the rest, the one named like the SRDF or the robot
  wins. joint_limits.yaml, kinematics.yaml, ros2_controllers.yaml, moveit_controllers.yaml,
  initial_positions.yaml and ompl_planning.yaml are found by name, in config/ before the folder.
- A lone URDF (*.urdf, *.urdf.xacro, *.xacro) or SRDF (*.srdf, *.srdf.xacro) goes with the
  other file of the pair found beside it: the one of the same name, or the only one, in its
  folder, then ../config and ../srdf (an SRDF) or ../urdf, ../robots and ../config (a URDF).
- --urdf and --srdf (a file, or `package://pkg/path`) replace what any of these supply.
- Ambiguity or absence is an error naming the files and the flag that settles it.
- `$(find pkg)` and `package://pkg` search, in order: the config folder, moveplan.yaml
  `package_paths`, --package-path, the colcon workspace the config lies in (the nearest
  ancestor folder named `src`), ROS_PACKAGE_PATH, AMENT_PREFIX_PATH shares, and
  Python-installed (cmeel) package shares (core/config/xacro.py and workspace.py find them).
"""

from __future__ import annotations

import logging
import os
import re
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import ConfigError, UsageError, known
from ._setup_assistant import SETUP_ASSISTANT_FILE, builder_srdf, builder_urdf, read_setup_assistant, robot_names
from ._workspace import packages_under, workspace_src
from .fields import check_keys, load_yaml, mapping, read_input_text, string_list
from .launch_files import LaunchFiles
from .xacro import PackagePath

__all__ = [
    "CONFIG_FILE", "FILE_KEYS", "Discovered", "discover", "discover_beside", "flag_file", "manifest_files",
    "read_manifest", "resolve_config_path", "robot_file_kind", "search_path", "shipped_config", "shipped_configs",
    "stem",
]

logger = logging.getLogger(__name__)

CONFIG_FILE = "moveplan.yaml"
FILE_KEYS = ("urdf", "srdf", "joint_limits", "kinematics", "controllers", "moveit_controllers", "initial_positions")
_MOVEPLAN_KEYS = {*FILE_KEYS, "name", "planning", "package_paths", "xacro_args", "plant"}
# A folder without moveplan.yaml: a MoveIt config package keeps these in config/, a plain folder
# beside the URDF; config/ is searched first.
_PACKAGE_FILES = {
    "joint_limits": "joint_limits.yaml",
    "kinematics": "kinematics.yaml",
    "controllers": "ros2_controllers.yaml",
    "moveit_controllers": "moveit_controllers.yaml",
    "initial_positions": "initial_positions.yaml",
    "ompl_planning": "ompl_planning.yaml",
    "fake_controllers": "fake_controllers.yaml",  # MoveIt 1: where its fake controllers start the robot
}
_SRDF_FOLDERS = ("config", "srdf", ".")
_URDF_FOLDERS = ("config", "urdf", "robots", ".")
_SRDF_SUFFIXES = (".srdf", ".srdf.xacro")
_URDF_SUFFIXES = (".urdf", ".urdf.xacro")
# Description packages keep top-level xacros as robot.xacro in these; elsewhere a bare .xacro is a fragment.
_XACRO_URDF_FOLDERS = ("urdf", "robots")
_FLAGS = {"urdf": "--urdf", "srdf": "--srdf", "joint_limits": "--joint-limits"}
_INCLUDE = re.compile(r"<xacro:include\s[^>]*?filename\s*=\s*[\"']([^\"']+)[\"']")
_ACCEPTED = ("a moveplan.yaml or a folder holding one, a MoveIt config package folder, a URDF (.urdf, "
             ".urdf.xacro, .xacro) or SRDF (.srdf, .srdf.xacro) file")


@dataclass(frozen=True)
class Discovered:
    """A config's files found without a moveplan.yaml.

    Attributes:
        root: The config folder (for a lone file: the package it lies in, else its folder).
        paths: Setting -> file (urdf, srdf, joint_limits, ...).
        xacro_args: Default xacro args from `.setup_assistant` (--xacro-arg overrides them).
        xacro_source: The file they came from, None without any.
    """

    root: Path
    paths: dict[str, Path]
    xacro_args: dict[str, str] = field(default_factory=dict)
    xacro_source: Path | None = None


def resolve_config_path(robot: str | Path, srdf_given: bool = False) -> Path:
    """Return what a --robot argument names: a moveplan.yaml, a URDF or SRDF file, or a folder to read without one.

    A bare name such as `ur10e` names a config shipped with moveplan. A folder holding a
    moveplan.yaml means that file; a folder without one is read as a MoveIt config package
    (or a plain folder holding a URDF and an SRDF) if it holds an SRDF, a .setup_assistant, a
    launch/ folder or a package.xml, or if `srdf_given` (--srdf names the SRDF).
    """
    path = Path(robot)
    shipped = shipped_config(str(robot))
    if not path.exists() and shipped is not None:
        path = shipped
    if path.is_dir():
        if (path / CONFIG_FILE).is_file():
            return path / CONFIG_FILE
        if srdf_given or (path / SETUP_ASSISTANT_FILE).is_file() or (path / "launch").is_dir() or (
                path / "package.xml").is_file() or any(
                _candidates(path / sub, _SRDF_SUFFIXES) for sub in _SRDF_FOLDERS):
            return path
        raise ConfigError(f"{robot}: no robot config: no {CONFIG_FILE}, and no *.srdf in config/, srdf/ "
                          "or the folder itself, and no launch/ folder or package.xml (a MoveIt config package); "
                          "pass --srdf FILE to name one")
    if not path.is_file():
        raise ConfigError(f"{robot}: robot config not found (expected {_ACCEPTED}, or a shipped config: "
                          f"{known(shipped_configs())})")
    if robot_file_kind(path) is None:
        raise ConfigError(f"{robot}: not a robot config; expected {_ACCEPTED}, or a shipped config: "
                          f"{known(shipped_configs())}")
    return path


def robot_file_kind(path: Path) -> str | None:
    """Return "moveplan", "urdf" or "srdf" for a file --robot may name, by its name; None for any other file."""
    name = path.name.lower()
    if name.endswith((".yaml", ".yml")):
        return "moveplan"
    if name.endswith(_SRDF_SUFFIXES):
        return "srdf"
    if name.endswith((*_URDF_SUFFIXES, ".xacro")):
        return "urdf"
    return None


def shipped_config(name: str) -> Path | None:
    """Return the folder of the config shipped with moveplan under the bare name `name`, None if there is none."""
    if not name or Path(name).name != name:
        return None
    folder = Path(str(resources.files("moveplan.configs"))) / name
    return folder if (folder / CONFIG_FILE).is_file() else None


def shipped_configs() -> list[str]:
    """Return the names of the robot configs shipped with moveplan."""
    folder = Path(str(resources.files("moveplan.configs")))
    return sorted(p.name for p in folder.iterdir() if (p / CONFIG_FILE).is_file())


def search_path(root: Path, package_paths: Sequence[Path] = (), extra: Sequence[Path] = ()) -> tuple[Path, ...]:
    """Return the folders searched for ROS packages, in order (first match wins).

    The config folder, moveplan.yaml's `package_paths` (`extra`), --package-path, the
    colcon workspace the config folder lies in (its nearest ancestor named `src`), then
    ROS_PACKAGE_PATH, then the `share` folder of each AMENT_PREFIX_PATH entry (a sourced
    ROS 2 workspace), then the share folders of Python-installed (cmeel) packages such as
    example-robot-data.
    """
    workspace = workspace_src(root)
    env = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    ament = [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    cmeel = [Path(p) / "cmeel.prefix" / "share" for p in sys.path if p]
    cmeel = [p for p in cmeel if p.is_dir()]
    found = (root, *extra, *package_paths, *([workspace] if workspace else []), *env, *ament, *cmeel)
    return tuple(dict.fromkeys(found))


def read_manifest(manifest: Path) -> tuple[dict[str, Any], tuple[Path, ...]]:
    """Return a moveplan.yaml's checked content and its `package_paths`, relative to its folder."""
    top = mapping(load_yaml(manifest), str(manifest))
    check_keys(top, _MOVEPLAN_KEYS, str(manifest))
    folders = string_list(top.get("package_paths"), f"{manifest}: package_paths", "folder names")
    return top, tuple(manifest.parent / p for p in folders)


def manifest_files(
    manifest: Path, top: dict[str, Any], packages: PackagePath, given: Mapping[str, Path] | None = None
) -> dict[str, Path]:
    """Return setting -> file for the files moveplan.yaml names (relative to it, or package://); `given` wins."""
    root = manifest.parent
    paths: dict[str, Path] = dict(given or {})
    for key in FILE_KEYS:
        if key in paths:
            continue
        if key not in top:
            if key in ("urdf", "srdf"):
                raise ConfigError(f"{manifest}: missing key '{key}' (or pass {_FLAGS[key]} FILE)")
            continue
        value = top[key]
        if not isinstance(value, str):
            raise ConfigError(f"{manifest}: {key}: expected a file name, got {value!r}")
        file = packages.resolve_uri(value, root, f"{manifest}: {key}")[0] if "://" in value else root / value
        if not file.is_file():
            raise ConfigError(f"{manifest}: {key}: file not found: {file}")
        paths[key] = file
    return paths


def flag_file(value: str, key: str, packages: PackagePath) -> Path:
    """Return the file --urdf, --srdf or --joint-limits (`key`) names: a path, or a `package://` or `file://` URI."""
    flag = _FLAGS[key]
    other = "srdf" if key == "urdf" else "urdf"
    if key in ("urdf", "srdf") and robot_file_kind(Path(value)) == other:
        article = "an SRDF" if other == "srdf" else "a URDF"
        raise UsageError(f"{flag} {value}: {article} file; pass it with {_FLAGS[other]}")
    path = packages.resolve_uri(value, Path.cwd(), f"{flag} {value}")[0] if "://" in value else Path(value)
    if not path.is_file():
        where = f" ({path})" if str(path) != value else ""
        raise ConfigError(f"{flag} {value}: file not found{where}")
    return path


def discover(
    root: Path, packages: PackagePath, given: Mapping[str, Path], launch: LaunchFiles | None = None
) -> Discovered:
    """Return the files of a folder without moveplan.yaml (see the module's rules); `given` (flags) wins.

    `launch` is what the package's launch files name (core/config/launch_files.py): after the
    flags, before the rules by name.
    """
    launched = launch or LaunchFiles()
    names = robot_names(root)
    assistant = read_setup_assistant(root)
    if "urdf" not in given:
        _check_required(root, launched)
    srdf = (given.get("srdf") or (launched.srdf.path if launched.srdf else None)
            or builder_srdf(root, names, assistant) or _pick([root / sub for sub in _SRDF_FOLDERS], "srdf", names)
            or _below(root, launched))
    if srdf is None:
        raise ConfigError(_absent(root, "srdf", _where(_SRDF_FOLDERS), launched))
    names = tuple(dict.fromkeys((*names, stem(srdf))))
    urdf = given.get("urdf") or (launched.urdf.path if launched.urdf else None)
    from_assistant = urdf is None and builder_urdf(root, names, assistant, packages) is not None
    urdf = (urdf or builder_urdf(root, names, assistant, packages)
            or _pick([root / sub for sub in _URDF_FOLDERS], "urdf", (stem(srdf), *names))
            or _robot_urdf(root, srdf, names, packages))
    if urdf is None:
        raise ConfigError(_absent(root, "urdf", _where(_URDF_FOLDERS) + f", and no {SETUP_ASSISTANT_FILE} naming one",
                                  launched))
    paths = {"srdf": srdf, "urdf": urdf, **_settings((root / "config", root)), **launched.files}
    if not from_assistant or assistant is None or not assistant.xacro_args:
        return Discovered(root, paths)
    return Discovered(root, paths, dict(assistant.xacro_args), assistant.path)


def _check_required(root: Path, launched: LaunchFiles) -> None:
    """Raise for a launch argument without default or value that picks the hardware: ros2 launch asks for it too.

    It picks the hardware when it has choices or a file's name waits for it.
    """
    missing = {name: choices for name, choices in launched.required.items() if name not in launched.given}
    if not missing:
        return
    name, choices = next(iter(missing.items()))
    listed = f"; choices: {', '.join(choices)}" if choices else ""
    below = _below_candidates(root)
    srdfs = f"; SRDFs in the package: {', '.join(stem(p) for p in below)}" if below else ""
    launch = ", ".join(p.name for p in launched.launch)
    raise ConfigError(f"{root}: launch argument '{name}' has no value ({launch}: declared without a default"
                      f"{listed}){srdfs}; pass --launch-arg {name}:=VALUE")


def _below(root: Path, launched: LaunchFiles) -> Path | None:
    """Return the SRDF one folder down (config/srdf/) that is the only one, or the one a launch argument names."""
    found = _below_candidates(root)
    if len(found) == 1:
        return found[0]
    named = [p for p in found if stem(p) in launched.given.values()]
    return named[0] if len(named) == 1 else None


def _below_candidates(root: Path) -> list[Path]:
    """Return the SRDFs in the subfolders of config/ and srdf/ (a family's package keeps one per robot there)."""
    found: list[Path] = []
    for sub in ("config", "srdf"):
        if (root / sub).is_dir():
            for folder in sorted(p for p in (root / sub).iterdir() if p.is_dir()):
                found.extend(_files(folder, "srdf"))
    return found


def _robot_urdf(root: Path, srdf: Path, names: Sequence[str], packages: PackagePath) -> Path | None:
    """Return the URDF of the SRDF's robot in a package of the search path (see _robot_files).

    MoveIt packages whose launch files take the URDF from the robot's driver (robot_description
    on a topic) do not name it; the description package of the workspace holds it.
    """
    wanted = dict.fromkeys((*_srdf_robot_names(srdf), stem(srdf), *names))
    hits: list[Path] = []
    for folder in packages.folders:
        if not folder.is_dir() or folder == root:
            continue
        for package in dict.fromkeys((*(([folder]) if (folder / "package.xml").is_file() else []),
                                      *packages_under(folder).values())):
            for name in wanted:
                hits.extend(candidate for candidate in _robot_files(package, name) if candidate.is_file())
        if hits:
            break
    hits = list(dict.fromkeys(hits))
    if len(hits) > 1:
        raise ConfigError(f"{root}: names no URDF, and the workspace holds several of its robot: "
                          f"{', '.join(map(str, hits))}; pass --urdf FILE")
    if hits:
        logger.warning("%s: no launch file or config names the URDF; using %s, the robot's in the workspace "
                       "(pass --urdf FILE for another)", root, hits[0])
    return hits[0] if hits else None


def _robot_files(package: Path, name: str) -> list[Path]:
    """Return where a description package keeps robot `name`'s URDF: urdf/, robots/ or xacro/, or a folder of its name.

    ROBOTIS keeps `urdf/<robot>/<robot>.urdf.xacro`, TM and Doosan `xacro/<robot>.urdf.xacro`.
    """
    folders = [package / sub for sub in _ROBOT_FOLDERS] + [package / sub / name for sub in _ROBOT_FOLDERS]
    return [folder / f"{name}{suffix}" for folder in folders for suffix in (".urdf.xacro", ".urdf")]


_ROBOT_FOLDERS = ("urdf", "robots", "xacro")
_ROBOT_NAME = re.compile(r"<robot\b[^>]*?\bname\s*=\s*[\"']([A-Za-z0-9_.-]+)[\"']")


def _srdf_robot_names(srdf: Path) -> tuple[str, ...]:
    """Return the robot name an SRDF's <robot name=...> gives, when it is written out (not a xacro arg)."""
    try:
        match = _ROBOT_NAME.search(read_input_text(srdf)[:4096])
    except ConfigError:
        return ()
    return (match.group(1),) if match else ()


def _absent(root: Path, kind: str, where: str, launched: LaunchFiles) -> str:
    """Return the error for a config without a URDF or SRDF: where moveplan looked, what the launch files wait for."""
    flag = _FLAGS[kind]
    example = "package://pkg/urdf/robot.urdf.xacro" if kind == "urdf" else "package://pkg/config/robot.srdf"
    below = _below_candidates(root) if kind == "srdf" else []
    several = f"; one folder down: {', '.join(str(p.relative_to(root)) for p in below)}" if below else ""
    waits = (f"; its launch files read launch arguments without a value: {', '.join(launched.needs)} "
             "(pass --launch-arg NAME:=VALUE)") if launched.needs else ""
    return (f"{root}: no {kind.upper()} file ({where}){several}{waits}; pass {flag} FILE or {flag} {example}, "
            f"or write a {CONFIG_FILE} that names it")


def discover_beside(file: Path, given: Mapping[str, Path]) -> Discovered:
    """Return the files of a lone URDF or SRDF: the other one of the pair found beside it, or `given`."""
    folder = file.parent
    kind = "srdf" if robot_file_kind(file) == "srdf" else "urdf"
    paths = {kind: given.get(kind, file)}
    other = "urdf" if kind == "srdf" else "srdf"
    subs = ("../urdf", "../robots", "../config") if other == "urdf" else ("../config", "../srdf")
    folders = [folder, *(folder.parent / sub.removeprefix("../") for sub in subs)]
    found = given.get(other) or _pick(folders, other, (stem(file),))
    if found is None:
        flag = _FLAGS[other]
        raise ConfigError(f"{file}: no {other.upper()} beside it (of the same name or the only one, in {folder}, "
                          f"{', '.join(subs)}); pass {flag} FILE, or write a {CONFIG_FILE} that names it")
    paths[other] = found
    root = next((p for p in (folder, folder.parent, folder.parent.parent) if (p / "package.xml").is_file()), folder)
    paths.update(_settings((paths["srdf"].parent, root / "config", root)))
    return Discovered(root, paths)


def stem(path: Path) -> str:
    """Return a robot file's name without .xacro and its format suffix: panda.urdf.xacro -> panda."""
    name = path.name.removesuffix(".xacro")
    return name.rsplit(".", 1)[0]


def _settings(folders: Sequence[Path]) -> dict[str, Path]:
    """Return setting -> file for joint_limits.yaml and the others, from the first of `folders` holding each."""
    found: dict[str, Path] = {}
    for setting, name in _PACKAGE_FILES.items():
        for folder in dict.fromkeys(folders):
            if (folder / name).is_file():
                found[setting] = folder / name
                break
    return found


def _where(subs: Sequence[str]) -> str:
    return "in " + ", ".join(f"{s}/" for s in subs if s != ".") + " or the folder itself"


def _candidates(folder: Path, suffixes: tuple[str, ...]) -> list[Path]:
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.is_file() and p.name.endswith(suffixes))


def _files(folder: Path, kind: str) -> list[Path]:
    """Return the files in `folder` that may be a `kind` (urdf, srdf) by their names."""
    if kind == "srdf":
        return _candidates(folder, _SRDF_SUFFIXES)
    suffixes = (*_URDF_SUFFIXES, ".xacro") if folder.name in _XACRO_URDF_FOLDERS else _URDF_SUFFIXES
    return [p for p in _candidates(folder, suffixes) if not p.name.endswith(_SRDF_SUFFIXES)]


def _pick(folders: Sequence[Path], kind: str, prefer: Sequence[str]) -> Path | None:
    """Return the one `kind` file in the first of `folders` that has any (see _narrow), None if none has any.

    Raises:
        ConfigError: Several candidates in that folder; names them and the flag that settles it.
    """
    flag = _FLAGS[kind]
    for folder in folders:
        found = _files(folder, kind)
        if not found:
            continue
        chosen = _narrow(found, prefer)
        if len(chosen) == 1:
            return chosen[0]
        raise ConfigError(f"{folder}: several {kind.upper()} files ({', '.join(p.name for p in chosen)}); "
                          f"write a {CONFIG_FILE} that names one, or pass {flag} FILE")
    return None


def _narrow(found: list[Path], prefer: Sequence[str]) -> list[Path]:
    """Return the candidates that are robots: not `*_macro*`, not included by another; named like `prefer` if any is."""
    kept = [p for p in found if "_macro" not in p.name] or found
    included = {name for p in kept for name in _included(p)}
    kept = [p for p in kept if p.name not in included] or kept
    if len(kept) > 1:
        for name in prefer:
            named = [p for p in kept if stem(p) == name]
            if named:
                return named
    return kept


def _included(path: Path) -> set[str]:
    """Return the file names a xacro file includes (`xacro:include filename=...`)."""
    if not path.name.endswith(".xacro"):
        return set()
    try:
        text = read_input_text(path)
    except ConfigError:
        return set()
    return {Path(name).name for name in _INCLUDE.findall(text)}
