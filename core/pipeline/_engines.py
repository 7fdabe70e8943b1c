"""Where a batch's work runs: spawned processes on this machine, or actors on an existing Ray cluster.

The batch check and the benchmark hand their tasks here; the engines themselves are
_local_engine.process_map and _ray_engine.ray_map.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..errors import UsageError

__all__ = ["ENGINES", "check_engine", "spread"]

ENGINES = ("local", "ray")
"""Where a batch runs: processes on this machine, or actors on an existing Ray cluster."""


def check_engine(engine: str) -> None:
    """Return None if `engine` is one of ENGINES; else raise UsageError naming --engine."""
    if engine not in ENGINES:
        raise UsageError(f"--engine: expected local or ray, got '{engine}'")


def spread(
    make: Callable[[], Any], tasks: Sequence[Any], jobs: int | None, engine: str, ray_address: str | None,
    arrived: Callable[[Any], None],
) -> None:
    """Run `tasks` on workers `make()` builds; `arrived` gets each result as it comes; return None.

    Engine "local": `jobs` spawned processes (None: 1). Engine "ray": `jobs` actors (None: one
    per CPU of the cluster at `ray_address`, or RAY_ADDRESS).

    Raises:
        UsageError: An unknown engine; for "ray", Ray missing or no cluster address.
        InputError: The Ray cluster cannot be reached.
    """
    check_engine(engine)
    if engine == "ray":
        from ._ray_engine import ray_cluster, ray_map

        with ray_cluster(ray_address) as ray:
            ray_map(ray, make, tasks, jobs, arrived)
    else:
        from ._local_engine import process_map

        process_map(make, tasks, jobs or 1, arrived)
