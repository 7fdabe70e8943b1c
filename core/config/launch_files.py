"""The robot a MoveIt package's launch files name: URDF, SRDF, their xacro args, limits and controller files.

Vendors build the robot in launch files. moveplan reads them without running them (Python
ones through core/config/_launch_python.py, XML and YAML ones through _launch_markup.py),
with the launch arguments `--launch-arg NAME:=VALUE` gives and the defaults they declare,
and takes from the nodes they start:
- robot_description and robot_description_semantic: a `xacro FILE name:=value...` command,
  xacro.process_file(FILE, mappings=...), a file's text, or a MoveItConfigsBuilder chain's
  robot_description / robot_description_semantic (file_path relative to its package,
  mappings), with the builder's defaults (core/config/_setup_assistant.py);
- joint limits: the builder's joint_limits, or a YAML loaded under robot_description_planning;
- kinematics, MoveIt's controllers (robot_description_kinematics, trajectory_execution,
  moveit_simple_controller_manager), and ros2_control's: a parameter file of
  ros2_control_node, or a spawner's `-p`/`--param-file`.
A xacro arg whose value waits for a launch argument without a default is left to xacro's
own default; a file that does is left to the package's other rules, and the error that
follows names the argument. A file a package's CMakeLists.txt generates at build time
(`xacro_add_files(... REMAP a:=b OUTPUT name INSTALL DESTINATION dir)`) is read as the xacro
it comes from, with those args, since the workspace is not built.

Without --launch, every launch file of the package's launch/ folder is read; where they name
different URDFs, SRDFs or joint limits, --launch chooses.
"""

from __future__ import annotations

import functools
import glob
import logging
import re
import shlex
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._launch_markup import evaluate_markup_launch
from ._launch_python import evaluate_python_launch
from ._launch_values import Builder, LaunchContext, LaunchRecord, Lazy, Unknown, XacroFile, YamlFile, text
from ._setup_assistant import builder_srdf, builder_urdf, read_setup_assistant
from ._workspace import package_name, packages_under
from .fields import load_yaml, read_input_text
from .xacro import PackagePath, parse_xacro_args

__all__ = ["LaunchFiles", "RobotFile", "launch_arguments", "read_launch"]

logger = logging.getLogger(__name__)

MAX_LAUNCH_FILES = 50
"""Launch files read in a package's launch/ folder (real ones hold up to twenty)."""

MAX_INCLUDE_DEPTH = 8

_SUFFIXES = (".launch.py", ".launch.xml", ".launch.yaml", "_launch.py", ".py", ".xml", ".yaml")
_SETTINGS = ("joint_limits", "kinematics", "controllers", "moveit_controllers")
_CHOSEN = ("urdf", "srdf", "joint_limits")  # launch files that differ on these need --launch


@dataclass(frozen=True)
class RobotFile:
    """A URDF or SRDF a launch file names, and the xacro args it expands it with."""

    path: Path
    args: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class LaunchFiles:
    """What a package's launch files name; None or empty where they name nothing.

    Attributes:
        launch: The launch files read (with --launch: that one).
        urdf, srdf: The robot description files and their xacro args.
        files: joint_limits, kinematics, controllers (ros2_control), moveit_controllers -> file.
        needs: Launch arguments read without a value: those a file waited for first, then the others.
        required: Those of them declared with choices (a hardware choice), -> the choices known.
        given: The launch arguments given (--launch-arg).
        source: The launch file the URDF (else the SRDF) was taken from.
    """

    launch: tuple[Path, ...] = ()
    urdf: RobotFile | None = None
    srdf: RobotFile | None = None
    files: dict[str, Path] = field(default_factory=dict)
    needs: tuple[str, ...] = ()
    required: dict[str, tuple[str, ...]] = field(default_factory=dict)
    given: dict[str, str] = field(default_factory=dict)
    source: Path | None = None


@dataclass
class _Found:
    """What one launch file (with its includes) names, resolved."""

    launch: Path
    urdf: RobotFile | None = None
    srdf: RobotFile | None = None
    files: dict[str, Path] = field(default_factory=dict)
    needs: dict[str, None] = field(default_factory=dict)
    unset: dict[str, int] = field(default_factory=dict)  # urdf, srdf -> xacro args left to xacro's default
    required: dict[str, tuple[str, ...]] = field(default_factory=dict)  # read without value, declared with choices
    undeclared: dict[str, None] = field(default_factory=dict)  # read without value, declared nowhere
    blocking: dict[str, tuple[str, ...]] = field(default_factory=dict)  # a file's name waits for it -> values on disk


def launch_arguments(words: Sequence[str]) -> dict[str, str]:
    """Return --launch-arg NAME:=VALUE words as a mapping, as `ros2 launch` takes them (each name once)."""
    return parse_xacro_args(words, "--launch-arg")


def read_launch(root: Path, packages: PackagePath, given: Mapping[str, str], launch: str | None = None) -> LaunchFiles:
    """Return what the launch files of the package at `root` name (with `launch`: that file only).

    An argument the launch files read but never declare (a helper of a package outside the
    workspace declares it: PAL's get_arm) takes the default the URDF they name gives its xacro
    arg of the same name, with a warning: the SRDF and controllers chosen by it then describe
    the hardware the URDF does.
    """
    files = [_launch_file(launch, root, packages)] if launch else _package_launch_files(root)
    result, undeclared = _read_all(root, packages, dict(given), files, strict=bool(launch))
    if not launch and result.urdf is None and result.srdf is None:
        # Denso and TM keep the MoveIt launch file in a bringup or demo package that names this one.
        elsewhere = _naming_launch_files(root, packages)
        if elsewhere:
            result, undeclared = _read_all(root, packages, dict(given), elsewhere, strict=False)
            if result.source is not None:
                logger.info("%s: its robot comes from %s, a launch file of the workspace that names the package",
                            root, result.source)
    if result.urdf is None or not undeclared:
        return result
    defaults = _xacro_defaults(result.urdf.path)
    taken = {name: defaults[name] for name in undeclared if name in defaults}
    if not taken:
        return result
    logger.warning("%s: launch arguments %s have no value and no declaration moveplan can read; using the defaults "
                   "%s gives its xacro args (pass --launch-arg NAME:=VALUE for others)", root,
                   ", ".join(f"{name}:={value}" for name, value in taken.items()), result.urdf.path.name)
    return _read_all(root, packages, {**given, **taken}, list(result.launch), strict=bool(launch))[0]


def _read_all(root: Path, packages: PackagePath, given: dict[str, str], files: list[Path],
              strict: bool) -> tuple[LaunchFiles, list[str]]:
    """Return what the launch files name, and the arguments they read without declaring or being given them.

    With `strict` (the one file --launch names), a file that cannot be read is an error.
    """
    found = []
    for file in files:
        try:
            found.append(_read_one(file, root, packages, dict(given)))
        except ConfigError as exc:
            if strict:
                raise
            logger.info("%s; not read", exc)  # one unreadable launch file among many must not stop a run
    undeclared = list(dict.fromkeys(name for item in found for name in item.undeclared))
    return _combine(root, found, given), undeclared


_XACRO_ARG = re.compile(r"<xacro:arg\b([^>]*)/?>")
_ATTRIBUTE = re.compile(r"""\b(name|default)\s*=\s*(?:"([^"]*)"|'([^']*)')""")


def _xacro_defaults(path: Path) -> dict[str, str]:
    """Return the plain defaults (no substitution in them) of the xacro args a xacro file declares."""
    try:
        source = read_input_text(path)
    except ConfigError:
        return {}
    defaults: dict[str, str] = {}
    for attributes in _XACRO_ARG.findall(source):
        values = {key: double or single for key, double, single in _ATTRIBUTE.findall(attributes)}
        if "name" in values and "default" in values and "$" not in values["default"]:
            defaults.setdefault(values["name"], values["default"])
    return defaults


def _launch_file(value: str, root: Path, packages: PackagePath) -> Path:
    """Return the file --launch names: a path, a `package://` URI, or a name in the package's launch/ folder."""
    if "://" in value:
        path = packages.resolve_uri(value, Path.cwd(), f"--launch {value}")[0]
    else:
        path = Path(value)
        if not path.is_file() and (root / "launch" / value).is_file():
            path = root / "launch" / value
    if not path.is_file():
        choices = ", ".join(p.name for p in _package_launch_files(root)) or "none"
        raise ConfigError(f"--launch {value}: file not found (launch files of {root}: {choices})")
    return path


def _naming_launch_files(root: Path, packages: PackagePath) -> list[Path]:
    """Return the launch files of the workspace's other packages whose text names the package at `root`."""
    name = package_name(root) or root.name
    quoted = (f"'{name}'", f'"{name}"', f"/{name}/", f"({name})", f"find-pkg-share {name}")
    found: list[Path] = []
    for folder in packages.folders:
        if not folder.is_dir() or folder == root:
            continue
        for package in packages_under(folder).values():
            if package.resolve() == root.resolve():
                continue
            for file in _package_launch_files(package):
                try:
                    text_ = read_input_text(file)
                except ConfigError:
                    continue
                if any(q in text_ for q in quoted):
                    found.append(file)
                if len(found) >= MAX_LAUNCH_FILES:
                    return found
    return found


def _package_launch_files(root: Path) -> list[Path]:
    folder = root / "launch"
    if not folder.is_dir():
        return []
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.name.endswith(_SUFFIXES)
                   and p.name != "__init__.py")
    return files[:MAX_LAUNCH_FILES]


def _read_one(file: Path, root: Path, packages: PackagePath, given: dict[str, str]) -> _Found:
    """Return what one launch file and those it includes name."""
    record = _evaluate(file, given, packages, depth=0, stack=())
    found = _Found(file)
    for item in _walk(record):
        _resolve(item, found, packages)
    for item in _walk(record):
        for name in item.context.missing:
            declared = item.context.declared.get(name)
            found.needs.setdefault(name)
            # Declared without a default, it must be given when it has choices or a file's name waits for it.
            if declared is not None and (declared.choices is not None or name in found.blocking):
                found.required.setdefault(name, declared.choices or found.blocking.get(name, ()))
            if declared is None:
                found.undeclared.setdefault(name)
    return found


def _evaluate(file: Path, given: dict[str, str], packages: PackagePath, depth: int,
              stack: tuple[Path, ...], computed: frozenset[str] = frozenset()) -> LaunchRecord:
    """Return one launch file's record, its includes followed (bounded, without cycles)."""
    context = LaunchContext(given, lambda name: _find(packages, name), computed=computed)

    def include(source: Any, arguments: Any, condition: Any, record: LaunchRecord) -> None:
        if condition is not None and hasattr(condition, "holds") and not condition.holds(record.context):
            return
        path = text(source, record.context)
        if isinstance(path, Unknown) or depth + 1 > MAX_INCLUDE_DEPTH:
            return
        target = Path(path)
        if not target.is_file() or target.resolve() in stack:
            return  # a package not in the workspace, or a launch file including itself
        passed: dict[str, str] = {}
        unknown: set[str] = set()
        pairs = arguments if isinstance(arguments, list | tuple) else list(arguments.items()) \
            if isinstance(arguments, dict) else []
        for pair in pairs:
            if isinstance(pair, tuple) and len(pair) == 2:
                name, value = text(pair[0], record.context), text(pair[1], record.context)
                if isinstance(name, str) and isinstance(value, str):
                    passed[name] = value
                elif isinstance(name, str) and not (isinstance(value, Unknown) and value.needs):
                    unknown.add(name)  # computed by the includer (xArm's yaml.dump(...)): no one can pass it
        try:
            record.included.append(_evaluate(target, passed, packages, depth + 1, (*stack, file.resolve()),
                                             frozenset(unknown)))
        except ConfigError as exc:
            record.notes.append(str(exc))

    if file.name.endswith(".py"):
        return evaluate_python_launch(file, context, lambda module: _find_module(packages, module), include)
    return evaluate_markup_launch(file, context, include)


def _walk(record: LaunchRecord) -> list[LaunchRecord]:
    return [record, *(inner for included in record.included for inner in _walk(included))]


def _find(packages: PackagePath, name: str) -> str | None:
    """Return a package's folder (its share folder, in an unbuilt workspace its source), None if not found."""
    return _found(packages.folders, name)


@functools.lru_cache(maxsize=4096)
def _found(folders: tuple[Path, ...], name: str) -> str | None:
    # A launch file asks for launch, launch_ros, yaml...: not found, every time, without this.
    try:
        return str(PackagePath(folders).find(name, "launch file"))
    except ConfigError:
        return None


def _find_module(packages: PackagePath, module: str) -> Path | None:
    """Return the .py file of a Python module a workspace package installs (pkg/pkg/mod.py), None if none."""
    return _module_file(packages.folders, module)


@functools.lru_cache(maxsize=4096)
def _module_file(folders: tuple[Path, ...], module: str) -> Path | None:
    parts = module.split(".")
    folder = _found(folders, parts[0]) if parts[0] and parts[0].isidentifier() else None
    if folder is None:
        return None
    for base in (Path(folder), Path(folder) / "module", Path(folder) / "src"):
        candidate = base.joinpath(*parts).with_suffix(".py")
        if candidate.is_file():
            return candidate
        if (base.joinpath(*parts) / "__init__.py").is_file():
            return base.joinpath(*parts) / "__init__.py"
    return None


# -- what the nodes are given ---------------------------------------------------------------------

def _resolve(record: LaunchRecord, found: _Found, packages: PackagePath) -> None:
    """Add what a record's builders and nodes name to `found` (the first naming a setting wins)."""
    context = record.context
    for builder in record.builders:
        _builder(builder, context, found, packages)
    for node in record.nodes:
        if node.condition is not None and hasattr(node.condition, "holds") and not node.condition.holds(context):
            continue
        executable = text(node.executable, context)
        control = isinstance(executable, str) and "ros2_control_node" in executable
        for parameter in node.parameters:
            _parameter(parameter, context, found, packages, control)
        _spawner(node.arguments, executable, context, found)
    for parameters in record.loose:  # after the nodes': what a node is given comes first
        _parameter(parameters, context, found, packages, control=False)


def _builder(builder: Builder, context: LaunchContext, found: _Found, packages: PackagePath) -> None:
    """Add a MoveItConfigsBuilder's files, with its defaults for what its chain does not name."""
    robot = text(builder.robot_name, context)
    package = text(builder.package, context) if builder.package is not None else (
        robot + "_moveit_config" if isinstance(robot, str) else robot)
    if isinstance(robot, Unknown) or isinstance(package, Unknown):
        _need(found, robot if isinstance(robot, Unknown) else package, context)  # type: ignore[arg-type]
        return
    folder = _find(packages, package)
    if folder is None:
        return
    root = Path(folder)
    for method, setting in (("robot_description", "urdf"), ("robot_description_semantic", "srdf")):
        if method in builder.calls and builder.calls[method][0] is not None:
            path, mappings = builder.calls[method]
            _description(setting, _under(root, path, context), mappings, context, found, packages)
        elif getattr(found, setting) is None:
            assistant = read_setup_assistant(root)
            chosen = (builder_urdf(root, (robot,), assistant, packages) if setting == "urdf"
                      else builder_srdf(root, (robot,), assistant))
            mappings = builder.calls.get(method, (None, None))[1]
            if chosen is not None:
                # MoveItConfigsBuilder: `mappings or` .setup_assistant's xacro_args, not both.
                args = dict(assistant.xacro_args) if assistant is not None and setting == "urdf" else {}
                _set_description(setting, chosen, _mappings(mappings, context, found) if mappings else args, found)
    for method, setting, default in (("joint_limits", "joint_limits", "config/joint_limits.yaml"),
                                     ("robot_description_kinematics", "kinematics", "config/kinematics.yaml"),
                                     ("trajectory_execution", "moveit_controllers", "config/moveit_controllers.yaml")):
        path = builder.calls.get(method, (None, None))[0]
        file = _under(root, path, context) if path is not None else str(root / default)
        if isinstance(file, str) and Path(file).is_file():
            found.files.setdefault(setting, Path(file))


def _under(root: Path, path: Any, context: LaunchContext) -> str | Unknown:
    """Return a builder's file_path: relative ones are in its package, as pathlib's `/` makes them."""
    resolved = text(path, context)
    return resolved if isinstance(resolved, Unknown) else str(root / resolved)


def _parameter(value: Any, context: LaunchContext, found: _Found, packages: PackagePath, control: bool) -> None:
    """Add what one item of a node's parameters names: a dict of parameters, a builder, or a parameter file."""
    if isinstance(value, Builder):
        _builder(value, context, found, packages)
    elif isinstance(value, dict):
        for key, item in value.items():
            if key in ("robot_description", "robot_description_semantic"):
                _description("urdf" if key == "robot_description" else "srdf", item, None, context, found, packages)
            elif key in _KEYED and isinstance(item, YamlFile) and _holds(Path(item.path), _KEYED[key]):
                found.files.setdefault(_KEYED[key], Path(item.path))
            elif key in _KEYED and isinstance(item, dict) and isinstance(item.get("joint_limits"), YamlFile):
                found.files.setdefault(_KEYED[key], Path(item["joint_limits"].path))
    elif isinstance(value, YamlFile):
        _parameter_file(Path(value.path), found, control)
    else:
        words, holes = _words(value, context)
        if len(words) == 1 and not holes and words[0].endswith((".yaml", ".yml")):
            _parameter_file(Path(words[0]), found, control)
        elif holes and len(words) == 1 and words[0].endswith((".yaml", ".yml")):
            for hole in holes:
                _need(found, hole, context)
            _blocked(words, holes, found)


def _holds(path: Path, setting: str) -> bool:
    """Return False for a file loaded under robot_description_planning that holds no joint limits (Pilz's)."""
    if setting != "joint_limits":
        return True
    try:
        return "joint_limits" in _keys(load_yaml(path))
    except ConfigError:
        return False


_KEYED = {"robot_description_planning": "joint_limits", "robot_description_kinematics": "kinematics",
          "moveit_simple_controller_manager": "moveit_controllers"}


def _parameter_file(path: Path, found: _Found, control: bool) -> None:
    """Add a parameter file, by what reads it: ros2_control_node's is the controllers', move_group's by its keys."""
    if not path.is_file():
        return
    if control:
        found.files.setdefault("controllers", path)
        return
    try:
        top = load_yaml(path)
    except ConfigError:
        return
    keys = _keys(top)
    if "joint_limits" in keys:  # MoveIt's joint_limits.yaml, bare or as move_group's node parameters
        found.files.setdefault("joint_limits", path)
    elif "controller_manager" in keys:
        found.files.setdefault("controllers", path)
    elif "moveit_simple_controller_manager" in keys or "controller_names" in keys:
        found.files.setdefault("moveit_controllers", path)
    elif "robot_description_kinematics" in keys or any(k.startswith("kinematics_solver") for k in keys):
        found.files.setdefault("kinematics", path)


def _keys(value: Any, depth: int = 0) -> set[str]:
    """Return the keys of a parameter file down to four levels (under /**, ros__parameters, a group)."""
    if not isinstance(value, dict) or depth > 3:
        return set()
    keys = {str(k) for k in value}
    for item in value.values():
        keys |= _keys(item, depth + 1)
    return keys


def _spawner(arguments: list[Any], executable: Any, context: LaunchContext, found: _Found) -> None:
    """Add the parameter file a controller spawner is given (`-p FILE`, `--param-file FILE`)."""
    words = [text(word, context) for word in arguments]
    if not (isinstance(executable, str) and "spawner" in executable) and "spawner" not in words:
        return
    for flag, value in zip(words, words[1:], strict=False):
        if flag in ("-p", "--param-file") and isinstance(value, str) and Path(value).is_file():
            found.files.setdefault("controllers", Path(value))


def _description(setting: str, value: Any, mappings: Any, context: LaunchContext, found: _Found,
                 packages: PackagePath) -> None:
    """Add a robot description: a xacro command line, a xacro document, or a file path, with its args."""
    if isinstance(value, XacroFile):
        value, mappings = value.path, value.mappings
    words, holes = _words(value, context)
    path, args = _command(words)
    for hole in holes:
        # A hole in the file's name leaves the file unknown; in an arg's value, xacro's default serves.
        _need(found, hole, context, xacro=path is not None)
    if path is None:
        _blocked(words, holes, found)
    if path is None or getattr(found, setting) is not None:
        return
    found.unset[setting] = len(holes)
    args.update(_mappings(mappings, context, found))
    file = Path(path)
    if not file.is_file():
        generated = _generated(file, packages)
        if generated is None:
            logger.warning("%s: the launch file names %s, which does not exist; looking for one in the package",
                           found.launch, file)
            return
        file, made = generated
        args = {**made, **args}
    _set_description(setting, file, args, found)


def _set_description(setting: str, file: Path, args: dict[str, str], found: _Found) -> None:
    if getattr(found, setting) is None:
        setattr(found, setting, RobotFile(file, args))


def _mappings(mappings: Any, context: LaunchContext, found: _Found) -> dict[str, str]:
    """Return a builder's or xacro's mappings as text; one waiting for an argument without value is left out."""
    if not isinstance(mappings, dict):
        return {}
    args: dict[str, str] = {}
    for name, value in mappings.items():
        key, resolved = text(name, context), text(value, context)
        if isinstance(key, str) and isinstance(resolved, str):
            args[key] = resolved
        elif isinstance(resolved, Unknown):
            _need(found, resolved, context, xacro=True)
    return args


_HOLE = "\x00"


def _words(value: Any, context: LaunchContext) -> tuple[list[str], list[Unknown]]:
    """Return a command line's words, a part not known marked by a hole, and those parts."""
    pieces: list[str] = []
    holes: list[Unknown] = []
    for part in _flatten(value):
        resolved = text(part, context)
        if isinstance(resolved, Unknown):
            holes.append(resolved)
            pieces.append(_HOLE)
        else:
            pieces.append(resolved)
    return _split("".join(pieces)), holes


def _split(line: str) -> list[str]:
    """Return a command line's words as launch's Command splits them (shlex: `prefix:=""` is `prefix:=`)."""
    try:
        return shlex.split(line)
    except ValueError:  # an unbalanced quote: launch would fail too; whitespace words name what can be named
        return line.split()


def _flatten(value: Any) -> list[Any]:
    """Return a substitution's parts, a path's with its separators, so that an unknown part leaves a gap in place."""
    if isinstance(value, Lazy) and value.kind == "concat":
        return [inner for part in value.parts for inner in _flatten(part)]
    if isinstance(value, Lazy) and value.kind == "path" and value.parts:
        joined: list[Any] = []
        for index, part in enumerate(value.parts):
            joined.extend(([] if index == 0 else ["/"]) + _flatten(part))
        return joined
    if isinstance(value, list | tuple):
        return [inner for part in value for inner in _flatten(part)]
    return [value]


def _command(words: list[str]) -> tuple[str | None, dict[str, str]]:
    """Return the file and `name:=value` args of `xacro FILE args...` (or of a lone file path)."""
    if not words:
        return None, {}
    start = next((i + 1 for i, w in enumerate(words) if Path(w).name in ("xacro", "xacro.py", "cat")), 0)
    rest = words[start:]
    files = [w for w in rest if ":=" not in w]
    if not files or _HOLE in files[0] or not files[0].endswith((".urdf", ".xacro", ".srdf", ".xml")):
        return None, {}
    args = {}
    for word in rest:
        name, sep, value = word.partition(":=")
        if sep and _HOLE not in word:
            args[name] = value
    return files[0], args


def _blocked(words: list[str], holes: list[Unknown], found: _Found) -> None:
    """Note the arguments a file's name waits for, with the values the files on disk give the gap."""
    names = {name for hole in holes for name in hole.needs}
    word = next((w for w in words if _HOLE in w), "")
    values = _hole_values(word) if len(names) == 1 and word.count(_HOLE) == 1 else ()
    for name in names:
        found.blocking.setdefault(name, values)


def _hole_values(word: str) -> tuple[str, ...]:
    """Return what a path with one gap (a launch argument without value) can be, by the files that exist."""
    before, after = word.split(_HOLE)
    if "/" in after.split("/", 1)[0] or not before:
        return ()
    matches = sorted(glob.glob(glob.escape(before) + "*" + glob.escape(after)))[:_MAX_HOLE_VALUES]
    values = [m[len(before):len(m) - len(after)] for m in matches]
    return tuple(v for v in values if v and "/" not in v)


_MAX_HOLE_VALUES = 200


def _need(found: _Found, unknown: Unknown, context: LaunchContext, xacro: bool = False) -> None:
    """Note the launch arguments a value waited for (a xacro arg's only at debug level: xacro's default serves)."""
    for name in sorted(unknown.needs):
        if xacro:
            logger.debug("%s: launch argument %s has no value; the xacro arg it sets keeps its default",
                         found.launch, name)
            continue
        found.needs.setdefault(name)


# -- files a build would generate -----------------------------------------------------------------

_XACRO_ADD = re.compile(r"xacro_add_files\s*\(([^)]*)\)", re.S)
_SET = re.compile(r"set\s*\(\s*(\w+)\s+([^)]*)\)", re.S)
_FOREACH = re.compile(r"foreach\s*\(\s*(\w+)\s+(?:IN\s+LISTS\s+(\w+)|([^)]*))\)(.*?)endforeach", re.S | re.I)


def _generated(file: Path, packages: PackagePath) -> tuple[Path, dict[str, str]] | None:
    """Return the xacro and args a package's CMakeLists.txt makes `file` from (xacro_add_files), None if none."""
    package = next((p for p in file.parents if (p / "package.xml").is_file()), None)
    if package is None or not (package / "CMakeLists.txt").is_file():
        return None
    try:
        cmake = re.sub(r"#[^\n]*", "", read_input_text(package / "CMakeLists.txt"))
    except ConfigError:
        return None
    lists = {name: values.split() for name, values in _SET.findall(cmake)}
    relative = file.relative_to(package)
    for body, variable, values in _calls(cmake, lists):
        words = [w.replace("${" + variable + "}", values) if variable else w for w in body.split()]
        if "OUTPUT" not in words or words.index("OUTPUT") + 1 >= len(words):
            continue
        output = words[words.index("OUTPUT") + 1]
        destination = words[words.index("DESTINATION") + 1] if "DESTINATION" in words[:-1] else ""
        if Path(destination, output) != relative:
            continue
        sources = [w for w in words if w.endswith(".xacro")]
        args = dict(w.split(":=", 1) for w in words if ":=" in w)
        if sources and (package / sources[0]).is_file():
            return package / sources[0], args
    return None


def _calls(cmake: str, lists: dict[str, list[str]]) -> list[tuple[str, str, str]]:
    """Return each xacro_add_files call's body, with the loop variable and each value it takes in a foreach."""
    calls: list[tuple[str, str, str]] = []
    for variable, listed, inline, body in _FOREACH.findall(cmake):
        values = lists.get(listed, []) if listed else inline.split()
        for inner in _XACRO_ADD.findall(body):
            calls.extend((inner, variable, value) for value in values)
    calls.extend((inner, "", "") for inner in _XACRO_ADD.findall(_FOREACH.sub("", cmake)))
    return calls


# -- several launch files -------------------------------------------------------------------------

_MAX_LISTED = 6


def _choose(root: Path, setting: str, named: dict[Path, list[Path]]) -> str:
    """Return the error for launch files that name different robots: each file with a few of those naming it.

    xArm's package has forty launch files: the message lists some of each, and counts the rest.
    """
    def shown(items: list[str]) -> str:
        more = f", and {len(items) - _MAX_LISTED} more" if len(items) > _MAX_LISTED else ""
        return ", ".join(items[:_MAX_LISTED]) + more

    # Launch files a user starts come first: a leading underscore marks one others include.
    listed = [f"{shown(sorted((f.name for f in files), key=lambda n: (n.startswith('_'), n)))}: {path.name}"
              for path, files in list(named.items())[:_MAX_LISTED]]
    more = f"; and {len(named) - _MAX_LISTED} more files" if len(named) > _MAX_LISTED else ""
    return (f"{root}: its launch files name {len(named)} different {setting.replace('_', ' ')} files "
            f"({'; '.join(listed)}{more}); pass --launch FILE to choose one")


def _combine(root: Path, found: list[_Found], given: dict[str, str]) -> LaunchFiles:
    """Return what the launch files agree on; ConfigError naming them where they name different robots."""
    for setting in _CHOSEN:
        named: dict[Path, list[Path]] = {}
        for item in found:
            value = getattr(item, setting) if setting in ("urdf", "srdf") else item.files.get(setting)
            path = value.path if isinstance(value, RobotFile) else value
            if path is not None:
                named.setdefault(path.resolve(), []).append(item.launch)
        if len(named) > 1:
            raise ConfigError(_choose(root, setting, named))
    # Of launch files naming the same file, the one that leaves fewest xacro args unset says most.
    urdf = min((f for f in found if f.urdf is not None), key=lambda f: f.unset.get("urdf", 0), default=None)
    srdf = min((f for f in found if f.srdf is not None), key=lambda f: f.unset.get("srdf", 0), default=None)
    files: dict[str, Path] = {}
    needs: dict[str, None] = {}
    required: dict[str, tuple[str, ...]] = {}
    for item in found:
        for setting, path in item.files.items():
            files.setdefault(setting, path)
        needs.update(item.needs)
        for name, choices in item.required.items():
            required.setdefault(name, choices)
    source = urdf.launch if urdf is not None else srdf.launch if srdf is not None else None
    return LaunchFiles(tuple(f.launch for f in found), urdf.urdf if urdf else None, srdf.srdf if srdf else None,
                       files, tuple(needs), required, given, source)
