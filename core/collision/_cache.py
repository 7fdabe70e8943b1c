"""Per-robot data computed once and kept on disk between runs (fitted spheres, distance tables).

Entries are pickles named by a digest of what they were computed from, in
$MOVEPLAN_CACHE_DIR, else $XDG_CACHE_HOME/moveplan, else ~/.cache/moveplan. An entry
that cannot be read is recomputed; one that cannot be written is skipped.
"""

from __future__ import annotations

import hashlib
import logging
import os
import pickle
from pathlib import Path
from typing import Any

import pinocchio as pin

__all__ = ["digest", "path", "read", "write"]

logger = logging.getLogger(__name__)


def digest(text: str, geometry: pin.GeometryModel) -> str:
    """Return a hex digest of `text` and the bytes of every mesh file `geometry` loaded."""
    hasher = hashlib.sha256(text.encode())
    for obj in geometry.geometryObjects:
        if obj.meshPath and Path(obj.meshPath).is_file():
            hasher.update(Path(obj.meshPath).read_bytes())
    return hasher.hexdigest()


def path(name: str) -> Path:
    """Return where the cache entry `name` is kept."""
    if os.environ.get("MOVEPLAN_CACHE_DIR"):
        return Path(os.environ["MOVEPLAN_CACHE_DIR"]) / name
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "moveplan" / name


def read(where: Path, kind: type) -> Any:
    """Return the object cached at `where` if it is a `kind`, else None (missing, unreadable or stale)."""
    try:
        with where.open("rb") as stream:
            value = pickle.load(stream)  # noqa: S301 - our own cache file, written by `write`
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ValueError, ImportError):
        return None
    return value if isinstance(value, kind) else None


def write(where: Path, value: Any) -> None:
    """Cache `value` at `where`, atomically; a cache that cannot be written is skipped."""
    try:
        where.parent.mkdir(parents=True, exist_ok=True)
        partial = where.with_name(f"{where.name}.{os.getpid()}.partial")
        with partial.open("wb") as stream:
            pickle.dump(value, stream)
        partial.replace(where)
    except OSError as exc:
        logger.debug("cache entry %s not written: %s", where, exc)
