"""Tables for people: headers with their units, and nothing cut to fit the terminal.

Rich fits a table that is too wide by cutting its cells ("wrist_1_j…"), which hides the very names
a report is about. A table that does not fit is printed instead as one line per row, each cell
after its header, which the terminal wraps between words.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

__all__ = ["console", "emit", "number", "show", "table"]

console = Console()
"""Where people's output goes (stdout: --json, which prints no table, has it to itself)."""


def table(title: str, columns: Sequence[str], left: int = 1, **options: Any) -> Table:
    """Return an empty table with this title and these headers; its first `left` columns (names) align left.

    Titles and headers are escaped: rich would read a unit such as "[ms]" as markup and drop it.
    """
    result = Table(title=escape(title), **options)
    for k, column in enumerate(columns):
        result.add_column(escape(column), justify="left" if k < left else "right")
    return result


def show(rows: Table, out: Console | None = None) -> None:
    """Print `rows` as a table if it fits the terminal's width, else one line per row with every cell whole."""
    out = out or console
    natural = out.measure(rows, options=out.options.update_width(1_000_000)).maximum  # unclamped by the terminal
    if natural <= out.width:
        out.print(rows)
        return
    if rows.title:
        out.print(rows.title)
    headers = [str(column.header) for column in rows.columns]
    for cells in zip(*(column.cells for column in rows.columns), strict=True):
        name, *rest = (str(cell) for cell in cells)
        pairs = "  ".join(f"{header} {cell}" for header, cell in zip(headers[1:], rest, strict=True) if cell)
        out.print(f"{name}: {pairs}" if name else f"  {pairs}")


def emit(document: dict[str, Any]) -> None:
    """Print one JSON document on stdout."""
    print(json.dumps(document, indent=2))


def number(value: float | None, spec: str) -> str:
    """Return a document's number formatted, or "inf/nan" for its null: not finite (a diverged plant)."""
    return "inf/nan" if value is None else format(value, spec)
