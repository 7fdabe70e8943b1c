"""Per-robot data computed once and kept on disk between runs (fitted spheres, distance tables).

Entries are files named by a digest of what they were computed from, in
$MOVEPLAN_CACHE_DIR, else $XDG_CACHE_HOME/moveplan, else ~/.cache/moveplan.

An entry is a header line, `moveplan-cache FORMAT SHA256` and a newline, then the payload; the
sha256 is the payload's. The payload is data checked as it is read (_cache_codec.py: JSON and raw
arrays), never a pickle: a shared cache folder must not let whoever writes to it run code here,
and the checksum guards against damage only (anyone can compute it). An entry that is missing is
computed silently; one that cannot be trusted (another format, a checksum that does not match, a
payload that does not decode or holds the wrong type, a file over _MOST_BYTES) is recomputed and
replaced, with one warning. An entry that cannot be written (a read-only folder, a full disk) is
skipped and leaves no partial file. The value read back is the value written, so a plan is the
same with a cold or warm cache.
"""

from __future__ import annotations

import contextlib
import functools
import glob
import hashlib
import logging
import os
import stat
import tempfile
import time
from pathlib import Path
from typing import Any, TypeVar

import pinocchio as pin

from ._cache_codec import decode, encode

__all__ = ["FORMAT", "announce", "announce_compilation", "digest", "path", "read", "write"]

logger = logging.getLogger(__name__)

FORMAT = 3
"""Version of the entry layout; bump it when the layout changes (the old entries are rebuilt)."""

_MAGIC = b"moveplan-cache"
_STALE_S = 3600.0  # a partial file this old belongs to no running writer
_MOST_BYTES = 256 * 1024 * 1024  # a robot's entries are kilobytes; a planted file must not fill memory


def digest(text: str, geometry: pin.GeometryModel) -> str:
    """Return a hex digest of `text` and the bytes of every mesh file `geometry` loaded."""
    hasher = hashlib.sha256(text.encode())
    for obj in geometry.geometryObjects:
        if not obj.meshPath:
            continue
        try:
            status = os.stat(obj.meshPath)  # one call, no Path: a benchmark digests a robot's meshes per problem
        except OSError:
            continue
        if stat.S_ISREG(status.st_mode):
            hasher.update(_file_digest(obj.meshPath, status.st_mtime_ns, status.st_size))
    return hasher.hexdigest()


@functools.lru_cache(maxsize=1024)
def _file_digest(file: str, mtime_ns: int, size: int) -> bytes:
    """Return the sha256 of a file's bytes; keyed by its time and size too, read again once it changes.

    A benchmark sets up a robot's checks for every problem: reading its meshes each time cost ~5 ms.
    """
    return hashlib.sha256(Path(file).read_bytes()).digest()


def path(name: str) -> Path:
    """Return where the cache entry `name` is kept."""
    if os.environ.get("MOVEPLAN_CACHE_DIR"):
        return Path(os.environ["MOVEPLAN_CACHE_DIR"]) / name
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "moveplan" / name


_Entry = TypeVar("_Entry")

def read(where: Path, kind: type[_Entry]) -> _Entry | None:
    """Return the object cached at `where` if it is a trustworthy `kind`, else None (missing or rebuilt)."""
    try:
        if where.stat().st_size > _MOST_BYTES:
            _untrusted(where, f"larger than {_MOST_BYTES:,} bytes")
            return None
        data = where.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as exc:
        _untrusted(where, exc.strerror or str(exc))
        return None
    header, newline, payload = data.partition(b"\n")
    fields = header.split(b" ")
    if not newline or len(fields) != 3 or fields[0] != _MAGIC or fields[1] != str(FORMAT).encode():
        _untrusted(where, f"not a moveplan cache entry of format {FORMAT}: another version wrote it, or damaged")
        return None
    if fields[2] != hashlib.sha256(payload).hexdigest().encode():
        _untrusted(where, "checksum mismatch (a damaged file)")
        return None
    try:
        value = decode(payload)
    except Exception as exc:  # noqa: BLE001 - whatever a malformed payload raises, the entry is rebuilt
        _untrusted(where, f"{type(exc).__name__}: {exc}")
        return None
    if not isinstance(value, kind):
        _untrusted(where, f"holds a {type(value).__name__}, not a {kind.__name__}")
        return None
    return value


def announce(work: str, where: Path) -> None:
    """Log at INFO, before it starts, one-time work (seconds) whose result is cached at `where`; return None.

    A first run on a fresh machine would otherwise sit silent for seconds; the command line shows these lines.
    """
    logger.info("%s (once per robot; cached in %s)", work, where.parent)


def announce_compilation(work: str, compiled: bool) -> None:
    """Log at INFO, before it starts, a compilation of numba kernels unless they are `compiled` already; return None.

    Decided by numba's cache, not by the clock: cached kernels load in a fraction of a second, but
    a busy machine can take longer and compiles nothing; a fresh install compiles for tens of seconds.
    """
    if not compiled:
        logger.info("%s", work)


def _untrusted(where: Path, why: str) -> None:
    logger.warning("cache entry %s cannot be used (%s): recomputing it", where, why)


def write(where: Path, value: Any) -> None:
    """Cache `value` at `where`, atomically; a cache that cannot be written is skipped, leaving no partial file.

    Concurrent writers of one entry each write their own temporary file (a random name beside
    `where`) and rename it: the entry is always one complete file, the same whichever wins.
    """
    payload = encode(value)
    header = b"%s %d %s\n" % (_MAGIC, FORMAT, hashlib.sha256(payload).hexdigest().encode())
    try:
        where.parent.mkdir(parents=True, exist_ok=True)
        descriptor, name = tempfile.mkstemp(prefix=f"{where.name}.", suffix=".partial", dir=where.parent)
    except OSError as exc:
        logger.debug("cache entry %s not written: %s", where, exc)
        return
    partial = Path(name)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(header + payload)
        partial.replace(where)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            partial.unlink()
        if not isinstance(exc, OSError):
            raise
        logger.debug("cache entry %s not written: %s", where, exc)
        return
    _sweep(where)


def _sweep(where: Path) -> None:
    """Remove partial files of `where` left by killed runs (or older versions); a writer's own is younger."""
    stale = time.time() - _STALE_S
    for leftover in where.parent.glob(f"{glob.escape(where.name)}.*.partial"):
        with contextlib.suppress(OSError):
            if leftover.stat().st_mtime < stale:
                leftover.unlink()
