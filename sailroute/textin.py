"""Reading user text files safely: CSV rows line by line, and what messages may quote.

Shared by the station and track readers (and any reader of delimited text):

* :func:`csv_rows` splits each line on its own, so that a stray quote spoils one line
  (and is reported with its number) instead of swallowing the rest of the file;
* :func:`looks_binary` tells a text file from a binary one before anything is parsed;
* :func:`excerpt` is the only form in which a file's content appears in a message:
  short, with control characters replaced, so that an error never prints a whole
  line of a file that is not what was expected (e.g. ``/etc/passwd`` given as a
  station CSV).  Readers quote a header only when :func:`looks_like_header` says it
  is one (two or more short column names).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Sequence

from sailroute.errors import InputError

__all__ = ["EXCERPT_CHARS", "csv_rows", "excerpt", "looks_binary", "looks_like_header",
           "quote_header"]

EXCERPT_CHARS = 60
"""Longest excerpt of a file's content a message quotes [characters]."""


def excerpt(text: str, limit: int = EXCERPT_CHARS) -> str:
    """``text`` as a message may quote it: printable characters only, at most ``limit``.

    Parameters
    ----------
    text : str
        A cell, a header, a line of a user's file.
    limit : int
        Most characters kept; a longer text ends in ``...``.

    Returns
    -------
    str
        The text with every non-printable character (controls, tabs, lone
        surrogates, the replacement character of undecodable bytes) as ``?``.
    """
    clean = "".join(ch if ch.isprintable() and ch != "\ufffd" else "?" for ch in text)
    return clean if len(clean) <= limit else clean[: max(limit - 3, 0)] + "..."


def quote_header(header: Sequence[str], limit: int = 2 * EXCERPT_CHARS) -> str:
    """A CSV header for a message: its fields joined by ``", "``, as :func:`excerpt`."""
    return excerpt(", ".join(h.strip() for h in header), limit)


_COLUMN_NAME = re.compile(r"[\w .()/%°#\[\]-]{1,40}")


def looks_like_header(header: Sequence[str]) -> bool:
    """True if ``header`` (the fields of a file's first line) looks like CSV column names:
    two or more, each of at most 40 letters, digits, blanks or ``_ . ( ) / % ° # [ ] -``.

    A line of another kind of text (``root:x:0:0:root:/root:/bin/bash``, a sentence,
    binary) is not, and a message about it does not quote it.
    """
    names = [h.strip() for h in header]
    return len(names) >= 2 and all(_COLUMN_NAME.fullmatch(h) for h in names if h)


def looks_binary(text: str) -> bool:
    """True for the text of a binary file: a NUL, or mostly undecodable bytes, in its
    first 4096 characters (read with ``errors="replace"``)."""
    head = text[:4096]
    return "\x00" in head or head.count("\ufffd") > max(8, len(head) // 20)


def csv_rows(lines: Sequence[tuple[int, str]], delimiter: str, src: str) -> list[list[str]]:
    """Split numbered lines into fields, each line on its own.

    Parameters
    ----------
    lines : sequence of (int, str)
        ``(1-based line number, line)`` of the header and the data rows.
    delimiter : str
        The separator (``,``, ``;``, tab).
    src : str
        The file, for messages.

    Returns
    -------
    list of list of str
        One list of fields per line.

    Raises
    ------
    InputError
        A line whose quotes do not pair up (``4.10,"61``: a field that opens a quote
        and never closes it, or text after a closing quote), or a field longer than
        the csv module's limit; the message names the line.
    """
    out: list[list[str]] = []
    for lineno, line in lines:
        try:
            out.append(next(csv.reader([line], delimiter=delimiter, strict=True), []))
        except csv.Error as exc:
            raise InputError(
                f"{src}, line {lineno}: cannot split the line into fields ({exc}); check "
                "its quotes: a field that starts with \" must end with \" before the next "
                f"{delimiter!r}") from None
    return out
