"""The figure of a tracked execution (execute and check-tolerances --plot): reference, actual, error, tolerances.

Per joint, three panels: the plan's reference and the actual position; the tracking error
against the path tolerance band and the goal window; and that goal window zoomed, scaled to
the goal tolerance. matplotlib is imported inside plot_figures' functions, when drawing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...types import frozen_array
from ._figures import (
    blended,
    corner_note,
    finite_or_nan,
    grid,
    legend,
    legend_line,
    prefixed,
    step_lines,
    symmetric_span,
    time_axis,
    value_axes,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["TrackedStep", "Tracking", "ViolationMark", "tracking_figure"]

_REFERENCE, _ACTUAL, _PATH, _GOAL, _VIOLATION = "0.15", "C0", "C2", "C1", "red"
_LEAST_SPAN = 0.01  # [rad] or [m]: a position panel is never narrower
# Checks whose numbers are positions: their violation is a point on the position and error panels.
_POSITION_CHECKS = ("path", "goal", "start_tolerance")


@dataclass(frozen=True)
class ViolationMark:
    """A violation on the plot's timeline: time [s], joint ("" for the time checks), check, actual and error."""

    time_s: float
    joint: str
    check: str
    actual: float
    error: float


@dataclass(frozen=True)
class TrackedStep:
    """One step's samples on the plot's timeline, decimated; arrays (m, n) in the plot's joint order.

    Attributes:
        name: The step's name.
        start_s: When its goal was sent, in [s] on the plot's timeline.
        planned_s: The trajectory's duration in [s] (its path tolerance holds until then).
        end_s: When it was decided, in [s] on the plot's timeline.
        times_s: Times of the kept samples in [s], shape (m,).
        reference, actual, error: Reference and actual positions and reference - actual.
        error_low, error_high: The smallest and largest error over the samples each kept one stands for.
        marks: Its violations.

    """

    name: str
    start_s: float
    planned_s: float
    end_s: float
    times_s: NDArray[np.float64]
    reference: NDArray[np.float64]
    actual: NDArray[np.float64]
    error: NDArray[np.float64]
    error_low: NDArray[np.float64]
    error_high: NDArray[np.float64]
    marks: tuple[ViolationMark, ...] = ()

    def __post_init__(self) -> None:
        times = frozen_array(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        for name in ("reference", "actual", "error", "error_low", "error_high"):
            object.__setattr__(self, name, frozen_array(getattr(self, name), (len(times), None), name))


@dataclass(frozen=True)
class Tracking:
    """What `tracking_figure` draws: steps, with the controller's tolerances per joint ([rad] or [m]; 0 = unchecked).

    `goal_time_s` and `period_s` (the controller's update period) are in [s].
    """

    title: str
    joints: tuple[str, ...]
    units: tuple[str, ...]
    steps: tuple[TrackedStep, ...]
    path_tolerance: NDArray[np.float64]
    goal_tolerance: NDArray[np.float64]
    goal_time_s: float
    period_s: float


def tracking_figure(tracking: Tracking) -> Figure:
    """Return a figure of an execution: per joint, reference and actual; the error against the tolerances.

    A third, narrower column zooms on the goal window of the last step drawn (the one that
    decided), where a goal tolerance far finer than the path tolerance can be seen. Error
    panels are scaled to the errors, in rad, mrad or µrad (m, mm or µm): a tolerance far
    above them is named in the panel's note rather than drawn.
    """
    figure, axes = grid(len(tracking.joints), 3, tracking.title, widths=(5, 5, 2), legend_rows=2)
    last = tracking.steps[-1] if tracking.steps else None
    begin = min([s.start_s for s in tracking.steps], default=0.0)
    end = max([s.end_s for s in tracking.steps], default=0.0)
    if last is not None and last.end_s >= _window(tracking, last)[0]:  # its goal window was reached
        end = max(end, _window(tracking, last)[1])
    for row, joint in enumerate(tracking.joints):
        position, error, goal = axes[row]
        unit = tracking.units[row]
        largest = _largest_error(tracking.steps, joint, row)
        span, off = symmetric_span(largest, (tracking.path_tolerance[row], tracking.goal_tolerance[row]))
        scale, scaled_unit = prefixed(span, unit)
        for step in tracking.steps:
            _tolerance_bands(error, tracking, step, row, step is last, scale)
            position.plot(step.times_s, step.reference[:, row], color=_REFERENCE, ls="--", lw=1.2)
            position.plot(step.times_s, finite_or_nan(step.actual[:, row]), color=_ACTUAL, lw=1.0)
            _error_curve(error, step, row, scale)
        error.axhline(0.0, color="0.7", lw=0.6)
        error.set_ylim(-span * scale, span * scale)
        corner_note(error, _tolerance_note(tracking, row, largest, off))
        _least_span(position)
        position.set_ylabel(f"{joint}\n[{unit}]", fontsize=9)
        error.set_ylabel(f"[{scaled_unit}]", fontsize=9)
        _violations((position, error), (1.0, scale), tracking.steps, joint, label=row == 0)
        if last is not None:
            _goal_zoom(goal, tracking, last, row)
    value_axes(axes)
    for column in (0, 1):
        time_axis(axes[:, column], begin, end + 0.01 * (end - begin) if end > begin else begin + 1.0)
    if last is not None and last.end_s >= _window(tracking, last)[0]:
        time_axis(axes[:, 2], *_zoom_range(tracking, last), bins=3)
    axes[0, 0].set_title("position: plan reference and actual", fontsize=10)
    axes[0, 1].set_title("tracking error = reference - actual", fontsize=10)
    axes[0, 2].set_title("goal window", fontsize=10)
    step_lines(axes[:, :2], [(s.name, s.start_s) for s in tracking.steps])
    legend(figure, _tracking_legend(tracking), 3)
    return figure


def _window(tracking: Tracking, step: TrackedStep) -> tuple[float, float]:
    """Return where a step's goal window starts and ends, in [s] on the plot's timeline.

    It starts a period before the last point (JTC checks the goal from the cycle whose command
    reaches it) and ends goal_time after the last point, or when the step was decided if that
    is later or goal_time is 0 (no deadline).
    """
    last_point = step.start_s + step.planned_s
    deadline = last_point + tracking.goal_time_s if tracking.goal_time_s > 0.0 else last_point
    return last_point - tracking.period_s, max(deadline, step.end_s)


def _tolerance_bands(
    axis: Axes, tracking: Tracking, step: TrackedStep, row: int, last: bool, scale: float
) -> None:
    """Shade the path tolerance while the step's trajectory runs and the goal tolerance after it; return None.

    The goal window of the last step runs to goal_time after its last point (a dotted line),
    the others' until they were decided; a tolerance of 0 is not checked and gets no band.
    Values are drawn times `scale` (the panel's unit prefix).
    """
    path, goal = tracking.path_tolerance[row] * scale, tracking.goal_tolerance[row] * scale
    start, end = _window(tracking, step)
    if path > 0.0:
        _band(axis, step.start_s, min(start, step.end_s), path, _PATH, 0.15)
    if step.end_s < start:
        return
    if not last:
        end = step.end_s
    elif tracking.goal_time_s > 0.0:
        axis.axvline(step.start_s + step.planned_s + tracking.goal_time_s, color=_GOAL, ls=":", lw=1.5)
    if goal > 0.0:
        _band(axis, start, end, goal, _GOAL, 0.3)


def _band(axis: Axes, start: float, end: float, half: float, color: str, alpha: float) -> None:
    """Shade [-half, half] from `start` to `end` [s]; return None. A rectangle: a tenth of fill_between's cost."""
    from matplotlib.patches import Rectangle

    axis.add_patch(Rectangle((start, -half), end - start, 2.0 * half, color=color, alpha=alpha, lw=0))


def _goal_zoom(axis: Axes, tracking: Tracking, step: TrackedStep, row: int) -> None:
    """Draw a step's error around its goal window, scaled to the goal tolerance; return None."""
    start = _window(tracking, step)[0]
    if step.end_s < start:
        axis.axis("off")
        if row == 0:
            axis.text(0.5, 0.9, f"not reached: step\n'{step.name}' ended\nat {step.end_s:.3f} s, before\n"
                      f"its last point at\n{start:.3f} s", transform=axis.transAxes, ha="center", va="top",
                      fontsize=9, color="0.3")
        return
    if row == 0:
        axis.text(0.02, 0.97, step.name, transform=axis.transAxes, rotation=90, va="top", fontsize=7, color="0.3")
    # Scaled to the error the zoom shows and the violations, not to the steps before it.
    joint = tracking.joints[row]
    checked = step.times_s >= _zoom_range(tracking, step)[0]
    decided = [float(np.nanmax(np.abs(finite_or_nan(bound[checked, row])), initial=0.0))
               for bound in (step.error_low, step.error_high)]
    marks = [abs(m.error) for m in step.marks if m.joint == joint and m.check in _POSITION_CHECKS]
    largest = max([value for value in (*decided, *marks) if math.isfinite(value)], default=0.0)
    span, off = symmetric_span(largest, (tracking.goal_tolerance[row],))
    scale, unit = prefixed(span, tracking.units[row])
    _tolerance_bands(axis, tracking, step, row, True, scale)
    _error_curve(axis, step, row, scale)
    axis.axhline(0.0, color="0.7", lw=0.6)
    axis.set_ylim(-span * scale, span * scale)
    axis.set_ylabel(f"[{unit}]", fontsize=8, labelpad=1)
    if off:
        corner_note(axis, f"goal ±{off[0]:.3g} {tracking.units[row]}\noff-scale")
    _violations((axis,), (scale,), [step], joint, label=False)


def _zoom_range(tracking: Tracking, step: TrackedStep) -> tuple[float, float]:
    """Return the time range [s] of a step's goal zoom: a little before the goal check to a little after the decision.

    A long goal_time would otherwise hide a quick decision.
    """
    start = _window(tracking, step)[0]
    margin = max(0.25 * (step.end_s - start), 0.1 * step.planned_s, 5.0 * tracking.period_s)
    return start - margin, max(step.end_s, start) + margin


def _largest_error(steps: Sequence[TrackedStep], joint: str, row: int) -> float:
    """Return a joint's largest finite |error| over the steps' samples and position violations."""
    sampled = [float(np.nanmax(np.abs(finite_or_nan(bound[:, row])), initial=0.0))
               for s in steps for bound in (s.error_low, s.error_high)]
    marked = [abs(m.error) for s in steps for m in s.marks
              if m.joint == joint and m.check in _POSITION_CHECKS and math.isfinite(m.error)]
    return max([*sampled, *marked], default=0.0)


def _error_curve(axis: Axes, step: TrackedStep, row: int, scale: float) -> None:
    """Draw a step's error times `scale`, shaded between its smallest and largest where thinned; return None."""
    low, high = finite_or_nan(step.error_low[:, row]), finite_or_nan(step.error_high[:, row])
    if not np.array_equal(low, high, equal_nan=True):
        axis.fill_between(step.times_s, low * scale, high * scale, color=_ACTUAL, alpha=0.35, lw=0)
    axis.plot(step.times_s, finite_or_nan(step.error[:, row]) * scale, color=_ACTUAL, lw=1.0)


def _least_span(axis: Axes) -> None:
    """Widen a position panel to at least _LEAST_SPAN: a joint at rest reads as a flat line."""
    low, high = axis.get_ylim()
    if high - low < _LEAST_SPAN:
        middle = 0.5 * (low + high)
        axis.set_ylim(middle - 0.5 * _LEAST_SPAN, middle + 0.5 * _LEAST_SPAN)


def _tolerance_note(tracking: Tracking, row: int, largest: float, off: Sequence[float]) -> str:
    """Return an error panel's note: the largest error and each tolerance, unchecked or off-scale."""
    unit = tracking.units[row]
    parts = []
    for what, value in (("path", tracking.path_tolerance[row]), ("goal", tracking.goal_tolerance[row])):
        if value <= 0.0:
            parts.append(f"{what} 0: not checked")
        else:
            parts.append(f"{what} ±{value:.3g}" + (" (off-scale)" if value in off else ""))
    return f"largest |error| {largest:.3g} {unit}; " + ", ".join(parts)


def _violations(
    axes: Sequence[Axes], scales: Sequence[float], steps: Sequence[TrackedStep], joint: str, label: bool
) -> None:
    """Mark a joint's violations on `axes` (position, then error panels, each drawn times its scale); return None.

    A position check is a red x at the actual position and at the error; another check of
    the joint, or a time check (no joint), a red dashed line, named on top if `label`.
    """
    for step in steps:
        for mark in step.marks:
            if mark.joint == joint and mark.check in _POSITION_CHECKS:
                values = (mark.actual, mark.error) if len(axes) == 2 else (mark.error,)
                for axis, value, scale in zip(axes, values, scales, strict=True):
                    axis.plot([mark.time_s], [value * scale], "x", color=_VIOLATION, ms=9, mew=2, zorder=5)
            elif mark.joint in (joint, ""):
                for axis in axes:
                    axis.axvline(mark.time_s, color=_VIOLATION, ls="--", lw=1.2)
                if label or mark.joint:
                    axes[-1].text(mark.time_s, 0.97, f"{mark.check} ", transform=blended(axes[-1]), ha="right",
                                  va="top", fontsize=8, color=_VIOLATION)


def _tracking_legend(tracking: Tracking) -> list[Any]:
    """Return the legend's entries, saying how zero tolerances and goal_time are drawn."""
    from matplotlib.patches import Patch

    unchecked = "; 0: not checked, no band"
    path_zero = unchecked if np.any(tracking.path_tolerance <= 0.0) else ""
    goal_zero = unchecked if np.any(tracking.goal_tolerance <= 0.0) else ""
    deadline = (f"until goal_time {tracking.goal_time_s:g} s (dotted)" if tracking.goal_time_s > 0.0
                else "goal_time 0: no deadline")
    return [
        legend_line(_REFERENCE, "--", "plan reference"),
        legend_line(_ACTUAL, "-", "actual (error: min-max band where thinned)"),
        Patch(color=_PATH, alpha=0.3, label=f"path tolerance{path_zero}"),
        Patch(color=_GOAL, alpha=0.45, label=f"goal tolerance, {deadline}{goal_zero}"),
        legend_line(_VIOLATION, "", "violation (dashed: a time check)", marker="x"),
        legend_line("0.55", "-", "step start"),
    ]
