"""What the plots of moveplan share: figures sized per joint, step lines, notes, and PNG files; a plan's figure.

matplotlib is imported inside the functions: importing this module loads nothing of it. A
figure is a matplotlib Figure built without pyplot (no global state, never a window), 12 in
wide with a row of panels per joint, at 100 dpi. tracking_figure draws executions.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...bag import atomic_file
from ...types import frozen_array

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "PlanCurves", "blended", "corner_note", "finite_or_nan", "grid", "legend_line", "plan_figure", "step_lines",
    "write_png",
]

_WIDTH_IN = 12.0
_ROW_IN = 1.9
_HEAD_IN = 1.4
_DPI = 100
_CURVE, _LIMIT = "C0", "C3"


@dataclass(frozen=True)
class PlanCurves:
    """What `plan_figure` draws: a plan sampled as the controller interpolates it, on the plan's timeline.

    Attributes:
        title: The figure's title.
        joints: Column order of the arrays; `units` their position units.
        steps: (name, start [s], duration [s]) of each step.
        times_s: Sample times [s], shape (m,); positions, velocities, accelerations (m, n).
        knots_s: Times of the waypoints [s]; knot_positions their positions.
        limits: Per joint lower, upper, max_velocity, max_acceleration (absent: not limited).

    """

    title: str
    joints: tuple[str, ...]
    units: tuple[str, ...]
    steps: tuple[tuple[str, float, float], ...]
    times_s: NDArray[np.float64]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    accelerations: NDArray[np.float64]
    knots_s: NDArray[np.float64]
    knot_positions: NDArray[np.float64]
    limits: Mapping[str, Mapping[str, float]]

    def __post_init__(self) -> None:
        times = frozen_array(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        shape = (len(times), len(self.joints))
        for name in ("positions", "velocities", "accelerations"):
            object.__setattr__(self, name, frozen_array(getattr(self, name), shape, name))


def write_png(figure: Figure, path: Path) -> None:
    """Write `figure` to `path` as a PNG, atomically (nothing is left if it fails); return None.

    The PNG's Title text chunk holds the figure's title, for tools (and tests) that read it.
    """
    metadata = {"Title": figure.get_suptitle().replace("\n", " - "), "Software": "moveplan"}
    with atomic_file(path) as stream:
        figure.savefig(stream, format="png", dpi=_DPI, metadata=metadata)


def plan_figure(curves: PlanCurves) -> Figure:
    """Return a figure of a plan: per joint, position, velocity and acceleration against their limits."""
    figure, axes = grid(len(curves.joints), 3, curves.title)
    columns = (("position", curves.positions, "lower", "upper", ""), ("velocity", curves.velocities,
               "max_velocity", "max_velocity", "/s"), ("acceleration", curves.accelerations, "max_acceleration",
               "max_acceleration", "/s²"))
    for row, joint in enumerate(curves.joints):
        limits = curves.limits.get(joint, {})
        for col, (what, values, low_key, high_key, per) in enumerate(columns):
            axis = axes[row, col]
            axis.plot(curves.times_s, values[:, row], color=_CURVE, lw=1.2)
            low = -limits[low_key] if low_key == high_key and low_key in limits else limits.get(low_key)
            for bound in (low, limits.get(high_key)):
                if bound is not None and math.isfinite(bound):
                    axis.axhline(bound, color=_LIMIT, ls="--", lw=1.0)
            if col:
                _peak_note(axis, values[:, row], limits.get(high_key), f"{curves.units[row]}{per}")
            axis.set_ylabel(f"[{curves.units[row]}{per}]")
            if row == 0:
                axis.set_title(what, fontsize=10)
        axes[row, 0].plot(curves.knots_s, curves.knot_positions[:, row], "o", color=_CURVE, ms=3)
        axes[row, 0].set_ylabel(f"{joint}\n[{curves.units[row]}]")
    step_lines(axes, [(name, start) for name, start, _ in curves.steps])
    handles = [legend_line(_CURVE, "-", "plan, as the controller interpolates it"),
               legend_line(_CURVE, "", "waypoints", marker="o"),
               legend_line(_LIMIT, "--", "joint limits (unscaled)"), legend_line("0.55", "-", "step start")]
    figure.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=9, frameon=False)
    return figure


def grid(rows: int, columns: int, title: str, widths: Sequence[float] | None = None) -> tuple[Figure, Any]:
    """Return a figure sized for `rows` joints and its (rows, columns) axes, each column sharing its time axis."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(_WIDTH_IN, _HEAD_IN + _ROW_IN * rows), layout="constrained")
    axes = figure.subplots(rows, columns, sharex="col", squeeze=False, width_ratios=widths)
    figure.suptitle(title, fontsize=10)
    for axis in axes.ravel():
        axis.grid(True, alpha=0.3)
        axis.tick_params(labelsize=8)
    for axis in axes[-1]:
        axis.set_xlabel("time [s]", fontsize=9)
    return figure, axes


def step_lines(axes: Any, steps: Sequence[tuple[str, float]]) -> None:
    """Draw a vertical line where each step starts, on every panel, named on the top row; return None."""
    for index, (name, start) in enumerate(steps):
        for axis in axes.ravel():
            if index:  # the first step starts where the plot does
                axis.axvline(start, color="0.55", lw=0.8)
        for axis in axes[0]:
            # Upright beside its line: the names of short steps do not run into each other.
            axis.annotate(name, (start, 0.97), xycoords=blended(axis), xytext=(2, 0), textcoords="offset points",
                          rotation=90, ha="left", va="top", fontsize=7, color="0.3", annotation_clip=True)


def _peak_note(axis: Axes, values: NDArray[np.float64], limit: float | None, unit: str) -> None:
    """Write the largest |value| and its share of the limit in a corner of the panel; return None."""
    peak = float(np.max(np.abs(values), initial=0.0))
    share = f" = {100.0 * peak / limit:.0f}% of limit" if limit and math.isfinite(limit) else ""
    corner_note(axis, f"peak {peak:.3g} {unit}{share}")


def corner_note(axis: Axes, text: str) -> None:
    """Write `text` small in the panel's lower right corner, over a faint white box; return None."""
    axis.text(0.99, 0.04, text, transform=axis.transAxes, ha="right", va="bottom", fontsize=7, color="0.3",
              bbox={"facecolor": "white", "alpha": 0.7, "lw": 0, "pad": 1})


def legend_line(color: str, style: str, label: str, marker: str = "") -> Any:
    """Return a legend entry: a line (or a marker alone) in `color`."""
    from matplotlib.lines import Line2D

    return Line2D([], [], color=color, ls=style or "none", marker=marker or None, mew=2 if marker == "x" else 1,
                  label=label)


def blended(axis: Axes) -> Any:
    """Return the transform of x in data and y in axes fractions."""
    from matplotlib.transforms import blended_transform_factory

    return blended_transform_factory(axis.transData, axis.transAxes)


def finite_or_nan(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return `values` with infinities as NaN: a diverged plant leaves a gap, not a broken axis."""
    return np.where(np.isfinite(values), values, np.nan)
