"""Tables for people: headers with their units, and nothing cut to fit the terminal.

Rich fits a table that is too wide by cutting its cells ("wrist_1_j…"), which hides the very names
a report is about. A table that does not fit is printed instead as one line per row, each cell
after its header, which the terminal wraps between words. Printed to a file or a pipe (a CI log),
every table takes that form and no line is wrapped: one record, one line, whatever `COLUMNS` says.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from typing import IO, Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

__all__ = ["console", "emit", "is_terminal", "number", "show", "table"]


def is_terminal(stream: IO[str] | None) -> bool:
    """Return True if `stream` is a terminal.

    Not rich's `is_terminal`, which FORCE_COLOR (set in many CI jobs for coloured logs) makes True.
    """
    try:
        return stream is not None and stream.isatty()
    except ValueError:  # closed
        return False


class _Output(Console):
    """rich's Console, except that on a file or a pipe it wraps no line: a log is read by grep and editors."""

    def print(self, *objects: Any, soft_wrap: bool | None = None, **options: Any) -> None:
        """Print as rich does; by default soft-wrapped (no line broken) when not on a terminal."""
        super().print(*objects, soft_wrap=not is_terminal(self.file) if soft_wrap is None else soft_wrap, **options)


console = _Output()
"""Where people's output goes (stdout: --json, which prints no table, has it to itself)."""


def table(title: str, columns: Sequence[str], left: int = 1, **options: Any) -> Table:
    """Return an empty table with this title and these headers; its first `left` columns (names) align left.

    Titles and headers are escaped: rich would read a unit such as "[ms]" as markup and drop it.
    """
    result = Table(title=escape(title), **options)
    for k, column in enumerate(columns):
        result.add_column(escape(column), justify="left" if k < left else "right")
    return result


def show(rows: Table) -> None:
    """Print `rows` as a table on a terminal it fits, else one line per row with every cell whole."""
    if is_terminal(console.file):
        natural = console.measure(rows, options=console.options.update_width(1_000_000)).maximum  # not clamped
        if natural <= console.width:
            console.print(rows)
            return
    if rows.title:
        console.print(rows.title)
    headers = [str(column.header) for column in rows.columns]
    for cells in zip(*(column.cells for column in rows.columns), strict=True):
        name, *rest = (str(cell) for cell in cells)
        pairs = "  ".join(f"{header} {cell}" if header else cell
                          for header, cell in zip(headers[1:], rest, strict=True) if cell)
        console.print(f"{name}: {pairs}" if name else f"  {pairs}")


def emit(document: dict[str, Any]) -> None:
    """Print one JSON document on stdout."""
    print(json.dumps(document, indent=2))


def number(value: float | None, spec: str) -> str:
    """Return a document's number formatted, or "inf/nan" for its null: not finite (a diverged plant)."""
    return "inf/nan" if value is None else format(value, spec)


# Control characters a hostile file put into a name would reach the terminal: shown escaped, as repr shows them.
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def escape_controls(text: str) -> str:
    """Return `text` with its control characters (escape sequences, newlines, bells) written as escapes."""
    return _CONTROL.sub(lambda found: repr(found.group())[1:-1], text)
