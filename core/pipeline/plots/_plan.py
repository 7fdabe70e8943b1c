"""The figure of a plan (inspect --plot) and the command drawing it: per joint, position, velocity, acceleration.

Each panel is scaled to what the plan does. Velocity and acceleration are drawn against the
limits as planned (the joint's limit times the step's scaling factor, dashed); the joint's own
limit is drawn dotted where it falls in range, else named in the panel's note, as are
position limits far outside the motion. matplotlib is imported inside the drawing functions.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...bag import PlanFile
from ...errors import UsageError
from ...trajectory import peak_rates, sample
from ...types import frozen_array
from .._plan_files import plan_config
from ._figures import (
    IN_RANGE,
    corner_note,
    grid,
    legend,
    legend_line,
    position_units,
    step_budget,
    step_lines,
    symmetric_span,
    time_axis,
    uncollected,
    value_axes,
    write_png,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["PlanCurves", "plan_curves", "plan_figure", "write_plan_plot"]

_CURVE, _LIMIT = "C0", "C3"
_LEAST_SPAN = 0.01  # [rad] or [m]: a position panel is never narrower
_RATES = (("velocity", "max_velocity", "/s"), ("acceleration", "max_acceleration", "/s²"))


@dataclass(frozen=True)
class PlanCurves:
    """What `plan_figure` draws: a plan sampled as the controller interpolates it, on the plan's timeline.

    Attributes:
        title: The figure's title.
        joints: Column order of the arrays; `units` their position units.
        steps: (name, start [s], duration [s]) of each step.
        scaling: Per step, the (velocity, acceleration) scaling its timing used; None: unknown (1 is drawn).
        times_s: Sample times [s], shape (m,); positions, velocities, accelerations (m, n).
        knots_s: Times of the waypoints [s]; knot_positions their positions.
        limits: Per joint lower, upper, max_velocity, max_acceleration (absent: not limited).

    """

    title: str
    joints: tuple[str, ...]
    units: tuple[str, ...]
    steps: tuple[tuple[str, float, float], ...]
    scaling: tuple[tuple[float, float] | None, ...]
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


def plan_figure(curves: PlanCurves) -> Figure:
    """Return a figure of a plan: per joint, position, velocity and acceleration against their limits."""
    figure, axes = grid(len(curves.joints), 3, curves.title)
    end = float(curves.times_s[-1]) if len(curves.times_s) and curves.times_s[-1] > 0.0 else 1.0
    scales = _sample_scaling(curves)
    for row, joint in enumerate(curves.joints):
        limits, unit = curves.limits.get(joint, {}), curves.units[row]
        position = axes[row, 0]
        position.plot(curves.times_s, curves.positions[:, row], color=_CURVE, lw=1.2)
        position.plot(curves.knots_s, curves.knot_positions[:, row], "o", color=_CURVE, ms=3)
        _position_range(position, np.concatenate((curves.positions[:, row], curves.knot_positions[:, row])),
                        limits.get("lower"), limits.get("upper"), unit)
        position.set_ylabel(f"{joint}\n[{unit}]", fontsize=9)
        for which, (what, key, per) in enumerate(_RATES):
            axis = axes[row, which + 1]
            values = (curves.velocities, curves.accelerations)[which][:, row]
            axis.plot(curves.times_s, values, color=_CURVE, lw=1.2)
            _rate_limits(axis, curves, values, scales[:, which], limits.get(key), which, f"{unit}{per}")
            axis.set_ylabel(f"[{unit}{per}]", fontsize=9)
            if row == 0:
                axis.set_title(what, fontsize=10)
    axes[0, 0].set_title("position", fontsize=10)
    value_axes(axes)
    for column in range(3):
        time_axis(axes[:, column], 0.0, end)
    step_lines(axes, [(name, start) for name, start, _ in curves.steps])
    legend(figure, _legend(curves), 5)
    return figure


@uncollected
def write_plan_plot(plan: PlanFile | None, source: Path, path: Path) -> None:
    """Write a PNG of a plan's joints (position, velocity, acceleration against their limits) to `path`; return None.

    `plan` is the plan read from `source`, None if `source` is no plan file.

    Raises:
        UsageError: `source` is not a moveplan plan file.
        InputError: `path` cannot be written.

    """
    if plan is None:
        raise UsageError(f"--plot: {source} is not a moveplan plan file; --plot draws the joints of a plan")
    write_png(plan_figure(plan_curves(plan, source)), path)


def plan_curves(plan: PlanFile, source: Path) -> PlanCurves:
    """Return what plan_figure draws of `plan` (read from `source`): its joints sampled as the controller would."""
    config = plan_config(plan, source)
    joints = plan.steps[0].trajectory.joint_names
    total = sum(step.trajectory.duration_s for step in plan.steps)
    times, positions, velocities, accelerations, knots, knot_positions = [], [], [], [], [], []
    for step in plan.steps:
        trajectory = step.trajectory
        count = step_budget(trajectory.duration_s, total)
        since = np.union1d(np.linspace(0.0, trajectory.duration_s, count), trajectory.times_s)
        p, v, a = sample(trajectory, since)
        times.append(step.start_s + since)
        positions.append(p)
        velocities.append(v)
        accelerations.append(a)
        knots.append(step.start_s + trajectory.times_s)
        knot_positions.append(trajectory.positions)
    limits = {j: dict(plan.limits.get(j, {})) for j in joints}
    for j in joints:
        if j in config.limits and config.limits[j].continuous:  # its ±pi bounds are no limits
            limits[j].pop("lower", None)
            limits[j].pop("upper", None)
    peaks = _peak_shares(plan)
    return PlanCurves(
        title=f"moveplan inspect {source.name}: {plan.robot_name} / {plan.group}, {len(plan.steps)} steps, "
              f"{total:.2f} s; peak velocity {peaks[0]:.0%}, acceleration {peaks[1]:.0%} of the limits",
        joints=joints, units=position_units(config, joints), steps=tuple((s.name, s.start_s, s.trajectory.duration_s)
                                                               for s in plan.steps),
        scaling=tuple(s.scaling for s in plan.steps),
        times_s=np.concatenate(times), positions=np.concatenate(positions), velocities=np.concatenate(velocities),
        accelerations=np.concatenate(accelerations), knots_s=np.concatenate(knots),
        knot_positions=np.concatenate(knot_positions), limits=limits,
    )


def _peak_shares(plan: PlanFile) -> tuple[float, float]:
    """Return the plan's largest velocity and acceleration as shares of the joint's limit, over joints and steps."""
    shares = [0.0, 0.0]
    for step in plan.steps:
        for which, peaks in enumerate(peak_rates(step.trajectory)):
            key = ("max_velocity", "max_acceleration")[which]
            for joint, peak in zip(step.trajectory.joint_names, peaks, strict=True):
                limit = plan.limits.get(joint, {}).get(key, 0.0)
                if limit > 0.0:
                    shares[which] = max(shares[which], float(peak) / limit)
    return shares[0], shares[1]


def _sample_scaling(curves: PlanCurves) -> NDArray[np.float64]:
    """Return per sample the (velocity, acceleration) scaling of the step it lies in, shape (m, 2)."""
    factors = np.array([s if s is not None else (1.0, 1.0) for s in curves.scaling] or [(1.0, 1.0)])
    starts = np.array([start for _, start, _ in curves.steps] or [0.0])
    index = np.clip(np.searchsorted(starts, curves.times_s, side="right") - 1, 0, len(factors) - 1)
    return np.asarray(factors[index], dtype=np.float64)


def _position_range(axis: Axes, values: NDArray[np.float64], lower: float | None, upper: float | None,
                    unit: str) -> None:
    """Scale a position panel to the motion, drawing the limits near it and naming those far off; return None."""
    low, high = float(np.min(values, initial=np.inf)), float(np.max(values, initial=-np.inf))
    if not low <= high:
        return
    span = max(high - low, _LEAST_SPAN)
    off = []
    for bound in (lower, upper):
        if bound is None or not math.isfinite(bound):
            continue
        if max(high, bound) - min(low, bound) <= IN_RANGE * span:
            axis.axhline(bound, color=_LIMIT, ls="--", lw=1.0)
            low, high = min(low, bound), max(high, bound)
        else:
            off.append(bound)
    span = max(high - low, _LEAST_SPAN)
    middle = 0.5 * (low + high)
    axis.set_ylim(middle - 0.56 * span, middle + 0.56 * span)
    if off:
        named = " and ".join(f"{bound:.3g}" for bound in off)
        corner_note(axis, f"limit{'s' if len(off) > 1 else ''} {named} {unit}: off-scale")


def _rate_limits(axis: Axes, curves: PlanCurves, values: NDArray[np.float64], scales: NDArray[np.float64],
                 limit: float | None, which: int, unit: str) -> None:
    """Draw a velocity or acceleration panel's limits as planned, scale it and note its peak; return None."""
    peak = float(np.max(np.abs(values), initial=0.0))
    if limit is None or not math.isfinite(limit) or limit <= 0.0:
        axis.set_ylim(*(-1.15 * peak, 1.15 * peak) if peak > 0.0 else (-1.0, 1.0))
        corner_note(axis, f"peak {peak:.3g} {unit}, not limited")
        return
    levels = [limit * (s[which] if s is not None else 1.0) for s in curves.scaling] or [limit]
    starts = [start for _, start, _ in curves.steps]
    ends = [start + duration for _, start, duration in curves.steps]
    axis.hlines([*levels, *(-level for level in levels)], [*starts, *starts], [*ends, *ends], color=_LIMIT, ls="--",
                lw=1.0)
    span, off = symmetric_span(max(peak, *levels), [limit])
    if not off and limit > max(levels) * (1.0 + 1e-9):
        for bound in (limit, -limit):
            axis.axhline(bound, color=_LIMIT, ls=":", lw=1.0)
    axis.set_ylim(-span, span)
    share = float(np.max(np.abs(values) / (limit * scales), initial=0.0))
    note = f"peak {peak:.3g} {unit}, {share:.0%} of planned limit"
    if off:
        note += f"; joint limit ±{limit:.3g}: off-scale"
    corner_note(axis, note)


def _legend(curves: PlanCurves) -> list[Any]:
    """Return the legend's entries; the joint limit's own entry only where a step was scaled."""
    scaled = any(s is not None and min(s) < 1.0 for s in curves.scaling)
    entries = [legend_line(_CURVE, "-", "plan, as the controller interpolates it"),
               legend_line(_CURVE, "", "waypoints", marker="o"),
               legend_line(_LIMIT, "--", "limit as planned (joint limit x the step's scaling)" if scaled
                           else "joint limits")]
    if scaled:
        entries.append(legend_line(_LIMIT, ":", "joint limit"))
    return [*entries, legend_line("0.55", "-", "step start")]
