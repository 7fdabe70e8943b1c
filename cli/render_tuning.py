"""Render tune-pid's result: a table of the stages each joint went through, the fitted plant, the verification."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.markup import escape

from .tables import console as _console
from .tables import emit as _emit
from .tables import number as _number
from .tables import show, table

if TYPE_CHECKING:
    from ..core.pipeline import TuneResult

__all__ = ["tuning_summary"]


def tuning_summary(result: TuneResult, plot: Path | None, as_json: bool, quiet: bool) -> None:
    """Print per joint the stages of the tuning, the fitted plant, the verification; or the tune-pid JSON document."""
    from ..core.pipeline import tuning_document

    document = tuning_document(result, plot)
    if as_json:
        _emit(document)
        return
    if quiet:
        return
    if document["fit"] is not None:
        _fit(document["fit"])
    rows = table(f"tune-pid {document['controller']} ({document['interface']}): the response each stage chose to a "
                 "bump of the joint at rest", ("joint", "stage", "p", "i", "d", "osc", "decay", "overshoot [rad]",
                                               "settle [s]", "why"), left=2)
    rows.columns[-1].justify = "left"  # the reason is text
    for joint, tuned in document["joints"].items():
        for number, stage in enumerate(s for s in tuned["stages"] if s["chosen"]):
            g, r = stage["gains"], stage["response"]
            settle = "-" if r["settling_time_s"] is None else f"{r['settling_time_s']:.3f}"
            # A diverged response has no decay or overshoot to give (JSON null): say why, not "inf/nan".
            decay, overshoot = (("diverged", "diverged") if r["diverged"] else
                                (_number(r["decay_ratio"], ".2f"), _number(r["overshoot"], ".1e")))
            rows.add_row(joint if number == 0 else "", stage["stage"], f"{g['p']:.4g}", f"{g['i']:.4g}",
                         f"{g['d']:.4g}", str(r["oscillations"]), decay, overshoot, settle, escape(stage["note"]),
                         end_section=stage["stage"] == "final")
    show(rows)
    verification = document["verification"]
    colour = "green" if document["ok"] else "red"
    ringing = ", ".join(document["ringing"]) or "none"
    _console.print(f"verification: execute --fake --plant pid with the tuned gains: [{colour}]"
                   f"{verification['result']['name']}[/{colour}], ringing: {ringing}")
    written = f"wrote {escape(document['output'])}" + (f" and {escape(str(plot))}" if plot else "")
    _console.print(written if document["ok"] else f"{written}, although the verification did not pass: "
                   f"{escape(verification['result']['message'])}")


def _fit(fit: dict[str, Any]) -> None:
    """Print the plant fitted to a recording and how well it reproduces it."""
    share = "" if fit["fraction"] is None else f" ({100 * fit['fraction']:.2f} % of the largest joint travel)"
    _console.print(f"plant fitted to the recording: replaying the plan, RMS position error "
                   f"{_number(fit['rms_error'], '.3g')} rad{share} over {fit['samples']} samples")
    rows = table("fitted plant parameters", ("joint", "parameters", "rms [rad]", "of travel"), left=2)
    for joint, entry in fit["joints"].items():
        # A limit the fit left unbounded is infinite: JSON null.
        params = ", ".join(f"{k}={'inf' if v is None else format(v, '.3g')}" for k, v in entry["params"].items())
        share = "-" if entry["fraction"] is None else f"{100 * entry['fraction']:.2f} %"
        rows.add_row(joint, params, _number(entry["rms_error"], ".2e"), share)
    show(rows)

