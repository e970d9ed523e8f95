"""Inputs and outputs of ``sailroute vpp``: boat YAML, text report, files, polar plot.

The CLI command only parses options and calls :func:`run_vpp_command`; every
piece is a plain function here so that it can be tested and reused.
"""

from __future__ import annotations

import re
from dataclasses import asdict, dataclass, replace
from itertools import pairwise
from pathlib import Path
from typing import Any, Final

import numpy as np

from sailroute.boat.build import vpp_polar
from sailroute.boat.io import write_pol, write_polar_csv, write_polar_json
from sailroute.boat.kinetics import STEADY, Kinetics, kinetics_from_spec
from sailroute.boat.laser import (
    CREW_MASS_RANGE_KG,
    ILCA7,
    LaserParams,
    params_from_mapping,
)
from sailroute.boat.polar import MAX_BOAT_SPEED_KN, MAX_BOAT_SPEED_MS, MAX_TWS_KN, MAX_TWS_MS, Polar
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, make_out_dir, write_output_set
from sailroute.units import speed_factor

DEFAULT_TWS: Final = {
    "kn": (4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 20.0, 24.0),
    "m/s": (2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0),
}
"""Default TWS columns of ``sailroute vpp`` per display unit."""
UNITS: Final = ("kn", "m/s")


@dataclass(frozen=True)
class VppRun:
    """Result of :func:`run_vpp_command`.

    Attributes
    ----------
    params : LaserParams
        Boat used.
    polar : Polar
        Computed polar (TWS [m s⁻¹], TWA [°]).
    report : str
        Text table and VMG summary (in the display unit).
    files : dict of str to Path
        ``pol``, ``csv``, ``json``, ``png`` outputs.
    """

    params: LaserParams
    polar: Polar
    report: str
    files: dict[str, Path]


def load_boat_file(path: str | Path) -> tuple[LaserParams, str]:
    """Read a boat YAML (see ``docs/vpp.md``) and return its parameters and a file stem.

    The YAML is read like a course file (YAML 1.2 scalars: ``1e6`` is a number,
    ``no`` is text), and a key given twice is an error rather than silently the
    last value.

    Raises
    ------
    InputError
        Missing file, folder, not UTF-8, YAML syntax error (with line and
        column), duplicate key, unknown key or bad value (with the key and its
        line), all in one message.
    """
    from sailroute.yamlfile import read_yaml

    p = Path(path)
    ydoc = read_yaml(p, what="boat file", hint="check the path, or leave BOAT.yaml out to "
                     "use the shipped ILCA 7 parameters")
    doc = {} if ydoc.data is None else ydoc.data
    if not isinstance(doc, dict):
        raise InputError(
            f"{p}: a boat file is a mapping like 'class: ilca7' and 'crew_mass_kg: 80'; "
            f"got {type(doc).__name__}"
        )
    if ydoc.duplicates:
        d = ydoc.duplicates[0]
        raise InputError(f"{p}:{d.line}: {d.path}: the key appears twice (lines "
                         f"{d.first_line} and {d.line}); keep one")
    lines = {k: v for k, v in ydoc.lines.items() if "." not in k and "[" not in k}
    return params_from_mapping(doc, where=str(p), lines=lines), _slug(p.stem)


KINETICS_LINES: Final = {
    "race": "race polar (the VPP with wave riding and pumping, as the built-in ilca7 that "
            "plan routes with; --kinetics steady for the VPP alone)",
    "steady": "steady VPP (no wave riding or pumping, as the built-in ilca7-steady; "
              "--kinetics race for the race polar)",
}
"""First line of the ``vpp`` report: which polar was written."""


def parse_speed_list(text: str, unit: str, *, option: str = "--tws") -> tuple[float, ...]:
    """Parse ``"4,6,8"`` (in ``unit``) into increasing speeds [m s⁻¹].

    Each must be positive and at most :data:`~sailroute.boat.polar.MAX_TWS_KN`, the
    highest TWS column sailroute's polar readers accept (so every table written from
    these columns can be read back).
    """
    f = speed_factor(unit)
    vals = []
    example = f"give comma-separated wind speeds in {unit}, e.g. '4,6,8'"
    top = f"{MAX_TWS_KN:g} kn" if unit == "kn" else f"{MAX_TWS_MS / f:.1f} {unit}"
    for k, cell in enumerate(c for c in re.split(r"[,\s]+", text.strip()) if c):
        try:
            v = float(cell)
        except ValueError:
            raise InputError(
                f"{option}: item {k + 1} ({cell!r}) is not a number; {example}") from None
        if not v > 0 or not np.isfinite(v):
            raise InputError(
                f"{option}: item {k + 1} ({cell!r}) must be a positive, finite speed; {example}")
        if v * f > MAX_TWS_MS * (1 + 1e-12):
            raise InputError(
                f"{option}: item {k + 1} ({cell} {unit}) is above {top}, stronger than any "
                f"wind a polar is made for (sailroute's polar readers refuse such a column); "
                f"give wind speeds up to {top}")
        vals.append(v * f)
    if not vals:
        raise InputError(f"{option}: no wind speed given; {example}")
    if any(b <= a for a, b in pairwise(vals)):
        raise InputError(
            f"{option}: wind speeds must increase from item to item; got {text!r}, e.g. '4,6,8'")
    return tuple(vals)


def twa_grid(step_deg: float) -> tuple[float, ...]:
    """TWA rows 0..180 [°] every ``step_deg`` (180 always included)."""
    if not 0.1 <= step_deg <= 90:
        raise InputError(f"--twa-step: expected a step between 0.1 and 90 degrees; got {step_deg}")
    grid = np.arange(0.0, 180.0, step_deg)
    return tuple(float(a) for a in np.append(grid, 180.0))


def polar_report(polar: Polar, unit: str = "kn") -> str:
    """Text table (rows TWA, columns TWS) and best VMG per TWS, in ``unit``.

    Speeds are printed with 2 decimals; the same numbers come from
    ``polar.speed(tws, twa)`` at the table's nodes.
    """
    f = speed_factor(unit)
    tws = polar.tws_ms
    label = f"TWA\\TWS [{unit}]"
    w = 7
    lines = [f"{polar.name}: boat speed [{unit}] (TWS at the sail's centre of effort)"]
    lines.append(f"{label:>14}" + "".join(f"{v / f:>{w}.1f}" for v in tws))
    for a, row in zip(polar.twa_deg, polar.speed_ms, strict=True):
        lines.append(f"{a:>14.1f}" + "".join(f"{v / f:>{w}.2f}" for v in row))
    up_a, up_v = polar.vmg_upwind(tws)
    dn_a, dn_v = polar.vmg_downwind(tws)
    lines.append("")
    lines.append(f"{'beat TWA [deg]':>14}" + "".join(f"{a:>{w}.1f}" for a in up_a))
    lines.append(f"{'beat VMG':>14}" + "".join(f"{v / f:>{w}.2f}" for v in up_v))
    lines.append(f"{'run TWA [deg]':>14}" + "".join(f"{a:>{w}.1f}" for a in dn_a))
    lines.append(f"{'run VMG':>14}" + "".join(f"{v / f:>{w}.2f}" for v in dn_v))
    return "\n".join(lines)


def plot_polar(polar: Polar, path: str | Path, unit: str = "kn") -> Path:
    """Polar plot (one curve per TWS, VMG points marked) as a PNG.

    Uses matplotlib's object-oriented API (no pyplot, no global state).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 7))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="polar")
    draw_polar(ax, polar, unit)
    ax.set_title(f"{polar.name}: boat speed [{unit}] vs TWA (dots: best VMG)")
    out = Path(path)
    fig.savefig(out, dpi=110)
    return out


def draw_polar(ax: Any, polar: Polar, unit: str = "kn", colors: list[Any] | None = None) -> None:
    """Draw one curve per TWS column and the best-VMG points on a polar ``ax``.

    ``ax`` is a matplotlib polar axes (set to 0-180°, north up, clockwise);
    ``colors`` gives one colour per TWS column (default: matplotlib's cycle).
    """
    f = speed_factor(unit)
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(0)
    ax.set_thetamax(180)
    a = np.linspace(0.0, 180.0, 361)
    up_a = polar.vmg_upwind(polar.tws_ms)[0]
    dn_a = polar.vmg_downwind(polar.tws_ms)[0]
    for j, tws in enumerate(polar.tws_ms):
        kw = {} if colors is None else {"color": colors[j]}
        (line,) = ax.plot(np.radians(a), polar.speed(tws, a) / f, lw=1.2,
                          label=f"{tws / f:g} {unit}", **kw)
        for ang in (up_a[j], dn_a[j]):
            ax.plot(np.radians(ang), polar.speed(tws, ang) / f, "o", ms=3, color=line.get_color())
    ax.legend(loc="lower left", fontsize=7, title="TWS", title_fontsize=7)


def write_outputs(
    polar: Polar, params: LaserParams, out_dir: str | Path, stem: str, unit: str = "kn",
    kinetics: Kinetics = STEADY,
) -> dict[str, Path]:
    """Write ``<stem>.pol``, ``.csv``, ``.json`` (with the parameters) and ``.png``."""
    d = make_out_dir(out_dir)
    extra: dict[str, Any] = {
        "tws_reference": "true wind at the sail's centre-of-effort height",
        "vpp_params": _jsonable(asdict(params)),
        "kinetics": "steady" if kinetics == STEADY else _jsonable(asdict(kinetics)),
    }
    return {
        "pol": write_pol(polar, d / f"{stem}.pol", unit=unit),
        "csv": write_polar_csv(polar, d / f"{stem}.csv", unit=unit),
        "json": write_polar_json(polar, d / f"{stem}.json", unit=unit, extra=extra),
        "png": plot_polar(polar, d / f"{stem}.png", unit=unit),
    }


def run_vpp_command(
    boat_file: str | Path | None,
    *,
    crew_mass_kg: float | None = None,
    tws: str | None = None,
    twa_step_deg: float = 5.0,
    out_dir: str | Path = "vpp-out",
    unit: str = "kn",
    kinetics: str = "race",
) -> VppRun:
    """Everything ``sailroute vpp`` does, minus printing.

    Parameters
    ----------
    boat_file : path or None
        Boat YAML; ``None`` uses the shipped ILCA 7 parameters.
    crew_mass_kg : float, optional
        Overrides the file's (or the class's) sailor mass [kg].
    tws : str, optional
        Comma-separated TWS list in ``unit``; default :data:`DEFAULT_TWS`.
    twa_step_deg : float
        TWA row spacing [°].
    out_dir : path
        Output folder (checked first; written as a set, see :mod:`sailroute.outdir`).
    unit : {"kn", "m/s"}
        Unit of the printed table and the written files.
    kinetics : {"race", "steady"}
        ``race`` (default): with wave riding and pumping (the model of the built-in
        ``ilca7`` that ``plan`` routes with, :mod:`sailroute.boat.kinetics`);
        ``steady``: the VPP alone (as ``ilca7-steady``).  The report's first line
        says which was written.
    """
    if unit not in UNITS:
        raise InputError(f"--unit: expected one of 'kn', 'm/s'; got {unit!r}")
    if kinetics not in ("steady", "race"):
        raise InputError(f"--kinetics: expected one of 'steady', 'race'; got {kinetics!r}")
    check_out_dir(out_dir)
    if boat_file is None:
        params, stem = ILCA7, "ilca7"
    else:
        params, stem = load_boat_file(boat_file)
    if crew_mass_kg is not None:
        lo, hi = CREW_MASS_RANGE_KG
        if not lo <= crew_mass_kg <= hi:
            raise InputError(
                f"--crew-mass: expected a sailor mass in {lo:g}-{hi:g} kg; got {crew_mass_kg}"
            )
        params = replace(params, crew_mass_kg=float(crew_mass_kg))
    tws_ms = (parse_speed_list(tws, unit) if tws is not None
              else tuple(v * speed_factor(unit) for v in DEFAULT_TWS[unit]))
    kin = kinetics_from_spec(kinetics)[0]
    polar = vpp_polar(params, tws_ms, twa_grid(twa_step_deg), kinetics=kin)
    fastest = float(np.nanmax(polar.speed_ms, initial=0.0))
    if fastest > MAX_BOAT_SPEED_MS:  # the polar readers' limit: a file they would refuse
        raise InputError(
            f"--tws: the VPP gives boat speeds up to {fastest / speed_factor('kn'):.1f} kn, "
            f"above {MAX_BOAT_SPEED_KN:g} kn (faster than any sailing craft has gone); "
            "give lower wind speeds")
    files = write_output_set(out_dir, lambda d: write_outputs(polar, params, d, stem, unit, kin))
    return VppRun(params=params, polar=polar, report=KINETICS_LINES[kinetics] + "\n"
                  + polar_report(polar, unit), files=files)


def _slug(text: str) -> str:
    s = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")
    return s or "boat"


def _jsonable(d: dict[str, Any]) -> dict[str, Any]:
    return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}
