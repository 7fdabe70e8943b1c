"""The robot description texts: a URDF or SRDF read as it is, or expanded by xacro with its args."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ConfigError, UsageError, known
from .fields import mapping, read_input_text
from .xacro import PackagePath, process_xacro

__all__ = ["check_xacro_args", "expand", "file_xacro_args"]


def file_xacro_args(source: Path, values: Any) -> dict[str, str]:
    """Return a file's `xacro_args` mapping (moveplan.yaml) as name -> text, booleans as xacro writes them."""
    args: dict[str, str] = {}
    for key, value in mapping(values, f"{source}: xacro_args").items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        if not isinstance(value, str | int | float):
            raise ConfigError(f"{source}: xacro_args.{key}: expected a string or number, got {value!r}")
        args[key] = str(value)
    return args


def expand(
    path: Path, root: Path, args: Mapping[str, str], packages: PackagePath
) -> tuple[str, tuple[Path, ...], frozenset[str]]:
    """Return a URDF or SRDF file's XML text (through xacro for *.xacro), the files it read, its args."""
    if path.name.endswith(".xacro"):
        shown = path.relative_to(root) if path.is_relative_to(root) else Path(path.name)
        result = process_xacro(path, args, packages, str(shown))
        return result.text, (path, *(p for p in result.includes if p != path)), result.declared
    return read_input_text(path), (path,), frozenset()


def check_xacro_args(
    args: Mapping[str, str], flags: frozenset[str], declared: frozenset[str], descriptions: tuple[Path, ...],
    source: Path | None,
) -> None:
    """Raise for a xacro arg no xacro file declares or substitutes (a typo must not pass silently).

    `descriptions` are the URDF and SRDF files. An arg set by flag is a UsageError; one from a
    file (`source`: moveplan.yaml or .setup_assistant) a ConfigError naming that file.
    """
    xacros = [str(p) for p in descriptions if p.name.endswith(".xacro")]
    for name in args:
        if name in declared:
            continue
        what = (f"xacro arg '{name}' is not declared or used by {' or '.join(xacros)} (or their includes); "
                f"declared or used: {known(declared)}")
        if not xacros:
            what = f"xacro arg '{name}' given, but {' and '.join(map(str, descriptions))} are not .xacro files"
        if name in flags:
            raise UsageError(f"--xacro-arg {name}: {what}")
        raise ConfigError(f"{source}: xacro_args: {what}")
