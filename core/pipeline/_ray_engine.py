"""Work spread over an existing Ray cluster: long-lived actors, each keeping what its items share loaded.

Ray is an optional extra (`pip install moveplan[ray]`), imported only here and only when an
engine asks for it. The cluster is the user's: its address comes from `--ray-address` or
RAY_ADDRESS, as Ray's own tools take it; moveplan connects to it and disconnects when done,
never starting or stopping one. The cluster's nodes need moveplan installed and the files at
the paths the items name (a shared file system).
"""

from __future__ import annotations

import logging
import os
import socket
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from ..errors import InputError, UsageError

__all__ = ["CONNECT_S", "ray_cluster", "ray_map"]

CONNECT_S = 5.0
"""Seconds to wait for the cluster's head to answer before giving up: a safety limit, not a result."""


@contextmanager
def ray_cluster(address: str | None) -> Iterator[Any]:
    """Yield the `ray` module connected to the cluster at `address` (None: RAY_ADDRESS); disconnect after.

    Raises:
        UsageError: Ray is not installed, or no address is given either way.
        InputError: The cluster cannot be reached at the address.
    """
    try:
        import ray
    except ImportError:
        raise UsageError("--engine ray needs Ray, an optional extra: pip install 'moveplan[ray]'") from None
    address = address or os.environ.get("RAY_ADDRESS")
    if not address:
        raise UsageError("--engine ray runs on an existing Ray cluster: give --ray-address HOST:PORT or set "
                         "RAY_ADDRESS (`ray start --head` starts one on this machine)")
    _reachable(address)
    try:
        ray.init(address=address, logging_level=logging.ERROR, log_to_driver=False, configure_logging=False)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        raise InputError(f"--ray-address {address}: cannot connect to a Ray cluster there: {exc}") from None
    try:
        yield ray
    finally:
        ray.shutdown()


def _reachable(address: str) -> None:
    """Raise InputError if nothing answers at a HOST:PORT address within CONNECT_S: Ray would retry for minutes.

    Other forms Ray takes ("auto", ray://...) are left to Ray.
    """
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit() or "://" in address:
        return
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_S).close()
    except OSError as exc:
        raise InputError(f"--ray-address {address}: cannot connect to a Ray cluster there: "
                         f"{exc.strerror or exc}") from None


def ray_map(
    ray: Any, make: Callable[[], Any], tasks: Sequence[Any], workers: int | None, arrived: Callable[[Any], None]
) -> None:
    """Run `tasks` on actors that `make()` builds (`workers` of them, None: one per CPU of the cluster).

    Each actor is an object with a `run(task)` method, kept for all its tasks; `arrived` gets
    every result as it comes, in completion order.
    """
    count = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
    actor = ray.remote(num_cpus=1)(_Actor)
    actors = [actor.remote(make) for _ in range(max(1, min(count, len(tasks))))]
    pool = ray.util.ActorPool(actors)
    for result in pool.map_unordered(lambda a, task: a.run.remote(task), list(tasks)):
        arrived(result)


class _Actor:
    """A Ray actor holding one worker object (`make()`'s) for all the tasks it is given."""

    def __init__(self, make: Callable[[], Any]) -> None:
        """Build the worker in the actor's process."""
        self._worker = make()

    def run(self, task: Any) -> Any:
        """Return the worker's result for `task`."""
        return self._worker.run(task)
