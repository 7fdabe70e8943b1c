"""A process-wide memo of the latest few values by key: what a process's problems of one robot share."""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TypeVar

__all__ = ["kept"]

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


def kept(cache: dict[K, V], key: K, make: Callable[[], V], most: int = 8) -> V:
    """Return `cache[key]`, made by `make` and kept if missing; past `most` values the oldest goes.

    A `make` that raises keeps nothing: the next call tries again, and raises again.
    """
    if key not in cache:
        value = make()
        if len(cache) >= most:
            del cache[next(iter(cache))]
        cache[key] = value
    return cache[key]
