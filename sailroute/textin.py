"""Reading user text files safely: CSV rows line by line, and what messages may quote.

Shared by the station and track readers (and any reader of delimited text):

* :func:`text_lines` splits a file's text at its line ends only (``\n``, ``\r\n``,
  ``\r``): a U+2028 or a form feed inside a name is not a line end;
* :func:`csv_rows` splits each line on its own, so that a stray quote spoils one line
  (and is reported with its number) instead of swallowing the rest of the file;
* :func:`looks_binary` tells a text file from a binary one before anything is parsed;
* :func:`bad_char` finds, and :func:`clean_text` replaces, the characters that no output
  file can carry (controls other than tab, LF and CR, lone surrogates, U+FFFE/U+FFFF):
  the YAML reader refuses them, the other readers and every writer of XML, HTML and
  CSV replace them;
* :func:`excerpt` is the only form in which a file's content appears in a message:
  short, with control characters replaced, so that an error never prints a whole
  line of a file that is not what was expected (e.g. ``/etc/passwd`` given as a
  station CSV).  Readers quote a header only when :func:`looks_like_header` says it
  is one (two or more short column names).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Iterable, Sequence
from typing import IO, Any

from sailroute.errors import InputError

__all__ = [
    "EXCERPT_CHARS",
    "CleanCsvWriter",
    "bad_char",
    "clean_text",
    "csv_rows",
    "excerpt",
    "looks_binary",
    "looks_like_header",
    "quote_header",
    "text_lines",
]

EXCERPT_CHARS = 60
"""Longest excerpt of a file's content a message quotes [characters]."""


_BAD_CHAR = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
"""Characters no output file can carry: controls other than tab, LF and CR (XML 1.0 has no
way to write them), lone surrogates (UTF-8 has none), U+FFFE and U+FFFF."""


def bad_char(text: str) -> str | None:
    """The first character of ``text`` that no output file can carry, described.

    Parameters
    ----------
    text : str
        User text (a name, a description).

    Returns
    -------
    str or None
        ``"U+0000 (a control character)"``, ``"U+D800 (a lone surrogate)"`` or
        ``"U+FFFE (a non-character)"``; None if every character is fine (tab, line
        feed and carriage return are).
    """
    m = _BAD_CHAR.search(text)
    if m is None:
        return None
    code = ord(m.group())
    kind = (
        "a lone surrogate"
        if 0xD800 <= code <= 0xDFFF
        else "a non-character"
        if code >= 0xFFFE
        else "a control character"
    )
    return f"U+{code:04X} ({kind})"


def clean_text(text: str) -> str:
    """``text`` with every character :func:`bad_char` refuses replaced by U+FFFD."""
    return _BAD_CHAR.sub("\ufffd", text)


class CleanCsvWriter:
    """A :func:`csv.writer` whose text cells go through :func:`clean_text` first.

    Parameters
    ----------
    fh : file
        Opened for writing text with ``newline=""``.
    **kwargs
        Passed to :func:`csv.writer`.
    """

    def __init__(self, fh: IO[str], **kwargs: Any) -> None:
        self._w = csv.writer(fh, **kwargs)

    def writerow(self, row: Iterable[Any]) -> None:
        """Write one row (text cells cleaned, others as :func:`csv.writer` writes them)."""
        self._w.writerow([clean_text(c) if isinstance(c, str) else c for c in row])

    def writerows(self, rows: Iterable[Iterable[Any]]) -> None:
        """Write several rows."""
        for r in rows:
            self.writerow(r)


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


_LINE_END = re.compile(r"\r\n|\r|\n")


def text_lines(text: str) -> list[str]:
    """The lines of a text file, split at ``\n``, ``\r\n`` and ``\r`` only.

    :meth:`str.splitlines` also splits at U+2028/U+2029, U+0085, form feed, vertical
    tab and the file/group/record separators, which a name in a CSV cell may hold: the
    row would be cut in two and its second half read as a row of its own.
    """
    lines = _LINE_END.split(text)
    if lines and lines[-1] == "":
        lines.pop()  # the line end of the last line
    return lines


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
            if len(line) > csv.field_size_limit():
                raise InputError(
                    f"{src}, line {lineno}: a line of {len(line)} characters, with a field "
                    f"longer than {csv.field_size_limit()}; expected short fields (is it "
                    "the right file?)"
                ) from None
            raise InputError(
                f"{src}, line {lineno}: cannot split the line into fields ({exc}); check "
                'its quotes: a field that starts with " must end with " before the next '
                f"{delimiter!r}"
            ) from None
    return out
