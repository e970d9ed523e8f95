"""A wind field with its speed scaled and its direction turned: one member of a band.

Leg-time bands (:mod:`sailroute.bands`) route a course in many versions of one
scenario's wind: the speed a few per cent up or down, the direction a few degrees
veered or backed, and a shift that changes in time (an oscillation, or a sample path
of a fitted shift model).  :class:`PerturbedWind` is that version: it samples the base
field and returns ``max(0, scale x TWS + add)`` from ``TWD + offset + shift(t)``.  Positive
angles veer the wind (clockwise, the direction it comes from increases).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.wind.base import Coverage, WindField
from sailroute.wind.rotation import rotate_by, rotate_clockwise

__all__ = ["PerturbedWind", "sample_perturbed"]


def _frozen(values: ArrayLike) -> NDArray[np.float64]:
    out = np.array(values, dtype=float, copy=True).reshape(-1)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class PerturbedWind:
    """``base`` with its speed scaled and its direction turned, optionally in time.

    Parameters
    ----------
    base : WindField
        The scenario's wind.
    speed_scale : float
        Factor on the true wind speed (1: unchanged), ``>= 0``.
    speed_add_ms : float
        Added to the scaled speed [m s⁻¹] (0: unchanged); the result is held at
        ``>= 0`` and a calm point stays calm.
    direction_offset_deg : float
        Constant turn of the direction [°], positive clockwise (a veer).
    shift_times : array_like, optional
        Epoch times [s] of a time-varying shift, strictly increasing; with
        ``shift_deg``.  Empty: no time-varying shift.
    shift_deg : array_like, optional
        Shift [°] at ``shift_times`` (positive clockwise), interpolated linearly and
        held constant before the first and after the last time.
    name : str
        Label for messages.
    """

    base: WindField
    speed_scale: float = 1.0
    speed_add_ms: float = 0.0
    direction_offset_deg: float = 0.0
    shift_times: ArrayLike = field(default_factory=lambda: _frozen([]))
    shift_deg: ArrayLike = field(default_factory=lambda: _frozen([]))
    name: str = "perturbed wind"

    def __post_init__(self) -> None:
        if not (np.isfinite(self.speed_scale) and self.speed_scale >= 0):
            raise InputError(
                f"{self.name}: speed_scale must be finite and >= 0; got {self.speed_scale}"
            )
        if not np.isfinite(self.speed_add_ms):
            raise InputError(f"{self.name}: speed_add_ms must be finite; got {self.speed_add_ms}")
        if not np.isfinite(self.direction_offset_deg):
            raise InputError(
                f"{self.name}: direction_offset_deg must be finite; got {self.direction_offset_deg}"
            )
        t, s = self._series
        if t.shape != s.shape:
            raise InputError(
                f"{self.name}: {t.size} shift times but {s.size} shifts; give one shift per time"
            )
        if t.size and (
            np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)) or not np.all(np.isfinite(s))
        ):
            raise InputError(
                f"{self.name}: shift times must be finite and increase strictly, shifts finite"
            )

    @cached_property
    def _series(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Read-only copies of the shift times [epoch s] and shifts [°]."""
        return _frozen(self.shift_times), _frozen(self.shift_deg)

    @property
    def coverage(self) -> Coverage:
        """The base field's coverage."""
        return self.base.coverage

    @property
    def clamp(self) -> bool:
        """The base field's clamping."""
        return bool(getattr(self.base, "clamp", False))

    def turn_deg(self, t: ArrayLike) -> NDArray[np.float64]:
        """Total turn of the direction at epoch ``t`` [s]: offset plus shift [°]."""
        tt = np.asarray(t, dtype=float)
        times, shifts = self._series
        if times.size == 0:
            return np.full(tt.shape, float(self.direction_offset_deg))
        return self.direction_offset_deg + np.interp(tt, times, shifts)

    def sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], local ``x, y`` [m] (broadcast).

        Raises
        ------
        OutOfCoverageError
            The base field does not cover a point (its own message).
        """
        u, v = self.base.sample(t, x, y)
        if self.speed_add_ms == 0.0:
            factor: NDArray[np.float64] | float = self.speed_scale
        else:
            factor = _speed_factor(
                np.asarray(u), np.asarray(v), self.speed_scale, self.speed_add_ms
            )
        if self.turns:
            turn = self.turn_deg(np.broadcast_to(np.asarray(t, dtype=float), np.shape(u)))
            u, v = rotate_clockwise(u, v, turn)
        return factor * u, factor * v

    @property
    def turns(self) -> bool:
        """Whether the direction is turned (an offset or a shift series)."""
        return bool(self._series[0].size) or self.direction_offset_deg != 0.0


def _speed_factor(u: NDArray, v: NDArray, scale: ArrayLike, add: ArrayLike) -> NDArray:
    """Factor on the wind vector that makes its speed ``max(0, scale x speed + add)``."""
    speed = np.hypot(u, v)
    new = np.maximum(scale * speed + add, 0.0)
    # a calm point stays calm: it has no direction to add the speed along
    return np.divide(new, speed, out=np.zeros_like(speed), where=speed > 0)


@dataclass(frozen=True, eq=False)
class _MemberParams:
    """The perturbations of a list of winds as arrays (:func:`sample_perturbed`)."""

    winds: tuple[PerturbedWind, ...]
    scale: NDArray[np.float64]
    add: NDArray[np.float64]
    turns: NDArray[np.bool_]
    cos: NDArray[np.float64]  # of the constant turn
    sin: NDArray[np.float64]
    series: tuple[int, ...]  # the winds with a shift series


_PARAMS: list[Any] = [((), None)]  # the last (winds, their _MemberParams)


def _member_params(winds: Sequence[PerturbedWind | WindField]) -> _MemberParams:
    """:class:`_MemberParams` of ``winds`` (kept for the next call with the same winds;
    a wind that is not a :class:`PerturbedWind` is its own base, unchanged)."""
    last, known = _PARAMS[0]  # one read: another thread may replace it
    if len(last) == len(winds) and all(a is b for a, b in zip(last, winds, strict=True)):
        return known
    params = tuple(w if isinstance(w, PerturbedWind) else PerturbedWind(w) for w in winds)
    a = np.radians(np.array([float(w.direction_offset_deg) for w in params]))
    out = _MemberParams(
        params,
        np.array([w.speed_scale for w in params], dtype=float),
        np.array([w.speed_add_ms for w in params], dtype=float),
        np.array([w.turns for w in params]),
        np.cos(a),
        np.sin(a),
        tuple(k for k, w in enumerate(params) if w._series[0].size),
    )
    _PARAMS[0] = (tuple(winds), out)
    return out


def sample_perturbed(
    winds: Sequence[PerturbedWind | WindField],
    which: NDArray[np.int64],
    t: NDArray[np.float64],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    *,
    compiled: Callable[..., None] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Wind ``(u, v)`` [m s⁻¹] at the points ``(t[i], x[i], y[i])`` (1-D) of the winds
    ``winds[which[i]]``, which all perturb one base field (or are it), with one
    ``sample`` call of the base: each point's wind is the one ``winds[which[i]].sample``
    gives there, bit for bit (the same operations, point by point).

    Used by the ensemble router (:mod:`sailroute.routing.batch`), whose members' winds
    are versions of one scenario's wind.  ``compiled``: a compiled function that does
    the arithmetic after the base's sample in one pass, with the same numbers
    (:func:`sailroute.routing.isochrone_jit.perturbed_winds` and its arguments).
    """
    base = winds[0].base if isinstance(winds[0], PerturbedWind) else winds[0]
    p = _member_params(winds)
    u, v = base.sample(t, x, y)
    u = np.array(np.broadcast_to(u, t.shape), dtype=float)
    v = np.array(np.broadcast_to(v, t.shape), dtype=float)
    if compiled is not None:
        return _compiled(compiled, p, which, t, u, v)
    scale, add = p.scale[which], p.add[which]
    factor = scale
    if p.add.any():  # each point's own factor: the same numbers, computed for all points
        factor = np.where(add != 0.0, _speed_factor(u, v, scale, add), scale)
    turns = p.turns[which]
    if turns.any():
        # a constant turn's cosine and sine once per member; a shift series' per point
        cos, sin = p.cos[which], p.sin[which]
        _series_turns(p, which, t, cos, sin)
        if turns.all():
            u, v = rotate_by(u, v, cos, sin)
        else:
            idx = np.flatnonzero(turns)
            u[idx], v[idx] = rotate_by(u[idx], v[idx], cos[idx], sin[idx])
    return factor * u, factor * v


def _series_turns(
    p: _MemberParams,
    which: NDArray[np.int64],
    t: NDArray[np.float64],
    cos: NDArray[np.float64],
    sin: NDArray[np.float64],
) -> None:
    """Write the cosine and sine of each shift-series member's turn at its points' times
    ``t`` [epoch s] into ``cos`` and ``sin`` (one per point; the others left as they
    are)."""
    for k in p.series:
        mine = np.flatnonzero(which == k)
        b = np.radians(p.winds[k].turn_deg(t[mine]))
        cos[mine], sin[mine] = np.cos(b), np.sin(b)


def _compiled(
    compiled: Callable[..., None],
    p: _MemberParams,
    which: NDArray[np.int64],
    t: NDArray[np.float64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`sample_perturbed`'s arithmetic by ``compiled``: the speeds and the shift
    series' turns (trigonometry) by NumPy, as there, the rest point by point."""
    speed = np.hypot(u, v) if p.add.any() else np.zeros(0)
    series = np.zeros(len(p.winds), dtype=np.bool_)
    cos_p = sin_p = np.zeros(0)
    if p.series:
        series[list(p.series)] = True
        cos_p, sin_p = np.empty_like(u), np.empty_like(u)
        _series_turns(p, which, t, cos_p, sin_p)
    out_u, out_v = np.empty_like(u), np.empty_like(v)
    compiled(
        u,
        v,
        speed,
        np.ascontiguousarray(which, dtype=np.int64),
        p.scale,
        p.add,
        p.turns,
        p.cos,
        p.sin,
        series,
        cos_p,
        sin_p,
        out_u,
        out_v,
    )
    return out_u, out_v
