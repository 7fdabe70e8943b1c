"""XML and YAML launch files (ROS 2's launch_xml and launch_yaml frontends), followed without running them.

Both frontends describe the same actions as a tree of entities: `<launch>` and its elements, or
`launch:` and its list of one-key mappings (the key names the entity). Either tree is read into
one form, and its actions are walked in order into the `LaunchRecord` a Python launch file gives
(core/config/_launch_values.py), so the rest of moveplan treats all three alike:

- `arg` (DeclareLaunchArgument): its default and `choice` values, declared in the context; a
  given argument keeps its value, as `ros2 launch` keeps it;
- `let` (SetLaunchConfiguration): its value replaces `$(var NAME)` in every attribute after it,
  up to the end of its scope (a group is scoped unless `scoped="false"`). Lets are applied where
  they are read, not stored in the context: a let overrides a given argument, and a scoped
  group's lets end with the group, which a context shared by the whole file could not model;
- `node`: its `pkg`, `exec`, `args` (split into words as ExecuteProcess splits a command line)
  and `param` children: `name`/`value` pairs (nested ones under dotted names), one dict per
  `param` as launch_ros makes them, and `from` parameter files;
- `executable`: its `cmd` words, recorded as the Python side records ExecuteProcess;
- `include`: its `file` and `arg` children, passed to the `include` callback once the file is walked;
- `group` and `timer`: their actions; a group whose condition is known false is skipped;
- `if` / `unless` on any of them.

Attribute text is read with the frontends' substitution grammar (`$(name arg ...)`, arguments
quoted or not, substitutions nested, backslash escapes): var (with its optional default),
find-pkg-share, find-pkg-prefix, find-exec, command, env (its default), dirname and filename.
Every other substitution (eval, anon, env without default...) and text that does not parse is
Unknown; anything else not understood is skipped, never an error. Only a file that is not XML or
YAML, or whose root is not a launch file's, is a ConfigError.

Not followed: namespaces, remappings, environment variables and set_parameter / set_remap
actions, composable nodes, `for` loops and event handlers. find-pkg-prefix is read as
find-pkg-share: moveplan's workspace is not built, and a package's one folder serves for both.
`command` is its command line, not run; the shell quotes of its text are dropped as shlex drops
them, but quoted whitespace still separates words. A group's condition known only at launch time
reaches the actions in it that have no condition of their own. Arguments declared inside a
scoped group stay declared after it. Nothing runs, only the launch file itself is read (at most
MAX_LAUNCH_BYTES) and at most MAX_ENTITIES of its elements are followed.
"""

from __future__ import annotations

import re
import shlex
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ._launch_values import Condition, Declared, LaunchContext, LaunchRecord, Lazy, NodeRecord, Unknown, is_true, text
from .fields import parse_yaml, read_input_text

__all__ = ["MAX_ENTITIES", "MAX_LAUNCH_BYTES", "evaluate_markup_launch"]

MAX_ENTITIES = 5_000
"""Elements (actions, params, args, choices) of one launch file followed: real ones have a few hundred."""

MAX_NESTING = 32
"""Elements in elements, and substitutions in substitutions, followed: real launch files nest a few."""

MAX_LAUNCH_BYTES = 4 * 1024 * 1024
"""Size of an XML or YAML launch file read: real ones are a few kB."""

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
_UNKNOWN = Unknown()


@dataclass(frozen=True)
class _Entity:
    """One element of either frontend: its kind (tag or key), attributes and child entities."""

    kind: str
    attributes: dict[str, Any]
    children: list[_Entity]

    def each(self, kind: str) -> list[_Entity]:
        """Return the children of one kind, in order."""
        return [child for child in self.children if child.kind == kind]


@dataclass
class _Budget:
    """The elements still to be followed; `cut` once some were left out."""

    left: int = MAX_ENTITIES
    cut: bool = False

    def take(self) -> bool:
        """Return True if one more element may be followed (and count it)."""
        if self.left <= 0:
            self.cut = True
            return False
        self.left -= 1
        return True


class _Malformed(Exception):
    """Attribute text the substitution grammar does not parse: its value is Unknown."""


class _Refused(Exception):
    """An XML document type declaration: it declares entities, which a launch file never needs."""


def evaluate_markup_launch(
    path: Path, context: LaunchContext, include: Callable[[Any, Any, Any, LaunchRecord], None],
) -> LaunchRecord:
    """Return what an XML or YAML launch file's nodes are given, following it as `ros2 launch` would.

    Args:
        path: The launch file (`.xml`: XML, `.yaml`/`.yml`: YAML, another name: by its first character).
        context: Its launch arguments; declarations are added to it.
        include: Called with (source, [(name, value), ...], condition, record) for each included
            launch file, in order, after the file is walked.
    """
    record = LaunchRecord(path, context)
    budget = _Budget()
    root = _read(path, budget)
    walker = _Walker(path, record)
    walker.actions(root.children, None)
    if budget.cut:
        record.notes.append(f"{path}: followed its first {MAX_ENTITIES:,} elements (nested {MAX_NESTING} deep) "
                            "only; what they name is used")
    for source, arguments, condition in walker.includes:
        include(source, arguments, condition, record)
    return record


# -- reading either frontend into entities ------------------------------------------------------------

def _read(path: Path, budget: _Budget) -> _Entity:
    """Return a launch file's root entity; ConfigError names the file when it is not a launch file."""
    content = read_input_text(path, MAX_LAUNCH_BYTES)
    xml = path.suffix == ".xml" or (path.suffix not in (".yaml", ".yml") and content.lstrip().startswith("<"))
    return _read_xml(content, path, budget) if xml else _read_yaml(content, path, budget)


class _TreeBuilder(ET.TreeBuilder):
    """ElementTree's tree builder, refusing a document type declaration (and so any entity it declares)."""

    def doctype(self, name: str, pubid: str | None, system: str | None) -> None:
        """Refuse the declaration: returns nothing."""
        raise _Refused


def _read_xml(content: str, path: Path, budget: _Budget) -> _Entity:
    """Return the `<launch>` root of an XML launch file as an entity."""
    parser = ET.XMLParser(target=_TreeBuilder())
    try:
        parser.feed(content)
        root = parser.close()
    except ET.ParseError as exc:
        raise ConfigError(f"{path}: malformed XML: {exc}") from None
    except _Refused:
        raise ConfigError(f"{path}: an XML launch file with a <!DOCTYPE> declaration; moveplan reads none "
                          "(a ROS 2 launch file needs none)") from None
    if not isinstance(root, ET.Element) or root.tag != "launch":
        tag = root.tag if isinstance(root, ET.Element) else "?"
        raise ConfigError(f"{path}: root element <{tag}>, not <launch>: not a ROS 2 XML launch file")
    return _from_xml(root, budget, 0)


def _from_xml(element: ET.Element, budget: _Budget, depth: int) -> _Entity:
    """Return an element as an entity: its attributes, and its child elements as far as the budget goes."""
    children: list[_Entity] = []
    if depth >= MAX_NESTING:
        budget.cut = budget.cut or len(element) > 0
    else:
        for child in element:
            if isinstance(child.tag, str) and budget.take():
                children.append(_from_xml(child, budget, depth + 1))
    return _Entity(element.tag, dict(element.attrib), children)


def _read_yaml(content: str, path: Path, budget: _Budget) -> _Entity:
    """Return the `launch:` list of a YAML launch file as the root entity."""
    document = parse_yaml(content, path)
    if not isinstance(document, dict) or list(document) != ["launch"] or not isinstance(document["launch"], list):
        raise ConfigError(f"{path}: not a ROS 2 YAML launch file (expected one top-level key, launch:, "
                          "holding a list of actions)")
    return _Entity("launch", {}, _yaml_children(document["launch"], budget, 0))


def _yaml_children(items: list[Any], budget: _Budget, depth: int) -> list[_Entity]:
    """Return the entities a list of one-key mappings names (the key is the kind); other items are skipped."""
    entities: list[_Entity] = []
    for item in items:
        if isinstance(item, dict) and len(item) == 1:
            kind, body = next(iter(item.items()))
            if isinstance(kind, str) and budget.take():
                entities.append(_from_yaml(kind, body, budget, depth + 1))
    return entities


def _from_yaml(kind: str, body: Any, budget: _Budget, depth: int) -> _Entity:
    """Return a YAML entity: a list of mappings under a key is child entities of that kind, as launch_yaml reads it."""
    if depth >= MAX_NESTING:
        budget.cut = True
        return _Entity(kind, {}, [])
    if isinstance(body, list):
        return _Entity(kind, {}, _yaml_children(body, budget, depth))
    if not isinstance(body, dict):
        return _Entity(kind, {}, [])
    attributes: dict[str, Any] = {}
    children: list[_Entity] = []
    for key, value in body.items():
        if not isinstance(key, str):
            continue
        if key == "children" and isinstance(value, list):
            children.extend(_yaml_children(value, budget, depth))
        elif isinstance(value, list) and value and all(isinstance(item, dict) for item in value):
            children.extend(_from_yaml(key, item, budget, depth + 1) for item in value if budget.take())
        else:
            attributes[key] = value
    return _Entity(kind, attributes, children)


# -- walking the actions --------------------------------------------------------------------------------

class _Walker:
    """Walks one launch file's actions in order, recording them; see the module docstring for what it follows."""

    def __init__(self, path: Path, record: LaunchRecord) -> None:
        self.path = path
        self.record = record
        self.context = record.context
        self.lets: dict[str, Any] = {}  # name -> value set by a let, in the current scope
        self.includes: list[tuple[Any, Any, Any]] = []  # (source, arguments, condition)

    def actions(self, entities: list[_Entity], inherited: Condition | None) -> None:
        """Walk actions in order, each under its own condition, else the enclosing group's."""
        for entity in entities:
            handler = _ACTIONS.get(entity.kind)
            if handler is not None:
                own = self.condition(entity)
                handler(self, entity, own if own is not None else inherited)

    def condition(self, entity: _Entity) -> Condition | None:
        """Return an entity's `if` or `unless` condition, None without one."""
        for kind in ("if", "unless"):
            if kind in entity.attributes:
                return Condition(kind, (self.value(entity.attributes[kind]),))
        return None

    def state(self, condition: Condition | None) -> bool | Unknown:
        """Return whether a condition holds with the arguments known now; Unknown (naming those it waits for) if not."""
        if condition is None:
            return True
        resolved = text(condition.parts[0], self.context)
        if isinstance(resolved, Unknown):
            return resolved
        truth = is_true(resolved, self.context)
        return _UNKNOWN if truth is None else truth == (condition.kind == "if")

    def declare(self, entity: _Entity, condition: Condition | None) -> None:
        """Record an `arg` declaration: its default and choices (a given argument keeps its value)."""
        name = entity.attributes.get("name")
        if not isinstance(name, str) or self.state(condition) is False:
            return
        default = self.value(entity.attributes.get("default"))
        choices = tuple(str(choice.attributes["value"]) for choice in entity.each("choice")
                        if "value" in choice.attributes)
        self.context.declared[name] = Declared(default, choices or None)

    def let(self, entity: _Entity, condition: Condition | None) -> None:
        """Set an argument for the attributes after it; under a condition of its own not known yet, to Unknown."""
        name = entity.attributes.get("name")
        if not isinstance(name, str) or "value" not in entity.attributes:
            return
        # A group's condition does not matter here: the actions the let reaches are in the group too
        # (an unscoped group's lets are seen to when it ends).
        state = self.state(self.condition(entity))
        if state is False:
            return
        value = state if isinstance(state, Unknown) else self.value(entity.attributes["value"])
        self.lets[name] = _UNKNOWN if isinstance(value, list) else value

    def include(self, entity: _Entity, condition: Condition | None) -> None:
        """Queue an included launch file with its `arg` children, passed on after this file is walked."""
        if "file" not in entity.attributes:
            return
        arguments = [(self.value(arg.attributes["name"]), self.value(arg.attributes["value"]))
                     for arg in entity.each("arg") if "name" in arg.attributes and "value" in arg.attributes]
        self.includes.append((self.value(entity.attributes["file"]), arguments, condition))

    def node(self, entity: _Entity, condition: Condition | None) -> None:
        """Record a node: its package, executable, parameters and arguments."""
        attributes = entity.attributes
        arguments = attributes.get("args")
        self.record.nodes.append(NodeRecord(
            self.value(attributes.get("pkg")), self.value(attributes.get("exec")), self.parameters(entity),
            self.command_line(arguments) if isinstance(arguments, str) else [], condition))

    def process(self, entity: _Entity, condition: Condition | None) -> None:
        """Record an `executable` as the Python side records ExecuteProcess: `ros2 run pkg exe` and the rest."""
        command = entity.attributes.get("cmd")
        words = self.command_line(command) if isinstance(command, str) else []
        self.record.nodes.append(NodeRecord(None, words[:4], [], words[4:], condition))

    def group(self, entity: _Entity, condition: Condition | None) -> None:
        """Walk a group's actions under its condition (none if known false); a scoped group's lets end with it."""
        state = self.state(condition)
        if state is False:
            return
        scoped = text(self.value(entity.attributes.get("scoped", "true")), self.context)
        saved = dict(self.lets)
        self.actions(entity.children, condition)
        if not (isinstance(scoped, str) and scoped.strip().lower() in ("false", "0")):
            self.lets = saved
        elif isinstance(state, Unknown):
            # Lets of an unscoped group that may not run: after it, their values are not known.
            self.lets.update({name: state for name, value in self.lets.items() if saved.get(name, state) is not value})

    def timer(self, entity: _Entity, condition: Condition | None) -> None:
        """Walk a timer's actions: they run later, but the same (a timer has no scope of its own)."""
        if self.state(condition) is not False:
            self.actions(entity.children, condition)

    def parameters(self, entity: _Entity) -> list[Any]:
        """Return a node's parameters as launch_ros makes them: a dict per named `param`, a `from` file's path."""
        items: list[Any] = []
        for param in entity.each("param"):
            if "from" in param.attributes:
                items.append(self.value(param.attributes["from"]))
            elif "name" in param.attributes:
                values: dict[Any, Any] = {}
                self.parameter(param, None, values)
                items.append(values)
        return items

    def parameter(self, param: _Entity, prefix: Any, into: dict[Any, Any]) -> None:
        """Add a `param` to `into`: its value, or its nested params under `prefix.name` (ROS's dotted names)."""
        name = self.value(param.attributes.get("name"))
        key = name if prefix is None else _concat([prefix, ".", name])
        if not isinstance(key, str | Lazy):
            return  # a name that is not text, or not known: no key to look it up by
        nested = param.each("param")
        for inner in nested:
            self.parameter(inner, key, into)
        if not nested and "value" in param.attributes:
            into[key] = self.value(param.attributes["value"])

    # -- values ---------------------------------------------------------------------------------------

    def value(self, raw: Any) -> Any:
        """Return an attribute as a launch value: text with its substitutions read, a YAML scalar as it is."""
        if isinstance(raw, str):
            parts = self.parts(raw)
            return _UNKNOWN if parts is None else _concat(parts)
        if raw is None or isinstance(raw, bool | int | float):
            return raw
        if isinstance(raw, list) and all(isinstance(item, str | bool | int | float) for item in raw):
            return [self.value(item) for item in raw]
        return _UNKNOWN

    def parts(self, raw: str) -> list[Any] | None:
        """Return attribute text as its literal texts and substitution values, in order; None if it does not parse."""
        try:
            parts, _ = _Reader(raw, self).template(0, None, 0)
        except _Malformed:
            return None
        return parts

    def command_line(self, raw: str) -> list[Any]:
        """Return a command line's words, split as ExecuteProcess splits its text (shlex), substitutions kept whole."""
        parts = self.parts(raw)
        return [] if parts is None else _split_command(parts)

    def substitution(self, name: str, arguments: list[list[Any]]) -> Any:
        """Return the value of `$(name arguments...)`: a launch value, Unknown for one not followed."""
        first = _concat(arguments[0]) if arguments else None
        if name == "var" and first is not None:
            if isinstance(first, str) and first in self.lets:
                return self.lets[first]
            return Lazy("arg", (first, _concat(arguments[1]) if len(arguments) > 1 else None))
        if name in ("find-pkg-share", "find-pkg-prefix") and first is not None:
            return Lazy("share", (first,))
        if name == "find-exec" and first is not None:
            return first  # as the Python side reads FindExecutable: its name, which `xacro` words match
        if name == "command" and arguments:
            return _concat(_unquoted(arguments[0]))
        if name == "env" and len(arguments) > 1:
            return _concat(arguments[1])  # the user's environment is not the launch's: only a default is taken
        if name == "dirname":
            return str(self.path.parent)
        if name == "filename":
            return str(self.path)
        return _UNKNOWN


_ACTIONS: dict[str, Callable[[_Walker, _Entity, Condition | None], None]] = {
    "arg": _Walker.declare,
    "let": _Walker.let,
    "include": _Walker.include,
    "node": _Walker.node,
    "executable": _Walker.process,
    "group": _Walker.group,
    "timer": _Walker.timer,
}


class _Reader:
    """Reads one attribute's text by launch's frontend grammar (launch/frontend/grammar.lark)."""

    def __init__(self, source: str, walker: _Walker) -> None:
        self.source = source
        self.walker = walker

    def template(self, index: int, quote: str | None, depth: int) -> tuple[list[Any], int]:
        """Return the parts of the text from `index` up to `quote` (None: the end), and the index there.

        Quotes are literal outside a substitution; a backslash makes the next character literal.
        """
        return self.scan(index, quote, depth, "")

    def scan(self, index: int, quote: str | None, depth: int, stops: str) -> tuple[list[Any], int]:
        """Return the parts of the text from `index` up to `quote`, a character of `stops` or the end, and the index."""
        source = self.source
        parts: list[Any] = []
        literal: list[str] = []
        while index < len(source) and source[index] != quote and source[index] not in stops:
            if source.startswith("$(", index):
                parts.append("".join(literal))
                literal = []
                value, index = self.substitution(index, quote, depth + 1)
                parts.append(value)
            elif source[index] == "\\" and index + 1 < len(source):
                literal.append(source[index + 1])
                index += 2
            else:
                literal.append(source[index])
                index += 1
        parts.append("".join(literal))
        return parts, index

    def substitution(self, index: int, quote: str | None, depth: int) -> tuple[Any, int]:
        """Return the value of the substitution at `index` (`$(`) and the index after its `)`."""
        if depth > MAX_NESTING:
            raise _Malformed
        match = _IDENTIFIER.match(self.source, index + 2)
        if match is None:
            raise _Malformed
        index = match.end()
        arguments: list[list[Any]] = []
        while index < len(self.source) and self.source[index] == " ":
            while index < len(self.source) and self.source[index] == " ":
                index += 1
            if index < len(self.source) and self.source[index] != ")":
                argument, index = self.argument(index, quote, depth)
                arguments.append(argument)
        if index >= len(self.source) or self.source[index] != ")":
            raise _Malformed
        return self.walker.substitution(match.group(), arguments), index + 1

    def argument(self, index: int, quote: str | None, depth: int) -> tuple[list[Any], int]:
        """Return one substitution argument's parts and the index after it.

        Outside quotes an argument may be quoted, and then holds spaces and parentheses; inside
        quotes its arguments may not be (the grammar's single_quoted_value), the other quote is a
        character of it.
        """
        source = self.source
        if quote is None and source[index] in "'\"":
            parts, end = self.template(index + 1, source[index], depth)
            if end >= len(source):
                raise _Malformed  # a quote never closed
            return parts, end + 1
        return self.scan(index, quote, depth, " )")


def _concat(parts: list[Any]) -> Any:
    """Return parts as one value: their text if all are text, the part itself if one, else a Lazy concatenation."""
    kept = [part for part in parts if not (isinstance(part, str) and not part)]
    if all(isinstance(part, str) for part in kept):
        return "".join(kept)
    if len(kept) == 1:
        return kept[0]
    return Lazy("concat", tuple(kept))


def _unquoted(parts: list[Any]) -> list[Any]:
    """Return a command's parts with the shell quotes of their text dropped, as Command's shlex.split drops them."""
    result: list[Any] = []
    quote: str | None = None  # a quote opened before a substitution may close after it
    for part in parts:
        if not isinstance(part, str):
            result.append(part)
            continue
        kept: list[str] = []
        for character in part:
            if quote is None and character in "'\"":
                quote = character
            elif character == quote:
                quote = None
            else:
                kept.append(character)
        result.append("".join(kept))
    return result


def _split_command(parts: list[Any]) -> list[Any]:
    """Return a command line's words as ExecuteProcess._parse_cmdline makes them (substitutions join touching text)."""
    words: list[list[Any]] = []
    word: list[Any] = []

    def close() -> None:
        nonlocal word
        if word:
            words.append(word)
        word = []

    for part in parts:
        if not isinstance(part, str):
            word.append(part)
            continue
        if not part:
            continue
        try:
            tokens = shlex.split(part)
        except ValueError:
            tokens = part.split()  # a quote that a substitution closes: launch fails; its words still serve
        if not tokens:
            close()
            continue
        if part[0].isspace():
            close()
        word.append(tokens[0])
        if len(tokens) > 1:
            close()
            words.extend([token] for token in tokens[1:-1])
            word = [tokens[-1]]
        if part[-1].isspace():
            close()
    close()
    return [_concat(word) for word in words]
