"""Map moveplan errors to one line on stderr (or a JSON document) and the documented exit code."""

from __future__ import annotations

import json
import logging
import sys
import traceback
from collections.abc import Iterator
from contextlib import contextmanager

import typer

from moveplan.core.errors import MoveplanError

__all__ = ["exit_codes"]

logger = logging.getLogger("moveplan")


@contextmanager
def exit_codes(as_json: bool) -> Iterator[None]:
    """Turn a MoveplanError into its exit code and an unexpected exception into exit 1, no traceback."""
    try:
        yield
    except MoveplanError as exc:
        _report(exc.exit_code, exc.kind, str(exc), as_json)
    except KeyboardInterrupt:
        _report(130, "Interrupted", "interrupted", as_json)
    except Exception as exc:  # noqa: BLE001 - the last line of defence: a bug must still exit cleanly
        logger.debug("internal error", exc_info=True)
        detail = traceback.extract_tb(exc.__traceback__)[-1]
        message = (f"internal error (a bug in moveplan, please report it): {type(exc).__name__}: {exc} "
                   f"[{detail.filename.rsplit('/', 1)[-1]}:{detail.lineno}]")
        _report(1, "InternalError", message, as_json)


def _report(code: int, kind: str, message: str, as_json: bool) -> None:
    if as_json:
        print(json.dumps({"ok": False, "error": {"exit_code": code, "kind": kind, "message": message}}))
    else:
        print(f"moveplan: error: {message}", file=sys.stderr)
    raise typer.Exit(code)
