"""The OMPL geometric planners moveplan runs, by name, known without importing OMPL.

Reading a MoveIt request or a config names a planner; checking that name should not
load OMPL. tests/planning/test_planning.py holds this list equal to the ompl package's own.
"""

from __future__ import annotations

__all__ = ["PLANNERS"]

PLANNERS = (
    "AORRTC", "BFMT", "BITstar", "BKPIECE1", "FMT", "InformedRRTstar", "KPIECE1", "LBKPIECE1", "PRM", "PRMstar",
    "RRT", "RRTConnect", "RRTstar", "SORRTstar",
)
