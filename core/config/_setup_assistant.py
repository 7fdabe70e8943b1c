"""The URDF and SRDF a MoveIt config package names, as moveit_configs_utils' MoveItConfigsBuilder finds them.

The builder is given a robot name and the package `<robot name>_moveit_config`; moveplan
takes the robot name from the package: its package.xml name, then its folder name, each
without `_moveit_config`. The SRDF is the one `.setup_assistant` names, else
`config/<robot name>.srdf`. The URDF is `config/<robot name>.urdf.xacro` where that exists
(the Setup Assistant's copy with ros2_control tags; the SRDF's name counts as a robot name
too, as the Setup Assistant names both files after the robot), else the one
`.setup_assistant` names.

`.setup_assistant` is read as the builder reads it: under `moveit_setup_assistant_config`,
the `urdf` (or `URDF`) entry names a package, a `relative_path` in it and `xacro_args`, one
string of `name:=value` words (YAML may fold it over several lines); the `srdf` (or `SRDF`)
entry a `relative_path` in the config package. Every other entry (author, control_xacro,
...) is the Setup Assistant's own. A file it names that does not exist is looked for with
`.xacro` appended (packages that turned their SRDF into xacro keep the old name there), then
left to moveplan's own search, with a warning.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._workspace import package_name
from .fields import load_yaml, mapping
from .xacro import PackagePath

__all__ = [
    "SETUP_ASSISTANT_FILE", "SetupAssistant", "builder_srdf", "builder_urdf", "read_setup_assistant", "robot_names",
]

_log = logging.getLogger(__name__)

SETUP_ASSISTANT_FILE = ".setup_assistant"
_TOP = "moveit_setup_assistant_config"


@dataclass(frozen=True)
class SetupAssistant:
    """What a `.setup_assistant` file says; None where it says nothing.

    Attributes:
        path: The `.setup_assistant` file.
        urdf_package: Package the URDF lies in.
        urdf_path: The URDF's path inside `urdf_package`.
        xacro_args: xacro args the URDF was expanded with (name -> value).
        srdf_path: The SRDF's path inside the config package.
    """

    path: Path
    urdf_package: str | None = None
    urdf_path: str | None = None
    xacro_args: dict[str, str] = field(default_factory=dict)
    srdf_path: str | None = None


def read_setup_assistant(folder: Path) -> SetupAssistant | None:
    """Return what `folder`'s .setup_assistant says, or None if it has none."""
    path = folder / SETUP_ASSISTANT_FILE
    if not path.is_file():
        if path.is_symlink() or path.exists():
            raise ConfigError(f"{path}: not a readable file (a folder, or a link to nothing); "
                              "remove it or make it the Setup Assistant's YAML")
        return None
    top = mapping(load_yaml(path), str(path))
    config = mapping(top.get(_TOP), f"{path}: {_TOP}")
    urdf = _entry(config, "urdf", path)
    srdf = _entry(config, "srdf", path)
    return SetupAssistant(
        path=path,
        urdf_package=_text(urdf, "package", path, "urdf"),
        urdf_path=_relative(_text(urdf, "relative_path", path, "urdf"), path, "urdf"),
        xacro_args=_xacro_args(urdf.get("xacro_args"), path),
        srdf_path=_relative(_text(srdf, "relative_path", path, "srdf"), path, "srdf"),
    )


def _relative(value: str | None, path: Path, where: str) -> str | None:
    """Return a `relative_path` that stays inside its package: not absolute, no `..`, no NUL."""
    if value is None:
        return None
    if Path(value).is_absolute() or ".." in Path(value).parts or "\0" in value or len(value) > 4096:
        shown = value if len(value) <= 80 else value[:77] + "..."
        raise ConfigError(f"{path}: {_TOP}.{where}.relative_path: '{shown}' leaves the package; the Setup "
                          "Assistant writes a path inside it, such as config/robot.srdf")
    return value


def _entry(config: dict[str, Any], key: str, path: Path) -> dict[str, Any]:
    """Return the `urdf` or `srdf` entry (either case, as MoveItConfigsBuilder accepts), {} if absent."""
    name = key if key in config else key.upper()
    return mapping(config.get(name), f"{path}: {_TOP}.{name}")


def _text(entry: dict[str, Any], key: str, path: Path, where: str) -> str | None:
    value = entry.get(key)
    if value is None or value == "":
        return None
    if not isinstance(value, str):
        raise ConfigError(f"{path}: {_TOP}.{where}.{key}: expected a path, got {value!r}")
    return value


def _xacro_args(value: Any, path: Path) -> dict[str, str]:
    """Return `name:=value` words (one string, split at whitespace as MoveItConfigsBuilder splits it) as a mapping."""
    if value is None:
        return {}
    if not isinstance(value, str):
        raise ConfigError(f"{path}: {_TOP}.urdf.xacro_args: expected a string of name:=value words, got {value!r}")
    args: dict[str, str] = {}
    for word in value.split():
        name, sep, arg = word.partition(":=")
        if not sep or not name:
            raise ConfigError(f"{path}: {_TOP}.urdf.xacro_args: '{word}': expected name:=value")
        args[name] = arg
    return args


def robot_names(root: Path) -> tuple[str, ...]:
    """Return the robot names a package suggests: its package.xml name, then its folder's, without _moveit_config."""
    names = (package_name(root), root.resolve().name)
    return tuple(dict.fromkeys(name.removesuffix("_moveit_config") for name in names if name))


def builder_urdf(
    root: Path, names: tuple[str, ...], assistant: SetupAssistant | None, packages: PackagePath
) -> Path | None:
    """Return the URDF MoveItConfigsBuilder would load: config/<name>.urdf.xacro, else .setup_assistant's; or None."""
    for name in names:
        if (root / "config" / f"{name}.urdf.xacro").is_file():
            return root / "config" / f"{name}.urdf.xacro"
    if assistant is None or not assistant.urdf_package or not assistant.urdf_path:
        return None
    package = packages.find(assistant.urdf_package, f"{assistant.path}: {_TOP}.urdf.package")
    return _existing(package / assistant.urdf_path, assistant, "URDF")


def builder_srdf(root: Path, names: tuple[str, ...], assistant: SetupAssistant | None) -> Path | None:
    """Return the SRDF MoveItConfigsBuilder would load: .setup_assistant's, else config/<name>.srdf; or None."""
    if assistant is not None and assistant.srdf_path:
        found = _existing(root / assistant.srdf_path, assistant, "SRDF")
        if found is not None:
            return found
    return next((root / "config" / f"{n}.srdf" for n in names if (root / "config" / f"{n}.srdf").is_file()), None)


def _existing(path: Path, assistant: SetupAssistant, kind: str) -> Path | None:
    """Return `path`, else `path`.xacro, if it is a file; else None, with a warning naming the .setup_assistant."""
    for candidate in (path, path.with_name(path.name + ".xacro")):
        if candidate.is_file():
            return candidate
    _log.warning("%s names the %s %s, which does not exist; looking for one in the package", assistant.path, kind, path)
    return None
