"""moveit_commander.exception, under its MoveIt name: MoveItCommanderException, moveplan's base error."""

from ..core.errors import MoveplanError

__all__ = ["MoveItCommanderException"]

MoveItCommanderException = MoveplanError
"""moveit_commander's exception: every moveplan error is one, so `except MoveItCommanderException` catches them."""
