"""The PNG plots of inspect, execute, check-tolerances and tune-pid: one file a command, written atomically.

`commands` runs a command with its plot (a plan's curves, an execution's or a recording's
tracking), `tracking` and `tuning` draw those figures, `figures` is what they share (figures
sized per joint, step lines, notes, PNG files). matplotlib is imported inside the functions
that draw, so importing these modules loads none of it.
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from .commands import check_plot_path, check_plotted, execute_plotted, write_plan_plot
    from .tuning import write_tuning_plot

__all__ = [
    "check_plot_path",
    "check_plotted",
    "execute_plotted",
    "write_plan_plot",
    "write_tuning_plot",
]

__getattr__ = lazy_exports(__name__, {
    "check_plot_path": "commands",
    "check_plotted": "commands",
    "execute_plotted": "commands",
    "write_plan_plot": "commands",
    "write_tuning_plot": "tuning",
})
