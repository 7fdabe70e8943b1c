"""The robot description texts: a URDF or SRDF read as it is, or expanded by xacro with its args."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ConfigError, UsageError, known
from .fields import mapping
from .xacro import PackagePath, process_xacro

__all__ = ["check_xacro_args", "expand", "resolve_xacro_args"]


def resolve_xacro_args(
    manifest: Path | None, top: dict[str, Any], flags: Mapping[str, str]
) -> tuple[dict[str, str], frozenset[str]]:
    """Return the xacro args in force (flag > moveplan.yaml) and the names set by flag."""
    args: dict[str, str] = {}
    for key, value in mapping(top.get("xacro_args"), f"{manifest}: xacro_args").items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        if not isinstance(value, str | int | float):
            raise ConfigError(f"{manifest}: xacro_args.{key}: expected a string or number, got {value!r}")
        args[key] = str(value)
    args.update(flags)
    return args, frozenset(flags)


def expand(
    path: Path, root: Path, args: Mapping[str, str], packages: PackagePath
) -> tuple[str, tuple[Path, ...], frozenset[str]]:
    """Return a URDF or SRDF file's XML text (through xacro for *.xacro), the files it read, its args."""
    if path.name.endswith(".xacro"):
        shown = path.relative_to(root) if path.is_relative_to(root) else Path(path.name)
        result = process_xacro(path, args, packages, str(shown))
        return result.text, (path, *(p for p in result.includes if p != path)), result.declared
    try:
        return path.read_text(encoding="utf-8"), (path,), frozenset()
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None


def check_xacro_args(
    args: Mapping[str, str], flags: frozenset[str], declared: frozenset[str], urdf: Path, manifest: Path | None
) -> None:
    """Raise for a xacro arg no xacro file declares (a typo must not pass silently)."""
    for name in args:
        if name in declared:
            continue
        what = f"xacro arg '{name}' is not declared by {urdf} or the files it includes; declared: {known(declared)}"
        if not urdf.name.endswith(".xacro"):
            what = f"xacro arg '{name}' given, but {urdf} is not a .xacro file"
        if name in flags:
            raise UsageError(f"--xacro-arg {name}: {what}")
        raise ConfigError(f"{manifest}: xacro_args: {what}")
