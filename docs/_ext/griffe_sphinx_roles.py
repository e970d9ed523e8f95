"""Griffe extension for the API reference: Sphinx roles in docstrings -> links.

The docstrings are numpydoc and use Sphinx cross-reference roles
(``:func:`~sailroute.planning.route.plan_course```), which Markdown would print as they are.
This rewrites each role into an optional mkdocs-autorefs reference in a code span:
a link where the target is rendered in the site (``docs/api.md``), plain code
where it is not (optional references never warn).  A ``~`` shows the last
component only, as in Sphinx.  A ``[`` right after ``]`` is escaped (units in
brackets, ``[kg] [T]``, would be a Markdown reference link).  RST's ``Example::``
literal-block marker loses one colon (the indented block is a Markdown code block
already).

Loaded by ``mkdocs.yml`` (mkdocstrings ``extensions:``); not part of the package.
"""

from __future__ import annotations

import html
import re
from typing import Any

from griffe import Extension, Object

ROLE = re.compile(
    r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const|term|ref):`(?P<body>[^`]+)`"
)
EXPLICIT = re.compile(r"^(?P<title>.+?)\s*<(?P<target>[^<>]+)>$")
LITERAL_MARKER = re.compile(r"(\S)::$", flags=re.MULTILINE)
CODE_SPAN = re.compile(r"(``.+?``|`[^`]+`)")
ADJACENT = re.compile(r"\](\s?)\[")


def _reference(match: re.Match[str], module: str) -> str:
    body = match["body"].strip()
    explicit = EXPLICIT.match(body)
    if explicit:
        title, target = explicit["title"], explicit["target"]
    else:
        target = body.lstrip("~").lstrip(".")
        title = target.rsplit(".", 1)[-1] if body.startswith("~") else target
    if "." not in target and module:
        target = f"{module}.{target}"  # a name of the same module
    return (
        f'<autoref identifier="{html.escape(target)}" optional>'
        f"<code>{html.escape(title)}</code></autoref>"
    )


def _brackets(line: str) -> str:
    """Escape ``[`` after ``]``: units such as ``[kg] [T]`` are not a Markdown link."""
    if line.lstrip().startswith((">>>", "...")):
        return line
    parts = CODE_SPAN.split(line)
    parts[::2] = [ADJACENT.sub(r"]\1\\[", p) for p in parts[::2]]
    return "".join(parts)


def rewrite(text: str, module: str = "") -> str:
    """``text`` with Sphinx roles replaced by optional autorefs (and see :func:`_brackets`)."""
    text = "\n".join(_brackets(line) for line in text.split("\n"))
    text = ROLE.sub(lambda m: _reference(m, module), text)
    return LITERAL_MARKER.sub(r"\1:", text)


class SphinxRoles(Extension):
    """Rewrite Sphinx roles in every docstring as it is read."""

    def on_instance(self, *, obj: Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            module = obj.module.path if obj.module is not None else ""
            obj.docstring.value = rewrite(obj.docstring.value, module)
