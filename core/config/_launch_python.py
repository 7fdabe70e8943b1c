"""Python launch files, followed statement by statement without running them.

A launch file is a program; moveplan never imports or executes it. It parses the file (ast)
and walks its statements as an interpreter that knows only plain values (strings, numbers,
lists, dicts), the launch API (launch, launch_ros, ament_index_python, moveit_configs_utils,
xacro, yaml, os.path, pathlib) and the functions the launch file, and Python modules of the
workspace's packages, define. Every other call is `Unknown`. Nothing is written, no process
starts, no module is imported: reading a file is the only effect, and it is bounded
(MAX_STEPS evaluations, MAX_CALL_DEPTH nested calls).

The module level runs first, then `generate_launch_description()`, then each OpaqueFunction's
function in turn (with the launch context, so `.perform(context)` resolves arguments), the way
`ros2 launch` would.
"""

from __future__ import annotations

import ast
import functools
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._launch_values import (
    Builder,
    Condition,
    Declared,
    LaunchContext,
    LaunchRecord,
    Lazy,
    NodeRecord,
    Unknown,
    XacroFile,
    YamlFile,
    text,
)
from .fields import read_input_text

__all__ = ["MAX_STEPS", "evaluate_python_launch"]

MAX_STEPS = 200_000
"""Statements and expressions one launch file (with its functions) may evaluate: real ones take a few thousand."""

MAX_CALL_DEPTH = 40
MAX_ITERATIONS = 10_000
_UNKNOWN = Unknown()


class _Stop(Exception):
    """The evaluation ran out of steps or depth: what was recorded so far stands."""


class _Return(Exception):
    def __init__(self, value: Any) -> None:
        self.value = value


class _Break(Exception):
    pass


class _Continue(Exception):
    pass


@dataclass(frozen=True)
class _Module:
    """An imported module by its dotted name: attributes are names in it."""

    name: str


@dataclass(frozen=True)
class _Function:
    """A function (or lambda) the launch file or a workspace module defines, with the names it closes over."""

    node: ast.FunctionDef | ast.Lambda
    scope: dict[str, Any]
    interpreter: _Interpreter


@dataclass(frozen=True)
class _Class:
    """A class a workspace module defines (xArm's own MoveItConfigsBuilder): its bases and members."""

    name: str
    bases: tuple[Any, ...]
    members: dict[str, Any]


@dataclass
class _Instance:
    """An object of a `_Class`, with the attributes its methods set."""

    cls: _Class
    attributes: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class _Bound:
    """A method of an instance: `function` called with `instance` first."""

    function: _Function
    instance: _Instance


@dataclass(frozen=True)
class _Super:
    """`super()` in a method of `cls` on `instance`."""

    instance: _Instance
    cls: _Class


@dataclass(frozen=True)
class _Method:
    """An attribute of a value, called later: `target.name(...)`."""

    target: Any
    name: str


@dataclass(frozen=True)
class _Object:
    """A launch object moveplan keeps only as a kind (LaunchDescription, an include's source, a file...)."""

    kind: str
    value: Any = None


@dataclass
class _Queue:
    """OpaqueFunctions and includes, run after generate_launch_description() as launch runs them."""

    opaque: list[tuple[Any, list[Any], dict[str, Any]]] = field(default_factory=list)
    includes: list[tuple[Any, Any, Any]] = field(default_factory=list)  # (source, launch_arguments, condition)


@dataclass
class _Budget:
    steps: int = MAX_STEPS
    depth: int = 0


def parsed(path: Path) -> ast.Module:
    """Return a Python file's syntax tree, parsed once per version of the file.

    A family's launch files share helpers: xArm's 40 launch files import the same modules.
    """
    stat = path.stat()
    return _parse(str(path), stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=512)
def _parse(path: str, mtime_ns: int, size: int) -> ast.Module:
    return ast.parse(read_input_text(Path(path)), path)


def evaluate_python_launch(
    path: Path, context: LaunchContext, find_module: Callable[[str], Path | None],
    include: Callable[[Any, Any, Any, LaunchRecord], None],
) -> LaunchRecord:
    """Return what a Python launch file's nodes are given, following it as `ros2 launch` would.

    Args:
        path: The launch file.
        context: Its launch arguments; declarations are added to it.
        find_module: Dotted module name -> the .py file of a workspace package's module, or None.
        include: Called with (source, launch_arguments, condition, record) for each included launch file.
    """
    record = LaunchRecord(path, context)
    try:
        tree = parsed(path)
    except SyntaxError as exc:
        raise ConfigError(f"{path}: not a Python launch file moveplan can read "
                          f"(line {exc.lineno}: {exc.msg})") from None
    queue = _Queue()
    interpreter = _Interpreter(path, record, queue, find_module, _Budget())
    try:
        interpreter.run_module(tree)
        entry = interpreter.scope.get("generate_launch_description")
        if isinstance(entry, _Function):
            interpreter.call(entry, [], {})
        while queue.opaque:
            function, args, kwargs = queue.opaque.pop(0)
            interpreter.call(function, [_Object("context"), *args], kwargs)
    except _Stop:
        record.notes.append(f"{path}: stopped following it after {MAX_STEPS} steps; what it named so far is used")
    for source, arguments, condition in queue.includes:
        include(source, arguments, condition, record)
    return record


class _Interpreter:
    """Walks one module's statements; see the module docstring for what it follows."""

    def __init__(self, path: Path, record: LaunchRecord, queue: _Queue,
                 find_module: Callable[[str], Path | None], budget: _Budget) -> None:
        self.path = path
        self.record = record
        self.queue = queue
        self.find_module = find_module
        self.budget = budget
        self.scope: dict[str, Any] = {"__file__": str(path), "__name__": "launch"}

    # -- statements ---------------------------------------------------------------------------------

    def run_module(self, tree: ast.Module) -> None:
        """Run a module's top-level statements in its own scope."""
        self.block(tree.body, self.scope)

    def block(self, statements: list[ast.stmt], scope: dict[str, Any]) -> None:
        """Run statements in order."""
        for statement in statements:
            self.statement(statement, scope)

    def statement(self, node: ast.stmt, scope: dict[str, Any]) -> None:  # noqa: C901 - one case per statement kind
        """Run one statement."""
        self._step()
        if isinstance(node, ast.Expr):
            self.expr(node.value, scope)
        elif isinstance(node, ast.Assign):
            value = self.expr(node.value, scope)
            for target in node.targets:
                self.assign(target, value, scope)
        elif isinstance(node, ast.AnnAssign) and node.value is not None:
            self.assign(node.target, self.expr(node.value, scope), scope)
        elif isinstance(node, ast.AugAssign):
            current = self.expr(node.target, scope)  # its ctx is Store; read the same way as Load here
            self.assign(node.target, self.binary(node.op, current, self.expr(node.value, scope)), scope)
        elif isinstance(node, ast.Return):
            raise _Return(self.expr(node.value, scope) if node.value is not None else None)
        elif isinstance(node, ast.If):
            test = self.truth(self.expr(node.test, scope))
            if test is not False:
                self.block(node.body, scope)
            if test is not True:
                self.block(node.orelse, scope)
        elif isinstance(node, ast.For):
            self.loop(node, scope)
        elif isinstance(node, ast.FunctionDef):
            scope[node.name] = _Function(node, scope, self)
        elif isinstance(node, ast.ClassDef):
            scope[node.name] = self.class_def(node, scope)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                name = alias.asname or alias.name.split(".")[0]
                scope[name] = _Module(alias.name if alias.asname else alias.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom):
            self.import_from(node, scope)
        elif isinstance(node, ast.Try):
            try:
                self.block(node.body, scope)
                self.block(node.orelse, scope)
            finally:
                self.block(node.finalbody, scope)
        elif isinstance(node, ast.With):
            for item in node.items:
                value = self.expr(item.context_expr, scope)
                if item.optional_vars is not None:
                    self.assign(item.optional_vars, value, scope)
            self.block(node.body, scope)
        elif isinstance(node, ast.Break):
            raise _Break
        elif isinstance(node, ast.Continue):
            raise _Continue
        elif isinstance(node, ast.Raise):
            raise _Return(_UNKNOWN)  # the function fails in ROS too; what it built so far is kept
        # while loops, classes, global, del, assert, match: nothing a launch file names files with

    def loop(self, node: ast.For, scope: dict[str, Any]) -> None:
        """Run a for loop over a known sequence; over an unknown one, not at all."""
        items = self.expr(node.iter, scope)
        if isinstance(items, dict):
            items = list(items)
        if not isinstance(items, list | tuple | str):
            return
        for item in list(items)[:MAX_ITERATIONS]:  # a copy: a loop appending to its own list ends
            self.assign(node.target, item, scope)
            try:
                self.block(node.body, scope)
            except _Break:
                return
            except _Continue:
                continue
        self.block(node.orelse, scope)

    def assign(self, target: ast.expr, value: Any, scope: dict[str, Any]) -> None:
        """Bind a name, unpack a tuple, or set a dict or list item."""
        if isinstance(target, ast.Name):
            scope[target.id] = value
        elif isinstance(target, ast.Tuple | ast.List):
            values = list(value) if isinstance(value, list | tuple) else [_UNKNOWN] * len(target.elts)
            for element, item in zip(target.elts, values + [_UNKNOWN] * (len(target.elts) - len(values)),
                                     strict=False):
                self.assign(element, item, scope)
        elif isinstance(target, ast.Attribute):
            owner = self.expr(target.value, scope)
            if isinstance(owner, _Instance):
                owner.attributes[target.attr] = value
        elif isinstance(target, ast.Subscript):
            container = self.expr(target.value, scope)
            key = self.expr(target.slice, scope)
            if isinstance(container, dict) and _hashable(key):
                container[key] = value
            elif isinstance(container, list) and isinstance(key, int) and -len(container) <= key < len(container):
                container[key] = value

    def import_from(self, node: ast.ImportFrom, scope: dict[str, Any]) -> None:
        """Bind imported names: a workspace module's functions where found, else the launch API's names."""
        module = node.module or ""
        if node.level:
            module = ".".join([*_package_of(self.path, node.level), *([module] if module else [])])
        source = self.find_module(module) if module else None
        loaded = self._load_module(source) if source is not None else None
        for alias in node.names:
            name = alias.asname or alias.name
            if loaded is not None:
                # A workspace module's class (xArm's own MoveItConfigsBuilder) is not the launch API's namesake.
                scope[name] = loaded.get(alias.name, _UNKNOWN)
            else:
                scope[name] = _Module(f"{module}.{alias.name}")

    def class_def(self, node: ast.ClassDef, scope: dict[str, Any]) -> _Class:
        """Return a class: its bases and its body's names (methods see the enclosing scope, as Python's do)."""
        body: dict[str, Any] = {}
        self.block(node.body, body)
        made = _Class(node.name, tuple(self.expr(base, scope) for base in node.bases), {})
        owners: dict[int, _Class] = scope.setdefault("__class_of__", {})
        for name, value in body.items():
            if isinstance(value, _Function):
                owners[id(value.node)] = made
                value = _Function(value.node, scope, value.interpreter)
            made.members[name] = value
        return made

    def instantiate(self, cls: _Class, args: list[Any], kwargs: dict[str, Any]) -> _Instance:
        """Return a new object of `cls`, its __init__ run (a dataclass's fields left as the class gives them)."""
        instance = _Instance(cls)
        init = _lookup(cls, "__init__")
        if isinstance(init, _Function):
            init.interpreter._run(init, [instance, *args], kwargs)
        return instance

    def _load_module(self, source: Path) -> dict[str, Any] | None:
        """Return the top-level names of a workspace Python module (its functions, constants), followed the same way."""
        try:
            tree = parsed(source)
        except (SyntaxError, ConfigError, ValueError):
            return None
        other = _Interpreter(source, self.record, self.queue, self.find_module, self.budget)
        other.run_module(tree)
        return other.scope

    # -- expressions --------------------------------------------------------------------------------

    def expr(self, node: ast.expr, scope: dict[str, Any]) -> Any:  # noqa: C901 - one case per expression kind
        """Return an expression's value (Unknown for what moveplan does not follow)."""
        self._step()
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in scope:
                return scope[node.id]
            if node.id in self.scope:
                return self.scope[node.id]
            return _BUILTINS.get(node.id, _UNKNOWN)
        if isinstance(node, ast.JoinedStr):
            return _concat([self._formatted(part, scope) for part in node.values])
        if isinstance(node, ast.BinOp):
            return self.binary(node.op, self.expr(node.left, scope), self.expr(node.right, scope))
        if isinstance(node, ast.BoolOp):
            return self._bool_op(node, scope)
        if isinstance(node, ast.UnaryOp):
            operand = self.expr(node.operand, scope)
            if isinstance(node.op, ast.Not):
                truth = self.truth(operand)
                return _UNKNOWN if truth is None else not truth
            return -operand if isinstance(node.op, ast.USub) and isinstance(operand, int | float) else _UNKNOWN
        if isinstance(node, ast.Compare):
            return self._compare(node, scope)
        if isinstance(node, ast.IfExp):
            test = self.expr(node.test, scope)
            truth = self.truth(test)
            if truth is None:
                return _unknown(test)
            return self.expr(node.body if truth else node.orelse, scope)
        if isinstance(node, ast.List | ast.Tuple | ast.Set):
            items: list[Any] = []
            for element in node.elts:
                if isinstance(element, ast.Starred):
                    inner = self.expr(element.value, scope)
                    items.extend(inner if isinstance(inner, list | tuple) else [_UNKNOWN])
                else:
                    items.append(self.expr(element, scope))
            return tuple(items) if isinstance(node, ast.Tuple) else items
        if isinstance(node, ast.Dict):
            result: dict[Any, Any] = {}
            for key, value in zip(node.keys, node.values, strict=True):
                if key is None:
                    inner = self.expr(value, scope)
                    result.update(inner if isinstance(inner, dict) else {})
                    continue
                key_value = self.expr(key, scope)
                if _hashable(key_value):
                    result[key_value] = self.expr(value, scope)
            if self.path != self.record.file and any(key in _ROBOT_PARAMETERS for key in result):
                # A builder of a workspace package (xArm's uf_ros_lib) may hand these to a node through
                # yaml.dump, which moveplan does not follow: what it builds counts.
                self.record.loose.append(result)
            return result
        if isinstance(node, ast.ListComp | ast.GeneratorExp | ast.SetComp):
            return self._comprehension(node.generators, lambda s: self.expr(node.elt, s), scope)
        if isinstance(node, ast.DictComp):
            pairs = self._comprehension(node.generators, lambda s: (self.expr(node.key, s), self.expr(node.value, s)),
                                        scope)
            return {k: v for k, v in pairs if _hashable(k)}
        if isinstance(node, ast.Attribute):
            return self.attribute(self.expr(node.value, scope), node.attr)
        if isinstance(node, ast.Subscript):
            return _subscript(self.expr(node.value, scope), self.expr(node.slice, scope))
        if isinstance(node, ast.Call):
            if isinstance(node.func, ast.Name) and node.func.id == "super" and not node.args:
                owner, instance = scope.get("__class__"), scope.get("__self__")
                return _Super(instance, owner) if isinstance(owner, _Class) and isinstance(instance, _Instance) \
                    else _UNKNOWN
            function = self.expr(node.func, scope)
            args: list[Any] = []
            for arg in node.args:
                if isinstance(arg, ast.Starred):
                    inner = self.expr(arg.value, scope)
                    args.extend(inner if isinstance(inner, list | tuple) else [])
                else:
                    args.append(self.expr(arg, scope))
            kwargs: dict[str, Any] = {}
            for keyword in node.keywords:
                value = self.expr(keyword.value, scope)
                if keyword.arg is not None:
                    kwargs[keyword.arg] = value
                elif isinstance(value, dict):
                    kwargs.update({str(k): v for k, v in value.items()})
            return self.call(function, args, kwargs)
        if isinstance(node, ast.Lambda):
            return _Function(node, scope, self)
        return _UNKNOWN

    def _formatted(self, part: ast.expr, scope: dict[str, Any]) -> Any:
        if isinstance(part, ast.FormattedValue):
            value = self.expr(part.value, scope)
            return value if isinstance(value, str | Lazy | Unknown) else _str(value)
        return self.expr(part, scope)

    def _bool_op(self, node: ast.BoolOp, scope: dict[str, Any]) -> Any:
        value: Any = _UNKNOWN
        for operand in node.values:
            value = self.expr(operand, scope)
            truth = self.truth(value)
            if truth is None:
                return _UNKNOWN
            if truth == isinstance(node.op, ast.Or):
                return value
        return value

    def _compare(self, node: ast.Compare, scope: dict[str, Any]) -> Any:
        left = self.expr(node.left, scope)
        for op, right_node in zip(node.ops, node.comparators, strict=True):
            right = self.expr(right_node, scope)
            opaque = _opaque(left) or _opaque(right)
            if opaque and isinstance(op, ast.Eq | ast.NotEq | ast.Is | ast.IsNot):
                # A launch object is equal only to itself, as a Python object is (`config == False`).
                same = left is right
                result: Any = same if isinstance(op, ast.Eq | ast.Is) else not same
            elif not _plain(left) or not _plain(right):
                return _unknown(left, right)
            else:
                compare = _COMPARE.get(type(op))
                result = compare(left, right) if compare is not None else _UNKNOWN
            if result is not True:
                return result
            left = right
        return True

    def _comprehension(self, generators: list[ast.comprehension], element: Callable[[dict[str, Any]], Any],
                       scope: dict[str, Any]) -> list[Any]:
        results: list[Any] = []

        def walk(index: int, inner: dict[str, Any]) -> None:
            if index == len(generators):
                results.append(element(inner))
                return
            generator = generators[index]
            items = self.expr(generator.iter, inner)
            if isinstance(items, dict):
                items = list(items)
            if not isinstance(items, list | tuple | str):
                return
            for item in items:
                local = dict(inner)
                self.assign(generator.target, item, local)
                if all(self.truth(self.expr(test, local)) is not False for test in generator.ifs):
                    walk(index + 1, local)

        walk(0, dict(scope))
        return results

    def binary(self, op: ast.operator, left: Any, right: Any) -> Any:
        """Return `left op right` for strings, numbers, lists and launch substitutions."""
        if isinstance(left, Unknown) or isinstance(right, Unknown):
            return _unknown(left, right)
        if isinstance(op, ast.Add):
            if isinstance(left, list) and isinstance(right, list):
                return left + right
            if isinstance(left, int | float) and isinstance(right, int | float):
                return left + right
            if _textual(left) and _textual(right):
                return _concat([left, right])
        if isinstance(op, ast.Div) and _textual(left) and _textual(right):
            return _path([left, right])  # pathlib's /
        if isinstance(op, ast.Mod) and isinstance(left, str):
            values = right if isinstance(right, tuple) else (right,)
            if all(isinstance(v, str | int | float) for v in values):
                try:
                    return left % values
                except (TypeError, ValueError):
                    return _UNKNOWN
        if isinstance(left, int | float) and isinstance(right, int | float) and type(op) in _ARITHMETIC:
            try:
                return _ARITHMETIC[type(op)](left, right)
            except (ArithmeticError, ValueError):
                return _UNKNOWN
        return _UNKNOWN

    @staticmethod
    def truth(value: Any) -> bool | None:
        """Return Python's truth of a plain value, None for an unknown or a substitution."""
        if isinstance(value, Unknown | Lazy | _Module | _Object):
            return None
        return bool(value)

    def attribute(self, value: Any, name: str) -> Any:
        """Return `value.name`: a module's member, a path's parent or name, or a method to call."""
        if isinstance(value, _Instance):
            if name in value.attributes:
                return value.attributes[name]
            member = _lookup(value.cls, name)
            return _Bound(member, value) if isinstance(member, _Function) else member
        if isinstance(value, _Class):
            return _lookup(value, name)
        if isinstance(value, _Super):
            return _super_member(value, name)
        if isinstance(value, _Module):
            return _Module(f"{value.name}.{name}")
        if isinstance(value, str) and name in ("parent", "name", "stem", "suffix"):
            return _path_attribute(value, name)
        if isinstance(value, Unknown):
            return value
        return _Method(value, name)

    @staticmethod
    def parameter(value: Any) -> Any:
        """Return a node parameter as recorded: `moveit_config.robot_description` is the builder's."""
        if isinstance(value, _Method) and isinstance(value.target, Builder):
            return value.target
        return value

    # -- calls --------------------------------------------------------------------------------------

    def call(self, function: Any, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Return the value of a call: a defined function run, the launch API followed, else Unknown."""
        if isinstance(function, _Function):
            return function.interpreter._run(function, args, kwargs)
        if isinstance(function, _Bound):
            return function.function.interpreter._run(function.function, [function.instance, *args], kwargs)
        if isinstance(function, _Class):
            return self.instantiate(function, args, kwargs)
        if isinstance(function, _Object) and function.kind == "package_builder_init":
            instance, package = function.value, _arg(args, kwargs, 0, "package_name")
            # launch_param_builder's ParameterBuilder: its package's share folder, for the relative files.
            found = self.record.context.find_package(package) if isinstance(package, str) else None
            instance.attributes["_package_path"] = found if found is not None else _UNKNOWN
            return None
        if isinstance(function, _Method):
            return self._method(function.target, function.name, args, kwargs)
        if isinstance(function, _Module):
            handler = _API.get(function.name) or _API.get(function.name.rsplit(".", 1)[-1])
            return handler(self, args, kwargs) if handler is not None else _UNKNOWN
        if callable(function) and function in _BUILTINS.values():
            return function(self, args, kwargs)
        return _UNKNOWN

    def _run(self, function: _Function, args: list[Any], kwargs: dict[str, Any]) -> Any:
        if self.budget.depth >= MAX_CALL_DEPTH:
            return _UNKNOWN  # a recursion this deep names no file; the caller goes on
        local = dict(function.scope) if function.scope is not self.scope else {}
        _bind(function.node.args, args, kwargs, local, lambda e: self.expr(e, function.scope))
        owner = function.scope.get("__class_of__", {}).get(id(function.node)) if "__class_of__" in function.scope \
            else None
        if owner is not None and args and isinstance(args[0], _Instance):
            local["__class__"], local["__self__"] = owner, args[0]
        self.budget.depth += 1
        try:
            if isinstance(function.node, ast.Lambda):
                return self.expr(function.node.body, local)
            self.block(function.node.body, local)
        except _Return as done:
            return done.value
        finally:
            self.budget.depth -= 1
        return None

    def _method(self, target: Any, name: str, args: list[Any], kwargs: dict[str, Any]) -> Any:  # noqa: C901
        """Return what a method call gives: str, list and dict methods, substitutions, builders, files."""
        if name == "perform" and isinstance(target, Lazy | str | list):
            return text(target, self.record.context)
        if isinstance(target, Builder):
            return _builder_method(target, name, args, kwargs)
        if isinstance(target, _Object):
            return self._object_method(target, name, args)
        if isinstance(target, XacroFile) and name in ("toxml", "toprettyxml"):
            return target
        if isinstance(target, dict):
            return _dict_method(target, name, args)
        if isinstance(target, list):
            if name == "append" and len(args) == 1:
                target.append(args[0])
            elif name == "extend" and len(args) == 1 and isinstance(args[0], list | tuple):
                target.extend(args[0])
            elif name == "insert" and len(args) == 2 and isinstance(args[0], int):
                target.insert(args[0], args[1])
            elif name == "copy":
                return list(target)
            return None
        if isinstance(target, str):
            return _str_method(target, name, args, kwargs)
        return _UNKNOWN

    def _object_method(self, target: _Object, name: str, args: list[Any]) -> Any:
        if target.kind == "file" and name == "read":
            return XacroFile(target.value, None)  # the text of a URDF or SRDF file
        if target.kind == "context" and name == "perform_substitution" and args:
            return text(args[0], self.record.context)
        return _UNKNOWN

    def _step(self) -> None:
        self.budget.steps -= 1
        if self.budget.steps < 0:
            raise _Stop

    # -- records the launch API makes ----------------------------------------------------------------

    def declare(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Record a DeclareLaunchArgument (a given argument keeps its value)."""
        name = _arg(args, kwargs, 0, "name")
        if isinstance(name, str):
            choices = kwargs.get("choices")
            # Choices a function of another package lists are not known, but that there are choices is.
            kept = (tuple(c for c in choices if isinstance(c, str)) if isinstance(choices, list | tuple) else ()) \
                if "choices" in kwargs else None
            self.record.context.declared[name] = Declared(_arg(args, kwargs, 1, "default_value", None), kept)
        return _Object("action")

    def node(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Record a Node: its parameters and arguments, for the robot description and parameter files."""
        parameters = kwargs.get("parameters")
        arguments = kwargs.get("arguments")
        self.record.nodes.append(NodeRecord(
            kwargs.get("package"), kwargs.get("executable", kwargs.get("node_executable")),
            [self.parameter(p) for p in parameters] if isinstance(parameters, list | tuple) else [],
            list(arguments) if isinstance(arguments, list | tuple) else [], kwargs.get("condition")))
        return _Object("action")

    def process(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Record an ExecuteProcess: `ros2 run controller_manager spawner ...` names parameter files too."""
        command = _arg(args, kwargs, 0, "cmd", [])
        words = list(command) if isinstance(command, list | tuple) else []
        self.record.nodes.append(NodeRecord(None, words[:4], [], words[4:], kwargs.get("condition")))
        return _Object("action")

    def include(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Queue an included launch file, followed after this one."""
        source = _arg(args, kwargs, 0, "launch_description_source")
        arguments = kwargs.get("launch_arguments", _arg(args, kwargs, 1, "launch_arguments", None))
        if isinstance(source, _Object) and source.kind == "source":
            self.queue.includes.append((source.value, arguments, kwargs.get("condition")))
        return _Object("action")

    def opaque(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Queue an OpaqueFunction's function, run with the launch context after generate_launch_description."""
        function = _arg(args, kwargs, 0, "function")
        extra = kwargs.get("args") or []
        named = kwargs.get("kwargs") or {}
        if isinstance(function, _Function):
            self.queue.opaque.append((function, list(extra) if isinstance(extra, list | tuple) else [],
                                      named if isinstance(named, dict) else {}))
        return _Object("action")

    def builder(self, args: list[Any], kwargs: dict[str, Any]) -> Any:
        """Return a MoveItConfigsBuilder, recorded: the files its chain names are the config's."""
        robot_name = _arg(args, kwargs, 0, "robot_name")
        package = _arg(args, kwargs, 2, "package_name", None)
        made = Builder(robot_name, package)
        self.record.builders.append(made)
        return made


def _lookup(cls: _Class, name: str, depth: int = 0) -> Any:
    """Return a class's member by name, searched in its bases (depth first, as single inheritance has it)."""
    if name in cls.members:
        return cls.members[name]
    for base in cls.bases:
        if isinstance(base, _Class) and depth < 20:
            found = _lookup(base, name, depth + 1)
            if not isinstance(found, Unknown):
                return found
    return _UNKNOWN


def _super_member(view: _Super, name: str) -> Any:
    """Return `super().name`: a base's method bound to the instance; ParameterBuilder's __init__ as launch has it."""
    for base in view.cls.bases:
        if isinstance(base, _Class):
            found = _lookup(base, name)
            if isinstance(found, _Function):
                return _Bound(found, view.instance)
        elif isinstance(base, _Module) and base.name.endswith("ParameterBuilder") and name == "__init__":
            return _Object("package_builder_init", view.instance)
    return _UNKNOWN


def _builder_method(builder: Builder, name: str, args: list[Any], kwargs: dict[str, Any]) -> Any:
    """Record a builder method's file and mappings; return the builder (the chain goes on) or its configs."""
    if name in ("to_moveit_configs", "to_dict"):
        return builder  # MoveItConfigs: its parameters are the files the chain named
    file_path = _arg(args, kwargs, 0, "file_path", None)
    mappings = _arg(args, kwargs, 1, "mappings", None)
    builder.calls[name] = (file_path, mappings)
    return builder


def _dict_method(target: dict[Any, Any], name: str, args: list[Any]) -> Any:
    if name == "items":
        return list(target.items())
    if name == "keys":
        return list(target)
    if name == "values":
        return list(target.values())
    if name == "copy":
        return dict(target)
    if name == "get" and args and _hashable(args[0]):
        return target.get(args[0], args[1] if len(args) > 1 else None)
    if name == "update" and args and isinstance(args[0], dict):
        target.update(args[0])
        return None
    if name == "setdefault" and args and _hashable(args[0]):
        return target.setdefault(args[0], args[1] if len(args) > 1 else None)
    return _UNKNOWN


def _str_method(target: str, name: str, args: list[Any], kwargs: dict[str, Any]) -> Any:
    if name == "join" and args and isinstance(args[0], list | tuple):
        return _concat(_interleave(list(args[0]), target))
    if name == "format":
        parts = [a for a in (*args, *kwargs.values())]
        if all(isinstance(p, str | int | float) for p in parts):
            try:
                return target.format(*args, **kwargs)
            except (IndexError, KeyError, ValueError):
                return _UNKNOWN
        return _UNKNOWN
    if name in ("joinpath",):
        return _path([target, *args])
    if name in ("resolve", "absolute", "as_posix", "expanduser"):
        return target
    if name in _STR_METHODS and all(isinstance(a, str | int) for a in args) and not kwargs:
        try:
            return getattr(target, name)(*args)
        except (TypeError, ValueError):
            return _UNKNOWN
    return _UNKNOWN


_ROBOT_PARAMETERS = frozenset({"robot_description", "robot_description_semantic", "robot_description_planning"})

_STR_METHODS = frozenset({"replace", "strip", "lstrip", "rstrip", "split", "lower", "upper", "startswith", "endswith",
                          "removesuffix", "removeprefix", "rsplit", "capitalize"})


def _interleave(items: list[Any], separator: str) -> list[Any]:
    joined: list[Any] = []
    for index, item in enumerate(items):
        if index:
            joined.append(separator)
        joined.append(item)
    return joined


# -- the launch API, by name ----------------------------------------------------------------------

def _arg(args: list[Any], kwargs: dict[str, Any], index: int, name: str, default: Any = _UNKNOWN) -> Any:
    """Return a call's argument given by position or by name."""
    if name in kwargs:
        return kwargs[name]
    return args[index] if index < len(args) else default


def _substitution(value: Any) -> Any:
    """Return a value used as a substitution: a list of them is their concatenation."""
    return _concat(list(value)) if isinstance(value, list | tuple) else value


def _concat(parts: list[Any]) -> Any:
    if all(isinstance(p, str) for p in parts):
        return "".join(parts)
    return Lazy("concat", tuple(_substitution(p) for p in parts))


def _path(parts: list[Any]) -> Any:
    parts = [_substitution(p) for p in parts]
    if all(isinstance(p, str) for p in parts):
        return os.path.join(*parts) if parts else ""
    return Lazy("path", tuple(parts))


def _path_attribute(value: str, name: str) -> str:
    path = Path(value)
    return str(path.parent) if name == "parent" else getattr(path, name)


def _share(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    package = _arg(args, kwargs, 0, "package")
    if isinstance(package, str):
        found = interpreter.record.context.find_package(package)
        return found if found is not None else _UNKNOWN
    return Lazy("share", (package,))


def _env(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    # The user's environment is not the launch's: only a default is taken.
    default = _arg(args, kwargs, 1, "default_value", None)
    return default if default is not None else _UNKNOWN


def _yaml_load(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    source = _arg(args, kwargs, 0, "stream")
    if isinstance(source, _Object) and source.kind == "file":
        return YamlFile(source.value) if isinstance(source.value, str) else _UNKNOWN
    return _UNKNOWN


def _open(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    path = _arg(args, kwargs, 0, "file")
    return _Object("file", path) if isinstance(path, str) else _UNKNOWN


def _load_yaml(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    """launch_param_builder's load_yaml(path): the file's parameters."""
    path = _arg(args, kwargs, 0, "file_path")
    return YamlFile(path) if isinstance(path, str) else _UNKNOWN


def _xacro(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    return XacroFile(_arg(args, kwargs, 0, "input_file_name", _arg(args, kwargs, 0, "file_path")),
                  kwargs.get("mappings", args[1] if len(args) > 1 else None))


def _read_argument(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    """launch_pal's read_launch_argument(name, context): the argument's value."""
    name = _arg(args, kwargs, 0, "arg_name")
    return text(Lazy("arg", (name, None)), interpreter.record.context)


def _condition(kind: str) -> Callable[[_Interpreter, list[Any], dict[str, Any]], Any]:
    def make(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
        if kind in ("if", "unless"):
            return Condition(kind, (_substitution(_arg(args, kwargs, 0, "predicate_expression")),))
        return Condition(kind, (_arg(args, kwargs, 0, "launch_configuration_name"),
                                _arg(args, kwargs, 1, "expected_value")))
    return make


def _source(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    return _Object("source", _substitution(_arg(args, kwargs, 0, "launch_file_path")))


def _value(index: int, name: str) -> Callable[[_Interpreter, list[Any], dict[str, Any]], Any]:
    return lambda interpreter, args, kwargs: _arg(args, kwargs, index, name)


def _os_path(function: Callable[..., Any]) -> Callable[[_Interpreter, list[Any], dict[str, Any]], Any]:
    def call(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
        if function is os.path.join:
            return _path(args)
        if len(args) == 1 and isinstance(args[0], str):
            return function(args[0])
        return _UNKNOWN
    return call


_API: dict[str, Callable[[_Interpreter, list[Any], dict[str, Any]], Any]] = {
    "LaunchConfiguration": lambda i, a, k: Lazy("arg", (_arg(a, k, 0, "variable_name"),
                                                        _arg(a, k, 1, "default", None))),
    "PathJoinSubstitution": lambda i, a, k: _path(list(_arg(a, k, 0, "substitutions", [])))
    if isinstance(_arg(a, k, 0, "substitutions", []), list | tuple) else _UNKNOWN,
    "Command": lambda i, a, k: _substitution(_arg(a, k, 0, "command")),
    "FindExecutable": lambda i, a, k: _arg(a, k, 0, "name"),
    "TextSubstitution": lambda i, a, k: _arg(a, k, 0, "text"),
    "ThisLaunchFileDir": lambda i, a, k: str(i.record.file.parent),
    "ThisLaunchFile": lambda i, a, k: str(i.record.file),
    "EnvironmentVariable": _env,
    "FindPackageShare": _share,
    "FindPackagePrefix": _share,
    "get_package_share_directory": _share,
    "get_package_share_path": _share,
    "get_package_prefix": _share,
    "ParameterValue": _value(0, "value"),
    "ParameterFile": _value(0, "param_file"),
    "DeclareLaunchArgument": lambda i, a, k: i.declare(a, k),
    "Node": lambda i, a, k: i.node(a, k),
    "ExecuteProcess": lambda i, a, k: i.process(a, k),
    "IncludeLaunchDescription": lambda i, a, k: i.include(a, k),
    "PythonLaunchDescriptionSource": _source,
    "XMLLaunchDescriptionSource": _source,
    "YAMLLaunchDescriptionSource": _source,
    "AnyLaunchDescriptionSource": _source,
    "FrontendLaunchDescriptionSource": _source,
    "OpaqueFunction": lambda i, a, k: i.opaque(a, k),
    "MoveItConfigsBuilder": lambda i, a, k: i.builder(a, k),
    "IfCondition": _condition("if"),
    "UnlessCondition": _condition("unless"),
    "LaunchConfigurationEquals": _condition("equals"),
    "LaunchConfigurationNotEquals": _condition("not_equals"),
    "LaunchDescription": lambda i, a, k: _Object("launch_description"),
    "read_launch_argument": _read_argument,
    "os.path.join": _os_path(os.path.join),
    "os.path.dirname": _os_path(os.path.dirname),
    "os.path.basename": _os_path(os.path.basename),
    "os.path.abspath": _os_path(lambda p: p),
    "os.path.realpath": _os_path(lambda p: p),
    "os.path.expanduser": _os_path(lambda p: p),
    "os.getenv": _env,
    "os.environ.get": _env,
    "Path": lambda i, a, k: _path(a) if a else "",
    "PurePath": lambda i, a, k: _path(a) if a else "",
    "yaml.safe_load": _yaml_load,
    "yaml.load": _yaml_load,
    "yaml.full_load": _yaml_load,
    "launch_param_builder.load_yaml": _load_yaml,
    "xacro.process_file": _xacro,
    "xacro.process": _xacro,
    "load_xacro": _xacro,
}


def _builtin_str(interpreter: _Interpreter, args: list[Any], kwargs: dict[str, Any]) -> Any:
    return _str(args[0]) if args else ""


def _str(value: Any) -> Any:
    if isinstance(value, str | Lazy | Unknown):
        return value
    if isinstance(value, bool | int | float) or value is None:
        return str(value)
    return _UNKNOWN


_BUILTINS: dict[str, Callable[[_Interpreter, list[Any], dict[str, Any]], Any]] = {
    "str": _builtin_str,
    "open": _open,
    "print": lambda i, a, k: None,
    "len": lambda i, a, k: len(a[0]) if a and isinstance(a[0], list | tuple | dict | str) else _UNKNOWN,
    "list": lambda i, a, k: list(a[0]) if a and isinstance(a[0], list | tuple | dict | str) else [] if not a
    else _UNKNOWN,
    "tuple": lambda i, a, k: tuple(a[0]) if a and isinstance(a[0], list | tuple) else _UNKNOWN,
    "dict": lambda i, a, k: dict(k) if not a else dict(a[0]) if isinstance(a[0], dict) else _UNKNOWN,
    "sorted": lambda i, a, k: sorted(a[0]) if a and isinstance(a[0], list | tuple)
    and all(isinstance(x, str) for x in a[0]) else _UNKNOWN,
    "enumerate": lambda i, a, k: list(enumerate(a[0])) if a and isinstance(a[0], list | tuple) else _UNKNOWN,
    "zip": lambda i, a, k: list(zip(*a, strict=False)) if a and all(isinstance(x, list | tuple) for x in a)
    else _UNKNOWN,
    "range": lambda i, a, k: list(range(*a)) if a and all(isinstance(x, int) for x in a)
    and len(range(*a)) <= 10_000 else _UNKNOWN,
    "bool": lambda i, a, k: bool(a[0]) if a and _plain(a[0]) else _UNKNOWN,
    "int": lambda i, a, k: _number(int, a),
    "float": lambda i, a, k: _number(float, a),
    "all": lambda i, a, k: _all_any(all, a),
    "any": lambda i, a, k: _all_any(any, a),
    "isinstance": lambda i, a, k: _isinstance(a),
}


def _all_any(function: Callable[[Any], bool], args: list[Any]) -> Any:
    items = args[0] if args else None
    if not isinstance(items, list | tuple) or not all(_plain(item) for item in items):
        return _unknown(*(items if isinstance(items, list | tuple) else []))
    return function(items)


def _isinstance(args: list[Any]) -> Any:
    """Return isinstance for plain values and the launch API's LaunchConfiguration; Unknown otherwise."""
    if len(args) != 2:
        return _UNKNOWN
    value, kinds = args[0], args[1] if isinstance(args[1], tuple) else (args[1],)
    if isinstance(value, Unknown):
        return value
    results = []
    for kind in kinds:
        if isinstance(kind, _Module) and kind.name.endswith("LaunchConfiguration"):
            results.append(isinstance(value, Lazy) and value.kind == "arg")
        elif callable(kind) and kind in _PYTHON_TYPES:
            expected = _PYTHON_TYPES[kind]
            results.append(isinstance(value, expected) and not (expected is int and isinstance(value, bool)))
        else:
            return _UNKNOWN
    return any(results)


def _number(kind: type, args: list[Any]) -> Any:
    if len(args) != 1 or not isinstance(args[0], str | int | float):
        return _UNKNOWN
    try:
        return kind(args[0])
    except ValueError:
        return _UNKNOWN


_ARITHMETIC: dict[type, Callable[[Any, Any], Any]] = {
    ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
    ast.FloorDiv: lambda a, b: a // b,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b,
    ast.In: lambda a, b: a in b if isinstance(b, list | tuple | dict | str) and (
        not isinstance(b, str) or isinstance(a, str)) else _UNKNOWN,
    ast.NotIn: lambda a, b: a not in b if isinstance(b, list | tuple | dict | str) and (
        not isinstance(b, str) or isinstance(a, str)) else _UNKNOWN,
    ast.Is: lambda a, b: a is b if a is None or b is None else _UNKNOWN,
    ast.IsNot: lambda a, b: a is not b if a is None or b is None else _UNKNOWN,
}


def _unknown(*values: Any) -> Unknown:
    """Return an Unknown that waits for every launch argument the unknown `values` wait for."""
    return Unknown(frozenset().union(*(v.needs for v in values if isinstance(v, Unknown))))


def _opaque(value: Any) -> bool:
    """Return True for a launch or Python object moveplan models (not a plain value, not unknown)."""
    return isinstance(value, Lazy | _Object | _Instance | _Class | _Module | Builder | YamlFile | XacroFile)


def _plain(value: Any) -> bool:
    """Return True for a value Python compares as moveplan would: no substitution, nothing unknown inside."""
    if isinstance(value, str | int | float | bool) or value is None:
        return True
    if isinstance(value, list | tuple):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(_plain(k) and _plain(v) for k, v in value.items())
    return False


def _textual(value: Any) -> bool:
    return isinstance(value, str | Lazy) or (isinstance(value, list) and all(_textual(v) for v in value))


def _hashable(value: Any) -> bool:
    return isinstance(value, str | int | float | bool | tuple) or value is None


def _subscript(container: Any, key: Any) -> Any:
    if isinstance(container, dict) and _hashable(key):
        return container.get(key, _UNKNOWN)
    if isinstance(container, list | tuple | str) and isinstance(key, int):
        return container[key] if -len(container) <= key < len(container) else _UNKNOWN
    return _UNKNOWN


def _bind(arguments: ast.arguments, args: list[Any], kwargs: dict[str, Any], local: dict[str, Any],
          default: Callable[[ast.expr], Any]) -> None:
    """Bind a call's arguments to a function's parameters, with its defaults; extra ones are dropped."""
    positional = [*arguments.posonlyargs, *arguments.args]
    defaults = [None] * (len(positional) - len(arguments.defaults)) + list(arguments.defaults)
    for index, (parameter, fallback) in enumerate(zip(positional, defaults, strict=True)):
        if index < len(args):
            local[parameter.arg] = args[index]
        elif parameter.arg in kwargs:
            local[parameter.arg] = kwargs[parameter.arg]
        else:
            local[parameter.arg] = default(fallback) if fallback is not None else _UNKNOWN
    for parameter, fallback in zip(arguments.kwonlyargs, arguments.kw_defaults, strict=True):
        local[parameter.arg] = kwargs.get(parameter.arg, default(fallback) if fallback is not None else _UNKNOWN)
    if arguments.vararg is not None:
        local[arguments.vararg.arg] = tuple(args[len(positional):])
    if arguments.kwarg is not None:
        names = {p.arg for p in (*positional, *arguments.kwonlyargs)}
        local[arguments.kwarg.arg] = {k: v for k, v in kwargs.items() if k not in names}


def _package_of(path: Path, level: int) -> list[str]:
    """Return the dotted package a relative import starts from: the launch file's folders, `level` up."""
    parts = list(path.parent.parts)
    return parts[len(parts) - (level - 1):] if level > 1 else [path.parent.name]


_PYTHON_TYPES: dict[Any, type] = {
    _BUILTINS["str"]: str, _BUILTINS["bool"]: bool, _BUILTINS["int"]: int, _BUILTINS["float"]: float,
    _BUILTINS["list"]: list, _BUILTINS["dict"]: dict, _BUILTINS["tuple"]: tuple,
}
