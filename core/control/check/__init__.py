"""A recording judged as JTC would have judged it: each plan step's goal found in the samples, then checked.

`recording` is the entry (check_recording): the samples read as columns (samples), each step
aligned with the recording (alignment), its context (context), the control cycles rebuilt and
judged window by window with the controller's own rules (cycles, windows), and the verdicts
gathered (verdicts) into the report (report).
"""

from .recording import check_recording, uses_velocities
from .report import CheckReport, CycleCheck, StepCheck

__all__ = ["CheckReport", "CycleCheck", "StepCheck", "check_recording", "uses_velocities"]
