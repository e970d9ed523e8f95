"""Dębski's dynamic segment model: a boat that accelerates along straight segments.

The model (Dębski 2016) moves a boat along a straight
segment with the 1-D equation of motion

.. math::

    \\ddot s + k \\dot s^2 = (c_1 \\beta_a - c_2)\\, v_a^2,

    v_a = \\sqrt{(\\dot s \\sin\\beta_t)^2 + (v_t + \\dot s\\cos\\beta_t)^2},\\qquad
    \\beta_a = \\beta_t - \\arccos\\frac{v_t + \\dot s \\cos\\beta_t}{v_a},

with the true wind angle ``β_t`` = |TWA| [rad], true wind speed ``v_t`` [m s⁻¹],
apparent wind speed ``v_a`` and angle ``β_a`` [rad].  A turn of angle ``δ``
between consecutive segments keeps, scales (``cos⁴ δ``) or kills the speed
(:meth:`DynamicBoat.initial_speed`).

Scaling
-------
With ``w = ṡ / v_t`` and ``τ = v_t t`` [m] the equation becomes autonomous and
free of ``v_t``:

.. math::  \\frac{dw}{d\\tau} = g(w, \\beta) = (c_1\\beta_a(w) - c_2)(w^2 + 2w\\cos\\beta + 1)
           - k w^2,\\qquad \\frac{ds}{d\\tau} = w .

So the steady speed is ``v_t w_ss(β)`` and distances are independent of the
wind speed.  For a segment of constant wind the time to cover a length ``ℓ``
from the scaled entry speed ``w0`` is, once the transient has died out,

.. math::  t = \\frac{1}{v_t}\\Big(\\frac{\\ell}{w_{ss}} + \\Lambda(\\beta, w_0)\\Big),\\qquad
           \\Lambda(\\beta, w_0) = \\frac{1}{w_{ss}}\\int_{w_0}^{w_{ss}}
           \\frac{w_{ss} - w}{g(w, \\beta)}\\,dw ,

a *regular* integral (the integrand tends to ``1/(w_ss γ)`` at the fixed point,
``γ = -∂g/∂w``).  :class:`SegmentTable` tabulates ``w_ss(β)`` and ``Λ(β, w0)``
once per boat, which makes a segment evaluation a table lookup instead of an
ODE integration.  Segments shorter than the transient length fall back to a
vectorised RK4 integration (:func:`simulate_pieces`).  Design and accuracy
numbers: ``docs/design/griddp.md``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_simpson

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.numerics import hermite, hermite_coefficients, hermite_crossing, rk4_step
from sailroute.units import wrap180

# ---------------------------------------------------------------------------
# pure kernels (radians, scaled variables; ``xp`` is numpy or a compatible module)
# ---------------------------------------------------------------------------


def drive(w: Any, beta: Any, c1: float, c2: float, k: float, xp: ModuleType = np) -> Any:
    """Scaled acceleration ``g(w, β) = dw/dτ`` of the segment model [1/m].

    Parameters
    ----------
    w : array
        Boat speed over true wind speed ``ṡ / v_t`` [-].
    beta : array
        True wind angle ``|TWA|`` [rad], in ``[0, π]``.
    c1, c2, k : float
        Model constants.
    xp : module
        Array module.

    Returns
    -------
    array
        ``(c1 β_a − c2)(w² + 2w cos β + 1) − k w²``; the physical acceleration
        is ``v_t² g`` [m s⁻²].
    """
    cb = xp.cos(beta)
    a2 = w * w + 2.0 * w * cb + 1.0
    beta_a = xp.arctan2(xp.sin(beta), cb + w)  # apparent wind angle off the bow, in [0, π]
    return (c1 * beta_a - c2) * a2 - k * w * w


def steady_w(beta: Any, c1: float, c2: float, k: float, xp: ModuleType = np) -> Any:
    """Scaled steady speed ``w_ss(β)`` [-]: the root of ``g(w, β) = 0`` (0 if none).

    Vectorised bisection on ``(0, w_hi]``; ``g`` has at most one positive root
    (checked for the default constants in ``tests/boat/test_dynamic.py``) and is
    negative for large ``w``.
    """
    beta = xp.asarray(beta, dtype=xp.float64)
    lo = xp.zeros_like(beta)
    hi = xp.full_like(beta, _w_upper(c1, c2, k))
    drives = drive(xp.zeros_like(beta), beta, c1, c2, k, xp) > 0
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        pos = drive(mid, beta, c1, c2, k, xp) > 0
        lo = xp.where(pos, mid, lo)
        hi = xp.where(pos, hi, mid)
    return xp.where(drives, 0.5 * (lo + hi), 0.0)


def _w_upper(c1: float, c2: float, k: float) -> float:
    """A scaled speed above which ``g < 0`` for every angle (by doubling)."""
    beta = np.linspace(0.0, np.pi, 721)
    w = 0.5
    while np.any(drive(np.full_like(beta, w), beta, c1, c2, k) >= 0):
        w *= 2.0
        if w > 1e6:  # pragma: no cover - guarded by DynamicBoat validation
            raise InputError("dynamic boat: k too small, the boat has no finite top speed")
    return w


def turn_factor(cos_delta: Any, um: float, lm: float, xp: ModuleType = np) -> Any:
    """Speed factor of a turn: 1 if ``cos δ ≥ Um``, ``cos⁴ δ`` if ``Lm < cos δ < Um``, else 0."""
    c2_ = cos_delta * cos_delta
    return xp.where(cos_delta >= um, 1.0, xp.where(cos_delta > lm, c2_ * c2_, 0.0))


# ---------------------------------------------------------------------------
# the boat
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class DynamicBoat:
    """Dębski's toy boat: segment dynamics with momentum carried between segments.

    Parameters
    ----------
    c1 : float
        Drive coefficient per radian of apparent wind angle [1/(m rad)].
    c2 : float
        Drive offset [1/m]; no drive below ``β_a = c2/c1`` [rad].
    k : float
        Quadratic resistance coefficient [1/m].
    um, lm : float
        Turn rule thresholds on ``cos δ`` (``0 ≤ lm < um ≤ 1``).
    name : str
        Label for reports.

    Notes
    -----
    The defaults are the paper's ``c1 = 0.03, c2 = 0.005, k = 0.7, Um = 0.98,
    Lm = 0.5`` (the mass cancels).  At TWS 12 m s⁻¹ the steady state gives the
    best upwind VMG 1.424 m s⁻¹ at TWA 41.65° (boat speed 1.906 m s⁻¹) and
    3.157 m s⁻¹ dead downwind (Wang et al. 2024).
    """

    c1: float = 0.03
    c2: float = 0.005
    k: float = 0.7
    um: float = 0.98
    lm: float = 0.5
    name: str = "Debski toy boat"

    def __post_init__(self) -> None:
        c1, c2, k = float(self.c1), float(self.c2), float(self.k)
        if not (np.isfinite(c1) and c1 > 0):
            raise InputError(f"dynamic boat: c1 must be > 0, got {self.c1!r}")
        if not (np.isfinite(c2) and 0 <= c2 < c1 * np.pi * 0.99):
            raise InputError(
                f"dynamic boat: c2 must be in [0, 0.99 π c1) so that the boat can drive "
                f"somewhere, got c2={self.c2!r} with c1={self.c1!r}"
            )
        if not (np.isfinite(k) and k > 0.05):
            raise InputError(f"dynamic boat: k must be > 0.05 (finite top speed), got {self.k!r}")
        if not (0.0 <= self.lm < self.um <= 1.0):
            raise InputError(
                f"dynamic boat: need 0 <= lm < um <= 1, got lm={self.lm!r}, um={self.um!r}"
            )

    # -- steady state ---------------------------------------------------------

    @property
    def no_drive_twa_deg(self) -> float:
        """TWA below which a boat at rest gets no drive, ``c2/c1`` [°]."""
        return float(np.degrees(self.c2 / self.c1))

    def acceleration(
        self, v_ms: ArrayLike, twa_deg: ArrayLike, tws_ms: ArrayLike
    ) -> NDArray[np.float64]:
        """Along-track acceleration ``s''`` [m s⁻²] at boat speed [m s⁻¹], TWA [°], TWS [m s⁻¹]."""
        v = np.asarray(v_ms, dtype=float)
        vt = np.asarray(tws_ms, dtype=float)
        beta = np.radians(np.abs(wrap180(twa_deg)))
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(vt > 0, v / np.where(vt > 0, vt, 1.0), 0.0)
        acc = vt * vt * drive(w, beta, self.c1, self.c2, self.k)
        return np.where(vt > 0, acc, -self.k * v * v)

    def steady_speed(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        """Steady boat speed [m s⁻¹] (``s'' = 0``) at TWS [m s⁻¹] and TWA [°] (broadcast)."""
        tws = np.asarray(tws_ms, dtype=float)
        beta = np.radians(np.abs(wrap180(twa_deg)))
        return tws * steady_w(beta, self.c1, self.c2, self.k)

    def best_vmg(self, upwind: bool = True, step_deg: float = 0.01) -> tuple[float, float]:
        """Best VMG angle [°] and VMG per unit TWS [-] (independent of TWS in this model)."""
        twa = np.arange(0.0, 180.0 + step_deg / 2, step_deg)
        w = steady_w(np.radians(twa), self.c1, self.c2, self.k)
        vmg = w * np.cos(np.radians(twa)) * (1.0 if upwind else -1.0)
        i = int(np.argmax(vmg))
        return float(twa[i]), float(vmg[i])

    def steady_polar(self, tws_ms_list: ArrayLike, twa_step: float = 1.0) -> Polar:
        """Steady-state polar of the model, for routers that use a :class:`Polar`.

        Parameters
        ----------
        tws_ms_list : array_like
            Increasing true wind speeds of the table columns [m s⁻¹].
        twa_step : float
            TWA spacing of the rows [°], from 0 to 180.

        Returns
        -------
        Polar
            Exact steady speeds at the nodes.  The steady speed is proportional to
            TWS, so interpolation between TWS columns is exact; between TWA rows
            it is linear (relative error ≈ 1e-4 at 1° steps).
        """
        tws = np.atleast_1d(np.asarray(tws_ms_list, dtype=float))
        if not (0.0 < twa_step <= 45.0):
            raise InputError(f"steady_polar: twa_step must be in (0, 45] degrees, got {twa_step}")
        n = int(np.ceil(180.0 / twa_step))
        twa = np.linspace(0.0, 180.0, n + 1)
        speed = self.steady_speed(tws[None, :], twa[:, None])
        return Polar.from_arrays(twa, tws, speed, name=f"{self.name} (steady state)")

    # -- the BoatModel protocol (sailroute.boat.model) --------------------------

    def vmg_angles_deg(self, tws_ms: float) -> tuple[float, float]:
        """Upwind and downwind best-VMG TWA [°] (:meth:`best_vmg` on a 0.05° grid; the
        angles do not depend on ``tws_ms`` in this model)."""
        return self.best_vmg(True, 0.05)[0], self.best_vmg(False, 0.05)[0]

    def routing_polar(self) -> None:
        """None: the speed depends on the speed carried in, so no steady polar stands
        for the boat (route :meth:`steady_polar` explicitly to ignore momentum)."""
        return None

    def dynamics(self) -> DynamicBoat:
        """The segment-dynamics model the grid routers carry momentum with: this boat."""
        return self

    # -- turns and segments ---------------------------------------------------

    def initial_speed(self, v_prev_ms: ArrayLike, cos_delta: ArrayLike) -> NDArray[np.float64]:
        """Entry speed [m s⁻¹] after a turn with ``cos δ`` from the previous end speed [m s⁻¹]."""
        v = np.asarray(v_prev_ms, dtype=float)
        return v * turn_factor(np.asarray(cos_delta, dtype=float), self.um, self.lm)

    def simulate(
        self,
        length_m: ArrayLike,
        twa_deg: ArrayLike,
        tws_ms: ArrayLike,
        v0_ms: ArrayLike = 0.0,
        *,
        dt_s: float = 0.01,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Reference RK4 simulation of straight segments in constant wind (vectorised).

        Parameters
        ----------
        length_m, twa_deg, tws_ms, v0_ms : array_like
            Segment length [m], TWA [°], TWS [m s⁻¹] and entry speed [m s⁻¹]
            (broadcast against each other).
        dt_s : float
            Time step [s]; the final partial step is resolved by cubic Hermite
            interpolation, so the error is O(dt⁴).

        Returns
        -------
        time_s, v_end_ms : ndarray
            Time to cover the segment [s] (``inf`` if the boat stops for good)
            and the speed at its end [m s⁻¹].
        """
        ell, twa, vt, v0 = np.broadcast_arrays(
            np.asarray(length_m, float),
            np.asarray(twa_deg, float),
            np.asarray(tws_ms, float),
            np.asarray(v0_ms, float),
        )
        beta = np.radians(np.abs(wrap180(twa)))
        calm = vt <= _CALM
        vts = np.where(calm, 1.0, vt)
        tau, w1 = simulate_pieces(
            self,
            beta[..., None],
            np.ones_like(beta)[..., None],
            ell[..., None],
            v0 / vts,
            h_tau=dt_s * vts,
        )
        t = np.where(calm, np.where(ell > 0, np.inf, 0.0), tau / vts)
        return t, np.where(calm, v0, w1 * vts)

    def segment(
        self,
        length_m: ArrayLike,
        twa_deg: ArrayLike,
        tws_ms: ArrayLike,
        v0_ms: ArrayLike = 0.0,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Fast segment time and end speed (table lookup, RK4 where the transient is long).

        Same parameters and returns as :meth:`simulate`; agrees with a fine RK4
        reference to ~1e-4 s for the default constants (see the design note).
        """
        ell, twa, vt, v0 = np.broadcast_arrays(
            np.asarray(length_m, float),
            np.asarray(twa_deg, float),
            np.asarray(tws_ms, float),
            np.asarray(v0_ms, float),
        )
        shape = ell.shape
        beta = np.radians(np.abs(wrap180(twa))).reshape(-1, 1)
        t, v1 = chain_time(
            self,
            beta,
            vt.reshape(-1, 1),
            ell.reshape(-1, 1),
            np.ones_like(beta),
            v0.reshape(-1),
        )
        return t.reshape(shape), v1.reshape(shape)

    def table(self) -> SegmentTable:
        """The (cached) segment lookup table of this boat."""
        return _table_for(self.c1, self.c2, self.k)


_EPS_CONV = 1e-3  # relative speed deviation at which a transient counts as over
_CALM = 1e-6  # true wind speeds at or below this [m s⁻¹] count as calm (boat cannot sail)


# ---------------------------------------------------------------------------
# lookup table
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class SegmentTable:
    """Tabulated steady speed and transient time loss of a :class:`DynamicBoat`.

    Attributes
    ----------
    c1, c2, k : float
        Model constants the table was built for.
    beta_min : float
        No-drive angle ``c2/c1`` [rad].
    beta_lo : float
        First tabulated angle [rad] (``beta_min`` + 1°).  In ``[beta_min, beta_lo)``
        a segment takes its steady-state time (the transient is ignored: these
        angles are far too slow to be optimal).
    dbeta : float
        Angle spacing [rad].
    nq : int
        Points per branch on the speed axis.
    w_max : float
        Largest tabulated scaled entry speed [-].
    w_ss : ndarray, shape (nb,)
        Scaled steady speed per angle.
    loss : ndarray, shape (nb, 2 nq - 1)
        ``Λ`` [m of τ] on the combined speed axis: index ``i < nq`` is
        ``w0 = w_ss i/(nq-1)`` (accelerating branch), ``i ≥ nq-1`` is
        ``w0 = w_ss + (w_max - w_ss)(i-nq+1)/(nq-1)`` (decelerating branch).
    dloss0, dloss1 : ndarray, shape (nb, 2 nq - 2)
        Derivative of ``Λ`` along that index axis at the left and right end of
        each interval (exact, ``dΛ/dw0 = -(w_ss - w0)/(w_ss g)``), for cubic
        Hermite interpolation.
    relax : ndarray, shape (nb,)
        Relaxation length ``w_ss / γ`` [m]: near the fixed point the speed
        deviation decays as ``exp(-s / relax)``.
    sconv : ndarray, shape (nb,)
        Upper bound of the distance [m] needed from any tabulated entry speed
        to come within ``1e-3`` (relative) of the steady speed.
    dist : ndarray, shape (nb, 2 nq - 1)
        Distance [m] from the entry speed to within 5 % of the steady speed, on
        the speed axis of ``loss`` (bounding the fine-grid values).
    stop_max : float
        Upper bound of the coasting distance [m] inside the no-drive zone from
        ``w_max``; longer no-drive pieces are infeasible.
    """

    c1: float
    c2: float
    k: float
    beta_min: float
    beta_lo: float
    dbeta: float
    nq: int
    w_max: float
    w_ss: NDArray[np.float64]
    loss: NDArray[np.float64]
    dloss0: NDArray[np.float64]
    dloss1: NDArray[np.float64]
    relax: NDArray[np.float64]
    sconv: NDArray[np.float64]
    dist: NDArray[np.float64]
    stop_max: float
    _xp_cache: dict = field(default_factory=dict, repr=False)

    @property
    def n_beta(self) -> int:
        """Number of tabulated angles."""
        return int(self.w_ss.size)

    def arrays(self, xp: ModuleType) -> tuple[Any, ...]:
        """``(w_ss, loss, sconv, relax, dloss0, dloss1, dist)`` as ``xp`` arrays (cached)."""
        key = xp.__name__
        if key not in self._xp_cache:
            self._xp_cache[key] = tuple(
                xp.asarray(a)
                for a in (
                    self.w_ss,
                    self.loss,
                    self.sconv,
                    self.relax,
                    self.dloss0,
                    self.dloss1,
                    self.dist,
                )
            )
        return self._xp_cache[key]

    def column(self, beta: Any, xp: ModuleType = np) -> tuple[Any, Any]:
        """Lower column index and weight of angles ``beta`` [rad] (clipped to the table)."""
        jf = (beta - self.beta_lo) / self.dbeta
        jf = xp.clip(jf, 0.0, self.n_beta - 1.0 - 1e-9)
        j0 = xp.floor(jf).astype(xp.int64)
        return j0, jf - j0

    def steady(self, beta: Any, xp: ModuleType = np) -> Any:
        """Scaled steady speed at ``beta`` [rad] (0 in the no-drive zone).

        Interpolated from the table, then polished by two Newton steps (derivative by
        a forward difference of ``1e-7``).
        """
        w_ss = self.arrays(xp)[0]
        j0, fb = self.column(beta, xp)
        ws = (1.0 - fb) * w_ss[j0] + fb * w_ss[j0 + 1]
        # two Newton steps from the interpolated value make it exact to rounding
        for _ in range(2):
            h = 1e-7
            g0 = drive(ws, beta, self.c1, self.c2, self.k, xp)
            g1 = drive(ws + h, beta, self.c1, self.c2, self.k, xp)
            ws = ws - g0 * h / xp.where(g1 != g0, g1 - g0, -1.0)
        slow = (beta < self.beta_lo) & (beta >= self.beta_min)
        if bool(xp.any(slow)):
            idx = xp.nonzero(slow)
            ws = ws + 0.0  # own copy
            ws[idx] = steady_w(beta[idx], self.c1, self.c2, self.k, xp)
        return xp.where(beta < self.beta_min, 0.0, ws)

    def speed_index(self, w0: Any, w_ss: Any, xp: ModuleType = np) -> Any:
        """Fractional index of entry speeds ``w0`` on the combined speed axis."""
        m = self.nq - 1
        safe = xp.where(w_ss > 0, w_ss, 1.0)
        acc = w0 / safe * m
        dec = m + (w0 - w_ss) / (self.w_max - w_ss) * m
        return xp.where(w0 <= w_ss, acc, dec)

    def loss_at(self, beta: Any, w0: Any, w_ss: Any, xp: ModuleType = np) -> Any:
        """``Λ(β, w0)`` [m]: cubic Hermite in ``w0``, linear in ``β`` (``w0`` clipped)."""
        _, loss, _, _, d0, d1, _ = self.arrays(xp)
        j0, fb = self.column(beta, xp)
        x = xp.clip(self.speed_index(w0, w_ss, xp), 0.0, 2.0 * (self.nq - 1) - 1e-9)
        i0 = xp.floor(x).astype(xp.int64)
        fx = x - i0
        nv, nd = loss.shape[1], d0.shape[1]
        lv, l0, l1 = loss.reshape(-1), d0.reshape(-1), d1.reshape(-1)
        bv, bd = j0 * nv + i0, j0 * nd + i0
        lo = hermite(lv[bv], lv[bv + 1], l0[bd], l1[bd], fx)
        hi = hermite(lv[bv + nv], lv[bv + nv + 1], l0[bd + nd], l1[bd + nd], fx)
        return (1.0 - fb) * lo + fb * hi

    def poly(self, xp: ModuleType = np) -> Any:
        """Cubic coefficients of ``Λ`` per (angle, speed interval), shape ``(nb (2nq-2), 4)``.

        Row ``j (2nq-2) + i`` holds ``(c0, c1, c2, c3)`` with
        ``Λ = c0 + f (c1 + f (c2 + f c3))`` at fraction ``f`` of interval ``i`` of
        column ``j`` (the Hermite cubic of :meth:`loss_at` in power form).
        """
        key = ("poly", xp.__name__)
        if key not in self._xp_cache:
            y0, y1 = self.loss[:, :-1], self.loss[:, 1:]
            c = np.stack(hermite_coefficients(y0, y1, self.dloss0, self.dloss1), axis=-1).reshape(
                -1, 4
            )
            self._xp_cache[key] = xp.asarray(np.ascontiguousarray(c))
        return self._xp_cache[key]

    def relax_at(self, beta: Any, xp: ModuleType = np) -> Any:
        """Relaxation length [m] at ``beta`` (linear in the table's angles)."""
        relax = self.arrays(xp)[3]
        j0, fb = self.column(beta, xp)
        return (1.0 - fb) * relax[j0] + fb * relax[j0 + 1]

    def sconv_at(self, beta: Any, xp: ModuleType = np) -> Any:
        """Transient length bound [m] at ``beta`` (max of the two neighbouring columns)."""
        sconv = self.arrays(xp)[2]
        j0, _ = self.column(beta, xp)
        return xp.maximum(sconv[j0], sconv[j0 + 1])

    def transient_length(self, beta: Any, w0: Any, w_ss: Any, xp: ModuleType = np) -> Any:
        """Distance [m] after which a piece entered at ``w0`` is within ``1e-3`` of steady.

        ``1.25 ×`` the tabulated distance to within 5 % (:attr:`dist`, bilinear),
        then the exponential tail ``relax · ln(min(d, 0.05) / 1e-3)`` (``d`` the
        relative deviation at entry).
        """
        relax, dist = self.arrays(xp)[3], self.arrays(xp)[6]
        j0, fb = self.column(beta, xp)
        lam = xp.maximum(relax[j0], relax[j0 + 1])
        d = xp.abs(w0 / xp.where(w_ss > 0, w_ss, 1.0) - 1.0)
        tail = lam * xp.log(xp.clip(d, _EPS_CONV, 0.05) / _EPS_CONV)
        x = xp.clip(self.speed_index(w0, w_ss, xp), 0.0, 2.0 * (self.nq - 1) - 1e-9)
        i0 = xp.floor(x).astype(xp.int64)
        fx = x - i0
        ncol = dist.shape[1]
        flat = dist.reshape(-1)
        base = j0 * ncol + i0
        lo = (1.0 - fx) * flat[base] + fx * flat[base + 1]
        hi = (1.0 - fx) * flat[base + ncol] + fx * flat[base + ncol + 1]
        far = xp.where(d > 0.05, 1.25 * ((1.0 - fb) * lo + fb * hi), 0.0)
        return far + tail


@lru_cache(maxsize=8)
def _table_for(c1: float, c2: float, k: float) -> SegmentTable:
    return build_table(c1, c2, k)


def build_table(
    c1: float,
    c2: float,
    k: float,
    *,
    dbeta_deg: float = 0.1,
    nq: int = 129,
    nfine: int = 513,
    w_max: float = 2.0,
    margin_deg: float = 1.0,
) -> SegmentTable:
    """Tabulate ``w_ss(β)``, ``Λ(β, w0)`` and the transient length for one set of constants.

    ``Λ`` is integrated with the cumulative Simpson rule on ``nfine`` points per
    branch and column (the integrand is smooth: against 4097 points the largest
    difference is 2e-7 of the largest ``Λ`` for the default constants) and
    subsampled to ``nq`` points; the transient lengths and the no-drive coasting
    distance use the trapezoidal rule.
    Takes well under a second; cached per constants by :meth:`DynamicBoat.table`.
    """
    if (nfine - 1) % (nq - 1):
        raise ValueError("nfine - 1 must be a multiple of nq - 1")
    beta_min = c2 / c1
    beta_lo = beta_min + np.radians(margin_deg)
    nb = int(np.ceil((np.pi - beta_lo) / np.radians(dbeta_deg))) + 1
    beta = np.linspace(beta_lo, np.pi, nb)
    dbeta = float(beta[1] - beta[0])
    wss = steady_w(beta, c1, c2, k)
    eps_w = 1e-6 * np.maximum(wss, 1e-3)
    gamma = -(drive(wss + eps_w, beta, c1, c2, k) - drive(wss - eps_w, beta, c1, c2, k)) / (
        2 * eps_w
    )
    frac = np.linspace(0.0, 1.0, nfine)
    step = (nfine - 1) // (nq - 1)

    def branch(w: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Λ, its integrand h, the convergence length and the distance to 5 % of w_ss."""
        # w: (nb, nfine) ordered away from the fixed point (w[:, 0] == w_ss)
        g = drive(w, beta[:, None], c1, c2, k)
        dw = w - wss[:, None]
        near = np.abs(dw) <= 1e-9 * np.maximum(wss[:, None], 1e-3)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.where(near, 1.0 / (wss * gamma)[:, None], -dw / (wss[:, None] * g))
        # Λ(w) = ∫_w^{w_ss} h = -∫_{w_ss}^{w} h
        dw_dfrac = (w[:, -1] - w[:, 0])[:, None]  # w is linear in frac
        lam = -cumulative_simpson(h, x=frac, axis=1, initial=0.0) * dw_dfrac
        # transient length: ∫ w/g from w to 5 % of the fixed point (times 1.25), then
        # the exponential tail from 5 % to 1e-3 at rate γ/w_ss per metre
        delta = 0.05
        far = np.abs(dw) >= delta * wss[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            q = np.where(far, np.abs(w / g), 0.0)
        sq = 0.5 * (q[:, 1:] + q[:, :-1]) * np.abs(np.diff(w, axis=1))
        dist = np.concatenate([np.zeros((nb, 1)), np.cumsum(sq, axis=1)], axis=1)
        tail = wss / gamma * np.log(delta / _EPS_CONV)
        sconv = 1.25 * dist[:, -1] + tail
        return lam, h, sconv, dist

    # accelerating branch ordered from w_ss down to 0, decelerating from w_ss up to w_max
    w_acc = wss[:, None] * (1.0 - frac)[None, :]
    w_dec = wss[:, None] + (w_max - wss)[:, None] * frac[None, :]
    lam_acc, h_acc, s_acc, dist_acc = branch(w_acc)
    lam_dec, h_dec, s_dec, dist_dec = branch(w_dec)
    loss = np.concatenate([lam_acc[:, ::step][:, ::-1], lam_dec[:, ::step][:, 1:]], axis=1)
    sconv = np.maximum(s_acc, s_dec)

    # distance to come within 5 % of w_ss; the max over each node's two neighbouring
    # fine intervals keeps linear interpolation an upper bound
    def coarse(d: NDArray) -> NDArray:
        up = np.concatenate([d[:, 1:], d[:, -1:]], axis=1)
        return np.maximum(d, up)[:, ::step]

    dist = np.concatenate([coarse(dist_acc)[:, ::-1], coarse(dist_dec)[:, 1:]], axis=1)
    # dΛ/dx on the index axis x (dΛ/dw0 = -h), one-sided at the junction x = nq - 1
    m = nq - 1
    der_acc = -h_acc[:, ::step][:, ::-1] * (wss / m)[:, None]  # nodes 0..m
    der_dec = -h_dec[:, ::step] * ((w_max - wss) / m)[:, None]  # nodes m..2m
    dloss0 = np.concatenate([der_acc[:, :-1], der_dec[:, :-1]], axis=1)  # left end of interval
    dloss1 = np.concatenate([der_acc[:, 1:], der_dec[:, 1:]], axis=1)  # right end of interval

    # no-drive zone: coasting distance from w_max down to 0, ∫ w/|g| dw, max over angles
    bz = np.linspace(0.0, beta_min, 65)
    wz = np.linspace(0.0, w_max, 4097)
    gz = drive(wz[None, :], bz[:, None], c1, c2, k)
    with np.errstate(divide="ignore", invalid="ignore"):
        qz = np.where(gz < 0, wz[None, :] / -gz, np.inf)
    qz[:, 0] = 0.0
    stop = np.sum(0.5 * (qz[:, 1:] + qz[:, :-1]) * np.diff(wz), axis=1)
    stop_max = float(np.nanmax(np.where(np.isfinite(stop), stop, np.nan))) * 1.25
    if not np.isfinite(stop_max):
        stop_max = np.inf
    return SegmentTable(
        c1=c1,
        c2=c2,
        k=k,
        beta_min=beta_min,
        beta_lo=float(beta_lo),
        dbeta=dbeta,
        nq=nq,
        w_max=w_max,
        w_ss=wss,
        loss=loss,
        dloss0=dloss0,
        dloss1=dloss1,
        relax=wss / gamma,
        sconv=sconv,
        dist=dist,
        stop_max=stop_max,
    )


# ---------------------------------------------------------------------------
# chains of constant-wind pieces
# ---------------------------------------------------------------------------


def chain_time(
    boat: DynamicBoat,
    beta: Any,
    vt: Any,
    length: Any,
    cos_turn: Any,
    v_in: Any,
    xp: ModuleType = np,
    *,
    pieces: bool = False,
) -> tuple[Any, ...]:
    """Time and end speed along chains of straight constant-wind pieces.

    Parameters
    ----------
    boat : DynamicBoat
        Model.
    beta, vt, length, cos_turn : array, shape (..., n)
        Per piece: |TWA| [rad], TWS [m s⁻¹], length [m], cosine of the turn
        from the previous piece (the first entry is the turn into the chain).
    v_in : array, shape (...)
        Speed before the first turn [m s⁻¹].
    xp : module
        Array module.
    pieces : bool
        Also return per-piece times and entry speeds.

    Returns
    -------
    time_s, v_end : array, shape (...)
        Total time [s] (``inf`` where infeasible) and the exit speed [m s⁻¹].
    t_piece, v_entry : array, shape (..., n)
        Only with ``pieces=True``: time of each piece [s] (the transient's
        loss is booked on the piece where it starts) and the speed entering
        each piece after its turn [m s⁻¹].

    Notes
    -----
    A piece takes ``(ℓ/w_ss + Λ(β, w0)) / v_t`` and leaves at the steady
    speed; this is exact once the transient is over.  A transient may run on
    into the following pieces: that is exact in uniform wind and second order
    otherwise, but it must be over (speed within 1e-3 of steady, a time error
    ≲ ``1e-3 / (γ v_t)`` ≈ 2e-3 s at worst) by the chain's end.  Chains where it
    is not (too short for the entry speed), with an entry speed above the
    table, or with a short coast through the no-drive zone are integrated with
    RK4 in a distance-like variable instead.
    """
    tab = boat.table()
    n = beta.shape[-1]
    lead = beta.shape[:-1]
    v_start = xp.asarray(v_in, dtype=xp.float64) + xp.zeros(lead)
    v = v_start
    total = xp.zeros(lead)
    exact = xp.zeros(lead, dtype=bool)
    need = xp.zeros(lead)
    t_list, v_list = [], []
    for j in range(n):
        b, u, ell = beta[..., j], vt[..., j], length[..., j]
        v = v * turn_factor(cos_turn[..., j], boat.um, boat.lm, xp)
        v_list.append(v)
        calm = u <= _CALM
        us = xp.where(calm, 1.0, u)
        w0 = v / us
        ws = tab.steady(b, xp)
        nogo = b < tab.beta_min
        slow = (b < tab.beta_lo) & ~nogo
        lam = tab.loss_at(b, w0, ws, xp)
        wsafe = xp.where(ws > 0, ws, 1.0)
        tpiece = xp.where(slow, ell / wsafe, ell / wsafe + lam) / us
        tpiece = xp.where(nogo | calm, xp.inf, tpiece)
        tpiece = xp.where(ell <= 0, 0.0, tpiece)
        req = tab.transient_length(b, w0, ws, xp)
        need = xp.where((ell > 0) & ~nogo & ~slow, xp.maximum(need, req), need) - ell
        coast = nogo & (ell < tab.stop_max) & (v > 0) & ~calm
        exact = exact | (((w0 > tab.w_max) | coast) & (ell > 0) & ~calm)
        total = total + tpiece
        t_list.append(tpiece)
        v = xp.where(ell <= 0, v, ws * u)
    exact = exact | ((need > 0) & xp.isfinite(total))
    t_pieces = xp.stack(t_list, axis=-1) if pieces else None
    if bool(xp.any(exact)):
        idx = xp.nonzero(exact)
        t_ex, v_ex, tp_ex = _exact_chain(
            boat, beta[idx], vt[idx], length[idx], cos_turn[idx], v_start[idx], xp
        )
        total[idx] = t_ex
        v[idx] = v_ex
        if t_pieces is not None:  # pieces
            t_pieces[idx] = tp_ex
    if pieces:
        return total, v, t_pieces, xp.stack(v_list, axis=-1)
    return total, v


def _exact_chain(
    boat: DynamicBoat, beta: Any, vt: Any, length: Any, cos_turn: Any, v_in: Any, xp: ModuleType
) -> tuple[Any, Any, Any]:
    """RK4 version of :func:`chain_time` for a flat batch ``(m, n)`` (runs on the host).

    Pieces in ``[beta_min, beta_lo)`` keep the table's steady-state treatment.
    """
    from sailroute.backend import to_numpy

    tab = boat.table()
    b, u, ell, c, v0 = (to_numpy(a) for a in (beta, vt, length, cos_turn, v_in))
    total = np.zeros(b.shape[0])
    tp = np.zeros(b.shape)
    v = v0.astype(float).copy()
    for j in range(b.shape[1]):
        v = v * turn_factor(c[:, j], boat.um, boat.lm)
        calm = u[:, j] <= _CALM
        us = np.where(calm, 1.0, u[:, j])
        bj, lj = b[:, j], ell[:, j]
        slow = (bj >= tab.beta_min) & (bj < tab.beta_lo)
        ws = tab.steady(bj)
        w0 = v / us
        # pieces that hold their whole transient use the table, the others RK4
        table = (
            ~slow
            & (bj >= tab.beta_lo)
            & (w0 <= tab.w_max)
            & (lj >= tab.transient_length(bj, w0, ws))
        )
        sim = ~(slow | table) & (lj > 0)
        wsafe = np.where(ws > 0, ws, 1.0)
        tau = np.where(slow, lj / wsafe, lj / wsafe + tab.loss_at(bj, w0, ws))
        w1 = ws.copy()
        if sim.any():
            i = np.flatnonzero(sim)

            def finish(
                k_: NDArray,
                s_: NDArray,
                w_: NDArray,
                _b: NDArray = bj[i],
                _w: NDArray = ws[i],
                _l: NDArray = lj[i],
            ) -> tuple:
                bb, ww, rem = _b[k_], _w[k_], _l[k_] - s_
                ok = (
                    (bb >= tab.beta_lo)
                    & (w_ <= tab.w_max)
                    & (rem >= tab.transient_length(bb, w_, ww))
                )
                return ok, rem / np.where(ww > 0, ww, 1.0) + tab.loss_at(bb, w_, ww), ww

            # step ≈ a quarter of the relaxation length in σ, at least _H_SIGMA
            gam = np.where(ws[i] > 0, ws[i] / tab.relax_at(bj[i]), np.inf)
            h_i = np.clip(0.25 * _OMEGA / gam, _H_SIGMA, 20.0 * _H_SIGMA)
            tau_s, w_s = _rk4_piece_sigma(
                bj[i], lj[i], w0[i], h_i, _OMEGA, boat.c1, boat.c2, boat.k, 200_000, finish
            )
            tau[i] = tau_s
            w1[i] = w_s
        t = np.where(calm, np.where(ell[:, j] > 0, np.inf, 0.0), tau / us)
        tp[:, j] = t
        total = total + t
        v = np.where(calm, v, w1 * us)
    return xp.asarray(total), xp.asarray(v), xp.asarray(tp)


_H_SIGMA = 0.5  # smallest fallback RK4 step in σ [m] (error < 3e-5 s vs a fine τ-reference)
_OMEGA = 0.5  # [-]: σ = ∫ (w + ω) dτ, regular from rest
_W_STUCK = 1e-3  # scaled speed below which a decelerating boat counts as stopped
_A_RATE = 0.1  # adaptive RK4: largest relative change of (w + ω) per step
_B_RELAX = 0.1  # adaptive RK4: largest step in local relaxation lengths


def _rk4_piece_sigma(
    beta: NDArray,
    ell: NDArray,
    w0: NDArray,
    h: ArrayLike,
    omega: float,
    c1: float,
    c2: float,
    k: float,
    max_steps: int,
    finish: Callable[[NDArray, NDArray, NDArray], tuple] | None = None,
) -> tuple[NDArray, NDArray]:
    """RK4 over one constant-wind piece in ``σ`` with ``dσ = (w + ω) dτ``.

    The state ``(s, w, τ)`` has ``ds/dσ = w/(w+ω)``, ``dw/dσ = g/(w+ω)``,
    ``dτ/dσ = 1/(w+ω)``: steps are ≈ ``h`` metres of track once the boat
    moves, and regular at rest.  Returns ``(τ, w)`` at ``s = ell`` (``inf``
    if the boat stops for good); the last step is resolved by cubic Hermite
    interpolation.  ``finish(items, s, w) -> (ok, τ_rest, w_end)`` may end
    items early (when the rest of the piece holds the rest of the transient).
    """
    n = beta.size
    w_ss = steady_w(beta, c1, c2, k)
    h_all = np.broadcast_to(np.asarray(h, float), (n,))
    y, out_tau, out_w, act = _piece_start(n, w0, ell, 3)  # s, w, tau

    def f(yv: NDArray, bv: NDArray) -> NDArray:
        wv = np.maximum(yv[1], 0.0)
        inv = 1.0 / (wv + omega)
        return np.stack([wv * inv, drive(wv, bv, c1, c2, k) * inv, inv])

    def step(act: NDArray[np.int64]) -> NDArray[np.bool_]:
        bv, yv = beta[act], y[:, act]
        k1 = f(yv, bv)
        # adaptive: at most 10 % change of (w + ω) and a tenth of the local
        # relaxation length (w + ω)/|∂g/∂w| per step; never below the given step
        wp = np.maximum(yv[1], 0.0) + omega
        gw = (
            np.abs(
                drive(np.maximum(yv[1], 0.0) + 1e-6, bv, c1, c2, k)
                - drive(np.maximum(yv[1], 0.0), bv, c1, c2, k)
            )
            * 1e6
        )
        lim = np.minimum(
            _A_RATE * wp / np.maximum(np.abs(k1[1]), 1e-300), _B_RELAX * wp / np.maximum(gw, 1e-300)
        )
        hs = np.clip(lim, h_all[act], 40.0 * h_all[act])  # this step's h per item
        yn, _ = rk4_step(f, yv, hs, k1, args=(bv,))
        # stopped for good: (nearly) at rest and decelerating (a no-drive coast
        # that has run out; at w < 1e-3 it would crawl for ages before stopping)
        stopped = (yn[1] <= _W_STUCK) & (drive(np.maximum(yn[1], 0.0), bv, c1, c2, k) <= 0.0)
        yn[1] = np.maximum(yn[1], 0.0)
        cross = yn[0] >= ell[act]
        if cross.any():
            i = act[cross]
            f1 = f(yn[:, cross], bv[cross])
            hh = hs[cross]
            th = hermite_crossing(yv[0, cross], yn[0, cross], k1[0, cross], f1[0], hh, ell[i])
            out_tau[i] = hermite(yv[2, cross], yn[2, cross], k1[2, cross], f1[2], th, hh)
            out_w[i] = hermite(yv[1, cross], yn[1, cross], k1[1, cross], f1[1], th, hh)
        dead = stopped & ~cross
        if dead.any():
            out_tau[act[dead]] = np.inf
        # at the steady speed (to 1e-6) the rest of the piece is sailed at that speed
        wt = w_ss[act]
        steady = ~(cross | dead) & (wt > 0) & (np.abs(yn[1] - wt) <= 1e-6 * wt)
        if steady.any():
            i = act[steady]
            out_tau[i] = yn[2, steady] + (ell[i] - yn[0, steady]) / yn[1, steady]
            out_w[i] = yn[1, steady]
        done = cross | dead | steady
        if finish is not None and (~done).any():
            cand = np.flatnonzero(~done)
            ok, tau_rest, w_end = finish(act[cand], yn[0, cand], yn[1, cand])
            if ok.any():
                i = act[cand[ok]]
                out_tau[i] = yn[2, cand[ok]] + tau_rest[ok]
                out_w[i] = w_end[ok]
                done[cand[ok]] = True
        y[:, act] = yn
        return done

    _march_piece(step, act, max_steps, y, y[2], ell, (out_tau, out_w))
    return out_tau, out_w


def simulate_pieces(
    boat: DynamicBoat,
    beta: NDArray,
    vt_scale: NDArray,
    length: NDArray,
    w0: ArrayLike,
    *,
    h_tau: ArrayLike = 0.02,
    max_steps: int = 2_000_000,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """RK4 integration of the scaled model over chains of constant-wind pieces (host numpy).

    Parameters
    ----------
    boat : DynamicBoat
        Model.
    beta : ndarray, shape (..., n)
        |TWA| per piece [rad].
    vt_scale : ndarray, shape (..., n)
        TWS per piece relative to the first piece's [-] (1 for a single piece).
    length : ndarray, shape (..., n)
        Piece lengths [m].
    w0 : array_like, shape (...)
        Entry speed over the first piece's TWS [-].
    h_tau : array_like, shape (...)
        RK4 step in ``τ = v_t t`` [m] (``dt_s · v_t``).
    max_steps : int
        Safety cap; an item still running then finishes at its current speed.

    Returns
    -------
    tau, w_end : ndarray, shape (...)
        Scaled time ``v_t t`` [m] (``inf`` if the boat stops for good) and exit
        speed over the first piece's TWS.
    """
    c1, c2, k = boat.c1, boat.c2, boat.k
    beta = np.asarray(beta, float)
    shape = beta.shape[:-1]
    b = beta.reshape(-1, beta.shape[-1])
    sc = np.broadcast_to(np.asarray(vt_scale, float), beta.shape).reshape(b.shape)
    ell = np.broadcast_to(np.asarray(length, float), beta.shape).reshape(b.shape)
    w_first = np.broadcast_to(np.asarray(w0, float), shape).reshape(-1).copy()
    h_all = np.broadcast_to(np.asarray(h_tau, float), shape).reshape(-1)
    tau_tot = np.zeros(b.shape[0])
    w_cur = w_first  # scaled by the first piece's TWS
    for j in range(b.shape[1]):
        s_j = sc[:, j]
        # integrate in the piece's own scaling: w' = w s_first / s_j, τ' = τ s_j
        wj = w_cur / s_j
        tau_j, w_end = _rk4_piece(b[:, j], ell[:, j], wj, h_all * s_j, c1, c2, k, max_steps)
        tau_tot = tau_tot + tau_j / s_j
        w_cur = w_end * s_j
    return tau_tot.reshape(shape), w_cur.reshape(shape)


def _rk4_piece(
    beta: NDArray,
    ell: NDArray,
    w0: NDArray,
    h: NDArray,
    c1: float,
    c2: float,
    k: float,
    max_steps: int,
) -> tuple[NDArray, NDArray]:
    n = beta.size
    tau = np.zeros(n)
    y, out_tau, out_w, act = _piece_start(n, w0, ell, 2)  # s, w

    def f(wv: NDArray, bv: NDArray) -> NDArray:
        return drive(np.maximum(wv, 0.0), bv, c1, c2, k)

    def rhs(yv: NDArray, bv: NDArray) -> NDArray:
        """``d(s, w)/dτ = (w, g(max(w, 0)))``: ``s`` rides on ``w``'s stages."""
        dy = np.empty_like(yv)  # cheaper than np.stack on these short rows (per step)
        dy[0] = yv[1]
        dy[1] = f(yv[1], bv)
        return dy

    no_drive = f(np.zeros_like(beta), beta) <= 0.0  # a boat at rest stays at rest

    def step(act: NDArray[np.int64]) -> NDArray[np.bool_]:
        bv, yv, hv = beta[act], y[:, act], h[act]
        y_new, k1 = rk4_step(rhs, yv, hv, args=(bv,))
        s_new = y_new[0]
        stopped = (y_new[1] <= 0.0) & no_drive[act]
        w_new = y_new[1] = np.maximum(y_new[1], 0.0)
        cross = s_new >= ell[act]
        if cross.any():
            i = act[cross]
            sv, wv = yv[0, cross], yv[1, cross]
            th = hermite_crossing(sv, s_new[cross], wv, w_new[cross], hv[cross], ell[i])
            g1 = f(w_new[cross], bv[cross])
            out_tau[i] = tau[i] + th * hv[cross]
            out_w[i] = hermite(wv, w_new[cross], k1[1, cross], g1, th, hv[cross])
        dead = stopped & ~cross
        if dead.any():
            out_tau[act[dead]] = np.inf
            out_w[act[dead]] = 0.0
        tau[act] = tau[act] + hv
        y[:, act] = y_new
        return cross | dead

    _march_piece(step, act, max_steps, y, tau, ell, (out_tau, out_w))
    return out_tau, out_w


def _piece_start(
    n: int, w0: ArrayLike, ell: NDArray, n_state: int
) -> tuple[NDArray, NDArray, NDArray, NDArray[np.int64]]:
    """Start of an RK4 piece of ``n`` items: the state ``(n_state, n)`` (``s = 0``, ``w``
    the entry speed clipped at 0, the rest 0), the scaled time and exit speed (0 and the
    entry speed for an empty piece, ``inf`` and 0 until known), the items to integrate."""
    y = np.zeros((n_state, n))
    y[1] = np.maximum(np.asarray(w0, float), 0.0)
    out_tau = np.full(n, np.inf)
    out_w = np.zeros(n)
    done0 = ell <= 0
    out_tau[done0] = 0.0
    out_w[done0] = y[1, done0]
    return y, out_tau, out_w, np.flatnonzero(~done0)


def _march_piece(
    step: Callable[[NDArray[np.int64]], NDArray[np.bool_]],
    act: NDArray[np.int64],
    max_steps: int,
    y: NDArray,
    tau: NDArray,
    ell: NDArray,
    out: tuple[NDArray, NDArray],
) -> None:
    """The RK4 loop over a constant-wind piece: ``step(items) -> done`` advances the active
    items one step (the state ``y`` = ``(s, w, ...)`` and scaled time ``tau`` [m]; the
    results ``out = (τ, w_end)`` of the items it ends) until none is left.  After
    ``max_steps`` steps the items still running finish at their current (near steady)
    speed."""
    steps = 0
    while act.size and steps < max_steps:
        steps += 1
        act = act[~step(act)]
    if act.size:  # cap reached: finish at the current speed
        out_tau, out_w = out
        ws = np.maximum(y[1, act], 1e-300)
        out_tau[act] = tau[act] + (ell[act] - y[0, act]) / ws
        out_w[act] = y[1, act]
