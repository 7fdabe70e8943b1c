"""xacro's Python expressions, evaluated without reaching Python's internals and within size bounds.

xacro evaluates `${...}` with Python's eval and refuses names that start with "__" in an
expression's own code only: a comprehension, or str.format, steps around that (to `__class__`,
then to every class and module of the process). Here an expression is parsed first and refused
(Refused, naming it) if it is longer than MAX_EXPRESSION_CHARS, names anything starting with "__",
reads an attribute starting with "_", defines a function (lambda) or assigns (`:=`); then it is
rewritten so that what it does passes through guards:

- attributes (and `str.format` fields): no name starting with "_", nothing of a module, frame,
  code object, traceback or generator; `a.b` of a xacro namespace is its entry `b`, never a
  method of the table behind it;
- integers of at most MAX_INT_BITS bits from `**`, `*`, `<<`, math.prod and factorials;
- values of at most MAX_SEQUENCE items (characters of a string, elements of a list, a shared
  element counted where it appears) from `+`, `*`, `%`, sum, format widths, the str methods that
  grow a string, str(), repr(), and as the expression's result;
- each comprehension step is counted (`step`, the document's budget: xacro_sandbox.py).

These bound runaway arithmetic and expansion; they do not make eval a general sandbox, which is
why the names an expression sees are xacro's few (xacro_sandbox.py) and no plan file runs xacro.
"""

from __future__ import annotations

import ast
import builtins
import math
import re
import string
import types
from collections.abc import Callable
from typing import Any

import xacro as _xacro  # the PyPI package ships no type hints (pyproject: ignore_missing_imports)

__all__ = ["MAX_EXPRESSION_CHARS", "MAX_INT_BITS", "MAX_SEQUENCE", "Refused", "bounded_range", "evaluator"]

MAX_EXPRESSION_CHARS = 2_000
"""Characters of one expression; the longest in seven real description packages has 126."""

MAX_INT_BITS = 4_096
"""Bits of an integer an operation may make (about 1e1233): no robot's number is near it; 9**9**9 is far beyond."""

MAX_SEQUENCE = 1_000_000
"""Items of a value: characters of a string, elements of a list (a shared one counted where it appears)."""

_SHOWN = 80  # characters of an expression quoted in a message
_INTERNALS = ("reaches Python's internals; xacro expressions compute with numbers, strings, lists "
              "and xacro's functions")
_HIDDEN = (types.ModuleType, types.FrameType, types.CodeType, types.TracebackType, types.GeneratorType,
           types.CoroutineType, types.AsyncGeneratorType)
_CONTAINERS = (list, tuple, dict, set, frozenset)
_SCALARS = {int, float, bool, complex, type(None)}
_DIGITS = re.compile(r"\d+")
_FIELD = re.compile(r"([^.\[]*)((?:\.[^.\[]+|\[[^\]]+\])*)")  # str.format's arg_name ("." name | "[" key "]")*
_FIELD_PART = re.compile(r"\.([^.\[]+)|\[([^\]]+)\]")
_PERCENT = re.compile(r"%(?:\([^)]*\))?[#0 +-]*(\*|\d*)(?:\.(\*|\d*))?")


class Refused(Exception):
    """An expression, or a document, that moveplan does not evaluate: what and why.

    Attributes:
        why: The reason. expression: The expression refused; None for a bound of the whole document.
    """

    def __init__(self, why: str, expression: str | None = None) -> None:
        self.why, self.expression = why, expression
        super().__init__(why)

    def __str__(self) -> str:
        if self.expression is None:
            return self.why
        text = " ".join(self.expression.split())
        shown = text if len(text) <= _SHOWN else text[:_SHOWN - 3] + "..."
        return f"expression ${{{shown}}} refused: {self.why}"


class _Counted:
    """An iterator spending one comprehension step per item (a class, not a generator: no frame to reach)."""

    def __init__(self, iterable: Any, step: Callable[[], None]) -> None:
        self._items, self._step = iter(iterable), step

    def __iter__(self) -> _Counted:
        return self

    def __next__(self) -> Any:
        item = next(self._items)
        self._step()
        return item


def _weight(value: Any) -> int:
    """Return the items `value` holds, a shared part counted where it appears: its repr's order of size."""
    if isinstance(value, str | bytes):
        return len(value)
    if not isinstance(value, _CONTAINERS):
        return 1
    weights: dict[int, int] = {}
    open_ids: set[int] = set()
    stack: list[tuple[Any, list[Any], bool]] = [(value, _children(value), False)]
    while stack:
        node, children, done = stack.pop()
        # A list of numbers is weighed by its length: a million-item list in 20 ms, not 200.
        flat = set(map(type, children)) <= _SCALARS
        if done:
            open_ids.discard(id(node))
            total = 1 + (len(children) if flat else sum(
                weights.get(id(c), 1) if isinstance(c, _CONTAINERS) else _weight(c) for c in children))
            weights[id(node)] = min(total, MAX_SEQUENCE + 1)
            continue
        if id(node) in weights or id(node) in open_ids:
            continue  # weighed already, or a list inside itself (its repr shows [...])
        open_ids.add(id(node))
        stack.append((node, children, True))
        if not flat:
            stack.extend((c, _children(c), False) for c in children if isinstance(c, _CONTAINERS))
    return weights[id(value)]


def _children(value: Any) -> list[Any]:
    # Raw items: xacro's YAML wrappers make a new wrapper object each time they are iterated.
    if isinstance(value, dict):
        return [*dict.keys(value), *dict.values(value)]
    if isinstance(value, list):
        return list(list.__iter__(value))
    return list(value)


def _sized(weight: int) -> None:
    if weight > MAX_SEQUENCE:
        raise Refused(f"it makes a value of more than {MAX_SEQUENCE:,} items")


def _big_int(bits: int) -> None:
    if bits > MAX_INT_BITS:
        raise Refused(f"it makes an integer of more than {MAX_INT_BITS:,} bits")


def _formatting(value: Any, spec: str) -> None:
    """Refuse formatting `value` with `spec` into a string of more than MAX_SEQUENCE characters."""
    _sized(_weight(value))
    for width in _DIGITS.findall(spec):
        if len(width) > 8 or int(width) > MAX_SEQUENCE:
            raise Refused(f"a format width or precision above {MAX_SEQUENCE:,}")


class _Formatter(string.Formatter):
    """str.format, reading fields' attributes through the guard, with widths bounded."""

    def get_field(self, field_name: str, args: Any, kwargs: Any) -> tuple[Any, Any]:
        parts = _FIELD.fullmatch(field_name)
        if parts is None:
            raise ValueError(f"malformed format field {field_name!r}")
        first: int | str = int(parts[1]) if parts[1].isdigit() else parts[1]
        value = self.get_value(first, args, kwargs)
        for part in _FIELD_PART.finditer(parts[2]):
            attribute, key = part.groups()
            value = _attribute(value, attribute) if attribute is not None else value[int(key) if key.isdigit() else key]
        return value, first

    def format_field(self, value: Any, format_spec: str) -> Any:
        _formatting(value, format_spec)
        return super().format_field(value, format_spec)


# str and bytes methods whose result can be far larger than their inputs: name -> the result's size.
_GROWING: dict[str, Callable[..., int]] = {
    "center": lambda text, width, *_: width, "ljust": lambda text, width, *_: width,
    "rjust": lambda text, width, *_: width, "zfill": lambda text, width: width,
    "expandtabs": lambda text, tabsize=8: len(text) * max(tabsize, 1),
    "join": lambda text, items: len(text) * max(len(items) - 1, 0) + sum(map(_weight, items)),
    "replace": lambda text, old, new, count=-1: len(text) + max(len(new) - len(old), 0) * (
        (len(text) + 1 if not old else text.count(old)) if count < 0 else count),
    "translate": lambda text, table: len(text) * max([1, *map(_weight, table.values())])
    if isinstance(table, dict) else len(text),
}


def _attribute(value: Any, name: str) -> Any:
    """Return `value.name`, as an expression may read it."""
    if name.startswith("_") or isinstance(value, _HIDDEN):
        raise Refused(f"'{name}' {_INTERNALS}")
    if isinstance(value, _xacro.Table):
        try:
            return value[name]
        except KeyError:
            raise NameError(f"name '{name}' is not defined") from None
    if name in ("format", "format_map") or isinstance(value, type) and name in _GROWING:
        if not isinstance(value, str):
            raise Refused(f"'{name}' of anything but a string (write 'text'.{name}(...))")
        formatter = _Formatter()
        if name == "format":
            return lambda *args, **kwargs: formatter.vformat(value, args, kwargs)
        return lambda mapping: formatter.vformat(value, (), mapping)
    method = getattr(value, name)
    if isinstance(value, int) and name == "to_bytes":
        return lambda length=1, *rest, **kwargs: method(_checked_size(length), *rest, **kwargs)
    if isinstance(value, str | bytes) and name in _GROWING:
        size = _GROWING[name]

        def bounded(*args: Any) -> Any:
            if name == "join":
                args = (list(args[0]),)
            _sized(size(value, *args))
            return method(*args)
        return bounded
    return method


def _checked_size(length: Any) -> Any:
    if isinstance(length, int):
        _sized(length)
    return length


def _power(base: Any, exponent: Any) -> Any:
    if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1:
        _big_int((abs(base).bit_length() - 1) * exponent)
    return base ** exponent


def _times(left: Any, right: Any) -> Any:
    if isinstance(left, int) and isinstance(right, int):
        _big_int(left.bit_length() + right.bit_length() - 1)
    for sequence, count in ((left, right), (right, left)):
        if isinstance(count, int) and isinstance(sequence, str | bytes):
            _sized(len(sequence) * count)
        elif isinstance(count, int) and isinstance(sequence, list | tuple):
            _sized(1 + (_weight(sequence) - 1) * count)  # the items repeated, the list itself once
    return left * right


def _shift(left: Any, right: Any) -> Any:
    if isinstance(left, int) and isinstance(right, int) and left:
        _big_int(left.bit_length() + right)
    return left << right


def _plus(left: Any, right: Any) -> Any:
    if isinstance(left, str | bytes | list | tuple):
        _sized(_weight(left) + _weight(right))
    return left + right


def _modulo(left: Any, right: Any) -> Any:
    if isinstance(left, str | bytes):
        text = left.decode("latin-1") if isinstance(left, bytes) else left
        for width, precision in _PERCENT.findall(text):
            if "*" in (width, precision):
                raise Refused("a '*' width in %-formatting")
            _formatting(right, f"{width} {precision}")
    return left % right


def _formatted(value: Any, conversion: int, spec: str) -> str:
    """Return an f-string field: `value` converted (!s, !r, !a) and formatted with `spec`, within bounds."""
    _formatting(value, spec)
    conversions: dict[int, Callable[[object], str]] = {ord("s"): str, ord("r"): repr, ord("a"): ascii}
    converted = conversions.get(conversion)
    return format(converted(value) if converted else value, spec)


def _product(iterable: Any, /, *, start: Any = 1) -> Any:
    total = start
    for item in iterable:
        total = _times(total, item)
    return total


def _sum(iterable: Any, /, start: Any = 0) -> Any:
    if not isinstance(start, list | tuple):
        return sum(iterable, start)  # numbers; strings, which sum refuses, saying what to use instead
    # Lists and tuples are joined in one pass: sum() copies the total at each item.
    total, weight = list(start), _weight(start)
    for item in iterable:
        if type(item) is not type(start) and not isinstance(item, type(start)):
            raise TypeError(f'can only concatenate {type(start).__name__} (not "{type(item).__name__}")')
        weight += _weight(item)
        _sized(weight)
        total.extend(item)
    return total if isinstance(start, list) else tuple(total)


def _factorial_bound(function: Callable[..., Any]) -> Callable[..., Any]:
    """Return `function` (a factorial), refusing an argument whose result would pass MAX_INT_BITS by far."""
    def call(n: Any, *rest: Any) -> Any:
        if isinstance(n, int) and n > MAX_INT_BITS // 4:
            raise Refused(f"{function.__name__}({n}) is an integer of more than {MAX_INT_BITS:,} bits")
        return function(n, *rest)
    return call


def _converting(function: Callable[..., Any]) -> Callable[..., Any]:
    """Return `function` (str, repr), refusing to convert a value of more than MAX_SEQUENCE items."""
    def call(*args: Any, **kwargs: Any) -> Any:
        if args:
            _sized(_weight(args[0]))
        return function(*args, **kwargs)
    return call


# Functions called with other than their own bounds, by identity (an expression may reach them by any name).
_SWAPS: list[tuple[Any, Callable[..., Any]]] = [
    (builtins.sum, _sum), (math.prod, _product), (builtins.str, _converting(str)),
    (builtins.repr, _converting(repr)), *((f, _factorial_bound(f)) for f in (math.factorial, math.comb, math.perm)),
]
_CALLS: dict[int, tuple[Any, Callable[..., Any]]] = {id(f): (f, g) for f, g in _SWAPS}


def _call(function: Any, /, *args: Any, **kwargs: Any) -> Any:
    entry = _CALLS.get(id(function))
    if entry is not None and entry[0] is function:
        return entry[1](*args, **kwargs)
    return function(*args, **kwargs)


_OPERATORS: dict[type[ast.operator], str] = {
    ast.Pow: "__mp_power__", ast.Mult: "__mp_times__", ast.LShift: "__mp_shift__", ast.Add: "__mp_plus__",
    ast.Mod: "__mp_modulo__",
}


def _guard_call(name: str, *args: ast.expr) -> ast.Call:
    return ast.Call(ast.Name(name, ast.Load()), list(args), [])


class _Guard(ast.NodeTransformer):
    """Rewrites an expression so that attributes, calls, growing operators and comprehensions pass the guards."""

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        return _guard_call("__mp_attribute__", node.value, ast.Constant(node.attr))

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        return ast.Call(ast.Name("__mp_call__", ast.Load()), [node.func, *node.args], node.keywords)

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        guard = _OPERATORS.get(type(node.op))
        return node if guard is None else _guard_call(guard, node.left, node.right)

    def visit_FormattedValue(self, node: ast.FormattedValue) -> ast.AST:
        self.generic_visit(node)
        spec = node.format_spec if node.format_spec is not None else ast.Constant("")
        node.value = _guard_call("__mp_formatted__", node.value, ast.Constant(node.conversion), spec)
        node.conversion, node.format_spec = -1, None
        return node

    def visit_comprehension(self, node: ast.comprehension) -> ast.AST:
        self.generic_visit(node)
        node.iter = _guard_call("__mp_iterate__", node.iter)
        return node


def _compile(expression: str) -> types.CodeType:
    """Return the guarded code of `expression`; Refused for what it may not do, SyntaxError as xacro raises it."""
    text = expression.strip()
    if len(text) > MAX_EXPRESSION_CHARS:
        raise Refused(f"longer than {MAX_EXPRESSION_CHARS:,} characters", expression)
    tree = ast.parse(text, "<expression>", mode="eval")
    # In the order they are written: an attribute's name ends its node.
    for node in sorted(ast.walk(tree), key=lambda n: (getattr(n, "end_lineno", 0), getattr(n, "end_col_offset", 0))):
        if isinstance(node, ast.Name) and node.id.startswith("__"):
            raise Refused(f"'{node.id}' {_INTERNALS}", expression)
        if isinstance(node, ast.Attribute) and (node.attr.startswith("_") or not isinstance(node.ctx, ast.Load)):
            raise Refused(f"'{node.attr}' {_INTERNALS}", expression)
        if isinstance(node, ast.Lambda | ast.NamedExpr):
            raise Refused("an expression may not define a function (lambda) or assign (:=)", expression)
    return compile(ast.fix_missing_locations(_Guard().visit(tree)), "<expression>", "eval")


def bounded_range(function: Callable[..., Any]) -> Callable[..., Any]:
    """Return `function` (range, or xacro's wrapper of it) refusing ranges of more than MAX_SEQUENCE items."""
    def call(*args: Any) -> Any:
        try:
            too_long = len(range(*args)) > MAX_SEQUENCE
        except OverflowError:
            too_long = True
        except (TypeError, ValueError):
            too_long = False  # range itself says what is wrong with the arguments
        if too_long:
            raise Refused(f"a range of more than {MAX_SEQUENCE:,} items")
        return function(*args)
    return call


def evaluator(step: Callable[[], None]) -> Callable[..., Any]:
    """Return a replacement of xacro.safe_eval, evaluating through the guards; `step` spends a comprehension step."""
    guards: dict[str, Callable[..., Any]] = {
        "__mp_attribute__": _attribute, "__mp_call__": _call, "__mp_power__": _power, "__mp_times__": _times,
        "__mp_shift__": _shift, "__mp_plus__": _plus, "__mp_modulo__": _modulo, "__mp_formatted__": _formatted,
        "__mp_iterate__": lambda iterable: _Counted(iterable, step),
    }

    def safe_eval(expression: str, names: dict[str, Any], local: Any = None) -> Any:
        code = _compile(expression)
        # The builtins of the evaluation, and of its comprehensions, are the guards alone.
        dict.__setitem__(names, "__builtins__", guards)
        try:
            result = eval(code, names, local)  # noqa: S307 - guarded code (module docstring)
            _sized(_weight(result))
        except Refused as exc:
            exc.expression = expression if exc.expression is None else exc.expression
            raise
        return result
    return safe_eval
