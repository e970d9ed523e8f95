"""Time handling: timezone-aware at the edges, POSIX seconds (UTC) inside.

Internally every time is a ``float`` number of seconds since
1970-01-01T00:00:00Z ("epoch seconds"), so wind sampling and routing can use
plain float64 arrays.  Timestamps read from files must carry an offset or ``Z``;
naive timestamps are rejected with an :class:`~sailroute.errors.InputError`, and so
are times outside the years :data:`FIRST_YEAR` .. :data:`LAST_YEAR` (UTC): a race is not
sailed then, and a time near the ends of Python's calendar (year 1 or 9999) overflows
once it is converted to UTC or a race's hours are added to it.
"""

from __future__ import annotations

from datetime import UTC, datetime

from sailroute.errors import InputError

FIRST_YEAR = 1900
"""Earliest year (UTC) of a time read from the user [year]."""
LAST_YEAR = 2199
"""Latest year (UTC) of a time read from the user [year]."""
_EARLIEST = datetime(FIRST_YEAR, 1, 1, tzinfo=UTC)
_LATEST = datetime(LAST_YEAR + 1, 1, 1, tzinfo=UTC)


def parse_time(text: str | datetime, where: str = "time") -> datetime:
    """Parse an ISO 8601 timestamp that carries a UTC offset.

    Parameters
    ----------
    text : str or datetime
        E.g. ``"2018-04-24T12:10:00+02:00"`` or ``"2018-04-24T10:10:00Z"``.
    where : str
        Where the value came from (file, key or line) for error messages.

    Returns
    -------
    datetime
        Timezone-aware, converted to UTC.

    Raises
    ------
    InputError
        If the text is not ISO 8601, has no offset, or is outside the years
        :data:`FIRST_YEAR` .. :data:`LAST_YEAR`.
    """
    return _aware(text, where).astimezone(UTC)


def parse_local_time(text: str | datetime, where: str = "time") -> datetime:
    """:func:`parse_time`, keeping the offset the time is written with
    (``"2025-01-19T16:08:00+13:00"`` stays at +13:00; a trailing ``z`` is UTC).

    Raises
    ------
    InputError
        As :func:`parse_time`.
    """
    return _aware(text, where)


def check_time(dt: datetime, where: str = "time") -> datetime:
    """``dt`` (timezone-aware) if it lies in the years :data:`FIRST_YEAR` ..
    :data:`LAST_YEAR` (UTC), else an error naming ``where``.

    Raises
    ------
    InputError
        ``dt`` is naive or out of that span.
    """
    if dt.tzinfo is None or dt.utcoffset() is None:
        raise InputError(f"{where}: time {dt.isoformat()} has no UTC offset")
    if not _EARLIEST <= dt < _LATEST:  # compared as instants, without converting dt
        raise InputError(
            f"{where}: time {dt.isoformat()} is outside the years {FIRST_YEAR}-{LAST_YEAR} "
            "(UTC); check the date"
        )
    return dt


def iso_datetime(text: str) -> datetime:
    """An ISO 8601 time as written: aware with its UTC offset (a trailing ``Z`` or ``z``
    is UTC), or naive when it carries none.

    The one ISO 8601 parser of the package: :func:`parse_time` (which refuses a naive
    time) and the track and station readers (which may apply a declared zone) build on it
    and word their own messages.

    Raises
    ------
    ValueError
        If ``text`` (blanks around it ignored) is not ISO 8601.
    """
    s = text.strip()
    if s.endswith(("Z", "z")):
        s = s[:-1] + "+00:00"
    return datetime.fromisoformat(s)


def _aware(text: str | datetime, where: str) -> datetime:
    """The time as written, with its own UTC offset (checks as :func:`parse_time`)."""
    if isinstance(text, datetime):
        dt = text
    else:
        try:
            dt = iso_datetime(str(text))
        except ValueError:
            raise InputError(
                f"{where}: cannot read {text!r} as an ISO 8601 time; "
                "expected e.g. '2018-04-24T12:10:00+02:00'"
            ) from None
    if dt.tzinfo is None or dt.utcoffset() is None:
        raise InputError(
            f"{where}: time {text!r} has no UTC offset; add one, e.g. "
            f"'{dt.isoformat()}+00:00' or '{dt.isoformat()}Z'"
        )
    return check_time(dt, where)


def utc_offset_s(text: str | datetime, where: str = "time") -> float:
    """The UTC offset [s] an ISO 8601 time is written with (``+02:00`` -> 7200).

    Raises
    ------
    InputError
        As :func:`parse_time`.
    """
    off = _aware(text, where).utcoffset()
    return off.total_seconds() if off is not None else 0.0


def to_epoch(dt: datetime) -> float:
    """Epoch seconds [s] of an aware datetime."""
    if dt.tzinfo is None:
        raise InputError(f"time {dt.isoformat()} has no UTC offset")
    return dt.timestamp()


def from_epoch(t: float) -> datetime:
    """Aware UTC datetime of epoch seconds ``t`` [s]."""
    return datetime.fromtimestamp(float(t), tz=UTC)


def iso(t: float) -> str:
    """ISO 8601 UTC string (``...Z``, millisecond precision) of epoch seconds ``t``."""
    return from_epoch(t).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def offset_text(utc_offset_s: float) -> str:
    """``UTC+02:00`` for an offset of 7200 s (rounded to the minute)."""
    sign = "+" if utc_offset_s >= 0 else "-"
    h, m = divmod(round(abs(utc_offset_s) / 60.0), 60)
    return f"UTC{sign}{h:02d}:{m:02d}"
