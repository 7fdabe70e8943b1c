"""ROS resources without ROS: finding packages on a package path, and xacro to URDF/SRDF.

A package is found as ROS finds it on ROS_PACKAGE_PATH: in the first folder of the
search path that is the package, holds a folder of that name, or holds (below it, as
colcon finds packages in a workspace: core/config/_workspace.py) a folder whose
package.xml names it. The same lookup resolves `$(find pkg)` in xacro files and
`package://pkg/...` URIs of meshes.

xacro itself resolves `$(find pkg)` through ament_index_python, which needs a sourced
ROS 2 install; here the PyPI `xacro` package runs with that one function replaced by
the lookup above (xacro keeps it in a module global, looked up at each call), and with its
expressions evaluated within the guards and bounds of core/config/_xacro_sandbox.py (no
expression reaches Python's internals).
"""

from __future__ import annotations

import contextlib
import io
import logging
import re
import xml.dom.minidom
import xml.parsers.expat
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import xacro as _xacro  # the PyPI package ships no type hints (pyproject: ignore_missing_imports)
from xacro import substitution_args as _substitution_args

from ..errors import ConfigError, UsageError
from ._workspace import duplicate_packages, package_name, packages_under

__all__ = ["PackagePath", "XacroResult", "parse_xacro_args", "process_xacro"]

_log = logging.getLogger(__name__)

_BANNER_LINES = 4  # the comments xacro.process_file puts before the document


@dataclass(frozen=True)
class PackagePath:
    """An ordered list of folders searched for ROS packages (first match wins).

    Attributes:
        folders: The search path, in order.
    """

    folders: tuple[Path, ...]
    _found: dict[str, Path] = field(default_factory=dict, compare=False, repr=False)

    def describe(self) -> str:
        """Return the search path as one line, for error messages."""
        return ", ".join(str(f) for f in self.folders) or "(empty)"

    def find(self, package: str, source: str) -> Path:
        """Return the folder of `package`; ConfigError names `source`, the package and the search path."""
        if package in self._found:
            return self._found[package]
        for folder in self.folders:
            hit = self._in(folder, package)
            # Only a package found by the walk below `folder` may have a namesake there.
            walked = hit is not None and hit not in (folder, folder / package)
            twice = duplicate_packages(folder).get(package) if walked else None
            if hit is not None and twice and hit in twice:
                # colcon refuses such a workspace ("Duplicate package names not supported").
                raise ConfigError(f"{source}: package '{package}' is defined by {len(twice)} folders in {folder}: "
                                  f"{', '.join(str(t) for t in twice)}; keep one, or mark the others COLCON_IGNORE")
            if hit is not None:
                self._found[package] = hit.resolve()  # absolute: xacro joins relative paths to the including file
                return self._found[package]
        raise ConfigError(
            f"{source}: package '{package}' not found; searched in order: {self.describe()} "
            f"(for a folder named {package} or one whose package.xml names it; "
            "add its parent folder with --package-path or ROS_PACKAGE_PATH)"
        )

    @staticmethod
    def _in(folder: Path, package: str) -> Path | None:
        if not folder.is_dir():
            return None
        if package_name(folder) == package or folder.name == package:
            return folder
        if (folder / package).is_dir():
            installed = folder / package / "share" / package  # a colcon install prefix: the package is in share/
            if not (folder / package / "package.xml").is_file() and (installed / "package.xml").is_file():
                return installed
            return folder / package
        return packages_under(folder).get(package)

    def resolve_uri(self, uri: str, base: Path, source: str) -> tuple[Path, str]:
        """Return the file a URDF resource URI names, and the package it came from ('' if none).

        `package://pkg/rest` resolves through the package lookup, `file://path` and absolute
        paths are taken as they are, and relative paths resolve against `base` (the URDF's
        folder), then each folder of the search path.
        """
        if uri.startswith("package://"):
            package, _, rest = uri[len("package://"):].partition("/")
            return self.find(package, source) / rest, package
        if uri.startswith("file://"):
            path = Path(uri[len("file://"):])
            return (path if path.is_absolute() else base / path), ""
        if "://" in uri:
            raise ConfigError(f"{source}: unsupported resource URI '{uri}' (use package://, file:// or a path)")
        path = Path(uri)
        if path.is_absolute():
            return path, ""
        for folder in (base, *self.folders):
            if _exists(folder / path):
                return folder / path, ""
        return base / path, ""


def _exists(path: Path) -> bool:
    """Return whether `path` exists; a name the system refuses (too long) does not."""
    try:
        return path.exists()
    except OSError:
        return False


@dataclass(frozen=True)
class XacroResult:
    """A processed xacro file.

    Attributes:
        text: The XML document it expands to.
        includes: Every file it read (includes and YAML loaded with xacro.load_yaml), in order.
        declared: Names of the xacro args it and its includes declare (`<xacro:arg>`) or
            substitute (`$(arg name)`, which xacro takes from the args given, declared or not:
            KUKA's SRDF uses `robot_name`, which CMake passes).
    """

    text: str
    includes: tuple[Path, ...]
    declared: frozenset[str]


class _RecordingArgs(dict[str, str]):
    """xacro's arg table; records which names `<xacro:arg>` asks about (declares) or `$(arg)` reads."""

    def __init__(self, values: Mapping[str, str]) -> None:
        super().__init__(values)
        self.declared: set[str] = set()

    def __contains__(self, key: object) -> bool:
        if isinstance(key, str):
            self.declared.add(key)
        return super().__contains__(key)

    def __getitem__(self, key: str) -> str:
        if isinstance(key, str) and super().__contains__(key):
            self.declared.add(key)
        return super().__getitem__(key)


MAX_ARG_LENGTH = 4096
"""Characters of one --xacro-arg value: a name, a prefix, a path or a number is far shorter."""


def parse_xacro_args(items: Sequence[str], flag: str = "--xacro-arg") -> dict[str, str]:
    """Return `name:=value` strings (--xacro-arg or --launch-arg, `flag`, as ros2 launch writes them) as a mapping."""
    args: dict[str, str] = {}
    for item in items:
        shown = item.encode("utf-8", "backslashreplace").decode("utf-8")
        shown = shown if len(shown) <= 80 else f"{shown[:77]}..."
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise UsageError(f"{flag} '{shown}': expected name:=value")
        try:
            item.encode("utf-8")
        except UnicodeEncodeError:  # bytes the shell passed that are no UTF-8 arrive as surrogates
            raise UsageError(f"{flag} '{shown}': not UTF-8 text") from None
        if len(value) > MAX_ARG_LENGTH:
            raise UsageError(f"{flag} '{shown}': {len(value):,} characters; at most {MAX_ARG_LENGTH:,}")
        if name.strip() in args:
            raise UsageError(f"{flag} {name.strip()}: given twice")
        args[name.strip()] = value
    return args


@contextlib.contextmanager
def _find_through(packages: PackagePath) -> Iterator[None]:
    """Make xacro resolve `$(find pkg)` (and `find()` in expressions) on `packages`."""

    def find(package: str) -> str:
        stack = [f for f in (_xacro.filestack or []) if f]
        return str(packages.find(package, f"{stack[-1] if stack else 'xacro'}: $(find {package})"))

    saved = _substitution_args._eval_find, _substitution_args._eval_dict["find"]
    _substitution_args._eval_find = find
    _substitution_args._eval_dict["find"] = find
    try:
        yield
    finally:
        _substitution_args._eval_find, _substitution_args._eval_dict["find"] = saved


def _cause(exc: BaseException) -> BaseException:
    """Return the innermost exception xacro wrapped (it wraps ours in XacroException.exc)."""
    while isinstance(inner := getattr(exc, "exc", None), BaseException):
        exc = inner
    return exc


def process_xacro(path: Path, args: Mapping[str, str], packages: PackagePath, shown_as: str) -> XacroResult:
    """Expand a xacro file with `args`, resolving `$(find pkg)` on `packages`.

    Args:
        path: The .xacro file.
        args: xacro args (name -> value), as `xacro file name:=value` takes them.
        packages: Where `$(find pkg)` looks.
        shown_as: How the output's banner names the file (relative, so output does not depend
            on where the config lies).

    Raises:
        ConfigError: A xacro or XML error (naming the file it happened in and the files that
            included it), a package `$(find)` cannot find, or an expression or a document that
            xacro_sandbox refuses (naming the expression).
    """
    # Imported here: a command that expands no xacro (a plan file's config) does not pay for the guards.
    from ._xacro_expressions import Refused
    from ._xacro_sandbox import sandboxed

    table = _RecordingArgs(args)
    _xacro.all_includes.clear()
    captured = io.StringIO()  # xacro prints warnings to stderr; a library logs them instead
    try:
        with _find_through(packages), sandboxed(), contextlib.redirect_stderr(captured):
            doc = _xacro.process_file(str(path), mappings=table, verbosity=0)
    except ConfigError:
        raise
    except Exception as exc:  # xacro raises bare Exception subclasses of many kinds
        cause = _cause(exc)
        if isinstance(cause, ConfigError):
            raise cause from None
        where = _location(path)
        if isinstance(cause, Refused):
            raise ConfigError(f"{where}: xacro: {cause}") from None
        if isinstance(exc, xml.parsers.expat.ExpatError):
            raise ConfigError(f"{where}: malformed XML: {exc}") from None
        if isinstance(cause, UnicodeDecodeError):
            raise ConfigError(f"{where}: cannot read: not UTF-8 text ({cause.reason} at byte {cause.start})") from None
        if isinstance(cause, OSError) and cause.filename:  # an include or xacro.load_yaml file; xacro says it twice
            raise ConfigError(f"{where}: cannot read {cause.filename}: {cause.strerror or cause}") from None
        message = "; ".join(line.strip() for line in str(exc).splitlines() if line.strip())
        if isinstance(cause, OverflowError):  # its text is errno's: (34, 'Numerical result out of range')
            message = message.replace(str(cause), "a number beyond a float's range", 1)
        if isinstance(cause, RecursionError) or "maximum recursion depth" in message:
            message = "a macro expands itself without end"
        elif len(message) > 300:
            message = message[:297] + "..."
        undefined = re.match(r"Undefined substitution argument (\S+)", message)
        if undefined:  # an arg without default: only the user can say its value, as launch files do
            message += f" (an xacro arg without default: pass --xacro-arg {undefined.group(1)}:=VALUE)"
        raise ConfigError(f"{where}: xacro error: {message or type(exc).__name__}") from None
    finally:
        for line in captured.getvalue().splitlines():
            if line.strip():
                _log.warning("xacro: %s", line.strip())
    _replace_banner(doc, shown_as)
    includes = tuple(dict.fromkeys(Path(p) for p in _xacro.all_includes))
    return XacroResult(doc.toprettyxml(indent="  "), includes, frozenset(table.declared))


def _location(path: Path) -> str:
    """Return where xacro stopped: the file (and its includers), or the macro being expanded."""
    stack: list[str] = [str(f) for f in (_xacro.filestack or []) if f] or [str(path)]
    links = [f" (included from {f})" for f in reversed(stack[:-1])]
    if len(links) > 4:  # an include cycle is 32 files deep: its first links say which files loop
        links = [*links[:3], f" ... {len(links) - 4} more", links[-1]]
    where = stack[-1] + "".join(links)
    macros = [str(m.body.getAttribute("name")) for m in reversed(_xacro.macrostack or [])]  # not popped on failure
    if macros:
        # xacro records where a macro was grabbed, which for a macro defined inside another
        # macro is where that one was expanded; the text that defines it says where it is.
        files = dict.fromkeys([str(path), *(str(f) for f in _xacro.all_includes)])
        defined_in = next((f for f in files if _defines(f, macros[0])), stack[-1])
        distinct = list(dict.fromkeys(macros))  # a recursive macro repeats: name each once
        calls = " <- ".join(repr(name) for name in distinct)
        if len(distinct) < len(macros):
            calls += f" (recursive: {len(macros)} nested expansions)"
        where = f"{defined_in}: in macro {calls}, expanded from {where}"
    return where


def _defines(file: str, macro: str) -> bool:
    try:
        text = Path(file).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    return re.search(rf"<xacro:macro\s[^>]*name\s*=\s*[\"']{re.escape(macro)}[\"']", text) is not None


def _replace_banner(doc: Any, shown_as: str) -> None:
    """Replace xacro's banner (which names the absolute input path) by one naming `shown_as`."""
    for _ in range(_BANNER_LINES):
        if doc.firstChild is None or doc.firstChild.nodeType != xml.dom.minidom.Node.COMMENT_NODE:
            break
        doc.removeChild(doc.firstChild)
    doc.insertBefore(doc.createComment(f" generated by xacro from {shown_as}; do not edit "), doc.firstChild)
