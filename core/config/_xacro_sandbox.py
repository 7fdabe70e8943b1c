"""What a xacro document may do: xacro's own names and functions, evaluated within bounds.

moveplan runs the PyPI xacro package on the user's workspace files (never on a plan file's) with:

- expressions evaluated by xacro_expressions.py, over xacro's documented names (math, list, dict,
  map, len, str, float, int, bool, min, max, round, the `python.` and `xacro.` namespaces) less
  `type` and `vars`, which open classes' dictionaries; `range` of at most MAX_SEQUENCE items;
- `$(eval ...)` through the same guards with roslaunch's names (math, list, dict, map, str, float,
  int, true, false, arg, env, optenv, find, dirname), where xacro gives it every builtin;
- per document, at most MAX_ITERATIONS comprehension steps, MAX_ELEMENTS elements expanded
  (macro bodies and blocks each time they are inserted), macros nested MAX_MACRO_DEPTH deep, and
  MAX_INCLUDES files read (includes and xacro.load_yaml), of MAX_FILE_BYTES each and
  MAX_TOTAL_BYTES together, nested MAX_INCLUDE_DEPTH deep.

The hooks are module globals xacro looks up at each use (safe_eval, _global_symbols, eval_all,
handle_macro_call, parse, substitution_args._eval), swapped for the duration of one document.
"""

from __future__ import annotations

import builtins
import contextlib
import math
import os
import stat
from collections.abc import Callable, Iterator
from typing import Any

import xacro as _xacro  # the PyPI package ships no type hints (pyproject: ignore_missing_imports)
from xacro import substitution_args as _substitution_args

from ._xacro_expressions import Refused, bounded_range, evaluator

__all__ = [
    "MAX_ELEMENTS", "MAX_FILE_BYTES", "MAX_INCLUDES", "MAX_INCLUDE_DEPTH", "MAX_ITERATIONS", "MAX_MACRO_DEPTH",
    "MAX_TOTAL_BYTES", "sandboxed",
]

MAX_ITERATIONS = 1_000_000
"""Steps of comprehensions (`[... for x in ...]`) in one document, all expressions together."""

MAX_MACRO_DEPTH = 100
"""Macro expansions nested in each other: descriptions nest a handful; deeper is a macro expanding itself."""

MAX_ELEMENTS = 50_000
"""XML elements one document expands, each copy of a macro's body or a block counted: TIAGo's description
expands ~3,200; a macro that inserts its body twice per level makes 2**depth (xacro takes ~0.1 ms per element)."""

MAX_INCLUDES = 1_000
"""Files one document reads: the file itself, its `xacro:include`s and its `xacro.load_yaml` files."""

MAX_FILE_BYTES = 16 * 1024 * 1024
"""Size of one file a document reads."""

MAX_TOTAL_BYTES = 64 * 1024 * 1024
"""Size of all the files a document reads, together."""

MAX_INCLUDE_DEPTH = 32
"""Files included in each other: deeper is a file that includes itself."""

_REMOVED = ("type", "vars")  # type(name, bases, dict) makes classes; vars(cls) is a class's __dict__


class _Budget:
    """What one document has spent: comprehension steps, elements expanded, files and bytes read."""

    def __init__(self) -> None:
        self.iterations = self.elements = self.files = self.bytes = 0

    def step(self) -> None:
        """Spend one comprehension step."""
        self.iterations += 1
        if self.iterations > MAX_ITERATIONS:
            raise Refused(f"comprehensions take more than {MAX_ITERATIONS:,} steps in one document")

    def read(self, filename: str) -> None:
        """Count a file the document reads; Refused if it is too large, or the files too many or nested too deep."""
        self.files += 1
        if self.files > MAX_INCLUDES:
            raise Refused(f"the document reads more than {MAX_INCLUDES:,} files")
        if len(_xacro.filestack or ()) > MAX_INCLUDE_DEPTH:
            raise Refused(f"files included more than {MAX_INCLUDE_DEPTH} deep (a file that includes itself?)")
        try:
            status = os.stat(filename)
        except OSError:
            return  # xacro reports a missing file itself
        if stat.S_ISDIR(status.st_mode):
            raise Refused(f"{filename} is a folder, not a file")
        if not stat.S_ISREG(status.st_mode):
            raise Refused(f"{filename} is not a regular file (a device, FIFO or socket)")
        size = status.st_size
        if size > MAX_FILE_BYTES:
            raise Refused(f"{filename} has {size:,} bytes; a file xacro reads may have {MAX_FILE_BYTES:,}")
        self.bytes += size
        if self.bytes > MAX_TOTAL_BYTES:
            raise Refused(f"the files the document reads have more than {MAX_TOTAL_BYTES:,} bytes together")


def _symbols(budget: _Budget) -> dict[str, Any]:
    """Return xacro's global names, as moveplan lets expressions use them."""
    symbols: dict[str, Any] = _xacro.create_global_symbols()
    python, namespace = symbols["python"], symbols["xacro"]
    for name in _REMOVED:
        dict.pop(python, name, None)
    for table in (symbols, python):
        dict.__setitem__(table, "range", bounded_range(dict.__getitem__(table, "range")))
    load_yaml = dict.__getitem__(namespace, "load_yaml")

    def counted_load_yaml(filename: str) -> Any:
        budget.read(_xacro.abs_filename_spec(filename))
        return load_yaml(filename)
    for table in (symbols, namespace):
        dict.__setitem__(table, "load_yaml", counted_load_yaml)
    return symbols


def _substitution_eval(safe_eval: Callable[..., Any]) -> Callable[[str, dict[str, Any]], str]:
    """Return the replacement of xacro's `$(eval ...)`: through the guards, with roslaunch's names only."""
    convert, args_of = _substitution_args.convert_value, _substitution_args._eval_arg

    def evaluate(expression: str, context: dict[str, Any]) -> str:
        args = context.setdefault("arg", {})
        names: dict[str, Any] = {k: v for k, v in math.__dict__.items() if not k.startswith("_")}
        names.update({"true": True, "false": False, "True": True, "False": False})
        names.update({k: getattr(builtins, k) for k in ("list", "dict", "map", "str", "float", "int")})
        names.update({k: convert(v, "auto") for k, v in args.items()})
        names.update({
            "arg": lambda name: convert(args_of(name, args), "auto"),
            "dirname": lambda: _substitution_args._eval_dirname(context.get("filename")),
            "env": _substitution_args._eval_env, "optenv": _substitution_args._eval_optenv,
            "find": _substitution_args._eval_dict["find"],
        })
        return str(safe_eval(expression, names))
    return evaluate


@contextlib.contextmanager
def sandboxed() -> Iterator[None]:
    """Return a context inside which xacro evaluates through the guards and within the bounds (module docstring)."""
    budget = _Budget()
    safe_eval = evaluator(budget.step)
    evaluate, expand, parse = _xacro.eval_all, _xacro.handle_macro_call, _xacro.parse

    def eval_all(node: Any, macros: Any, symbols: Any) -> Any:
        budget.elements += 1
        if budget.elements > MAX_ELEMENTS:
            raise Refused(f"the document expands to more than {MAX_ELEMENTS:,} elements")
        return evaluate(node, macros, symbols)

    def handle_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        if node.tagName.startswith("xacro:") and len(_xacro.macrostack or ()) >= MAX_MACRO_DEPTH:
            # Reported as the recursion it nearly always is (core/config/xacro.py).
            raise RecursionError(f"macros nested more than {MAX_MACRO_DEPTH} deep")
        return expand(node, macros, symbols)

    def parse_file(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            budget.read(os.path.join(_xacro.root_dir, filename))
        return parse(inp, filename)

    saved = (_xacro.safe_eval, _xacro._global_symbols, evaluate, expand, parse, _substitution_args._eval)
    _xacro.safe_eval, _xacro._global_symbols = safe_eval, _symbols(budget)
    _xacro.eval_all, _xacro.handle_macro_call, _xacro.parse = eval_all, handle_macro_call, parse_file
    _substitution_args._eval = _substitution_eval(safe_eval)
    try:
        yield
    finally:
        (_xacro.safe_eval, _xacro._global_symbols, _xacro.eval_all, _xacro.handle_macro_call, _xacro.parse,
         _substitution_args._eval) = saved
