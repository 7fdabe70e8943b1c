"""Whether numba's disk cache already holds the sphere filter's kernels, found without importing numba.

Where the kernels could not be compiled ahead of time (core/_native.py), numba's JIT runs them:
building the filter loads them in under a second when numba has cached them, and compiles them
for 15-60 s when it has not (a fresh install, a new numba). A one-shot command asks first,
so that it can stay with coal rather than pay a compilation a short plan does not need
(core/pipeline/_checks.py). Importing numba to ask would cost half a second itself, so the index
files are looked up where numba keeps them, as numba.core.caching names them.

An index is pickled, and unpickling a file runs whatever code it names. numba unpickles its own
cache when it loads the kernels: that is numba's trust in the folder it caches in (the
__pycache__ beside moveplan's source, or NUMBA_CACHE_DIR), where the modules compiled ahead of
time are kept too. This look unpickles nothing: it
compares bytes, so asking whether the kernels are cached runs no code from that folder.
"""

from __future__ import annotations

import hashlib
import pickle
import sys
from functools import cache
from importlib import metadata
from pathlib import Path

from .._native import cache_folder

__all__ = ["kernels_cached"]

_CORE = Path(__file__).resolve().parent.parent
_ENTRY_POINTS = {"collision/_kernels.py": ("classify", "edge"), "collision/_clearance.py": ("certify",),
                 "collision/_states.py": ("trajectory_states",), "timing/_compiled.py": ("speeds", "peaks"),
                 "trajectory.py": ("_velocity_extreme",)}
"""The kernels a filter loads, called from Python, by source file under core/; numba caches each under its own index."""


@cache
def kernels_cached() -> bool:
    """Return True if numba's cache holds an index for every kernel, written by this numba for its current source.

    False where it cannot tell (numba's user-wide cache, an unreadable index): the caller then
    treats the kernels as uncompiled, which costs speed, never a wrong answer.
    """
    try:
        version = metadata.version("numba")
        for name, functions in _ENTRY_POINTS.items():
            source = _CORE / name
            folder = cache_folder(source.parent)
            if folder is None:
                return False
            text = source.read_bytes()
            stamp, lines = hashlib.sha256(text).digest(), _first_lines(text)
            for function in functions:
                index = folder / f"{source.stem}.{function}-{lines[function]}.py{sys.version_info[0]}" \
                                 f"{sys.version_info[1]}.nbi"
                if not _index_matches(index, version, stamp):
                    return False
    except (OSError, KeyError, metadata.PackageNotFoundError):
        return False
    return True


def _first_lines(source: bytes) -> dict[str, int]:
    """Return each top-level function's first line (its first decorator's), numba's co_firstlineno.

    A line scan, not ast (a tenth of the time): the kernels' decorators each fit on one line.
    """
    lines, first = source.split(b"\n"), {}
    for number, line in enumerate(lines):
        if line.startswith(b"def "):
            top = number
            while top > 0 and lines[top - 1].startswith(b"@"):
                top -= 1
            first[line[4:].split(b"(")[0].decode()] = top + 1
    return first


def _index_matches(index: Path, version: str, stamp: bytes) -> bool:
    """Return True if `index` was written by numba `version` for the source whose sha256 is `stamp`.

    An index is the numba version pickled (numba: `pickle.dump(version, f, protocol=-1)`), then the
    pickled (stamp, overloads). The first is compared as bytes with the same pickling of `version`,
    and the stamp's 32 bytes are looked for in the rest: nothing is unpickled.
    """
    data = index.read_bytes()
    expected = pickle.dumps(version, protocol=pickle.HIGHEST_PROTOCOL)
    return data.startswith(expected) and stamp in data[len(expected):]
