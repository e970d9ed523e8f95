"""Surface-current specs: ``uniform``, ``diamond`` (tidal-diamond table) and ``netcdf``.

Each type's frozen dataclass (checked values in SI units), its parser (every check that
needs no file content) and its builder (makes the :class:`~sailroute.wind.current.CurrentField`);
registered in :data:`sailroute.wind.specs.CURRENT_KINDS`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from sailroute.checks import Checker, real_number, show
from sailroute.units import KNOT, SPEED_UNITS
from sailroute.wind.current import (
    CurrentField,
    DiamondCurrent,
    UniformCurrent,
    open_netcdf_current,
)
from sailroute.wind.spec_base import BuildContext, Pairs, _dict, _epoch, _pairs, _wrapped

_CURRENT_UNIFORM_KEYS = ("type", "speed_kn", "speed_ms", "set_deg")


_CURRENT_DIAMOND_KEYS = ("type", "high_water", "table", "rate_unit", "clamp")


_CURRENT_NETCDF_KEYS = (
    "type",
    "path",
    "variables",
    "speed_unit",
    "select",
    "interpolation",
    "steady",
    "clamp",
)


@dataclass(frozen=True, kw_only=True)
class UniformCurrentSpec:
    """``type: uniform``: one rate and set everywhere, all the time.

    Attributes
    ----------
    rate_ms : float
        Rate [m s⁻¹] (``speed_kn`` converted, or ``speed_ms``).
    set_deg : float
        Set: the direction the water flows towards [deg].
    clamp : bool
        Always False (a uniform current covers everything; not a key).
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "uniform"
    rate_ms: float
    set_deg: float
    clamp: bool = False
    where: str = ""


def _current_rate(chk: Checker, spec: Mapping[str, Any]) -> float | None:
    """The rate of a uniform current [m s⁻¹] from ``speed_kn`` or ``speed_ms``."""
    if "speed_kn" in spec and "speed_ms" in spec:
        chk.add("speed_kn", "give either speed_kn or speed_ms, not both")
        return None
    if "speed_ms" in spec:
        return chk.number(spec, "speed_ms", lo=0.0)
    if "speed_kn" in spec:
        rate = chk.number(spec, "speed_kn", lo=0.0)
        return None if rate is None else rate * KNOT
    chk.add("speed_kn", "missing required key; give the rate as speed_kn or speed_ms")
    return None


def _parse_uniform_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> UniformCurrentSpec | None:
    chk.keys(spec, _CURRENT_UNIFORM_KEYS, ("set_deg",))
    rate = _current_rate(chk, spec)
    set_deg = chk.number(spec, "set_deg", lo=0.0, hi=360.0) if "set_deg" in spec else None
    if rate is None or set_deg is None:  # (reported)
        return None
    return UniformCurrentSpec(rate_ms=rate, set_deg=set_deg, where=chk.where())


def _build_uniform_current(spec: UniformCurrentSpec, ctx: BuildContext) -> CurrentField:
    return UniformCurrent(spec.rate_ms, spec.set_deg)


@dataclass(frozen=True, kw_only=True)
class DiamondCurrentSpec:
    """``type: diamonds``: a tidal-diamond table of set and rate by hour from high water.

    Attributes
    ----------
    high_water : float
        The time of high water [epoch s].
    table : tuple of (float, float, float)
        Rows ``(hour from high water, set [deg], rate [m s⁻¹])``, hours increasing.
    clamp : bool
        Hold the first/last row outside the table's hours.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "diamonds"
    high_water: float
    table: tuple[tuple[float, float, float], ...]
    clamp: bool = False
    where: str = ""


def _diamond_rows(chk: Checker, table: Any, scale: float) -> list[tuple[float, float, float]]:
    """The rows ``(hour, set_deg, rate_ms)`` of a tidal-diamond table, problems to ``chk``."""
    rows: list[tuple[float, float, float]] = []
    tchk = chk.child("table")
    for k, row in enumerate(table):
        ok = isinstance(row, list | tuple) and len(row) == 3 and all(real_number(a) for a in row)
        if not ok:
            tchk.add(
                k,
                f"expected [hour, set_deg, rate_{'kn' if scale != 1 else 'ms'}]"
                f" (three numbers); got {row!r}",
            )
        elif not (0.0 <= row[1] <= 360.0 and row[2] >= 0):
            tchk.add(k, f"expected a set in [0, 360] and a rate >= 0; got {row!r}")
        elif rows and row[0] <= rows[-1][0]:
            tchk.add(
                k,
                f"the hours must increase strictly from row to row "
                f"({row[0]:g} after {rows[-1][0]:g})",
            )
        else:
            rows.append((float(row[0]), float(row[1]), float(row[2]) * scale))
    return rows


def _parse_diamond_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> DiamondCurrentSpec | None:
    chk.keys(spec, _CURRENT_DIAMOND_KEYS, ("high_water", "table"))
    unit = chk.choice(spec, "rate_unit", ["kn", "m/s"], "kn")
    scale = KNOT if unit == "kn" else 1.0
    clamp = chk.boolean(spec, "clamp", False)
    hw = _epoch(chk, spec, "high_water") if "high_water" in spec else None
    rows: list[tuple[float, float, float]] = []
    table = spec.get("table")
    if "table" in spec and (not isinstance(table, list) or not table):
        chk.add(
            "table",
            "expected a non-empty list of rows [hour, set_deg, rate_kn], "
            f"e.g. [[-6, 250, 0.4], [0, 70, 1.2]]; got {show(table)}",
        )
    elif isinstance(table, list):
        rows = _diamond_rows(chk, table, scale)
    if hw is None:  # (reported)
        return None
    return DiamondCurrentSpec(
        high_water=hw,
        table=tuple(rows),
        clamp=clamp,
        where=chk.where(),
    )


def _build_diamond_current(spec: DiamondCurrentSpec, ctx: BuildContext) -> CurrentField:
    h, s, r = (list(c) for c in zip(*spec.table, strict=True))
    return DiamondCurrent(spec.high_water, h, s, r, clamp=spec.clamp)


@dataclass(frozen=True, kw_only=True)
class NetcdfCurrentSpec:
    """``type: netcdf``: a gridded current (u, v) from a NetCDF file.

    Attributes
    ----------
    path : Path
        The file, resolved against the course file's folder.
    variables : tuple of (str, str) or None
        ``(("u", NAME), ("v", NAME))``: the file's variables (None: found by name).
    speed_unit : str or None
        Unit of the file's speeds, as written.
    select : tuple of (str, int) or None
        Dimension name -> index.
    interpolation : {"linear", "nearest"}
        In time.
    steady : bool
        Use a file of one time for the whole race.
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "netcdf"
    path: Path
    variables: Pairs | None = None
    speed_unit: str | None = None
    select: Pairs | None = None
    interpolation: str = "linear"
    steady: bool = False
    clamp: bool = False
    where: str = ""


def _parse_netcdf_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> NetcdfCurrentSpec | None:
    chk.keys(spec, _CURRENT_NETCDF_KEYS, ("path",))
    path = chk.file(spec, "path", base_dir)
    var = chk.mapping(spec, "variables", None)
    if var is not None and not (
        {"u", "v"} == set(var) and all(isinstance(v, str) and v for v in var.values())
    ):
        chk.add(
            "variables", f"expected {{u: NAME, v: NAME}}, e.g. {{u: uo, v: vo}}; got {dict(var)!r}"
        )
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
    sel = chk.mapping(spec, "select", None)
    interpolation = chk.choice(spec, "interpolation", ["linear", "nearest"], "linear")
    steady = chk.boolean(spec, "steady", False)
    clamp = chk.boolean(spec, "clamp", False)
    if path is None:  # (reported)
        return None
    return NetcdfCurrentSpec(
        path=path,
        variables=_pairs(var),
        speed_unit=unit,
        select=_pairs(sel),
        interpolation=interpolation,
        steady=steady,
        clamp=clamp,
        where=chk.where(),
    )


def _build_netcdf_current(spec: NetcdfCurrentSpec, ctx: BuildContext) -> CurrentField:
    return _wrapped(
        spec.where,
        lambda: open_netcdf_current(
            spec.path,
            ctx.frame,
            variables=_dict(spec.variables),
            speed_unit=spec.speed_unit,
            select=_dict(spec.select),
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            interpolation=spec.interpolation,
            steady=spec.steady,
            clamp=spec.clamp,
        ),
    )
