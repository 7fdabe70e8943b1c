"""The PNG plots of inspect, execute, check-tolerances and tune-pid: one file a command, written atomically.

`_plan` draws a plan's curves, `commands` runs execute and check-tolerances with their plot
(an execution's or a recording's tracking), `_tracking` and `tuning` draw those figures,
`_figures` is what they share (figures sized per joint, axis ranges, step lines, notes, PNG
files). matplotlib is imported inside the functions that draw, so importing these modules loads
none of it.
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from ._figures import check_plot_path
    from ._plan import write_plan_plot
    from .commands import check_plotted, checked_tracking, execute_plotted
    from .tuning import write_tuning_plot

__all__ = [
    "check_plot_path",
    "check_plotted",
    "checked_tracking",
    "execute_plotted",
    "write_plan_plot",
    "write_tuning_plot",
]

__getattr__ = lazy_exports(__name__, {
    "check_plot_path": "_figures",
    "check_plotted": "commands",
    "checked_tracking": "commands",
    "execute_plotted": "commands",
    "write_plan_plot": "_plan",
    "write_tuning_plot": "tuning",
})
