"""Reports of routed courses: terminal tables, output files and charts.

``make_plan`` assembles the routers' results into a :class:`Plan`;
``plan_table``/``write_plan_outputs`` render it; ``compare`` puts several
scenarios side by side.  Charts (``sailroute.report.plots``) import matplotlib
lazily; the interactive ``report.html`` (``sailroute.report.html``) reads plotly's
JavaScript bundle only when a page is written.
"""

from sailroute.report.files import write_comparison, write_plan_outputs
from sailroute.report.plan import Comparison, Plan, PlannedLeg, compare, make_plan
from sailroute.report.tables import comparison_table, plan_table

__all__ = [
    "Comparison", "Plan", "PlannedLeg", "compare", "comparison_table", "make_plan",
    "plan_table", "write_comparison", "write_plan_outputs",
]
