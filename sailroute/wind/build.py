"""Build a :class:`~sailroute.wind.base.WindField` (or a current) from a spec.

A spec is parsed once into its frozen dataclass (:mod:`sailroute.wind.specs`: one per
type, with its parser and builder in one registry); :func:`build_wind_field` and
:func:`build_current_field` read the files and build the field from the dataclass.
:func:`wind_from_spec` / :func:`current_from_spec` do both for a mapping (the Python
API).  Spec keys are documented in ``docs/design/wind.md`` ("Wind spec keys").  Every
problem in a spec is collected and reported in one :class:`~sailroute.errors.InputError`,
each line prefixed with its key path.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.geo import LocalFrame
from sailroute.wind.base import Coverage, WindField
from sailroute.wind.current import CurrentField
from sailroute.wind.spec_base import BBox
from sailroute.wind.specs import (
    CURRENT_KINDS,
    CURRENT_TYPES,
    MEASURED_MARGIN_S,
    WIND_KINDS,
    WIND_TYPES,
    BuildContext,
    CurrentSpec,
    WindSpec,
    parse_current_spec,
    parse_wind_spec,
)

__all__ = [
    "CURRENT_TYPES",
    "MEASURED_MARGIN_S",
    "WIND_TYPES",
    "build_current_field",
    "build_wind_field",
    "check_covers",
    "current_from_spec",
    "wind_from_spec",
    "wind_notes",
]


def wind_from_spec(
    spec: Mapping[str, Any],
    *,
    frame: LocalFrame,
    base_dir: Path,
    where: str,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
    lines: Mapping[str, int] | None = None,
) -> WindField:
    """Build a wind field from a spec mapping: :func:`~sailroute.wind.specs.parse_wind_spec`,
    then :func:`build_wind_field`.

    Parameters
    ----------
    spec : mapping
        The wind spec, e.g. ``{"type": "uniform", "tws_kn": 10, "twd_deg": 108}``;
        ``type`` is one of ``uniform``, ``wrf``, ``netcdf`` (CF lat/lon, or wrfout
        detected), ``grib``, ``stations``, ``blended``, ``measured`` (boat logs).
    frame : LocalFrame
        The course's local frame; gridded and station data are mapped into it.
    base_dir : Path
        Directory that relative ``path`` values are resolved against (the course file's).
    where : str
        Prefix for error messages, e.g. ``"courses/x.yaml: scenarios.wrf10[0]"``.
    crop_bbox : tuple of float, optional
        Course bounding box ``(xmin, xmax, ymin, ymax)`` [m] in ``frame`` (marks, no
        margin).  WRF data are cropped to it plus ``margin_m``; a source that does
        not cover it raises :class:`~sailroute.errors.OutOfCoverageError` now
        (unless the spec sets ``clamp: true``).
    time_window : tuple of float, optional
        Race time window ``(t0, t1)`` [epoch s].  WRF slices outside it are not
        read; a source that does not cover it raises now (unless ``clamp``).
    lines : mapping of str to int, optional
        1-based line of each key path of the file ``where`` names (the course
        file's line map, :attr:`~sailroute.course.model.Course.key_lines`): each
        problem is then reported at its own key's line.

    Returns
    -------
    WindField

    Raises
    ------
    InputError
        Unknown type, unknown/missing/invalid keys (all listed at once), unreadable files.
    WindDataError
        Malformed data files.
    OutOfCoverageError
        The data do not cover ``crop_bbox``/``time_window`` and ``clamp`` is false.
    """
    return build_wind_field(
        parse_wind_spec(spec, base_dir=Path(base_dir), where=where, lines=lines),
        frame=frame,
        crop_bbox=crop_bbox,
        time_window=time_window,
    )


def _check_window(
    where: str, crop_bbox: BBox | None, time_window: tuple[float, float] | None
) -> None:
    if crop_bbox is not None and not (
        crop_bbox[0] <= crop_bbox[1] and crop_bbox[2] <= crop_bbox[3]
    ):
        raise InputError(
            f"{where}: crop_bbox must be (xmin, xmax, ymin, ymax) in metres; got {tuple(crop_bbox)}"
        )
    if time_window is not None and not time_window[0] <= time_window[1]:
        raise InputError(
            f"{where}: time_window must be (t0, t1) with t0 <= t1; got {tuple(time_window)}"
        )


def _label(where: str, what: str) -> str:
    return f"{where}: {what}" if where else what


def build_wind_field(
    spec: WindSpec,
    *,
    frame: LocalFrame,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
) -> WindField:
    """Build the wind field of a parsed spec: read its files, make the field.

    Parameters
    ----------
    spec : WindSpec
        A parsed wind spec (:func:`~sailroute.wind.specs.parse_wind_spec`, or the
        ``wind`` of a loaded course's scenario); the same spec always gives an equal
        field.
    frame : LocalFrame
        The course's local frame.
    crop_bbox, time_window : optional
        As for :func:`wind_from_spec`: the course box [m] and race window [epoch s]
        that the field must cover unless the spec sets ``clamp``.

    Returns
    -------
    WindField

    Raises
    ------
    InputError
        Unreadable files (prefixed with the spec's key path).
    WindDataError
        Malformed data files.
    OutOfCoverageError
        The data do not cover ``crop_bbox``/``time_window`` and ``clamp`` is false.
    """
    _check_window(spec.where, crop_bbox, time_window)
    field: WindField = WIND_KINDS[spec.type].build(
        spec, BuildContext(frame, crop_bbox, time_window)
    )
    if not spec.clamp:
        name = _label(spec.where, f"{spec.type} wind")
        check_covers(field, crop_bbox, time_window, name=name, frame=frame)
    return field


def check_covers(
    field: WindField | CurrentField,
    bbox: BBox | None,
    time_window: tuple[float, float] | None,
    *,
    name: str = "wind field",
    frame: LocalFrame | None = None,
) -> None:
    """Raise :class:`OutOfCoverageError` unless ``field`` covers ``bbox`` and ``time_window``.

    Parameters
    ----------
    field : WindField
        The field to check.
    bbox : tuple of float or None
        ``(xmin, xmax, ymin, ymax)`` [m] that must lie inside the field's box.
    time_window : tuple of float or None
        ``(t0, t1)`` [epoch s] that must lie inside the field's time span.
    name : str
        Label for the message.
    frame : LocalFrame, optional
        Adds latitude/longitude to the message (the field's own frame is used
        when its coverage has one).
    """
    c = field.coverage
    t0, t1 = time_window if time_window is not None else (c.t0, c.t1)
    x0, x1, y0, y1 = bbox if bbox is not None else (c.xmin, c.xmax, c.ymin, c.ymax)
    if (
        t0 >= c.t0
        and t1 <= c.t1
        and x0 >= c.xmin
        and x1 <= c.xmax
        and y0 >= c.ymin
        and (y1 <= c.ymax)
    ):
        return
    frame = frame if frame is not None else c.frame
    need = Coverage(t0, t1, x0, x1, y0, y1, frame=frame)
    if c.frame is None and frame is not None:
        c = Coverage(
            c.t0, c.t1, c.xmin, c.xmax, c.ymin, c.ymax, frame=frame, source_span=c.source_span
        )
    span = c.source_span or (c.t0, c.t1)
    single = span[0] == span[1] and not (t0 >= c.t0 and t1 <= c.t1)
    raise OutOfCoverageError(
        f"{name} does not cover the course and race time.\n"
        f"  needed:  {need.describe()}\n"
        f"  covered: {c.describe()}\n"
        + (
            "  The source holds a single time: to use it as a steady wind for the whole race, "
            "set `steady: true`.\n"
            if single
            else ""
        )
        + "  Use wind data that covers the course (the thesis's main failure was extrapolating "
        "outside the data), or opt in to clamping at the edges with `clamp: true`."
    )


def wind_notes(field: WindField) -> list[str]:
    """One-line summaries of how a wind source was read, for the progress display.

    Gridded fields: the slices read, the cells and how many hold no wind (NaN);
    station fields: the rows read and how many were dropped for missing values.
    Other fields: none.
    """
    name = getattr(field, "name", type(field).__name__)
    info = getattr(field, "info", None)
    data = getattr(field, "data", None)
    if isinstance(info, Mapping) and "times" in info:
        text = f"{name}: {info['times']}"
        if "cells" in info:
            text += f", {info['cells']} cells"
            if info.get("nan_cells"):
                text += f" ({info['nan_cells']} without wind: land or masked)"
        if info.get("height_m") is not None:
            text += f", wind at {info['height_m']:g} m"
        return [text]
    if data is None:
        return []
    from sailroute.wind.stationread import StationData  # (a reader: only for a field with data)

    if isinstance(data, StationData):
        text = f"{name}: {data.n_raw} rows read"
        if data.n_missing:
            per = ", ".join(
                f"{k} {v}"
                for k, v in data.missing_by_column.items()
                if k not in ("gust", "height_m")
            )  # optional: no row dropped
            text += f", {data.n_missing} dropped for missing values ({per})"
        return [text + f", {len(data)} records used"]
    return []


def current_from_spec(
    spec: Mapping[str, Any],
    *,
    frame: LocalFrame,
    base_dir: Path,
    where: str,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
    lines: Mapping[str, int] | None = None,
) -> CurrentField:
    """Build a current field from a ``current:`` mapping (parse, then :func:`build_current_field`).

    Parameters
    ----------
    spec : mapping
        ``{type: uniform, speed_kn | speed_ms, set_deg}``,
        ``{type: diamonds, high_water, table: [[hour, set_deg, rate_kn], ...]}`` or
        ``{type: netcdf, path, variables, ...}`` (``docs/course-format.md``); the types
        are :data:`~sailroute.wind.specs.CURRENT_TYPES`.
    frame : LocalFrame
        The course's local frame.
    base_dir : Path
        Folder that a relative ``path`` resolves against.
    where : str
        Key-path prefix of messages, e.g. ``"courses/x.yaml:12: scenarios.spring.current"``.
    crop_bbox, time_window : optional
        Course box [m] and race window [epoch s] that the current must cover
        (unless ``clamp: true``), as for a wind spec.
    lines : mapping of str to int, optional
        1-based line of each key path of the file (the course's line map): each
        problem is reported at its own key's line.

    Raises
    ------
    InputError
        Every problem of the spec at once, each with its key path.
    OutOfCoverageError
        The current does not cover the course or the race time.
    """
    return build_current_field(
        parse_current_spec(spec, base_dir=Path(base_dir), where=where, lines=lines),
        frame=frame,
        crop_bbox=crop_bbox,
        time_window=time_window,
    )


def build_current_field(
    spec: CurrentSpec,
    *,
    frame: LocalFrame,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
) -> CurrentField:
    """Build the current field of a parsed spec, as :func:`build_wind_field`."""
    field: CurrentField = CURRENT_KINDS[spec.type].build(
        spec, BuildContext(frame, crop_bbox, time_window)
    )
    if not spec.clamp:
        name = _label(spec.where, f"{spec.type} current")
        check_covers(field, crop_bbox, time_window, name=name, frame=frame)
    return field
