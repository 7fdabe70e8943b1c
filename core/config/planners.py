"""The planners moveplan runs, by name, known without importing OMPL: OMPL's geometric ones and Pilz's.

Reading a MoveIt request or a config names a planner; checking that name should not
load OMPL. tests/planning/test_planning.py holds PLANNERS equal to the ompl package's own.
"""

from __future__ import annotations

__all__ = ["PILZ_PLANNERS", "PLANNERS"]

PLANNERS = (
    "AORRTC", "BFMT", "BITstar", "BKPIECE1", "FMT", "InformedRRTstar", "KPIECE1", "LBKPIECE1", "PRM", "PRMstar",
    "RRT", "RRTConnect", "RRTstar", "SORRTstar",
)

PILZ_PLANNERS = ("PTP", "LIN", "CIRC")
"""MoveIt's pilz_industrial_motion_planner, as moveplan plans them: PTP the straight line in joint space
(collision-checked, never planned around an obstacle), LIN the straight line of the tool to the goal pose
(a joint goal's pose, for a joint goal), as `--linear` plans it, CIRC the tool's circular arc to the goal
through an interim point or about a center. Each fails where its path collides."""
