"""The tune-pid plot: per joint, the disturbance response each stage of the procedure chose."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...control import JointTuning
from ..tuning import TuneResult
from ._figures import uncollected, write_png

__all__ = ["write_tuning_plot"]


@uncollected
def write_tuning_plot(result: TuneResult, path: Path) -> None:
    """Write a PNG with one panel per tuned joint: each chosen stage's bump response over time; return None.

    Raises:
        InputError: `path` cannot be written.
    """
    from matplotlib.figure import Figure

    rows = max(1, len(result.joints))
    height = 2.6 * rows + 0.6
    # Margins fixed in inches (title; the last time axis) rather than by tight_layout, which draws everything twice.
    figure = Figure(figsize=(12, height))
    axes = figure.subplots(rows, 1, squeeze=False, gridspec_kw={
        "left": 0.07, "right": 0.975, "top": 1.0 - 0.75 / height, "bottom": 0.55 / height, "hspace": 0.42})
    for axis, tuning in zip(axes[:, 0], result.joints, strict=False):
        setup = tuning.setup
        chosen = [s for s in tuning.stages if s.chosen and s.trace is not None]
        for number, stage in enumerate(chosen):
            assert stage.trace is not None
            times = np.arange(len(stage.trace)) * setup.dt
            trace = stage.trace.copy()
            beyond = np.flatnonzero(~(np.abs(trace) <= 1.5 * setup.bump))
            if len(beyond):
                trace[beyond[0] + 1 :] = np.nan  # a diverging response is drawn until it leaves the panel
            gains = stage.gains
            final = stage.stage == "final"
            axis.plot(times, trace * 1e3, color="black" if final else f"C{number % 10}",
                      linewidth=2.0 if final else 1.0,
                      label=f"{stage.stage}: p {gains.p:.4g}, i {gains.i:.4g}, d {gains.d:.4g}"
                            + (" (diverges)" if stage.response.diverged else ""))
        if setup.goal_tolerance > 0.0:
            axis.axhspan(-setup.goal_tolerance * 1e3, setup.goal_tolerance * 1e3, color="green", alpha=0.08,
                         label="goal tolerance")
        axis.axhline(0.0, color="grey", linewidth=0.5)
        # A diverging response (the file's gains, say) would squash the others to a line.
        axis.set_ylim(-1.6 * setup.bump * 1e3, 1.6 * setup.bump * 1e3)
        axis.set_title(f"{setup.joint} ({setup.interface}): bump of {setup.bump * 1e3:.3g} mrad at rest", fontsize=10)
        axis.set_ylabel("position - setpoint [mrad]")
        axis.set_xlim(0.0, _shown_s(tuning))
        axis.grid(True, alpha=0.3)
        axis.legend(fontsize="x-small", loc="upper right", ncol=2)
    axes[-1, 0].set_xlabel("time since the bump [s]")
    verdict = "verified" if result.ok else "NOT verified"
    figure.suptitle(f"tune-pid {result.controller}: {verdict} ({result.verification.result.name})", fontsize=11,
                    y=1.0 - 0.1 / height, va="top")
    write_png(figure, path)


def _shown_s(tuning: JointTuning) -> float:
    """Return how much of the window to show [s]: three times the slowest settling of a stage that settles."""
    times = [s.response.settling_time_s for s in tuning.stages if s.chosen and s.trace is not None]
    settled = [t for t in times if t is not None]
    if not settled:
        return tuning.setup.window_s
    return min(tuning.setup.window_s, max(0.1, 3.0 * max(settled)))
