"""Reports: terminal tables, output files, charts and pages of every command.

``plan_table``/``write_plan_outputs`` render a :class:`~sailroute.planning.result.Plan`;
:mod:`sailroute.report.analysis` an analysis, :mod:`sailroute.report.strategy` a tack
strategy, :mod:`sailroute.report.polar` a polar.  Charts (``sailroute.report.plots``)
import matplotlib lazily; the interactive ``report.html`` (``sailroute.report.html``)
reads plotly's JavaScript bundle only when a page is written.  Nothing here imports
:mod:`sailroute.commands`.
"""
