"""The data format of cache entries: JSON for the structure, raw bytes for arrays, checked as it is read.

A cache folder may be shared (a CI cache, a network home) and its files planted by someone
who can compute their checksum: an entry is data that is checked, never code to run (as a
pickle is). Its payload is one line of JSON, then the arrays' bytes. Values are None, bools,
ints, floats, strings, lists, and, as one-key objects, `{"$tuple": [...]}`,
`{"$dict": [[key, value], ...]}`, `{"$bytes": "base64"}`, `{"$array": [dtype, shape, offset,
size]}` (little-endian numbers or bools, at `offset` in the bytes after the JSON line) and
`{"$dataclass": [name, {field: value}]}` for the dataclasses of _DATACLASSES only, rebuilt by
their constructors.
"""

from __future__ import annotations

import base64
import dataclasses
import importlib
import json
import math
from typing import Any

import numpy as np

__all__ = ["decode", "encode"]

# The dataclasses an entry may hold: name -> (module under core/collision/, class). Fixed here, never
# taken from a file: a name the table lacks is refused.
_DATACLASSES = {"SphereSet": ("_sphere_fit", "SphereSet"), "PairTable": ("_pair_tables", "PairTable")}
_DTYPES = frozenset(np.dtype(t).str for t in ("<f8", "<f4", "<i8", "<i4", "<u8", "<u4", "|u1", "|i1", "|b1"))


def encode(value: Any) -> bytes:
    """Return the payload of an entry holding `value`; TypeError for a value the format cannot hold."""
    arrays: list[bytes] = []
    skeleton = json.dumps(_encoded(value, arrays), separators=(",", ":"))
    return skeleton.encode("utf-8") + b"\n" + b"".join(arrays)


def decode(payload: bytes) -> Any:
    """Return the value an entry's payload holds; ValueError (or TypeError) if it is not a well-formed entry."""
    skeleton, newline, blob = payload.partition(b"\n")
    if not newline:
        raise ValueError("no structure line")
    return _decoded(json.loads(skeleton.decode("utf-8")), blob)


def _encoded(value: Any, arrays: list[bytes]) -> Any:
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, list):
        return [_encoded(v, arrays) for v in value]
    if isinstance(value, tuple):
        return {"$tuple": [_encoded(v, arrays) for v in value]}
    if isinstance(value, dict):
        return {"$dict": [[_encoded(k, arrays), _encoded(v, arrays)] for k, v in value.items()]}
    if isinstance(value, bytes):
        return {"$bytes": base64.b64encode(value).decode("ascii")}
    if isinstance(value, np.ndarray) and value.dtype.newbyteorder("<").str in _DTYPES:
        data = np.ascontiguousarray(value, dtype=value.dtype.newbyteorder("<")).tobytes()
        offset = sum(map(len, arrays))
        arrays.append(data)
        return {"$array": [value.dtype.newbyteorder("<").str, list(value.shape), offset, len(data)]}
    name = type(value).__name__
    if dataclasses.is_dataclass(value) and name in _DATACLASSES and _dataclass(name) is type(value):
        fields = {f.name: _encoded(getattr(value, f.name), arrays) for f in dataclasses.fields(value)}
        return {"$dataclass": [name, fields]}
    raise TypeError(f"a cache entry cannot hold a {name} (add a dataclass to _cache_codec._DATACLASSES)")


def _decoded(node: Any, blob: bytes) -> Any:
    if node is None or isinstance(node, bool | int | float | str):
        return node
    if isinstance(node, list):
        return [_decoded(n, blob) for n in node]
    if not isinstance(node, dict) or len(node) != 1:
        raise ValueError("malformed structure")
    tag, content = next(iter(node.items()))
    if tag == "$tuple" and isinstance(content, list):
        return tuple(_decoded(n, blob) for n in content)
    if tag == "$dict" and isinstance(content, list) and all(isinstance(p, list) and len(p) == 2 for p in content):
        return {_decoded(k, blob): _decoded(v, blob) for k, v in content}
    if tag == "$bytes" and isinstance(content, str):
        return base64.b64decode(content.encode("ascii"), validate=True)
    if tag == "$array" and isinstance(content, list) and len(content) == 4:
        dtype, shape, offset, size = content
        return _array(dtype, shape, offset, size, blob)
    if tag == "$dataclass" and isinstance(content, list) and len(content) == 2 and content[0] in _DATACLASSES \
            and isinstance(content[1], dict):
        cls = _dataclass(content[0])
        if set(content[1]) != {f.name for f in dataclasses.fields(cls) if f.init}:
            raise ValueError(f"{content[0]} fields do not match")
        return cls(**{k: _decoded(v, blob) for k, v in content[1].items()})
    raise ValueError(f"malformed {tag!r} node")


def _array(dtype: Any, shape: Any, offset: Any, size: Any, blob: bytes) -> np.ndarray:
    """Return a copy of the array at `offset` in `blob`, once its dtype, shape and extent are checked."""
    if dtype not in _DTYPES or not isinstance(shape, list) or not all(
            isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in [*shape, offset, size]):
        raise ValueError("malformed array")
    if math.prod(shape) * np.dtype(dtype).itemsize != size or offset + size > len(blob):
        raise ValueError("array extent does not match its shape or the entry")
    return np.frombuffer(blob, dtype=dtype, count=math.prod(shape), offset=offset).reshape(shape).copy()


def _dataclass(name: str) -> type:
    module, cls = _DATACLASSES[name]
    found: type = getattr(importlib.import_module(f"{__package__}.{module}"), cls)
    return found
