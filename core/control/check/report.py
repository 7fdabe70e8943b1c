"""What a recording check found: each step judged, each execution (cycle) of the plan, and the report."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...types import SkippedData
from ..margins import merged_margins
from ..results import INCOMPLETE, SUCCESSFUL, ExecutionResult, ToleranceReport, Violation

__all__ = ["CheckReport", "CycleCheck", "StepCheck"]


@dataclass(frozen=True)
class StepCheck:
    """One step judged as a goal of its own.

    Attributes:
        name: The step's name.
        start_s: Where its goal starts, in [s] from the recording's first sample.
        duration_s: From its start to the sample that decided, in [s].
        report: The verdict; its times are from the step's start.
        aligned_by: How the start was found: "departure", "given", "previous step",
            "first departure" (never rested near the first point) or "first sample".

    """

    name: str
    start_s: float
    duration_s: float
    report: ToleranceReport
    aligned_by: str

    @property
    def ok(self) -> bool:
        """Return True if the step succeeded."""
        return self.report.ok

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the step off before a verdict (INCOMPLETE)."""
        return self.report.result.code != INCOMPLETE


@dataclass(frozen=True)
class CycleCheck:
    """One execution of the plan found in the recording (`start="all"`).

    Attributes:
        index: Its place in the recording, in time order from 0.
        start_s: Where its first goal started, in [s] from the recording's first sample; for
            one already running when the recording began, the first sample's time.
        steps: Its steps judged, up to the first that did not succeed (none for one already
            running when the recording began).
        result: Its verdict: the failing step's result, else INCOMPLETE if the recording cuts
            it off, else SUCCESSFUL.

    """

    index: int
    start_s: float
    steps: tuple[StepCheck, ...]
    result: ExecutionResult

    @property
    def ok(self) -> bool:
        """Return True if the execution succeeded."""
        return self.result.code == SUCCESSFUL

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the execution off before a verdict (INCOMPLETE)."""
        return self.result.code != INCOMPLETE

    @property
    def margins(self) -> dict[str, float]:
        """Return per joint the smallest margin to its tolerance over the steps, in [rad]."""
        return merged_margins(step.report.margins for step in self.steps)

    @property
    def worst_margin(self) -> float | None:
        """Return the smallest margin of any joint in [rad], None if nothing was checked."""
        return min(self.margins.values(), default=None)

    @property
    def duration_s(self) -> float:
        """Return the time from the execution's start to its last decision in [s]."""
        if not self.steps:
            return 0.0
        last = self.steps[-1]
        return last.start_s + last.duration_s - self.start_s


@dataclass(frozen=True)
class CheckReport:
    """The verdict on a recording.

    Attributes:
        ok: True if the execution succeeded; with `start="all"`, if no cycle failed and at
            least one is complete (INCOMPLETE cycles count neither way).
        result: How the execution ended, INCOMPLETE if the recording cuts it off before a
            verdict; with `start="all"`, the first failing cycle's code with a message naming
            it, else SUCCESSFUL, or INCOMPLETE if no cycle is complete.
        violations: (step name, violation) of the execution reported (the first failing
            cycle's, with `start="all"`); violation times are from that step's start.
        margins: Per joint the smallest tolerance - |error| over all checks, in [rad].
        duration_s: From the first checked start to the last decision in [s].
        start_s: The first execution's start in [s] from the recording's first sample.
        steps: The steps of the single execution (empty with `start="all"`).
        cycles: Every execution found (`start="all"` only), in time order.
        failing_cycles: Indices of the cycles that failed.
        incomplete_cycles: Indices of the cycles the recording cuts off (INCOMPLETE).
        gaps: (start_s, length_s) of pauses between samples longer than GAP_FACTOR median
            periods, start in [s] from the recording's first sample.
        warnings: Things the user should know: gaps, sparse samples, alignment fallbacks.
        recording_start_ns: Time of the recording's first sample in [ns].
        skipped: The damaged parts of the recording its read skipped, as asked (--skip-damaged).
        unchecked: Per check (path, goal), the joints the controller does not check (tolerance 0).
        prismatic: The plan's prismatic joints (their positions are in [m]).

    """

    ok: bool
    result: ExecutionResult
    violations: tuple[tuple[str, Violation], ...]
    margins: dict[str, float]
    duration_s: float
    start_s: float
    steps: tuple[StepCheck, ...]
    cycles: tuple[CycleCheck, ...]
    failing_cycles: tuple[int, ...]
    incomplete_cycles: tuple[int, ...]
    gaps: tuple[tuple[float, float], ...]
    warnings: tuple[str, ...]
    recording_start_ns: int
    skipped: tuple[SkippedData, ...] = ()
    unchecked: dict[str, tuple[str, ...]] = field(default_factory=dict)
    prismatic: frozenset[str] = frozenset()

    @property
    def complete(self) -> bool:
        """Return False if the recording cuts the execution (every execution) off before a verdict."""
        return self.result.code != INCOMPLETE
