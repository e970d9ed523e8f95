"""User text (names of marks, boats, scenarios) made safe for the pages' two markups.

A name is text: on a page it must read as written, never as markup.  ``report.html`` shows
names in two places that read markup differently: its HTML (titles, tables, notes) and the
plotly figure (trace names, hover text, mark labels), which draws its own small markup
(``<b>``, ``<a href>``, ``<br>``, entities) and reads ``%{...}`` in a hover template as a
placeholder.
"""

from __future__ import annotations

import html

from sailroute.textin import clean_text

__all__ = ["html_text", "plotly_label"]


def html_text(text: str) -> str:
    """User text for a page's HTML: escaped, control characters replaced."""
    return html.escape(clean_text(text))


def plotly_label(text: str) -> str:
    """User text (a name) for plotly: trace names, hover text and mark labels.

    ``&``, ``<`` and ``>`` become entities, ``%`` becomes ``&#37;`` (so ``%{y}`` in a name
    is no placeholder), control characters U+FFFD.  (``&quot;`` is not among the entities
    plotly knows, so quotes stay as they are.)
    """
    return html.escape(clean_text(text), quote=False).replace("%", "&#37;")
