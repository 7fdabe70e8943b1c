"""A recording judged as JTC would have judged it: each plan step's goal found in the samples, then checked.

`recording` is the entry (check_recording): the samples read as columns (samples), each step
aligned with the recording (alignment), its context (context), the control cycles rebuilt and
judged window by window with the controller's own rules (cycles, windows), and the verdicts
gathered (verdicts) into the report (report).
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from .recording import RecordingStart, check_recording, uses_velocities
    from .report import CheckReport, CycleCheck, StepCheck
    from .samples import SCAN_ROWS, SampleSource

__all__ = [
    "CheckReport",
    "CycleCheck",
    "RecordingStart",
    "SCAN_ROWS",
    "SampleSource",
    "StepCheck",
    "check_recording",
    "uses_velocities",
]

__getattr__ = lazy_exports(__name__, {
    "CheckReport": "report",
    "CycleCheck": "report",
    "RecordingStart": "recording",
    "SCAN_ROWS": "samples",
    "SampleSource": "samples",
    "StepCheck": "report",
    "check_recording": "recording",
    "uses_velocities": "recording",
})
