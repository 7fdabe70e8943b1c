"""Check many (plan, recording) pairs at once: a manifest, long-lived worker processes, results as they come.

A manifest is a CSV file with `plan` and `recording` columns (paths relative to the manifest's
folder; a cell may be a glob, each match an item); its other columns are carried into the
results. Each item is the check `check-tolerances PLAN RECORDING` makes, with the same flags
for every item: the same inputs give the same verdict as a single check. An item that cannot be
checked (a missing or corrupt file, a recording cut off before a verdict) is a result holding
its error, never the end of the batch. Items are keyed by their files' SHA-256, so a rerun can
skip the pairs a results file already judges.
"""

from __future__ import annotations

import csv
import functools
import glob
import hashlib
import io
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InputError, MoveplanError
from ._engines import spread

if TYPE_CHECKING:
    from ..bag import PlanFile

__all__ = [
    "RESULT_COLUMNS", "CheckFlags", "FleetItem", "ItemChecker", "ItemResult", "ResultsFile",
    "batch_exit_code", "check_item",
    "check_items", "fleet_summary", "judged_pairs", "read_manifest", "result_row", "sha256_of", "unresumed_items",
    "write_fleet_html",
]

RESULT_COLUMNS = ("index", "plan", "recording", "plan_sha256", "recording_sha256", "ok", "exit_code", "result",
                  "worst_joint", "worst_margin", "duration_s", "error")
"""The columns of a batch check's results CSV, the manifest's other columns after them."""

_GLOB = frozenset("*?[")
_HASH_BLOCK = 1 << 20
_WORST_LISTED = 10


@dataclass(frozen=True)
class FleetItem:
    """One pair to check: its place in the manifest, its files, and the manifest's other cells of its row."""

    index: int
    plan: Path
    recording: Path
    columns: dict[str, str] = field(default_factory=dict)
    sha256: tuple[str, str] | None = None  # the plan's and the recording's, once computed (unresumed_items)


@dataclass(frozen=True)
class ItemResult:
    """What checking one item gave: the single check's document (or its error's) and the files' SHA-256."""

    item: FleetItem
    document: dict[str, Any]
    plan_sha256: str = ""
    recording_sha256: str = ""
    series: dict[str, Any] | None = None  # the tracking errors the HTML report draws (CheckFlags.series_points)

    @property
    def exit_code(self) -> int:
        """Return the exit code a single check of the item would have ended with: 0, 5, or its error's."""
        error = self.document.get("error")
        if error is not None:
            return int(error["exit_code"])
        return 0 if self.document["ok"] else 5


def read_manifest(path: Path) -> tuple[FleetItem, ...]:
    """Return the items of the manifest at `path`, globs expanded (sorted), in row order.

    Raises:
        InputError: The manifest cannot be read, is not CSV with `plan` and `recording`
            columns, has a row without them, or lists no item; the message names it.
    """
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        rows = list(csv.DictReader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise InputError(f"{path}: not a CSV file: {exc}") from None
    header = list(rows[0]) if rows else next(csv.reader(io.StringIO(text)), [])
    if "plan" not in header or "recording" not in header:
        raise InputError(f"{path}: a manifest needs the columns plan and recording (its header: "
                         f"{', '.join(header) or 'none'})")
    folder = path.parent
    items: list[FleetItem] = []
    for number, row in enumerate(rows, start=2):
        plan, recording = (row.get("plan") or "").strip(), (row.get("recording") or "").strip()
        if not plan or not recording:
            raise InputError(f"{path}: row {number}: plan and recording are both needed")
        if None in row:
            raise InputError(f"{path}: row {number}: more cells than the header names")
        others = {key: value for key, value in row.items() if key not in ("plan", "recording")}
        for plan_path in _expanded(folder, plan):
            for recording_path in _expanded(folder, recording):
                items.append(FleetItem(len(items), plan_path, recording_path, others))
    if not items:
        raise InputError(f"{path}: the manifest lists no (plan, recording) pair")
    return tuple(items)


def _expanded(folder: Path, cell: str) -> list[Path]:
    """Return the paths a manifest cell names, relative to `folder`: a glob's matches (sorted), else the path itself."""
    path = Path(cell).expanduser()
    path = path if path.is_absolute() else folder / path
    if not _GLOB & set(cell):
        return [path]
    matches = sorted(Path(p) for p in glob.glob(str(path), recursive=True))
    return matches or [path]  # a glob matching nothing is an item whose file is missing


def sha256_of(path: Path) -> str:
    """Return the SHA-256 of a file's bytes, or of a bag folder's files in name order ("" if it cannot be read)."""
    digest = hashlib.sha256()
    try:
        files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
        for file in files:
            digest.update(file.relative_to(path).as_posix().encode() if path.is_dir() else b"")
            with file.open("rb") as stream:
                while block := stream.read(_HASH_BLOCK):
                    digest.update(block)
    except OSError:
        return ""
    return digest.hexdigest()


def judged_pairs(path: Path) -> dict[tuple[str, str], dict[str, str]]:
    """Return the rows of an earlier results CSV by (plan SHA-256, recording SHA-256): the pairs it judged.

    Raises:
        InputError: The file exists but is no batch check's results CSV.
    """
    if not path.exists():
        return {}
    try:
        rows = list(csv.DictReader(io.StringIO(path.read_text(encoding="utf-8"), newline="")))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path}: cannot read the results to resume from: {exc}") from None
    if rows and not set(RESULT_COLUMNS) <= set(rows[0]):
        raise InputError(f"{path}: not the results of a batch check (--resume reads the --csv a batch wrote)")
    # A pair whose files could not be read has no key: it is checked again.
    return {(r["plan_sha256"], r["recording_sha256"]): r for r in rows if r["plan_sha256"] and r["recording_sha256"]}


def unresumed_items(
    items: Sequence[FleetItem], judged: dict[tuple[str, str], dict[str, str]]
) -> tuple[list[FleetItem], list[dict[str, str]]]:
    """Return the items a results file does not judge yet (their files hashed once), and its rows for the others."""
    keyed = [replace(item, sha256=(sha256_of(item.plan), sha256_of(item.recording))) for item in items]
    resumed = [judged[key] for key in dict.fromkeys(item.sha256 for item in keyed if item.sha256) if key in judged]
    return [item for item in keyed if item.sha256 not in judged], resumed


@dataclass(frozen=True)
class CheckFlags:
    """The check-tolerances flags every item is checked with (as CheckRequest's fields)."""

    topic: str = "/joint_states"
    controllers: Path | None = None
    start: Any = "auto"
    time_source: Any = "header"
    skip_damaged: bool = False
    strict: bool = False
    series_points: int = 0  # per joint, the tracking error samples each result keeps for a report (0: none)
    hashes: bool = False  # each result carries its files' SHA-256 (a results file keys its rows by them)


def check_items(
    items: Sequence[FleetItem], flags: CheckFlags, jobs: int | None = None,
    on_result: Callable[[ItemResult], None] | None = None, engine: str = "local", ray_address: str | None = None,
) -> list[ItemResult]:
    """Return every item's result, in manifest order; `on_result` gets each as it arrives.

    Engine "local": `jobs` worker processes (None: 1, the items checked in this process)
    take items from one queue. Engine "ray": `jobs` actors (None: one per CPU of the
    cluster at `ray_address`, or RAY_ADDRESS). Either way a worker keeps what items share
    loaded across them (the interpreter, the plans it read), and an item's result does not
    depend on where it ran.

    Raises:
        UsageError: An unknown engine; for "ray", Ray missing or no cluster address.
        InputError: The Ray cluster cannot be reached.
    """
    results: list[ItemResult] = []

    def arrived(result: ItemResult) -> None:
        results.append(result)
        if on_result is not None:
            on_result(result)

    if engine == "local" and ((jobs or 1) <= 1 or len(items) <= 1):
        for item in items:
            arrived(check_item(item, flags))
    else:
        spread(functools.partial(ItemChecker, flags), items, jobs, engine, ray_address, arrived)
    return sorted(results, key=lambda r: r.item.index)


class ItemChecker:
    """A worker of the Ray engine: checks items with the same flags, keeping the plans it read."""

    def __init__(self, flags: CheckFlags) -> None:
        """Check with `flags`."""
        self._flags = flags

    def run(self, item: FleetItem) -> ItemResult:
        """Return the result of checking `item`."""
        return check_item(item, self._flags)


def check_item(item: FleetItem, flags: CheckFlags) -> ItemResult:
    """Return the result of checking one item: `check-tolerances` on its pair, or the error that stopped it."""
    from .execution import CheckRequest, check
    from .report import check_document

    request = CheckRequest(item.plan, item.recording, flags.topic, flags.controllers, flags.start, flags.time_source,
                           flags.skip_damaged, flags.strict)
    drawn: list[dict[str, Any]] = []

    def keep_series(checked: Any) -> None:
        if flags.series_points and checked.report.complete:
            from .plots import checked_tracking

            drawn.append(_series(checked_tracking(checked, request, flags.series_points)))

    try:
        document = check_document(check(request, keep_series, read_plan=_read_plan), item.recording)
    except MoveplanError as exc:
        document = _error_document(exc.exit_code, exc.kind, str(exc))
    except Exception as exc:  # noqa: BLE001 - a bug met on one item is that item's result, not the batch's end
        document = _error_document(1, "internal", f"internal error (a bug in moveplan, please report it): "
                                                  f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}")
    hashes = item.sha256 or ((sha256_of(item.plan), sha256_of(item.recording)) if flags.hashes else ("", ""))
    return ItemResult(item, document, *hashes, drawn[0] if drawn else None)


def _series(tracking: Any) -> dict[str, Any]:
    """Return a checked execution's tracking error per joint as JSON-ready lists: what a report draws."""
    import numpy as np

    times = np.concatenate([step.times_s for step in tracking.steps]) if tracking.steps else np.zeros(0)
    joints = []
    for column, joint in enumerate(tracking.joints):
        errors = np.concatenate([step.error[:, column] for step in tracking.steps]) if tracking.steps else times
        joints.append({"name": joint, "unit": tracking.units[column], "error": _rounded(errors),
                       "path": float(tracking.path_tolerance[column]), "goal": float(tracking.goal_tolerance[column])})
    return {"t": _rounded(times), "joints": joints, "steps": [[step.name, step.start_s] for step in tracking.steps]}


def _rounded(values: Any) -> list[float | None]:
    """Return values as floats of 6 significant digits, None where not finite (JSON has no NaN)."""
    return [float(f"{value:.6g}") if value == value and abs(value) != float("inf") else None
            for value in values.tolist()]


def _read_plan(path: Path) -> PlanFile:
    """Return the plan file at `path`, read and validated once per process while the file stays the same."""
    from ._plan_files import read_valid_plan

    try:
        stat = path.stat()
    except OSError:
        return read_valid_plan(path)  # which names the file and says why it cannot be read
    return _plan_read(path, stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=16)
def _plan_read(path: Path, mtime_ns: int, size: int) -> PlanFile:
    """Return the plan file at `path` as it was at `mtime_ns` with `size` bytes (the cache's key)."""
    from ._plan_files import read_valid_plan

    return read_valid_plan(path)


def _error_document(exit_code: int, kind: str, message: str) -> dict[str, Any]:
    """Return the document of an item that could not be checked."""
    return {"ok": False, "error": {"exit_code": exit_code, "kind": kind, "message": message}}


class ResultsFile:
    """A batch check's results CSV: a row per item, written and flushed as its result arrives (`--csv`).

    Rows stream out so that a run stopped half-way leaves the pairs it judged, which `--resume`
    skips; `append` adds to an earlier run's file instead of starting a new one.
    """

    def __init__(self, path: Path, extra: Sequence[str], append: bool = False) -> None:
        """Open `path` for RESULT_COLUMNS and the manifest's `extra` columns; InputError if it cannot be written."""
        self._columns = [*RESULT_COLUMNS, *extra]
        adding = append and path.exists() and path.stat().st_size > 0
        try:
            self._stream = path.open("a" if adding else "w", encoding="utf-8", newline="")
        except OSError as exc:
            raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from None
        self._writer = csv.DictWriter(self._stream, fieldnames=self._columns, extrasaction="ignore")
        if not adding:
            self._writer.writeheader()
            self._stream.flush()

    def write(self, result: ItemResult) -> None:
        """Write an item's row and flush it to the file; return None."""
        self._writer.writerow(result_row(result))
        self._stream.flush()

    def close(self) -> None:
        """Close the file; return None."""
        self._stream.close()


def batch_exit_code(codes: Iterable[int]) -> int:
    """Return a batch's exit code from its items' codes: 3 if any could not be checked, else 5 on any violation."""
    found = set(codes)
    if found - {0, 5}:
        return 3
    return 5 if 5 in found else 0


def result_row(result: ItemResult) -> dict[str, Any]:
    """Return an item's results CSV row: RESULT_COLUMNS, then the manifest's other columns."""
    document = result.document
    margins = {joint: margin for joint, margin in (document.get("margins") or {}).items() if margin is not None}
    worst = min(margins, key=lambda joint: margins[joint]) if margins else None
    error = document.get("error")
    return {
        "index": result.item.index, "plan": str(result.item.plan), "recording": str(result.item.recording),
        "plan_sha256": result.plan_sha256, "recording_sha256": result.recording_sha256,
        "ok": bool(document["ok"]), "exit_code": result.exit_code,
        "result": (document.get("result") or {}).get("name", error["kind"] if error else ""),
        "worst_joint": worst or "", "worst_margin": "" if worst is None else margins[worst],
        "duration_s": "" if document.get("duration_s") is None else document["duration_s"],
        "error": error["message"].splitlines()[0] if error else "",
        **result.item.columns,
    }


def fleet_summary(results: Sequence[ItemResult], resumed: Sequence[dict[str, str]] = ()) -> dict[str, Any]:
    """Return a batch's summary: counts, the failing items, and the items with the smallest margins.

    `resumed` are the results CSV rows of pairs an earlier run judged (--resume), counted too.
    """
    rows = [result_row(r) for r in results] + [dict(r) for r in resumed]
    codes = [int(r["exit_code"]) for r in rows]
    failing = [{"plan": r["plan"], "recording": r["recording"], "result": r["result"], "exit_code": int(r["exit_code"])}
               for r in rows if int(r["exit_code"]) != 0]
    margins = sorted(((float(r["worst_margin"]), r) for r in rows if r["worst_margin"] not in ("", None)),
                     key=lambda pair: pair[0])
    return {
        "items": len(rows),
        "checked": len(results),
        "resumed": len(resumed),
        "passed": codes.count(0),
        "failed": codes.count(5),
        "unreadable": len([c for c in codes if c not in (0, 5)]),
        "exit_code": batch_exit_code(codes),
        "failing": failing,
        "worst_margins": [{"plan": r["plan"], "recording": r["recording"], "joint": r["worst_joint"], "margin": margin}
                          for margin, r in margins[:_WORST_LISTED]],
    }


def write_fleet_html(
    path: Path, manifest: Path, results: Sequence[ItemResult], resumed: Sequence[dict[str, str]]
) -> None:
    """Write a batch check's HTML report to `path`: the summary, a row per item, each opening its errors; return None.

    Items an earlier run judged (--resume) are rows of their CSV values, with nothing to draw.
    """
    from .html_report import write_html

    summary = fleet_summary(results, resumed)
    extra = list(results[0].item.columns) if results else [k for k in (resumed[0] if resumed else {})
                                                           if k not in RESULT_COLUMNS]
    columns = ["#", "plan", "recording", "verdict", "exit", "worst joint", "margin", "ringing", "duration [s]", *extra]
    rows, details = [], []
    for result in results:
        row = result_row(result)
        ringing = [j for j, t in (result.document.get("tracking") or {}).items() if t.get("ringing")]
        rows.append([row["index"], row["plan"], row["recording"], row["result"], row["exit_code"], row["worst_joint"],
                     _number(row["worst_margin"]), ", ".join(ringing), _number(row["duration_s"]),
                     *(row.get(k, "") for k in extra)])
        details.append(result.series)
    for row in resumed:
        rows.append([int(row["index"]), row["plan"], row["recording"], row["result"], int(row["exit_code"]),
                     row["worst_joint"], _number(row["worst_margin"]), "", _number(row["duration_s"]),
                     *(row.get(k, "") for k in extra)])
        details.append(None)
    pairs = [("manifest", str(manifest)), ("items", str(summary["items"])), ("passed", str(summary["passed"])),
             ("failed (a violation)", str(summary["failed"])), ("not checked", str(summary["unreadable"])),
             ("judged by an earlier run", str(summary["resumed"])), ("exit code", str(summary["exit_code"]))]
    if summary["worst_margins"]:
        worst = summary["worst_margins"][0]
        pairs.append(("smallest margin", f"{worst['margin']:.4g} ({worst['joint']}, {worst['recording']})"))
    write_html(path, f"moveplan check-tolerances --manifest {manifest.name}", pairs, columns, rows, details, 3)


def _number(value: Any) -> float | None:
    """Return a CSV cell or a row value as a float, None if empty or not finite."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if number == number and abs(number) != float("inf") else None
