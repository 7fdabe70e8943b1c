"""rostest's entry point, for a MoveIt test script's `__main__` block: runs its unittest case here, no ROS master."""

from __future__ import annotations

import sys
import unittest
from typing import Any

__all__ = ["rosrun"]


def rosrun(package: str, test_name: str, test: Any, sysargs: Any = None) -> None:
    """Run the unittest TestCase `test` (as rostest.rosrun does), print the result, exit 0 if it passed."""
    suite = unittest.TestLoader().loadTestsFromTestCase(test)
    result = unittest.TextTestRunner(stream=sys.stderr, verbosity=2).run(suite)
    sys.exit(0 if result.wasSuccessful() else 1)
