"""Work spread over processes on this machine: long-lived workers taking tasks from one queue.

The counterpart of _ray_engine.ray_map: a worker is what `make()` builds, kept for every task
its process takes; `run(task)` returns a task's result. Processes are spawned (no state of
this one is inherited), so `make`, the tasks and the results must pickle. A worker logs at this
process's levels, and its records are handled here, by this process's handlers: a notice of
one-time work or a warning reads as the command's own.
"""

from __future__ import annotations

import logging
import logging.handlers
import multiprocessing
import queue as queue_module
import traceback
from collections.abc import Callable, Sequence
from typing import Any

from ..errors import InputError, MoveplanError, NoPlan, UsageError

__all__ = ["process_map"]


def process_map(make: Callable[[], Any], tasks: Sequence[Any], jobs: int, arrived: Callable[[Any], None]) -> None:
    """Run `tasks` on workers `make()` builds, in `jobs` spawned processes; `arrived` gets each result as it comes.

    Raises:
        MoveplanError: A worker raised one (re-raised here as its class of exit code), or died.
    """
    context = multiprocessing.get_context("spawn")
    queued, results = context.Queue(), context.Queue()
    for task in tasks:
        queued.put(task)
    workers = [context.Process(target=_serve, args=(make, queued, results, _levels()), daemon=True)
               for _ in range(max(1, min(jobs, len(tasks))))]
    for _ in workers:
        queued.put(None)  # one stop sign each, behind the work
    for process in workers:
        process.start()
    done = 0
    try:
        while done < len(workers):
            try:
                kind, payload = results.get(timeout=1.0)
            except queue_module.Empty:
                dead = [p.exitcode for p in workers if not p.is_alive() and p.exitcode != 0]
                if dead:
                    raise MoveplanError(f"a worker process died (exit code {dead[0]})") from None
                continue
            if kind == "result":
                arrived(payload)
            elif kind == "log":
                logging.getLogger(payload.name).handle(payload)
            elif kind == "done":
                done += 1
            else:
                raise _rebuilt(payload)
    finally:
        for process in workers:
            if process.is_alive() and done < len(workers):
                process.terminate()
            process.join()


def _rebuilt(payload: dict[str, Any]) -> Exception:
    """Return the error a worker reported, as the moveplan error class of its exit code."""
    by_code: dict[int, type[MoveplanError]] = {2: UsageError, 3: InputError, 4: NoPlan}
    if payload["exit_code"] in by_code:
        return by_code[payload["exit_code"]](payload["message"])
    return RuntimeError(f"worker process failed: {payload['message']}\n{payload['traceback']}")


def _levels() -> dict[str, int]:
    """Return the logging levels set in this process: the root logger's (under "") and each other logger's set one."""
    loggers = logging.Logger.manager.loggerDict.items()
    return {"": logging.getLogger().level,
            **{name: logger.level for name, logger in loggers if isinstance(logger, logging.Logger) and logger.level}}


class _Forward(logging.handlers.QueueHandler):
    """Puts each record on the results queue for the parent to handle, its message formatted (QueueHandler's)."""

    def enqueue(self, record: logging.LogRecord) -> None:
        """Put `record` on the queue as a ("log", record) result."""
        self.queue.put_nowait(("log", record))


def _serve(make: Callable[[], Any], queued: Any, results: Any, levels: dict[str, int]) -> None:
    """Build the worker, run tasks from `queued` until a stop sign, putting each result and log record on `results`."""
    for name, level in levels.items():
        logging.getLogger(name or None).setLevel(level)
    logging.getLogger().addHandler(_Forward(results))
    try:
        worker = make()
        while (task := queued.get()) is not None:
            results.put(("result", worker.run(task)))
    except Exception as exc:  # noqa: BLE001 - reported to the parent, which raises it there
        results.put(("error", {"exit_code": getattr(exc, "exit_code", 1), "message": str(exc),
                               "traceback": traceback.format_exc()}))
        return
    results.put(("done", None))
