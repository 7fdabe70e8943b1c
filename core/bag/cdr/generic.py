"""The schema-driven CDR encoder: any message, given as a dict, encoded from its ros2msg schema text.

The encoder the `*_cdr` twins are measured against, and the one the few small messages
(std_msgs/String, the scene's MarkerArray) take. It writes what mcap_ros2's encoder writes
(tests/bag/test_generic_cdr.py compares the two on every shipped type): a field left out takes
its definition's default, else zero, "" or False; a missing nested message is written with
its defaults; values are coerced with float(), int(), bool() and str(); a fixed-size array
is padded with defaults or cut to its size, a bounded one cut to its bound; and
builtin_interfaces Time and Duration are {uint32 sec, uint32 nanosec} where the schema
does not define them.
"""

from __future__ import annotations

import array
from collections.abc import Callable
from functools import cache
from typing import Any

from ._primitives import CdrWriter
from .definitions import Field, parse_definitions

__all__ = ["Encoder", "encoder"]

Encoder = Callable[[Any], bytes]
_Write = Callable[[CdrWriter, Any], None]

# struct code and size of each fixed-size primitive; a bool is one byte, 1 or 0.
_SCALARS = {
    "bool": ("B", 1), "byte": ("B", 1), "char": ("b", 1), "int8": ("b", 1), "uint8": ("B", 1),
    "int16": ("h", 2), "uint16": ("H", 2), "int32": ("i", 4), "uint32": ("I", 4),
    "int64": ("q", 8), "uint64": ("Q", 8), "float32": ("f", 4), "float64": ("d", 8),
}
_TIME = (Field("sec", "uint32"), Field("nanosec", "uint32"))


@cache
def encoder(msgtype: str, schema_text: bytes) -> Encoder:
    """Return the CDR encoder of `msgtype` ("pkg/msg/Type") built from its schema text.

    Cached: building parses the whole schema text.

    Raises:
        ValueError: The schema text is malformed or lacks a definition a field needs.

    """
    definitions = {
        "builtin_interfaces/Time": _TIME,
        "builtin_interfaces/Duration": _TIME,
        **parse_definitions(msgtype, schema_text.decode()),
    }
    write = _Builder(definitions).message(msgtype)

    def encode(message: Any) -> bytes:
        writer = CdrWriter()
        write(writer, message)
        return writer.data()

    return encode


def _get(message: Any, name: str) -> Any:
    """Return field `name` of a dict or of an object with attributes, None if it has none."""
    try:
        return message[name]
    except (KeyError, TypeError):
        return getattr(message, name, None)


class _Builder:
    """Builds the writers of a schema's messages, each message type once."""

    def __init__(self, definitions: dict[str, tuple[Field, ...]]) -> None:
        self.definitions = definitions
        self.writers: dict[str, _Write] = {}

    def message(self, msgtype: str) -> _Write:
        """Return the writer of a `msgtype` message: a dict, an object with its fields, or None."""
        if msgtype not in self.writers:
            fields = self.definitions.get(msgtype)
            if fields is None:
                raise ValueError(f"the schema has no definition of '{msgtype}'")
            self.writers[msgtype] = self._fields(fields)
        return self.writers[msgtype]

    def _fields(self, fields: tuple[Field, ...]) -> _Write:
        if not fields:
            # ROS 2 gives an empty message one uint8 member, so that its IDL is valid.
            return lambda writer, _: writer.scalars("B", 1, (0,))
        writers = [(field.name, self._field(field)) for field in fields]

        def write(writer: CdrWriter, message: Any) -> None:
            for name, write_field in writers:
                write_field(writer, _get(message, name))

        return write

    def _field(self, field: Field) -> _Write:
        if field.primitive:
            return _primitive_array(field) if field.array else _primitive(field)
        nested = self.message(field.type)
        if not field.array:
            return lambda writer, value: nested(writer, value or {})

        def write_array(writer: CdrWriter, values: Any) -> None:
            values = [] if values is None else values
            if not isinstance(values, list):
                raise _wrong_value(field, f"a {type(values).__name__}")
            for value in _sized(field, values, [{}], writer):
                nested(writer, value)

        return write_array


def _sized(field: Field, values: Any, padding: Any, writer: CdrWriter) -> Any:
    """Return `values` padded with `padding` (one element) or cut to a fixed size, else cut to a bound.

    A fixed-size array is written without a length; any other gets its uint32 length
    written to `writer` here.
    """
    if field.fixed:
        assert field.size is not None
        return values[: field.size] + padding * (field.size - len(values))
    if field.bounded and field.size is not None and len(values) > field.size:
        values = values[: field.size]
    writer.uint32(len(values))
    return values


def _coerce(field: Field) -> Callable[[Any], Any]:
    """Return the function that turns a field's value (None if missing) into the value written."""
    if field.type in ("string", "wstring"):
        text = field.default if field.default is not None else ""
        return lambda value: str(value) if value is not None else text
    convert: Callable[[Any], Any]
    if field.type in ("float32", "float64"):
        convert, zero = float, 0.0
    elif field.type == "bool":
        convert, zero = bool, False
    else:
        convert, zero = int, 0
    default = field.default if field.default is not None else zero
    return lambda value: convert(value) if value is not None else default


def _wrong_value(field: Field, given: str) -> ValueError:
    """Return the error for an array field given a value it cannot take."""
    return ValueError(f"field '{field.name}' has type {field.type}[] but was given {given}")


def _unsupported(field: Field) -> _Write:
    """Return a writer that raises NotImplementedError: the field's type has no CDR writer here."""

    def write(writer: CdrWriter, value: Any) -> None:
        raise NotImplementedError(f"writing {field.type} fields is not implemented ('{field.name}')")

    return write


def _primitive(field: Field) -> _Write:
    """Return the writer of a primitive field that is not an array."""
    coerce = _coerce(field)
    if field.type == "string":
        return lambda writer, value: writer.string(coerce(value))
    if field.type not in _SCALARS:
        return _unsupported(field)  # wstring, and ROS 1's time and duration
    code, size = _SCALARS[field.type]
    return lambda writer, value: writer.scalars(code, size, (coerce(value),))


def _primitive_array(field: Field) -> _Write:
    """Return the writer of an array of primitives; bytes go as they are into uint8 and byte arrays."""
    if field.type != "string" and field.type not in _SCALARS:
        return _unsupported(field)
    coerce = _coerce(field)
    code, size = _SCALARS.get(field.type, ("", 0))

    def write(writer: CdrWriter, values: Any) -> None:
        values = [] if values is None else values
        if isinstance(values, bytes) or (isinstance(values, array.array) and values.typecode == "B"):
            if field.type not in ("uint8", "byte"):
                raise _wrong_value(field, "bytes, which fit only uint8[] and byte[]")
            writer.raw(_sized(field, bytes(values), b"\0", writer))
            return
        if not isinstance(values, list | tuple | array.array):
            raise _wrong_value(field, f"a {type(values).__name__}")
        coerced = [coerce(value) for value in _sized(field, list(values), [None], writer)]
        if field.type == "string":
            for text in coerced:
                writer.string(text)
        else:
            writer.scalars(code, size, coerced)

    return write
