"""Layer 7: static figures (matplotlib, Agg canvas, no pyplot) and the HTML report.

* :mod:`uvnav.viz.figures` — episode figures (thesis Figs. 2.7–2.10) and campaign summaries.
* :mod:`uvnav.viz.report` — ``index.html`` from a results database.
* :mod:`uvnav.viz.reproduction` — figures and report of the Chapter 2 reproduction.
"""

from uvnav.viz.figures import plot_campaign_summary, plot_comparison, plot_episode
from uvnav.viz.report import summary_table, write_report

__all__ = [
    "plot_campaign_summary",
    "plot_comparison",
    "plot_episode",
    "summary_table",
    "write_report",
]
