"""Race polar: the steady VPP plus what racing dinghy sailors add downwind (waves, pumping).

The steady VPP (:mod:`sailroute.boat.vpp`) balances sail drive against hull
resistance in flat water.  Racing Lasers/ILCAs are far faster than that off
the wind: they ride the faces of wind waves and, when the race committee
flies flag O (wind above about 10 kn, ILCA class rules under RRS 42 and
Appendix P5), pump the sail.  This module adds both as an extra forward force
``T(TWS, TWA, V)`` in the same surge balance, solved by the same root finder::

    X_sail(V) - R(V) + T_wave(TWS, TWA, V) + T_pump(TWS, TWA, V) = 0   (largest root)

**Waves** (:func:`wind_sea`, :func:`wave_thrust`).  The wind sea is the
fetch-limited JONSWAP growth law (Hasselmann et al. 1973, as given in the US
Army Coastal Engineering Manual, EM 1110-2-1100 Part II-2):
``g H_s / U10² = 1.6e-3 (g F / U10²)^½`` and ``g T_p / U10 = 0.286 (g F / U10²)^⅓``,
capped at the fully developed (Pierson-Moskowitz) limits ``g H_s / U10² = 0.21``
and ``g T_p / U10 = 7.14``; deep-water wavelength ``L_p = g T_p² / 2π`` and
phase speed ``c_p = g T_p / 2π``.  U10 comes from the polar's TWS (at the
sail's centre of effort) by the 1/7 power law used elsewhere in sailroute.
A sinusoidal wave of height H_s has a steepest slope ``π H_s / L_p`` and a
mean front-face slope ``2 H_s / L_p``.  The boat gets ``m g · 2 H_s / L_p``
along the waves' direction while it rides a face, for a share of the time
``f = min(r, 1/r)`` with ``r = V cos φ / c_p`` its speed along the waves over
their phase speed (a boat much slower than the waves is passed by them; one
faster runs over them), times ``cos φ`` for the part of the push along its
heading, ``φ = 180° - TWA`` (wind waves travel with the wind; no push for
``TWA <= 90°``).  With flag O up the sailor pumps onto every wave and stays on
it: the share is 1 from TWA 120° on (smoothstep from 90°).

**Pumping** (:func:`pump_thrust`).  A sustained propulsive power
``η P`` gives a force ``η P / V``.  ``P`` is the sailor's extra mechanical
power when pumping: the oxygen uptake of Olympic sailors rose from 19.2 to
48.4 ml kg⁻¹ min⁻¹ (men) when they pumped (Vogiatzis et al. 2002, Eur J Appl
Physiol 86:450) = 29.2 ml kg⁻¹ min⁻¹ × 20.9 J ml⁻¹ (oxygen's energy
equivalent) × 0.20 (gross muscular efficiency) = 2.0 W kg⁻¹ of sailor.  The
propulsive efficiency ``η`` of a pumped sail (the part of that work that ends
as thrust) is an assumption (0.5).  Pumping is permitted only above the flag-O
threshold, 10 kn (ramped over ±0.5 kn so the polar stays smooth), and pays on
reaches and runs (eased, stalled sail): its weight rises from 0 at TWA 60° to 1
at 100°.

Every number and its source is listed in ``docs/vpp.md`` ("Race polar");
none was fitted to a race.  :data:`RACE` is the default set.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields, replace
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.laser import LaserParams
from sailroute.boat.polar import Polar
from sailroute.checks import Checker, Problems, show
from sailroute.errors import InputError
from sailroute.units import KNOT

G: Final = 9.81
"""Gravity [m s⁻²]."""

_JONSWAP_HS: Final = 1.6e-3
_JONSWAP_TP: Final = 0.286
_PM_HS: Final = 0.21
_PM_TP: Final = 7.14
_V_FLOOR: Final = 0.5  # [m/s] pumping force is P/V; below this speed it is held


@dataclass(frozen=True)
class Kinetics:
    """Parameters of the race model (waves and pumping); see the module docstring.

    Attributes
    ----------
    fetch_m : float
        Over-water fetch of the wind sea [m] (50 km: an open coast; assumption).
        0 switches the waves off.
    sea_age_h : float
        How long the wind has blown [h] (3: a sea breeze or gradient wind set up by
        the afternoon start; assumption).  The sea is the smaller of the
        fetch-limited and the duration-limited one (CEM II-2: ``g t / U10 =
        68.8 (g F / U10²)^⅔``); 0 switches the waves off.
    wind_ref_height_m : float
        Height of the wind the wave growth law uses [m] (10, JONSWAP's U10).
    shear_exponent : float
        Power-law exponent from the polar's TWS height to ``wind_ref_height_m``
        (1/7, sailroute's default).
    pump_power_w_per_kg : float
        Extra mechanical power of a pumping sailor per kg of sailor [W kg⁻¹]
        (2.0, from Vogiatzis et al. 2002; 0 switches pumping off).
    pump_efficiency : float
        Share of that power that becomes thrust (0.7: oscillating foils reach
        0.5-0.87, Anderson et al. 1998, J Fluid Mech 360:41; assumption for a sail).
    oscar_tws_kn : float
        Wind above which pumping is permitted [kn] (10, flag O, ILCA class rules).
    oscar_ramp_kn : float
        Width of the ramp around that threshold [kn] (1).
    pump_twa_deg : tuple of float
        TWA [°] where pumping starts to pay and where it pays fully (60, 100).
    upwind_efficiency : float
        Share of the steady VPP speed sailed on a beat, relative to off the wind
        (0.94: in the Tallinn 2023 instrument log the crew sailed a median 0.889 of
        its ORC VPP target at TWA < 60° and 0.945 at TWA > 120°; 0.889 / 0.945).
        1 switches it off.
    upwind_twa_deg : tuple of float
        TWA [°] up to which ``upwind_efficiency`` applies in full and from which it
        is 1 (60, 90; smooth in between).
    """

    fetch_m: float = 50_000.0
    sea_age_h: float = 3.0
    wind_ref_height_m: float = 10.0
    shear_exponent: float = 1.0 / 7.0
    pump_power_w_per_kg: float = 2.0
    pump_efficiency: float = 0.7
    oscar_tws_kn: float = 10.0
    oscar_ramp_kn: float = 1.0
    pump_twa_deg: tuple[float, float] = (60.0, 100.0)
    upwind_efficiency: float = 0.94
    upwind_twa_deg: tuple[float, float] = (60.0, 90.0)

    def __post_init__(self) -> None:
        problems = []
        for f in fields(self):
            v = getattr(self, f.name)
            vals = v if isinstance(v, tuple) else (v,)
            if not all(isinstance(x, int | float) and np.isfinite(x) and x >= 0 for x in vals):
                problems.append(f"{f.name} must be finite and >= 0; got {v!r}")
        if self.wind_ref_height_m <= 0:
            problems.append("wind_ref_height_m must be > 0")
        if not 0 < self.upwind_efficiency <= 1:
            problems.append(f"upwind_efficiency must lie in (0, 1]; got {self.upwind_efficiency}")
        if self.pump_efficiency > 1:
            problems.append(f"pump_efficiency is a share, at most 1; got {self.pump_efficiency}")
        for name in ("pump_twa_deg", "upwind_twa_deg"):
            lo, hi = getattr(self, name)
            if not lo < hi <= 180:
                problems.append(f"{name} must rise within [0, 180]; got {(lo, hi)}")
        if problems:
            raise InputError("race kinetics: " + "; ".join(problems))


RACE: Final = Kinetics()
"""The default race model (every value sourced in ``docs/vpp.md``)."""

STEADY: Final = Kinetics(fetch_m=0.0, sea_age_h=0.0, pump_power_w_per_kg=0.0, upwind_efficiency=1.0)
"""No waves, no pumping: the race model reduces to the steady VPP."""


def check_kinetics(c: Checker, value: object) -> Kinetics | None:
    """The race model a course file's ``kinetics`` value names, recording problems in ``c``.

    Parameters
    ----------
    c : Checker
        Checker of the ``kinetics`` key path (e.g. ``boat.kinetics``); its
        :class:`~sailroute.checks.Problems` collects the problems with the rest
        of the file's.
    value : {"race", "steady"} or mapping
        ``race`` (:data:`RACE`), ``steady`` (:data:`STEADY`) or a mapping of
        :class:`Kinetics` fields overriding :data:`RACE`, e.g. ``{sea_age_h: 6,
        fetch_m: 8000}`` (unknown keys get a did-you-mean).

    Returns
    -------
    Kinetics or None
        None after a problem.
    """
    if value == "race":
        return RACE
    if value == "steady":
        return STEADY
    if not c.is_mapping(value, "'race', 'steady' or a mapping of race-model parameters"):
        return None
    assert isinstance(value, Mapping)
    before = len(c.p)
    names = [f.name for f in fields(Kinetics)]
    c.keys(value, names)
    given: dict[str, Any] = {}  # field name -> float or (from, to)
    for k in names:
        if k not in value:
            continue
        v = value[k]
        if isinstance(getattr(RACE, k), tuple):
            if not isinstance(v, list | tuple) or len(v) != 2 or not all(_is_number(x) for x in v):
                c.add(k, f"expected two numbers [from, to]; got {show(v)}")
            else:
                given[k] = (float(v[0]), float(v[1]))
        else:
            x = c.number(value, k, None)
            if x is not None:
                given[k] = x
    if len(c.p) > before:
        return None
    try:
        return replace(RACE, **given)
    except InputError as exc:  # the cross-field checks of Kinetics.__post_init__
        c.add(None, str(exc).removeprefix("race kinetics: "))
        return None


def kinetics_from_spec(value: object, key: str = "kinetics") -> tuple[Kinetics, list[str]]:
    """The race model a ``kinetics`` value names, and its problems (:func:`check_kinetics`).

    Parameters
    ----------
    value : {"race", "steady"} or mapping
        As :func:`check_kinetics`.
    key : str
        Key path (or label) that starts each message.

    Returns
    -------
    kinetics : Kinetics
        :data:`RACE` where there are problems.
    problems : list of str
        ``"<key>.<field>: ..."`` messages, without a file (empty when valid).
    """
    probs = Problems("")  # no file: every message is ": <key path>: ..."
    kinetics = check_kinetics(Checker(probs, key), value)
    return kinetics or RACE, [m.removeprefix(": ") for m in probs.items]


def _is_number(x: object) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def wind_sea(
    u10_ms: ArrayLike, fetch_m: float, duration_s: float = np.inf
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Fetch- or duration-limited wind sea (JONSWAP growth, capped at full development).

    Parameters
    ----------
    u10_ms : array_like
        Wind speed at 10 m [m s⁻¹].
    fetch_m : float
        Fetch [m].
    duration_s : float
        How long the wind has blown [s]; the sea grows over the smaller of the
        fetch and the duration's equivalent fetch ``(g t / (68.8 U10))^{3/2} U10² / g``.

    Returns
    -------
    hs_m, tp_s, lp_m, cp_ms : ndarray
        Significant wave height [m], peak period [s], deep-water peak wavelength
        [m] and phase speed [m s⁻¹].  Zero wind gives zeros (``cp`` 0).
    """
    u = np.maximum(np.asarray(u10_ms, dtype=float), 0.0)
    u2 = np.where(u > 0, u * u, 1.0)
    x = np.minimum(G * fetch_m / u2, (G * duration_s / (68.8 * np.sqrt(u2))) ** 1.5)
    hs = np.where(u > 0, np.minimum(_JONSWAP_HS * np.sqrt(x), _PM_HS) * u2 / G, 0.0)
    tp = np.where(u > 0, np.minimum(_JONSWAP_TP * np.cbrt(x), _PM_TP) * u / G, 0.0)
    lp = G * tp * tp / (2.0 * np.pi)
    cp = G * tp / (2.0 * np.pi)
    return hs, tp, lp, cp


def _u10(tws_ms: NDArray, params: LaserParams, kin: Kinetics) -> NDArray:
    return tws_ms * (kin.wind_ref_height_m / params.ce_height_m) ** kin.shear_exponent


def wave_thrust(
    params: LaserParams, kin: Kinetics, tws_ms: ArrayLike, twa_deg: ArrayLike, v_ms: ArrayLike
) -> NDArray[np.float64]:
    """Mean forward force of riding wind-wave faces [N] (module docstring)."""
    tws, twa, v = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (tws_ms, twa_deg, v_ms))
    )
    if kin.fetch_m <= 0 or kin.sea_age_h <= 0:
        return np.zeros(tws.shape)
    hs, _, lp, cp = wind_sea(_u10(tws, params, kin), kin.fetch_m, kin.sea_age_h * 3600.0)
    # heading vs the waves' direction; waves travel downwind, so no push at TWA <= 90°
    cos_phi = np.where(np.abs(twa) > 90.0, np.cos(np.radians(180.0 - np.abs(twa))), 0.0)
    along = np.maximum(v * cos_phi, 0.0)
    r = np.divide(along, cp, out=np.zeros_like(along), where=cp > 0)
    share = np.minimum(r, np.divide(1.0, r, out=np.zeros_like(r), where=r > 0))
    # with flag O the sailor pumps onto every wave and stays on its face, once the boat
    # runs with the waves (smoothly from TWA 90° to 120°; a beam reach lets them pass)
    allowed = _oscar(tws, kin)
    share = allowed * _ramp(np.abs(twa), 90.0, 120.0) + (1.0 - allowed) * share
    slope = np.divide(2.0 * hs, lp, out=np.zeros_like(hs), where=lp > 0)
    # the hull feels the slope averaged over its waterline length: sinc(π L_wl / L_p); a hull
    # longer than the waves spans crest and trough and cannot ride one (0 past the first zero)
    x = np.divide(
        np.pi * params.lwl_m * np.maximum(cos_phi, 0.0), lp, out=np.zeros_like(lp), where=lp > 0
    )
    hull = np.where(x < np.pi, np.sinc(x / np.pi), 0.0)
    mass = params.hull_mass_kg + params.crew_mass_kg
    return mass * G * slope * hull * share * np.maximum(cos_phi, 0.0)


def _ramp(x: NDArray, lo: float, hi: float) -> NDArray:
    """C¹ smoothstep from 0 at ``lo`` to 1 at ``hi``."""
    s = np.clip((x - lo) / (hi - lo), 0.0, 1.0) if hi > lo else (x >= lo).astype(float)
    return s * s * (3.0 - 2.0 * s)


def _oscar(tws_ms: NDArray, kin: Kinetics) -> NDArray:
    """0 where pumping is not permitted, 1 where it is (ramped over ``oscar_ramp_kn``)."""
    half = 0.5 * kin.oscar_ramp_kn * KNOT
    return _ramp(tws_ms, kin.oscar_tws_kn * KNOT - half, kin.oscar_tws_kn * KNOT + half)


def pump_thrust(
    params: LaserParams, kin: Kinetics, tws_ms: ArrayLike, twa_deg: ArrayLike, v_ms: ArrayLike
) -> NDArray[np.float64]:
    """Mean forward force of pumping [N]: ``η P / V`` where flag O allows it."""
    tws, twa, v = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (tws_ms, twa_deg, v_ms))
    )
    power = kin.pump_efficiency * kin.pump_power_w_per_kg * params.crew_mass_kg
    allowed = _oscar(tws, kin)
    where = _ramp(np.abs(twa), *kin.pump_twa_deg)
    return power * allowed * where / np.maximum(v, _V_FLOOR)


def race_thrust(
    params: LaserParams, kin: Kinetics
) -> Callable[[NDArray, NDArray, NDArray], NDArray]:
    """The extra forward force ``T(tws, twa, V)`` [N] of the race model, for the VPP."""

    def thrust(tws: NDArray, twa: NDArray, v: NDArray) -> NDArray:
        return wave_thrust(params, kin, tws, twa, v) + pump_thrust(params, kin, tws, twa, v)

    return thrust


def race_polar(
    params: LaserParams,
    tws_ms: ArrayLike,
    twa_deg: ArrayLike,
    kinetics: Kinetics = RACE,
    *,
    name: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Race polar: the VPP's surge balance with waves and pumping added.

    Parameters
    ----------
    params : LaserParams
        Boat.
    tws_ms : array_like, shape (n,)
        TWS columns [m s⁻¹] (wind at the sail's centre of effort).
    twa_deg : array_like, shape (m,)
        TWA rows [°].
    kinetics : Kinetics
        Race-model parameters (default :data:`RACE`; :data:`STEADY` gives the
        steady VPP polar exactly).
    name : str, optional
        Polar name (default ``params.name``).
    interpolation : {"pchip", "linear"}
        Interpolation method of the result.

    Returns
    -------
    Polar
    """
    from sailroute.boat.vpp import solve_polar

    thrust = None if kinetics == STEADY else race_thrust(params, kinetics)
    polar = solve_polar(
        params, tws_ms, twa_deg, name=name, interpolation=interpolation, thrust=thrust
    )
    if kinetics.upwind_efficiency == 1.0:
        return polar
    scale = upwind_scale(kinetics, polar.twa_deg)
    return Polar.from_arrays(
        polar.twa_deg,
        polar.tws_ms,
        polar.speed_ms * scale[:, None],
        name=polar.name,
        interpolation=polar.interpolation,
    )


def upwind_scale(kin: Kinetics, twa_deg: ArrayLike) -> NDArray[np.float64]:
    """Speed factor per TWA [°]: ``upwind_efficiency`` on a beat, 1 off the wind."""
    lo, hi = kin.upwind_twa_deg
    return kin.upwind_efficiency + (1.0 - kin.upwind_efficiency) * _ramp(
        np.abs(np.asarray(twa_deg, dtype=float)), lo, hi
    )
