r"""ROS 2 launch substitutions in a parameter file, performed as `ParameterFile(allow_substs=True)` does.

launch_ros reads such a file as text, performs every `$(...)` in it, comments included, and
parses the result as YAML (launch_ros ParameterFile; grammar: launch/frontend/grammar.lark).
ur_robot_driver's ur_controllers.yaml is read that way: `$(var tf_prefix)shoulder_pan_joint`.
moveplan has no launch file, so the launch arguments are the xacro args in force (--xacro-arg,
moveplan.yaml `xacro_args`, a Setup Assistant config's): launch files pass the same values to
xacro and to these files.

- `$(var NAME)`: the launch argument NAME; not given, the default `$(var NAME DEFAULT)` names,
  else the empty string (the default of tf_prefix and the other prefix arguments).
- `$(env NAME)`, `$(env NAME DEFAULT)`: the environment variable; unset without a default is
  an error, as in launch.
- Any other substitution (find-pkg-share, command, eval, ...) is an error naming the file,
  line and substitution. `\$(` is a literal `$(`.

Arguments are separated by spaces, may be quoted with ' or ", and may hold substitutions.
"""

from __future__ import annotations

import logging
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from .fields import MAX_YAML_BYTES, load_yaml, parse_yaml, read_input_text

__all__ = ["load_substituted_yaml", "read_substituted", "substitute"]

_log = logging.getLogger(__name__)

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
_SHOWN = 60  # characters of a substitution quoted in a message
MAX_NESTING = 32
"""Substitutions inside substitutions: launch files nest two or three (`$(var a $(env B))`)."""


def load_substituted_yaml(path: Path, launch_args: Mapping[str, str] | None = None, merge: bool = False) -> Any:
    """Return a parameter file's content, parsed as YAML after its launch substitutions.

    The file as written is read by load_yaml first, with its limits and messages: the files that
    use substitutions are YAML before them too. Errors name `path`, the user's file, and the
    line: the substituted text keeps the file's lines. `merge`: repeated keys merge, as rcl
    reads a parameter file's.
    """
    content = load_yaml(path, merge)
    text = _read(path)
    if "$(" not in text:
        return content
    return parse_yaml(substitute(text, path, launch_args or {}), path, " once its launch substitutions are made", merge)


def read_substituted(path: Path, launch_args: Mapping[str, str] | None = None) -> str:
    """Return a parameter file's text with its launch substitutions made: what a plan file embeds."""
    return substitute(_read(path), path, launch_args or {})


def _read(path: Path) -> str:
    """Return a file's text; ConfigError names the file when it is missing or unreadable."""
    return read_input_text(path)


def substitute(
    text: str, source: Path | str, launch_args: Mapping[str, str], environ: Mapping[str, str] | None = None
) -> str:
    """Return `text` with its `$(var ...)` and `$(env ...)` substitutions made.

    Raises:
        ConfigError: An unknown or malformed substitution, or an unset environment variable
            without a default; names `source`, the line and the substitution.
    """
    if "$(" not in text:
        return text
    return _Parser(text, str(source), launch_args, os.environ if environ is None else environ).template()


class _Parser:
    """A recursive-descent reader of launch's substitution grammar, performing as it reads."""

    def __init__(self, text: str, source: str, launch_args: Mapping[str, str], environ: Mapping[str, str]) -> None:
        self.text, self.source, self.launch_args, self.environ = text, source, launch_args, environ
        self.pos = 0

    def template(self) -> str:
        """Return the whole text, substituted; text outside `$(...)` is kept as it is."""
        out: list[str] = []
        size = 0
        while True:
            start = self.text.find("$(", self.pos)
            if start < 0:
                out.append(self.text[self.pos:])
                return "".join(out)
            if start > 0 and self.text[start - 1] == "\\":
                out.append(self.text[self.pos:start - 1] + "$(")
                self.pos = start + 2
                continue
            out.append(self.text[self.pos:start])
            self.pos = start
            out.append(self._substitution())
            size += len(out[-2]) + len(out[-1])
            if size > MAX_YAML_BYTES:
                # A long value used many times must not grow a parameter file without bound.
                raise self._error(start, f"the substituted file grows beyond {MAX_YAML_BYTES:,} characters, "
                                         "moveplan's limit for a YAML file")

    def _substitution(self, depth: int = 0) -> str:
        """Return the value of the substitution at `pos` (at its `$(`), moving past its `)`."""
        start = self.pos
        if depth >= MAX_NESTING:
            raise self._error(start, f"substitutions nested more than {MAX_NESTING} deep")
        self.pos += 2
        name = _IDENTIFIER.match(self.text, self.pos)
        if name is None:
            raise self._error(start, "expected a substitution name after '$('")
        self.pos = name.end()
        args: list[str] = []
        while self._peek() == " ":
            while self._peek() == " ":
                self.pos += 1
            if self._peek() != ")":
                args.append(self._argument(start, depth))
        if self._peek() != ")":
            raise self._error(start, "unterminated substitution: expected ')'")
        self.pos += 1
        return self._perform(name.group(), args, start)

    def _argument(self, start: int, depth: int) -> str:
        """Return one argument: unquoted characters, quoted strings and substitutions, up to a space or ')'."""
        parts: list[str] = []
        while True:
            char = self._peek()
            if char in ("", "\n"):
                raise self._error(start, "unterminated substitution: expected ')'")
            if char in (" ", ")"):
                return "".join(parts)
            if self.text.startswith("$(", self.pos):
                parts.append(self._substitution(depth + 1))
            elif char in ("'", '"'):
                parts.append(self._quoted(char, start, depth))
            elif char == "\\" and self.pos + 1 < len(self.text):
                parts.append(self.text[self.pos + 1])
                self.pos += 2
            else:
                parts.append(char)
                self.pos += 1

    def _quoted(self, quote: str, start: int, depth: int) -> str:
        """Return a quoted argument's text, its substitutions made, moving past the closing quote."""
        self.pos += 1
        parts: list[str] = []
        while self._peek() != quote:
            if self._peek() in ("", "\n"):
                raise self._error(start, f"unterminated quoted argument: expected {quote}")
            if self.text.startswith("$(", self.pos):
                parts.append(self._substitution(depth + 1))
            else:
                parts.append(self._peek())
                self.pos += 1
        self.pos += 1
        return "".join(parts)

    def _perform(self, name: str, args: list[str], start: int) -> str:
        """Return the value of substitution `name` with its arguments."""
        if name not in ("var", "env"):
            raise self._error(start, f"the '{name}' substitution is not supported; moveplan makes "
                                     "$(var NAME [DEFAULT]) and $(env NAME [DEFAULT]) only")
        if not 1 <= len(args) <= 2:
            raise self._error(start, f"'{name}' takes a name and an optional default, got {len(args)} arguments")
        key, default = args[0], args[1] if len(args) == 2 else None
        if name == "env":
            value = self.environ.get(key, default)
            if value is None:
                raise self._error(start, f"environment variable '{key}' is not set, and no default is given")
            return value
        if key in self.launch_args:
            return self.launch_args[key]
        _log.info("%s: launch argument '%s' not given (--xacro-arg %s:=...); using %r",
                  self.source, key, key, default or "")
        return default or ""

    def _peek(self) -> str:
        """Return the character at `pos`, "" at the end of the text."""
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def _error(self, start: int, problem: str) -> ConfigError:
        """Return the error for the substitution at `start`, naming the source, its line and its text."""
        line = self.text.count("\n", 0, start) + 1
        end = self.text.find("\n", start)
        shown = self.text[start:end if end >= 0 else len(self.text)]
        close = shown.find(")")
        shown = shown[:close + 1] if close >= 0 else shown
        if len(shown) > _SHOWN:
            shown = shown[:_SHOWN] + "..."
        return ConfigError(f"{self.source}: line {line}: {shown}: {problem}")
