"""What the plots of moveplan share: figures sized per joint, axis ranges, step lines, notes, and PNG files.

matplotlib is imported inside the functions: importing this module loads nothing of it. A
figure is a matplotlib Figure built without pyplot (no global state, never a window), 12 in
wide with a row of panels per joint, at 100 dpi, its margins fixed in inches.
"""

from __future__ import annotations

import functools
import gc
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ParamSpec, TypeVar

import numpy as np
from numpy.typing import NDArray

from ...bag import atomic_file
from ...errors import InputError, UsageError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ...config import RobotConfig

__all__ = [
    "IN_RANGE", "POINTS_PER_SERIES", "blended", "check_plot_path", "corner_note", "finite_or_nan", "grid", "legend",
    "legend_line", "position_units", "prefixed", "step_budget", "step_lines", "symmetric_span", "time_axis",
    "uncollected", "value_axes", "write_png",
]

_P = ParamSpec("_P")
_R = TypeVar("_R")

_WIDTH_IN = 12.0
_ROW_IN = 1.9  # a joint's row of panels, with the gap below it
_HEAD_IN = 1.4  # title, column titles, time axis and one legend row
_TOP_IN = 0.7  # two title lines and the column titles
_LEGEND_ROW_IN = 0.2
_LEFT_IN, _RIGHT_IN = 1.1, 0.15  # the joint's name and the tick labels; the last panel's edge
_COLUMN_GAP_IN, _ROW_GAP_IN = 0.78, 0.22  # tick labels and unit of the next column; a row's time ticks
_DPI = 100
_VALUE_PT, _VALUE_PAD_PT = 8.0, 3.5  # a value label's size and its gap to the panel's edge
_ADVANCE_EM = {".": 0.32, ",": 0.32, "\N{MINUS SIGN}": 0.84, "-": 0.36}  # DejaVu Sans; a digit is 0.64 em
_LABEL_PX = 12.0  # the width of an upright step name at 7 pt (10 px), with a little air

IN_RANGE = 3.0
"""A tolerance or limit up to this many times what is drawn shares its panel's scale; a larger one is named
in a note instead, so that a passing run's small errors are not drawn as a flat line."""

POINTS_PER_SERIES = 5000
"""About how many samples per joint a plot keeps of each series, whatever the length of the run."""

_MIN_STEP_POINTS = 200
_PREFIXES = ((0.1, 1.0, ""), (1e-4, 1e3, "m"), (1e-7, 1e6, "µ"), (0.0, 1e9, "n"))
_LEAST_ERROR = 1e-9  # [rad] or [m]: a smaller error is rounding, drawn on a panel of about this height


def check_plot_path(path: Path, flag: str = "--plot") -> None:
    """Refuse a plot path before any work: it must name a .png file in an existing folder; return None.

    Raises:
        UsageError: The name does not end in .png.
        InputError: Its folder does not exist (as -o's "cannot write", exit 3).

    """
    if path.suffix.lower() != ".png":
        raise UsageError(f"{flag} '{path}': expected a file name ending in .png (the plot is a PNG image)")
    if not path.parent.is_dir():
        raise InputError(f"{flag} '{path}': cannot write: folder '{path.parent}' does not exist")


def uncollected(draw: Callable[_P, _R]) -> Callable[_P, _R]:
    """Return `draw` run with the cyclic garbage collector held, and collecting again afterwards.

    Importing matplotlib and drawing a figure make hundreds of thousands of small objects, and
    the collector's passes over them cost a sixth of a plot (0.1 s of 0.6 s for the pick and place).
    """
    @functools.wraps(draw)
    def held(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        enabled = gc.isenabled()
        gc.disable()
        try:
            return draw(*args, **kwargs)
        finally:
            if enabled:
                gc.enable()

    return held


def write_png(figure: Figure, path: Path) -> None:
    """Write `figure` to `path` as a PNG, atomically (nothing is left if it fails); return None.

    The PNG's Title text chunk holds the figure's title, for tools (and tests) that read it.
    """
    from matplotlib import rc_context

    metadata = {"Title": figure.get_suptitle().replace("\n", " - "), "Software": "moveplan"}
    # Unhinted glyphs: a sixth of the drawing's time, and at 100 dpi they read the same.
    with atomic_file(path) as stream, rc_context({"text.hinting": "no_hinting"}):
        # zlib level 1: a tenth of the time of the default for a file a quarter larger.
        figure.savefig(stream, format="png", dpi=_DPI, metadata=metadata, pil_kwargs={"compress_level": 1})


def grid(
    rows: int, columns: int, title: str, widths: Sequence[float] | None = None, legend_rows: int = 1
) -> tuple[Figure, Any]:
    """Return a figure sized for `rows` joints and its (rows, columns) axes; time_axis then sets each column's time.

    The margins are fixed in inches (title, column titles, tick labels, legend rows) rather
    than found by a layout engine: that engine draws the whole figure once more to measure it.
    """
    from matplotlib import rc_context
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullLocator

    head = _HEAD_IN + _LEGEND_ROW_IN * (legend_rows - 1)
    height = head + _ROW_IN * rows
    panel_height = (_ROW_IN * rows - _ROW_GAP_IN * (rows - 1)) / rows
    panel_width = (_WIDTH_IN - _LEFT_IN - _RIGHT_IN - _COLUMN_GAP_IN * (columns - 1)) / columns
    figure = Figure(figsize=(_WIDTH_IN, height), dpi=_DPI)
    # Titles at a fixed height: placed automatically, each panel's would be measured on every draw.
    with rc_context({"axes.titley": 1.0}):
        axes = figure.subplots(rows, columns, squeeze=False, width_ratios=widths, gridspec_kw={
            "left": _LEFT_IN / _WIDTH_IN, "right": 1.0 - _RIGHT_IN / _WIDTH_IN, "top": 1.0 - _TOP_IN / height,
            "bottom": (head - _TOP_IN) / height, "wspace": _COLUMN_GAP_IN / panel_width,
            "hspace": _ROW_GAP_IN / panel_height})
    figure.suptitle(title, fontsize=10, y=1.0 - 0.06 / height, va="top")
    for axis in axes.ravel():
        axis.yaxis.set_major_locator(NullLocator())  # values are labelled by value_axes
    for axis in axes[-1]:
        axis.grid(True, axis="x", alpha=0.3)
        axis.tick_params(axis="x", labelsize=8)
        axis.set_xlabel("time [s]", fontsize=9, labelpad=2)
    return figure, axes


def value_axes(axes: Any, bins: int = 4) -> None:
    """Label every shown panel's values at about `bins` round numbers, with a grid line each; return None.

    Call it once the panels have their ranges, which it fixes. Labels are plain texts and the
    grid one line collection, not ticks: a tick is a handful of artists, and making and drawing
    them was a third of a figure's cost.
    """
    from matplotlib import rcParams
    from matplotlib.ticker import MaxNLocator, ScalarFormatter
    from matplotlib.transforms import ScaledTranslation

    for axis in np.ravel(axes):
        if not axis.axison:
            continue
        low, high = axis.get_ylim()
        axis.set_ylim(low, high)  # the grid lines must not widen the autoscaled range
        values = [float(v) for v in MaxNLocator(nbins=bins).tick_values(low, high) if low <= v <= high]
        formatter = ScalarFormatter(useOffset=False)  # plain numbers: units carry the prefix
        formatter.set_scientific(False)
        axis.yaxis.set_major_formatter(formatter)
        formatter.set_locs(values)
        left = axis.get_yaxis_transform() + ScaledTranslation(-_VALUE_PAD_PT / 72.0, 0.0, axis.figure.dpi_scale_trans)
        labels = formatter.format_ticks(values)
        for value, label in zip(values, labels, strict=True):
            axis.text(0.0, value, label, transform=left, ha="right", va="center_baseline", fontsize=_VALUE_PT)
        # The axis' own label is placed past tick labels only: move it past these.
        axis.yaxis.labelpad += _VALUE_PAD_PT + max(map(_width_pt, labels), default=0.0)
        axis.hlines(values, 0.0, 1.0, transform=axis.get_yaxis_transform(), color=rcParams["grid.color"],
                    lw=rcParams["grid.linewidth"], alpha=0.3, zorder=0.5)


def time_axis(column: Sequence[Axes], low: float, high: float, bins: int = 7) -> None:
    """Give a column of panels the time range [low, high] [s]: ticks on the bottom one, grid lines on all; return None.

    The panels above get their vertical grid lines as one line collection, not as ticks:
    a tick is a handful of artists, and drawing them is most of a figure's cost.
    """
    from matplotlib import rcParams
    from matplotlib.ticker import MaxNLocator, NullLocator

    times = [float(t) for t in MaxNLocator(nbins=bins).tick_values(low, high) if low <= t <= high]
    for axis in column:
        axis.set_xlim(low, high)
    column[-1].set_xticks(times)
    for axis in column[:-1]:
        axis.xaxis.set_major_locator(NullLocator())
        axis.vlines(times, 0.0, 1.0, transform=axis.get_xaxis_transform(), color=rcParams["grid.color"],
                    lw=rcParams["grid.linewidth"], alpha=0.3, zorder=0.5)


def legend(figure: Figure, handles: Sequence[Any], columns: int) -> None:
    """Draw the figure's legend centred along its bottom edge, in `columns` columns; return None."""
    figure.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=columns, fontsize=9,
                  frameon=False, borderaxespad=0.3)


def step_lines(axes: Any, steps: Sequence[tuple[str, float]]) -> None:
    """Draw a vertical line where each step starts, on every panel, named on the top row; return None.

    Call it once the time axis has its range. Names of steps closer than a name's width are
    moved apart along the top and tied to their line, so that short steps stay legible.
    """
    starts = [start for _, start in steps[1:]]  # the first step starts where the plot does
    for axis in axes.ravel():
        if starts:
            axis.vlines(starts, 0.0, 1.0, transform=blended(axis), color="0.55", lw=0.8)
    for axis in axes[0]:
        low, high = axis.get_xlim()
        width_px = axis.get_position().width * axis.figure.get_figwidth() * _DPI
        wanted = [(start - low) / (high - low) * width_px for _, start in steps]
        for (name, start), at, x_px in zip(steps, wanted, _spread(wanted, _LABEL_PX, width_px), strict=True):
            shift_pt = (x_px - at) * 72.0 / _DPI
            arrow = {"arrowstyle": "-", "lw": 0.5, "color": "0.55", "relpos": (0.0, 1.0), "shrinkA": 0,
                     "shrinkB": 0} if abs(shift_pt) > 1.0 else None
            axis.annotate(name, (start, 1.0), xycoords=blended(axis), xytext=(shift_pt + 1.5, -4.0),
                          textcoords="offset points", rotation=90, ha="left", va="top", fontsize=7, color="0.3",
                          annotation_clip=True, arrowprops=arrow)


def _width_pt(label: str) -> float:
    """Return about how wide `label` (a number) is drawn at _VALUE_PT [pt], from DejaVu Sans' advances.

    Measuring the drawn text would lay it out, which is what labelling without ticks saves.
    """
    return _VALUE_PT * sum(_ADVANCE_EM.get(char, 0.64) for char in label)


def _spread(wanted: Sequence[float], gap: float, width: float) -> list[float]:
    """Return positions as near `wanted` (ascending) as keeps them `gap` apart, within [0, width] where they fit."""
    placed: list[float] = []
    for x in wanted:
        placed.append(max(x, placed[-1] + gap) if placed else x)
    overflow = placed[-1] - (width - gap) if placed else 0.0
    if overflow > 0.0:  # pushed off the right edge: pull the crowded tail back left
        for index in range(len(placed) - 1, -1, -1):
            limit = width - gap if index == len(placed) - 1 else placed[index + 1] - gap
            placed[index] = min(placed[index], limit)
    return placed


def symmetric_span(largest: float, bounds: Sequence[float]) -> tuple[float, list[float]]:
    """Return the half-height of a panel centred on 0 and the positive `bounds` it leaves off-scale.

    The panel holds `largest` (the biggest |value| drawn) and every bound up to IN_RANGE
    times it; a bound beyond that is left off, for a note to name.
    """
    drawn = [b for b in bounds if b > 0.0 and math.isfinite(b)]
    if not math.isfinite(largest):
        return (1.15 * max(drawn) if drawn else 1.0), []
    largest = max(largest, _LEAST_ERROR)
    kept = [b for b in drawn if b <= IN_RANGE * largest]
    return 1.15 * max([largest, *kept]), [b for b in drawn if b not in kept]


def prefixed(span: float, unit: str) -> tuple[float, str]:
    """Return the factor and unit to draw values of magnitude up to `span` in: rad, mrad or µrad (m, mm or µm)."""
    for least, factor, prefix in _PREFIXES:
        if span >= least:
            return factor, prefix + unit
    return 1.0, unit


def step_budget(duration_s: float, total_s: float, points: int = POINTS_PER_SERIES) -> int:
    """Return the samples a step of `duration_s` [s] keeps: its share of `points`, never very few."""
    share = duration_s / total_s if total_s > 0.0 else 1.0
    return max(min(_MIN_STEP_POINTS, points), int(points * share))


def position_units(config: RobotConfig, joints: Sequence[str]) -> tuple[str, ...]:
    """Return per joint its position unit: m for a prismatic joint, else rad."""
    kinds = config.urdf_joints
    return tuple("m" if j in kinds and kinds[j].type == "prismatic" else "rad" for j in joints)


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
