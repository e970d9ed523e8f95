"""The course file's ``uncertainty:`` section: what is uncertain about a scenario, and how much.

Leg-time bands (:mod:`sailroute.bands`) route a scenario in many versions of its wind
and boat; this module reads and checks the section that says how far they spread
(``docs/course-format.md``)::

    uncertainty:
      tws_kn: 1.5          # 1 standard deviation of the true wind speed, added [kn]
      twd_deg: 10          # 1 standard deviation of the mean direction [°]
      shifts: {model: oscillating, amplitude_deg: 8, period_min: 6}
      boat: {sea_age_h: [2, 4], pump_efficiency: [0.5, 0.87]}   # uniform over [lo, hi]
      polar: true          # a learned polar's own uncertainty (the default; false: off)
      members: 50
      seed: 1

Speeds and directions are normal (the numbers are 1 sigma); boat parameters are
uniform over the plausible ranges of ``docs/vpp.md``.  Everything is kept in SI units
(m/s, s, °) in :class:`UncertaintySpec`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

from sailroute.checks import Checker, Problems, show
from sailroute.units import KNOT

__all__ = [
    "DEFAULT_UNCERTAINTY",
    "SHIFT_MODELS",
    "UNCERTAINTY_KEYS",
    "PolarSpread",
    "ShiftSpec",
    "UncertaintySpec",
    "check_uncertainty",
    "uncertainty_from_mapping",
]

UNCERTAINTY_KEYS: Final = (
    "tws_kn",
    "tws_ms",
    "tws_pct",
    "twd_deg",
    "shifts",
    "boat",
    "polar",
    "members",
    "seed",
    "side_margin_s",
    "side_margin_pct",
)
"""Keys of the ``uncertainty`` section."""
SHIFT_MODELS: Final = ("oscillating", "ou", "persistent")
"""Shift models of ``uncertainty.shifts.model``."""
_SHIFT_KEYS: Final = {
    "oscillating": ("model", "amplitude_deg", "period_min"),
    "ou": ("model", "sigma_deg", "timescale_min"),
    "persistent": ("model", "rate_deg_per_min"),
}
BOAT_PARAMETERS: Final = (
    "fetch_m",
    "sea_age_h",
    "pump_power_w_per_kg",
    "pump_efficiency",
    "oscar_tws_kn",
    "upwind_efficiency",
)
"""Race-polar parameters (:class:`sailroute.boat.kinetics.Kinetics`) a band may vary."""


@dataclass(frozen=True)
class ShiftSpec:
    """A time-varying wind shift of the members.

    Attributes
    ----------
    model : {"oscillating", "ou", "persistent"}
        ``oscillating``: ``amplitude · sin(2π t / period + phase)``, the phase drawn
        uniformly per member; ``ou``: a sample path of the mean-reverting
        (Ornstein-Uhlenbeck) shift of :class:`sailroute.strategy.shiftmodel.OUShift`,
        starting from its stationary distribution; ``persistent``: a steady veer or
        back ``rate · t``, the rate normal with standard deviation ``rate_deg_per_s``.
    amplitude_deg : float
        Oscillation amplitude [°].
    period_s : float
        Oscillation period [s].
    sigma_deg : float
        OU stationary standard deviation [°].
    timescale_s : float
        OU e-folding time [s].
    rate_deg_per_s : float
        Persistent shift rate, 1 standard deviation [° s⁻¹].
    fit : Path or None
        The station CSV the OU parameters were fitted to (``{fit: PATH}``), for the
        report; the fit itself is done by :mod:`sailroute.bands.members`.
    station : str or None
        Station of ``fit`` (files with several stations).
    speed_unit : str or None
        Unit of the file's unsuffixed speed column (``kn``, ``m/s``, ...).
    """

    model: str
    amplitude_deg: float = 0.0
    period_s: float = 0.0
    sigma_deg: float = 0.0
    timescale_s: float = 0.0
    rate_deg_per_s: float = 0.0
    fit: Path | None = None
    station: str | None = None
    speed_unit: str | None = None


@dataclass(frozen=True)
class PolarSpread:
    """A learned polar whose uncertainty the members draw (the course's boat).

    Attributes
    ----------
    file : Path
        The learned polar's JSON (``sailroute polar fit``).
    level : str
        The level the course sails.
    modes : int
        The level's bootstrap modes.
    sd_log : float
        Median over the learned cells of the bootstrap's ``sd log speed`` [-].
    pace_sd_log : float
        The legs' scatter about the race pace [-] (0: learned without courses).
    """

    file: Path
    level: str
    modes: int = 0
    sd_log: float = 0.0
    pace_sd_log: float = 0.0


@dataclass(frozen=True)
class UncertaintySpec:
    """What is uncertain about a scenario, in SI units.

    Attributes
    ----------
    tws_add_ms : float
        Standard deviation of an added true wind speed [m s⁻¹] (``tws_kn``/``tws_ms``).
    tws_rel : float
        Relative speed change at one standard deviation (``tws_pct / 100``): the
        members' speeds are scaled by the log-normal factor ``(1 + tws_rel) ** z``.
    twd_deg : float
        Standard deviation of a constant direction offset [°].
    shifts : ShiftSpec or None
        Time-varying shift; None: none.
    boat : tuple of (str, float, float)
        Race-polar parameter, low and high end of its uniform range.
    draw_polar : bool
        Draw a learned polar's uncertainty when the course's boat is one (the
        section's ``polar``, default true).
    polar : PolarSpread or None
        The learned polar drawn (set from the course's boat by
        :func:`sailroute.bands.route.spec_for`); None: the boat is fixed.
    members : int
        Members of the main ensemble (>= 3).
    seed : int
        Seed of the Latin hypercube draw (the same seed gives the same members).
    side_margin_s, side_margin_pct : float
        A side counts only when it beats the other side by more than
        ``max(side_margin_s, side_margin_pct % of the leg time)``.
    where : str
        ``"file:line"`` of the section, for messages.
    """

    tws_add_ms: float = 0.0
    tws_rel: float = 0.0
    twd_deg: float = 0.0
    shifts: ShiftSpec | None = None
    boat: tuple[tuple[str, float, float], ...] = ()
    draw_polar: bool = True
    polar: PolarSpread | None = None
    members: int = 20
    seed: int = 1
    side_margin_s: float = 2.0
    side_margin_pct: float = 0.5
    where: str = ""

    def sources(self) -> tuple[str, ...]:
        """Names of the uncertain sources, in a fixed order: ``tws``, ``twd``,
        ``shifts``, ``polar`` (a learned polar), then ``boat.<parameter>`` for each boat
        parameter."""
        out = []
        if self.tws_add_ms > 0 or self.tws_rel > 0:
            out.append("tws")
        if self.twd_deg > 0:
            out.append("twd")
        if self.shifts is not None:
            out.append("shifts")
        if self.polar is not None:
            out.append("polar")
        out += [f"boat.{name}" for name, _, _ in self.boat]
        return tuple(out)

    def with_members(self, members: int) -> UncertaintySpec:
        """The same spec with another member count."""
        return dataclasses.replace(self, members=int(members))


DEFAULT_UNCERTAINTY: Final = UncertaintySpec(
    tws_add_ms=1.0 * KNOT,
    twd_deg=5.0,
    shifts=ShiftSpec("oscillating", amplitude_deg=5.0, period_s=360.0),
)
"""Used when a course has no ``uncertainty`` section: 1 kn and 5° (1 sigma), a 5° shift
oscillating every 6 min; no boat parameters (``docs/course-format.md``)."""


def _range(c: Checker, d: Mapping[str, Any], key: str) -> tuple[float, float] | None:
    v = d[key]
    ok = (
        isinstance(v, list)
        and len(v) == 2
        and all(isinstance(x, int | float) and not isinstance(x, bool) for x in v)
    )
    if not ok or not (float(v[0]) <= float(v[1])):
        c.add(key, f"expected a range [low, high] of two numbers, low <= high; got {show(v)}")
        return None
    return float(v[0]), float(v[1])


def _shifts(c: Checker, raw: Any, base_dir: Path | None) -> ShiftSpec | None:
    if not c.is_mapping(raw, "{model: oscillating|ou|persistent, ...} or {fit: PATH}"):
        return None
    if "fit" in raw:
        c.keys(raw, ("fit", "station", "speed_unit"))
        path = c.string(raw, "fit")
        station = c.string(raw, "station", None)
        unit = c.choice(raw, "speed_unit", ("kn", "m/s", "km/h", "mph"), None)
        if path is None:
            return None
        p = Path(path)
        if not p.is_absolute() and base_dir is not None:
            p = base_dir / p
        if not p.is_file():
            c.add(
                "fit",
                f"no station CSV at {p}; give a file of measured wind "
                "(docs/measured-wind.md) relative to the course file",
            )
            return None
        return ShiftSpec("ou", fit=p, station=station, speed_unit=unit)
    model = c.choice(raw, "model", SHIFT_MODELS)
    if model is None:
        return None
    c.keys(raw, _SHIFT_KEYS[model], _SHIFT_KEYS[model], of=f"a {model!r} shift")
    if model == "oscillating":
        a = c.number(raw, "amplitude_deg", None, lo=0.0, hi=90.0)
        per = c.number(raw, "period_min", None, lo=0.0, lo_open=True)
        return (
            None
            if a is None or per is None
            else ShiftSpec(model, amplitude_deg=a, period_s=60.0 * per)
        )
    if model == "ou":
        s = c.number(raw, "sigma_deg", None, lo=0.0, hi=90.0)
        ts = c.number(raw, "timescale_min", None, lo=0.0, lo_open=True)
        return (
            None
            if s is None or ts is None
            else ShiftSpec(model, sigma_deg=s, timescale_s=60.0 * ts)
        )
    r = c.number(raw, "rate_deg_per_min", None, lo=0.0, hi=30.0)
    return None if r is None else ShiftSpec(model, rate_deg_per_s=r / 60.0)


def _boat(c: Checker, raw: Any) -> tuple[tuple[str, float, float], ...]:
    if not c.is_mapping(raw, "a mapping of race-polar parameter to a range [low, high]"):
        return ()
    c.keys(raw, BOAT_PARAMETERS, of="the race polar (docs/vpp.md)")
    out = []
    for name in BOAT_PARAMETERS:
        if name in raw:
            r = _range(c, raw, name)
            if r is not None:
                out.append((name, *r))
    return tuple(out)


def check_uncertainty(c: Checker, raw: Any, base_dir: Path | None = None) -> UncertaintySpec | None:
    """Check the ``uncertainty`` mapping at ``c.path``; every problem goes to ``c``.

    Parameters
    ----------
    c : Checker
        Checker at the section's key path (``"uncertainty"``).
    raw : Any
        The section's value.
    base_dir : Path, optional
        Folder that a relative ``shifts.fit`` path resolves against.

    Returns
    -------
    UncertaintySpec or None
        None after a problem.
    """
    if not c.is_mapping(raw, "a mapping with tws_kn, twd_deg, shifts, boat, polar, members, seed"):
        return None
    n0 = len(c.p)
    c.keys(raw, UNCERTAINTY_KEYS)
    speeds = [k for k in ("tws_kn", "tws_ms", "tws_pct") if k in raw]
    if len(speeds) > 1:
        c.add(speeds[1], f"give one of tws_kn, tws_ms, tws_pct; got {', '.join(speeds)}")
    add = rel = 0.0
    if "tws_kn" in raw:
        add = (c.number(raw, "tws_kn", None, lo=0.0) or 0.0) * KNOT
    elif "tws_ms" in raw:
        add = c.number(raw, "tws_ms", None, lo=0.0) or 0.0
    elif "tws_pct" in raw:
        rel = (c.number(raw, "tws_pct", None, lo=0.0, hi=100.0) or 0.0) / 100.0
    twd = c.number(raw, "twd_deg", 0.0, lo=0.0, hi=90.0)
    shifts = (
        _shifts(c.child("shifts"), raw["shifts"], base_dir)
        if raw.get("shifts") is not None
        else None
    )
    boat = _boat(c.child("boat"), raw["boat"]) if raw.get("boat") is not None else ()
    draw_polar = c.boolean(raw, "polar", True)
    members = c.integer(raw, "members", DEFAULT_UNCERTAINTY.members, lo=3)
    seed = c.integer(raw, "seed", DEFAULT_UNCERTAINTY.seed, lo=0)
    m_s = c.number(raw, "side_margin_s", DEFAULT_UNCERTAINTY.side_margin_s, lo=0.0)
    m_pct = c.number(raw, "side_margin_pct", DEFAULT_UNCERTAINTY.side_margin_pct, lo=0.0, hi=100.0)
    if len(c.p) > n0:
        return None
    return UncertaintySpec(
        tws_add_ms=add,
        tws_rel=rel,
        twd_deg=twd or 0.0,
        shifts=shifts,
        boat=boat,
        draw_polar=bool(draw_polar),
        members=members,
        seed=seed,
        side_margin_s=m_s,
        side_margin_pct=m_pct,
        where=c.where(),
    )


def uncertainty_from_mapping(
    raw: Any, *, where: str = "<uncertainty>", base_dir: Path | None = None
) -> UncertaintySpec:
    """An :class:`UncertaintySpec` from a plain mapping (the Python API).

    Raises
    ------
    InputError
        Every problem, each naming its key (``<where>: uncertainty.tws_kn: ...``).
    """
    probs = Problems(where)
    spec = check_uncertainty(Checker(probs, "uncertainty"), raw, base_dir)
    probs.raise_if_any()
    assert spec is not None  # no problems
    return spec
