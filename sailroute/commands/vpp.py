"""``sailroute vpp``: a boat file or class in, the VPP polar computed, its files written.

The CLI command only parses options and calls :func:`run_vpp_command`; the boat file
is read by :mod:`sailroute.boat.boatfile`, the table, plot and files are
:mod:`sailroute.report.polar`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from itertools import pairwise
from pathlib import Path
from typing import Final

import numpy as np

from sailroute.boat.boatfile import load_boat_file
from sailroute.boat.build import vpp_polar
from sailroute.boat.kinetics import kinetics_from_spec
from sailroute.boat.laser import (
    CREW_MASS_RANGE_KG,
    ILCA7,
    LaserParams,
)
from sailroute.boat.polar import MAX_BOAT_SPEED_KN, MAX_BOAT_SPEED_MS, MAX_TWS_KN, MAX_TWS_MS, Polar
from sailroute.commands.result import CommandResult
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.report.files import POLAR_FILE_LABELS
from sailroute.report.polar import polar_report, write_vpp_outputs
from sailroute.units import speed_factor

DEFAULT_TWS: Final = {
    "kn": (4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 20.0, 24.0),
    "m/s": (2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0),
}
"""Default TWS columns of ``sailroute vpp`` per display unit."""
UNITS: Final = ("kn", "m/s")


@dataclass(frozen=True)
class VppRun:
    """What :func:`run_vpp_command` computed (its ``CommandResult.data``).

    Attributes
    ----------
    params : LaserParams
        Boat used.
    polar : Polar
        Computed polar (TWS [m s⁻¹], TWA [°]).
    """

    params: LaserParams
    polar: Polar


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
                f"{option}: item {k + 1} ({cell!r}) is not a number; {example}"
            ) from None
        if not v > 0 or not np.isfinite(v):
            raise InputError(
                f"{option}: item {k + 1} ({cell!r}) must be a positive, finite speed; {example}"
            )
        if v * f > MAX_TWS_MS * (1 + 1e-12):
            raise InputError(
                f"{option}: item {k + 1} ({cell} {unit}) is above {top}, stronger than any "
                f"wind a polar is made for (sailroute's polar readers refuse such a column); "
                f"give wind speeds up to {top}"
            )
        vals.append(v * f)
    if not vals:
        raise InputError(f"{option}: no wind speed given; {example}")
    if any(b <= a for a, b in pairwise(vals)):
        raise InputError(
            f"{option}: wind speeds must increase from item to item; got {text!r}, e.g. '4,6,8'"
        )
    return tuple(vals)


def twa_grid(step_deg: float) -> tuple[float, ...]:
    """TWA rows 0..180 [°] every ``step_deg`` (180 always included)."""
    if not 0.1 <= step_deg <= 90:
        raise InputError(f"--twa-step: expected a step between 0.1 and 90 degrees; got {step_deg}")
    grid = np.arange(0.0, 180.0, step_deg)
    return tuple(float(a) for a in np.append(grid, 180.0))


def run_vpp_command(
    boat_file: str | Path | None,
    *,
    crew_mass_kg: float | None = None,
    tws: str | None = None,
    twa_step_deg: float = 5.0,
    out_dir: str | Path = "vpp-out",
    unit: str = "kn",
    kinetics: str = "race",
) -> CommandResult:
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
    tws_ms = (
        parse_speed_list(tws, unit)
        if tws is not None
        else tuple(v * speed_factor(unit) for v in DEFAULT_TWS[unit])
    )
    kin = kinetics_from_spec(kinetics)[0]
    polar = vpp_polar(params, tws_ms, twa_grid(twa_step_deg), kinetics=kin)
    fastest = float(np.nanmax(polar.speed_ms, initial=0.0))
    if fastest > MAX_BOAT_SPEED_MS:  # the polar readers' limit: a file they would refuse
        raise InputError(
            f"--tws: the VPP gives boat speeds up to {fastest / speed_factor('kn'):.1f} kn, "
            f"above {MAX_BOAT_SPEED_KN:g} kn (faster than any sailing craft has gone); "
            "give lower wind speeds"
        )
    files = write_output_set(
        out_dir, lambda d: write_vpp_outputs(polar, params, d, stem, unit, kin)
    )
    return CommandResult(
        KINETICS_LINES[kinetics] + "\n" + polar_report(polar, unit),
        files,
        data=VppRun(params=params, polar=polar),
        main=("json",),
        labels=POLAR_FILE_LABELS,
    )
