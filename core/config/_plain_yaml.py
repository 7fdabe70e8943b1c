"""The plain YAML of scenes, requests and configs read line by line: PyYAML's values, 2-2.5x faster, or DECLINED.

PyYAML over libyaml builds a MotionBenchMaker scene in ~1 ms, of which libyaml's parse is 0.06:
the rest is a Python node, two marks and a resolver call per value, then a constructor call
per node (benchmarks/yaml_read.py). Most robot files use a small part of YAML: block mappings and
sequences of one-line values, flow lists and mappings, plain or simply quoted scalars, comments.
That part is read here with string methods and a regular expression per line (0.4 ms); any text
outside it (anchors, tags, block scalars, multi-line values, escapes, merge keys, non-ASCII,
tabs) is DECLINED and goes to PyYAML, which also reports every error. A scalar takes the tag
and value PyYAML's resolvers and constructors give it (the loader's own tables, the ROS float
pattern included), so whatever is read here is what PyYAML reads (tests/config/test_plain_yaml.py
compares the two on generated and mutated documents).
"""

from __future__ import annotations

import re
from typing import Any, Final

import yaml

__all__ = ["DECLINED", "read_plain"]


class _Declined:
    """The marker of a text outside the plain part of YAML."""


DECLINED: Final = _Declined()


class _Outside(Exception):
    """Raised inside the reader when the text leaves the plain part."""


# Characters that only YAML outside the plain part uses (anchors, aliases, tags, block scalars,
# merge keys, complex keys, directives, reserved indicators, escapes): any of them sends the text to PyYAML.
_OUTSIDE_CHARACTERS = "&*!|><%@`?\\"
_SAFE = r"A-Za-z0-9_./+~()=$^;\-"
_PLAIN = rf"[{_SAFE}](?:[{_SAFE} ]*[{_SAFE}])?"
_SCALAR = re.compile(_PLAIN)
# An item of a flow list: a plain scalar that is not "-" alone or "- " (a block entry's indicator).
_ITEM = rf"(?!-(?![^ ,])){_PLAIN}"
_SCALAR_LIST = re.compile(rf" *(?:{_ITEM}(?: *, *{_ITEM})*)? *")
_KEY = re.compile(rf"([A-Za-z0-9_./][{_SAFE}]*):(?: +(.*))?")
_FLOW_KEY = re.compile(rf"([A-Za-z0-9_./][{_SAFE}]*): ")
_DECIMAL = re.compile(r"[-+]?(?:0|[1-9][0-9]*)")
_STR, _NULL, _BOOL, _INT, _FLOAT = (f"tag:yaml.org,2002:{kind}" for kind in ("str", "null", "bool", "int", "float"))
_UNSEEN = object()
_CONSTRUCTED = frozenset((_STR, _NULL, _BOOL, _INT, _FLOAT, "tag:yaml.org,2002:timestamp"))


def read_plain(text: str, loader: type[Any], merge: Any = None) -> Any:
    """Return the document `text` as `loader` (a PyYAML SafeLoader) builds it, or DECLINED outside the plain part.

    `text` must parse as YAML (the caller has checked it with libyaml). `merge(old, new)`, if
    given, combines a repeated key's values (a ROS 2 parameter file's); else the later wins.
    """
    # isprintable: no control character (tab and carriage return included) but the line feeds.
    if not text.isascii() or not text.replace("\n", "").isprintable() or any(c in text for c in _OUTSIDE_CHARACTERS):
        return DECLINED
    if text.startswith(("---", "...")) or "\n---" in text or "\n..." in text:
        return DECLINED  # document markers
    try:
        return _Reader(loader, merge).document(text)
    except (_Outside, RecursionError):  # a few hundred levels of nesting: PyYAML's loader is not recursive
        return DECLINED


class _Reader:
    """One document's reading: its lines, and its scalars resolved by `loader`'s tables."""

    def __init__(self, loader: type[Any], merge: Any) -> None:
        self._loader = loader
        self._merge = merge
        self._scalars: dict[str, Any] = {}
        # Per line kept: indent, content, the content's key match (None: no "key:" line), block entry or not.
        self._lines: list[tuple[int, str, re.Match[str] | None, bool]] = []

    def document(self, text: str) -> Any:
        """Return the document's value."""
        lines = self._lines
        for line in text.split("\n"):
            content = line.strip(" ")
            if not content or content[0] == "#":
                continue
            if "#" in content:
                # A comment starts at " #"; a quote could hold one, so quotes with it go to PyYAML.
                if "'" in content or '"' in content:
                    raise _Outside
                content = content.split(" #", 1)[0].rstrip(" ")
                if "#" in content:
                    raise _Outside
            lines.append(_line(len(line) - len(line.lstrip(" ")), content))
        if not lines:
            return None
        if len(lines) == 1 and lines[0][2] is None and not lines[0][3]:
            return self._inline(lines[0][1])
        value, end = self._block(0, lines[0][0])
        if end != len(lines):
            raise _Outside
        return value

    def _block(self, i: int, indent: int) -> tuple[Any, int]:
        """Return the block mapping or sequence starting at line `i` (indented `indent`) and the line after it."""
        _, _, key, entry = self._lines[i]
        if entry:
            return self._sequence(i, indent)
        if key is not None:
            return self._mapping(i, indent)
        raise _Outside  # a scalar on lines of its own

    def _sequence(self, i: int, indent: int) -> tuple[list[Any], int]:
        """Return the block sequence at line `i` and the line after it."""
        lines, items = self._lines, []
        while i < len(lines) and lines[i][0] == indent and lines[i][3]:
            content = lines[i][1]
            rest = content[1:].lstrip(" ")
            if not rest:
                value, i = self._below(i, indent)
            else:
                column = indent + len(content) - len(rest)
                lines[i] = inner = _line(column, rest)
                if inner[2] is not None or inner[3]:  # "- key: value" or "- - item": a block in the entry
                    value, i = self._block(i, column)
                else:
                    value, i = self._inline(rest), self._after_value(i, indent)
            items.append(value)
        return items, i

    def _mapping(self, i: int, indent: int) -> tuple[dict[Any, Any], int]:
        """Return the block mapping at line `i` and the line after it."""
        lines, merge = self._lines, self._merge
        mapping: dict[Any, Any] = {}
        while i < len(lines) and lines[i][0] == indent:
            match = lines[i][2]
            if match is None:
                raise _Outside
            key = self._scalar(match[1])
            written = match[2]
            if written is not None:
                value, i = self._inline(written), self._after_value(i, indent)
            elif i + 1 < len(lines) and lines[i + 1][0] == indent and lines[i + 1][3]:
                value, i = self._sequence(i + 1, indent)  # a sequence may sit at its key's indent
            else:
                value, i = self._below(i, indent)
            mapping[key] = merge(mapping[key], value) if merge is not None and key in mapping else value
        return mapping, i

    def _below(self, i: int, indent: int) -> tuple[Any, int]:
        """Return the block under line `i` (null if the next line is not deeper) and the line after it."""
        lines = self._lines
        if i + 1 < len(lines) and lines[i + 1][0] > indent:
            return self._block(i + 1, lines[i + 1][0])
        return None, i + 1

    def _after_value(self, i: int, indent: int) -> int:
        """Return the line after a one-line value at line `i`; a deeper next line would continue it."""
        if i + 1 < len(self._lines) and self._lines[i + 1][0] > indent:
            raise _Outside
        return i + 1

    def _inline(self, text: str) -> Any:
        """Return the value written on one line: a flow collection, a quoted or a plain scalar."""
        first = text[0]
        if first == "[" and text[-1] == "]" and _SCALAR_LIST.fullmatch(text, 1, len(text) - 1):
            return self._scalar_list(text[1:-1])
        if first in "[{":
            value, end = self._flow(text, 0)
            if text[end:].strip(" "):
                raise _Outside
            return value
        if first in "'\"":
            return _quoted(text)
        if first == "-" and (len(text) == 1 or text[1] == " ") or not _SCALAR.fullmatch(text):
            raise _Outside
        return self._scalar(text)

    def _scalar_list(self, inner: str) -> list[Any]:
        """Return a flow list of plain scalars, written between its brackets as `inner` (checked by _SCALAR_LIST)."""
        if not inner.strip(" "):
            return []
        seen, scalar = self._scalars, self._scalar
        return [seen[item] if item in seen else scalar(item) for item in (raw.strip(" ") for raw in inner.split(","))]

    def _flow(self, text: str, at: int) -> tuple[Any, int]:
        """Return the flow value starting at `at` (spaces first allowed) and where it ends."""
        at = _skip(text, at)
        if at == len(text):
            raise _Outside
        first = text[at]
        if first in "[{":
            closing = "]" if first == "[" else "}"
            items: list[Any] = []
            entries: dict[Any, Any] = {}
            at = _skip(text, at + 1)
            if at < len(text) and text[at] == closing:
                return (items if first == "[" else entries), at + 1
            while True:
                if first == "[":
                    value, at = self._flow(text, at)
                    items.append(value)
                else:
                    match = _FLOW_KEY.match(text, at)
                    if match is None:
                        raise _Outside
                    key = self._scalar(match[1])
                    value, at = self._flow(text, match.end())
                    entries[key] = self._merge(entries[key], value) if self._merge and key in entries else value
                at = _skip(text, at)
                if at < len(text) and text[at] == closing:
                    return (items if first == "[" else entries), at + 1
                if at >= len(text) or text[at] != ",":
                    raise _Outside
                at = _skip(text, at + 1)
                if at >= len(text) or text[at] in "]}":
                    raise _Outside  # a trailing comma, or a mapping closing a list
        if first in "'\"":
            end = text.find(first, at + 1)
            if end < 0:
                raise _Outside
            return _quoted(text[at:end + 1]), end + 1
        end = at
        while end < len(text) and text[end] not in ",]}:":
            end += 1
        item = text[at:end].strip(" ")
        if end < len(text) and text[end] == ":" or not _SCALAR.fullmatch(item) or item[0] == "-" and (
                len(item) == 1 or item[1] == " "):
            raise _Outside
        return self._scalar(item), end

    def _scalar(self, text: str) -> Any:
        """Return a plain scalar's value, with the tag the loader's implicit resolvers give it."""
        value = self._scalars.get(text, _UNSEEN)
        if value is not _UNSEEN:
            return value
        resolvers = self._loader.yaml_implicit_resolvers
        # The first resolver whose pattern matches gives the tag, as PyYAML's BaseResolver.resolve.
        tag = next((tag for tag, pattern in (*resolvers.get(text[0], ()), *resolvers.get(None, ()))
                    if pattern.match(text)), _STR)
        if tag == _STR:
            value = text
        elif tag == _NULL:
            value = None
        elif tag == _BOOL:
            value = yaml.constructor.SafeConstructor.bool_values[text.lower()]
        elif tag == _INT and _DECIMAL.fullmatch(text):
            value = int(text)
        elif tag == _FLOAT and "_" not in text and "n" not in text.lower():  # .inf and .nan take the constructor
            value = float(text)
        elif tag in _CONSTRUCTED:
            value = self._loader.yaml_constructors[tag](self._loader(""), yaml.ScalarNode(tag, text))
        else:
            raise _Outside
        self._scalars[text] = value
        return value


def _line(indent: int, content: str) -> tuple[int, str, re.Match[str] | None, bool]:
    """Return what the reader keeps of a line: indent, content, its key match, whether it is a block entry."""
    return indent, content, _KEY.fullmatch(content), content[0] == "-" and (len(content) == 1 or content[1] == " ")


def _quoted(text: str) -> str:
    """Return a quoted scalar's text, for quotes holding no quote character (and, double, no escape)."""
    quote = text[0]
    if len(text) < 2 or text[-1] != quote or "'" in text[1:-1] or '"' in text[1:-1]:
        raise _Outside
    return text[1:-1]


def _skip(text: str, at: int) -> int:
    """Return the first position at or after `at` that is not a space."""
    while at < len(text) and text[at] == " ":
        at += 1
    return at
