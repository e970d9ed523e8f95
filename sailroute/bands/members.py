"""Members of a leg-time band: versions of a scenario's wind and boat, drawn from its uncertainty.

Each uncertain source (:meth:`~sailroute.course.uncertainty.UncertaintySpec.sources`)
is one dimension of a Latin hypercube in ``(0, 1)``: ``n`` members put exactly one
value in each of ``n`` equal-probability strata of every source (McKay, Beckman and
Conover 1979), so even a small ``n`` spans the tails.  A stratum value ``u`` becomes:

* ``tws``: ``z = Φ⁻¹(u)`` standard deviations of speed, added (``tws_kn``) or as a
  log-normal factor ``(1 + tws_pct / 100) ** z`` (one sigma up multiplies the speed by
  ``1 + tws_pct / 100``, one down divides it; never zero, so a wide spread such as
  ``tws_pct: 100`` gives light-air members, not calm ones);
* ``twd``: a constant direction offset ``z · twd_deg``;
* ``shifts``: ``oscillating``, the phase ``2π u``; ``persistent``, a rate
  ``z · rate``; ``ou``, the starting shift ``z · sigma`` of an Ornstein-Uhlenbeck
  path (:class:`sailroute.strategy.shiftmodel.OUShift`, stepped every 10 s with its exact
  transition, the innovations from the seeded generator);
* ``polar`` (the course's boat is a learned polar, :class:`~sailroute.boat.learn.PolarDraw`):
  the first bootstrap mode's coefficient ``z``; the other modes, each cell's rest and
  the pace factor (the legs' scatter about the race pace) standard normal from the
  seeded generator: a whole table, correlated along its rows and across them;
* ``boat.<parameter>``: ``low + u (high - low)``.

:func:`one_at_a_time` gives, per source, members at that source's quantiles 0.1, 0.5 and 0.9
with every other source at its nominal value (no change), for the breakdown of which
source widens the band most; the ``polar`` member at quantile ``q`` has every cell of the
table at its own quantile ``q``.  Members are data; :func:`member_wind` and
:func:`member_boat` build what a router needs.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from statistics import NormalDist
from typing import TYPE_CHECKING, Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.course.uncertainty import ShiftSpec, UncertaintySpec
from sailroute.errors import InputError
from sailroute.wind.base import WindField
from sailroute.wind.perturbed import PerturbedWind

if TYPE_CHECKING:  # the learned polar's module only where a band draws it
    from sailroute.boat.learn import PolarDraw

_NORMAL: Final = NormalDist()
"""The standard normal distribution: a stratum's quantile ``u`` as ``z`` (its inverse CDF,
accurate to about 1e-16: the standard library's, where SciPy's ``ndtri`` cost 0.27 s of
CPU to import)."""

__all__ = [
    "MAX_ENSEMBLE_BYTES",
    "NOMINAL",
    "Member",
    "check_ensemble_size",
    "draw_members",
    "fit_shifts",
    "member_boat",
    "member_wind",
    "one_at_a_time",
    "resolve_shifts",
]

SHIFT_STEP_S: Final = 10.0
"""Time step of a member's shift series [s]."""
OAT_QUANTILES: Final = (0.1, 0.5, 0.9)
"""Quantiles of one source in the one-at-a-time breakdown."""
MAX_ENSEMBLE_BYTES: Final = 2.0**30
"""Most memory the members of one band may hold, as :func:`check_ensemble_size`
estimates it [bytes] (1 GiB: some 15 000 members of a two-leg course)."""
MEMBER_BYTES: Final = 1024.0
"""A member without its shift series, and its place in the lists [bytes]."""
SHIFT_SAMPLE_BYTES: Final = 64.0
"""One sample of a member's shift series: a time and a shift, as Python floats in
tuples [bytes]."""
LEG_ROUTE_BYTES: Final = 16384.0
"""One member's routed leg: its track and records [bytes] (3-14 kB measured, pickled,
on the legs of tests/data/course/minimal.yaml and courses/hyeres-r1.yaml)."""


@dataclass(frozen=True)
class Member:
    """One version of a scenario's wind and boat.

    Attributes
    ----------
    name : str
        ``"m<k>"`` (main ensemble, k from 1), ``"nominal"`` or ``"<source>@<q>"``
        (one-at-a-time, q the source's quantile).
    tws_add_ms : float
        Added true wind speed [m s⁻¹].
    tws_scale : float
        Factor on the true wind speed.
    twd_offset_deg : float
        Constant veer (+) or back (-) [°].
    shift_t_s : tuple of float
        Times of the shift series, from the race start [s] (empty: no shift).
    shift_deg : tuple of float
        Shift at those times [°], positive clockwise.
    boat : tuple of (str, float)
        Race-polar parameters (:class:`~sailroute.boat.kinetics.Kinetics` fields)
        changed from the course's boat; empty: the course's boat.
    polar : PolarDraw or None
        The draw of the course's learned polar; None: its table as learned.
    """

    name: str
    tws_add_ms: float = 0.0
    tws_scale: float = 1.0
    twd_offset_deg: float = 0.0
    shift_t_s: tuple[float, ...] = ()
    shift_deg: tuple[float, ...] = ()
    boat: tuple[tuple[str, float], ...] = ()
    polar: PolarDraw | None = None


NOMINAL: Final = Member("nominal")
"""The scenario as given."""


def fit_shifts(shifts: ShiftSpec) -> ShiftSpec:
    """An OU shift spec with its parameters fitted to measured wind, if ``shifts.fit`` is set.

    The station file's directions are fitted with :func:`sailroute.strategy.fit.fit_station_file`
    (2 s bins, e-fold timescale); other specs are returned unchanged.
    """
    if shifts.fit is None:
        return shifts
    from sailroute.strategy.fit import fit_station_file

    ou, _ = fit_station_file(shifts.fit, shifts.station, speed_unit=shifts.speed_unit)
    if not (np.isfinite(ou.sigma_deg) and np.isfinite(ou.timescale_s) and ou.timescale_s > 0):
        raise InputError(
            f"uncertainty.shifts.fit: {shifts.fit}: the direction series gives no "
            f"usable shift model (sigma {ou.sigma_deg:g}°, timescale "
            f"{ou.timescale_s:g} s); give {{model: ou, sigma_deg, timescale_min}}"
        )
    return dataclasses.replace(
        shifts, sigma_deg=float(ou.sigma_deg), timescale_s=float(ou.timescale_s)
    )


def resolve_shifts(spec: UncertaintySpec) -> UncertaintySpec:
    """``spec`` with a fitted shift model's parameters filled in (:func:`fit_shifts`)."""
    if spec.shifts is None or spec.shifts.fit is None:
        return spec
    return dataclasses.replace(spec, shifts=fit_shifts(spec.shifts))


def _lhs(n: int, d: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Latin hypercube: ``(n, d)`` values in (0, 1), one per stratum ``[k/n, (k+1)/n)``."""
    out = np.empty((n, d))
    for j in range(d):
        out[:, j] = (rng.permutation(n) + rng.uniform(0.02, 0.98, n)) / n
    return out


def _shift_series(
    shifts: ShiftSpec, u: float, duration_s: float, rng: np.random.Generator
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The shift series ``(t, shift)`` of stratum value ``u`` over ``[0, duration_s]``."""
    t = np.arange(0.0, duration_s + SHIFT_STEP_S, SHIFT_STEP_S)
    z = _NORMAL.inv_cdf(u)
    if shifts.model == "oscillating":
        s = shifts.amplitude_deg * np.sin(2 * np.pi * t / shifts.period_s + 2 * np.pi * u)
    elif shifts.model == "persistent":
        s = z * shifts.rate_deg_per_s * t
    else:  # ou: the strategy module's shift model, stepped with its exact transition
        from sailroute.strategy.shiftmodel import OUShift

        if not shifts.sigma_deg > 0 or not shifts.timescale_s > 0:
            raise InputError(
                "uncertainty.shifts: an OU shift needs sigma_deg > 0 and "
                "timescale_min > 0 (or `fit:` a station file)"
            )
        model = OUShift(shifts.sigma_deg, shifts.timescale_s)
        eps = rng.standard_normal(t.size)
        s = np.empty(t.size)
        s[0] = z * shifts.sigma_deg  # the stationary distribution's quantile u
        for i in range(1, t.size):
            mean, sd = model.transition_moments(s[i - 1], SHIFT_STEP_S)
            s[i] = float(mean) + float(sd) * eps[i]
    return tuple(float(v) for v in t), tuple(float(v) for v in s)


def _apply(
    member: Member,
    source: str,
    u: float,
    spec: UncertaintySpec,
    duration_s: float,
    rng: np.random.Generator,
) -> Member:
    """``member`` with ``source`` set from its stratum value ``u``."""
    z = _NORMAL.inv_cdf(u)
    if source == "tws":
        return dataclasses.replace(
            member, tws_add_ms=z * spec.tws_add_ms, tws_scale=(1.0 + spec.tws_rel) ** z
        )
    if source == "twd":
        return dataclasses.replace(member, twd_offset_deg=z * spec.twd_deg)
    if source == "shifts":
        assert spec.shifts is not None
        t, s = _shift_series(spec.shifts, u, duration_s, rng)
        return dataclasses.replace(member, shift_t_s=t, shift_deg=s)
    if source == "polar":
        assert spec.polar is not None
        return dataclasses.replace(member, polar=_polar_draw(spec, z, rng))
    name = source.removeprefix("boat.")
    lo, hi = next((lo, hi) for p, lo, hi in spec.boat if p == name)
    return dataclasses.replace(member, boat=(*member.boat, (name, lo + u * (hi - lo))))


@lru_cache(maxsize=8)
def _level_table(file: Path, level: str) -> Any:
    from sailroute.boat.learnfile import read_learned

    return read_learned(file).level(level)


def _polar_draw(spec: UncertaintySpec, z: float, rng: np.random.Generator) -> PolarDraw:
    """A main member's draw of the learned polar, its first mode at ``z``."""
    from sailroute.boat.learn import PolarDraw

    assert spec.polar is not None
    return PolarDraw.random(_level_table(spec.polar.file, spec.polar.level), rng, first=z)


def check_ensemble_size(spec: UncertaintySpec, n: int, duration_s: float, n_legs: int) -> None:
    """Refuse ``n`` members whose shift series and routes would need more than
    :data:`MAX_ENSEMBLE_BYTES`, before anything is drawn (as the routers refuse
    settings whose work they estimate would take minutes).

    Parameters
    ----------
    spec : UncertaintySpec
        The uncertainties (a shift model makes each member hold a shift series).
    n : int
        Members of the main ensemble.
    duration_s : float
        Time span of the shift series [s] (the course's time limit).
    n_legs : int
        Legs each member routes.

    Raises
    ------
    InputError
        Naming the estimate and the most members that fit.
    """
    samples = duration_s / SHIFT_STEP_S + 2.0 if spec.shifts is not None else 0.0
    each = MEMBER_BYTES + SHIFT_SAMPLE_BYTES * samples + LEG_ROUTE_BYTES * n_legs
    need = float(n) * each
    if need <= MAX_ENSEMBLE_BYTES:
        return
    fit = int(MAX_ENSEMBLE_BYTES // each)
    raise InputError(
        f"{n} members would hold about {need / 2**30:.3g} GiB (each its shift series and "
        f"the routes of {n_legs} legs, about {each / 1024:.0f} kiB), more than "
        f"{MAX_ENSEMBLE_BYTES / 2**30:.0f} GiB; give at most {fit} members (--ensemble N "
        "or uncertainty.members; a band is steady from a few dozen)"
    )


def draw_members(
    spec: UncertaintySpec, duration_s: float, *, n: int | None = None, seed: int | None = None
) -> tuple[Member, ...]:
    """The main ensemble: ``n`` members from a Latin hypercube over every source.

    Parameters
    ----------
    spec : UncertaintySpec
        The uncertainties (a fitted shift model resolved: :func:`resolve_shifts`).
    duration_s : float
        Time span the shift series cover from the race start [s] (the course's
        time limit).
    n : int, optional
        Members; default ``spec.members``.
    seed : int, optional
        Default ``spec.seed``; the same seed gives the same members.

    Returns
    -------
    tuple of Member
        Named ``m1`` ... ``m<n>``.
    """
    n = spec.members if n is None else int(n)
    if n < 3:
        raise InputError(f"a band needs at least 3 members; got {n} (--ensemble N, N >= 3)")
    rng = np.random.default_rng(spec.seed if seed is None else seed)
    sources = spec.sources()
    u = _lhs(n, len(sources), rng)
    out = []
    for k in range(n):
        m = Member(f"m{k + 1}")
        for j, source in enumerate(sources):
            m = _apply(m, source, float(u[k, j]), spec, duration_s, rng)
        out.append(m)
    return tuple(out)


def one_at_a_time(
    spec: UncertaintySpec, duration_s: float, quantiles: Sequence[float] = OAT_QUANTILES
) -> dict[str, tuple[Member, ...]]:
    """Per source, members at its ``quantiles`` with every other source nominal.

    Returns
    -------
    dict of str to tuple of Member
        Source name -> members named ``"<source>@<q>"``.  OU paths use a generator
        seeded with ``spec.seed``, one per quantile.
    """
    out: dict[str, tuple[Member, ...]] = {}
    for source in spec.sources():
        members = []
        for i, q in enumerate(quantiles):
            rng = np.random.default_rng([spec.seed, i])
            m = Member(f"{source}@{q:g}")
            if source == "polar":  # every cell at its own quantile q
                from sailroute.boat.learn import PolarDraw

                draw = PolarDraw(quantile_z=_NORMAL.inv_cdf(float(q)))
                members.append(dataclasses.replace(m, polar=draw))
                continue
            members.append(_apply(m, source, float(q), spec, duration_s, rng))
        out[source] = tuple(members)
    return out


def member_wind(base: WindField, member: Member, t0: float) -> WindField:
    """The member's wind: ``base`` perturbed (:class:`~sailroute.wind.perturbed.PerturbedWind`).

    Parameters
    ----------
    base : WindField
        The scenario's wind.
    member : Member
        The member.
    t0 : float
        Race start [epoch s]; the member's shift times count from it.
    """
    if member == dataclasses.replace(
        NOMINAL, name=member.name, boat=member.boat, polar=member.polar
    ):
        return base
    return PerturbedWind(
        base,
        speed_scale=member.tws_scale,
        speed_add_ms=member.tws_add_ms,
        direction_offset_deg=member.twd_offset_deg,
        shift_times=t0 + np.asarray(member.shift_t_s, dtype=float),
        shift_deg=np.asarray(member.shift_deg, dtype=float),
        name=f"wind of member {member.name}",
    )


def _race_form(boat_spec: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The course's boat as a ``vpp`` spec with a ``kinetics`` mapping, for boat members."""
    from sailroute.boat.build import builtin_kind, builtin_names
    from sailroute.boat.kinetics import STEADY

    spec = dict(boat_spec)
    name = spec.get("builtin")
    if isinstance(name, str) and name.lower() in builtin_names():
        cls, kin = builtin_kind(name.lower())
        if kin != STEADY:
            keep = {k: v for k, v in spec.items() if k not in ("builtin",)}
            return {**keep, "vpp": {"class": cls}, "kinetics": {}}
    elif "vpp" in spec and spec.get("kinetics", "race") not in ("steady",):
        kin_raw = spec.get("kinetics", "race")
        return {**spec, "kinetics": {} if kin_raw == "race" else dict(kin_raw)}
    raise InputError(
        f"{where}: uncertainty.boat: race-polar parameters need a race polar "
        "(boat: {builtin: ilca7} or {vpp: {class: ...}}); this course's boat is "
        f"{dict(boat_spec)}; remove uncertainty.boat or use a race polar"
    )


def member_boat(
    boat_spec: Mapping[str, Any],
    base_boat: Any,
    member: Member,
    *,
    base_dir: Path,
    where: str,
) -> Any:
    """The member's boat: the course's boat, its race polar with parameters changed, or
    a draw of its learned polar.

    Parameters
    ----------
    boat_spec : mapping
        The course's raw ``boat`` section (a built-in race polar or a ``vpp`` boat).
    base_boat : Polar
        The course's built boat (returned for a member without boat parameters).
    member : Member
        The member.
    base_dir : Path
        The course's folder (relative paths of the boat spec).
    where : str
        ``"file:line"`` for messages.

    Raises
    ------
    InputError
        The member changes race-polar parameters but the course's boat is not a race
        polar (a polar file, a steady VPP).
    """
    if member.polar is not None:
        return _built(_freeze(dict(boat_spec)), str(base_dir), member.polar)
    if not member.boat:
        return base_boat
    form = _race_form(boat_spec, where)
    form["kinetics"] = {**form["kinetics"], **{k: float(v) for k, v in member.boat}}
    return _built(_freeze(form), str(base_dir))


def _freeze(value: Any) -> Any:
    if isinstance(value, Mapping):
        return tuple(sorted((str(k), _freeze(v)) for k, v in value.items()))
    if isinstance(value, list | tuple):
        return ("__list__", *(_freeze(v) for v in value))
    return value


def _thaw(value: Any) -> Any:
    if isinstance(value, tuple) and value and value[0] == "__list__":
        return [_thaw(v) for v in value[1:]]
    if isinstance(value, tuple):
        return {k: _thaw(v) for k, v in value}
    return value


@lru_cache(maxsize=256)
def _built(frozen: Any, base_dir: str, draw: PolarDraw | None = None) -> Any:
    """A race polar, or a draw of a learned polar, built once (members, and courses, that
    share boat parameters share it; the spec was checked by the course already, so
    problems cannot arise here)."""
    from sailroute.boat.build import boat_from_spec

    return boat_from_spec(
        _thaw(frozen), base_dir=Path(base_dir), where="uncertainty.boat", draw=draw
    )
