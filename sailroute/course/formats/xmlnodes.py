"""A small XML element tree that remembers the line of every element.

The course importers (GPX, KML, race XML) name the line of a bad element in their
messages; :mod:`xml.etree.ElementTree` does not keep lines, so the tree is built here
from the expat parser's callbacks.  Document type declarations are refused: no course
file needs one, and refusing them rules out entity expansion.  So are elements nested
deeper than :data:`MAX_DEPTH` (a course file needs a few levels; thousands of nested
KML folders would exhaust the stack of whatever walks the tree) and an encoding that
expat cannot read (``encoding="rot13"``, UTF-7).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from sailroute.errors import InputError

__all__ = ["MAX_DEPTH", "Node", "parse_xml"]

MAX_DEPTH = 100
"""Deepest nesting of elements a course file may have (KML's Document/Folder/Placemark/
Polygon/outerBoundaryIs/LinearRing/coordinates needs 8 and a few folders)."""


@dataclass(eq=False)
class Node:
    """One XML element.

    Attributes
    ----------
    tag : str
        The local name (namespace and prefix removed).
    attrs : dict of str to str
        Attributes, by local name.
    line : int
        1-based line of the start tag.
    children : list of Node
        Child elements in document order.
    text : str
        The element's own character data, stripped.
    """

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Node] = field(default_factory=list)
    text: str = ""

    def find(self, tag: str) -> Node | None:
        """The first child called ``tag``, or None."""
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list[Node]:
        """The children called ``tag``, in order."""
        return [c for c in self.children if c.tag == tag]

    def child_text(self, tag: str) -> str:
        """Text of the first child called ``tag`` (``""`` when absent)."""
        c = self.find(tag)
        return c.text if c is not None else ""

    def iter(self, tag: str) -> Iterator[Node]:
        """Every element called ``tag`` below this one (and itself), in document order."""
        todo = [self]
        while todo:
            node = todo.pop()
            if node.tag == tag:
                yield node
            todo.extend(reversed(node.children))


def _local(name: str) -> str:
    return name.rsplit("}", 1)[-1].rsplit(":", 1)[-1]


def parse_xml(path: Path, what: str) -> Node:
    """Parse an XML file into :class:`Node` s.

    Parameters
    ----------
    path : Path
        The file.
    what : str
        What the file should be, for messages (``"a GPX file"``).

    Returns
    -------
    Node
        The root element.

    Raises
    ------
    InputError
        Unreadable file, not well-formed XML (with line and column), a document type
        declaration, or no element at all.
    """
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(
            f"{path}: cannot read the file ({exc.strerror}); expected {what}"
        ) from None
    parser = expat.ParserCreate(namespace_separator="}")
    stack: list[Node] = []
    texts: list[list[str]] = []
    root: list[Node] = []

    def start(name: str, attrs: dict[str, str]) -> None:
        if len(stack) >= MAX_DEPTH:
            raise InputError(
                f"{path}: line {parser.CurrentLineNumber}: elements nested more than "
                f"{MAX_DEPTH} levels deep; expected {what} (a course needs a few levels)"
            )
        node = Node(
            _local(name), {_local(k): v for k, v in attrs.items()}, parser.CurrentLineNumber
        )
        if stack:
            stack[-1].children.append(node)
        else:
            root.append(node)
        stack.append(node)
        texts.append([])

    def end(name: str) -> None:
        node = stack.pop()
        node.text = "".join(texts.pop()).strip()

    def chars(chunk: str) -> None:
        if texts:
            texts[-1].append(chunk)

    def doctype(*_: object) -> None:
        raise InputError(
            f"{path}: line {parser.CurrentLineNumber}: a document type "
            f"declaration (<!DOCTYPE>); expected {what} without one (remove it)"
        )

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.StartDoctypeDeclHandler = doctype
    parser.buffer_text = True
    try:
        parser.Parse(data, True)
    except expat.ExpatError as exc:
        raise InputError(
            f"{path}:{exc.lineno}:{exc.offset + 1}: not well-formed XML "
            f"({expat.errors.messages[exc.code]}); expected {what}"
        ) from None
    except InputError:  # from the handlers above
        raise
    except (LookupError, ValueError) as exc:  # an encoding expat cannot use
        declared = re.search(rb"""encoding\s*=\s*["']([^"']{0,40})""", data[:200])
        name = declared.group(1).decode("ascii", "replace") if declared else "?"
        raise InputError(
            f"{path}: line 1: cannot read the encoding {name!r} the XML declaration "
            f"names ({exc}); expected {what} in UTF-8 (save it as UTF-8)"
        ) from None
    if not root:
        raise InputError(f"{path}: no XML element found; expected {what}")
    return root[0]
