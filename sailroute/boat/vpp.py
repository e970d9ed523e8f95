"""Velocity-prediction program (VPP) for the Laser/ILCA, after the thesis's §2 and §4.2-4.3.

Steady state, per (TWS, TWA): the boat speed V is the largest speed at which
the best sail setting still balances the resistance,

* surge: ``X_sail(V; f, t) - R_hull(V) - R_induced(V, Y) = 0`` (thesis eqs 2.5,
  2.12, 2.24),
* side force: the foils carry the sail side force ``Y`` (eq 2.6), which costs
  the induced resistance ``Y² / (½ ρw V² π T_eff²)``,
* heel (eq 2.8, 2.29-2.32): heeling moment ``Y · (z_CE(f, t) + z_CLR)`` equals
  the crew righting moment ``y_c m_c g (B/2 + e)`` with the crew position
  ``y_c ∈ [-1, 1]``; the boat is sailed flat (heel 0).  When ``y_c`` would
  exceed 1 the sail is depowered.

Controls: ``flat`` f ∈ [flat_min, 1] scales the lift (ORC "flat") and
``twist`` t ∈ [0, 1] adds induced drag (thesis eq 4.4, C_twist) but lowers the
centre of effort.  They are chosen to maximise the speed.

Algorithm (all vectorised over points, deterministic, no failure modes):

1. ``g(V) = max_{f,t feasible} [X - R]`` at fixed V has closed-form forces, so
   the inner problem is a golden-section search over f (t = 0) and, where the
   moment limit binds, a golden-section search over t with f on the moment
   limit found by safeguarded Newton iterations (a bisection step wherever the
   Newton step leaves the bracket).
2. ``g`` is scanned on a speed grid; the speed is the largest root, refined by
   the Illinois (regula-falsi) method to 1e-10 m s⁻¹.  No root means no
   steady sailing (speed 0: the no-go zone).

Pure building blocks (:func:`apparent_wind`, :func:`sail_coefficients`,
:func:`ittc57_cf`, :func:`friction_resistance`, :func:`residuary_resistance`,
:func:`induced_resistance`, :func:`crew_righting_moment`, ...) are public and
documented with their equations in ``docs/vpp.md``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache, lru_cache
from importlib import resources
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator

from sailroute.boat.laser import LaserParams, validate
from sailroute.boat.polar import Polar, fold_twa
from sailroute.errors import InputError
from sailroute.numerics import golden_max

_FN_MAX: Final = 0.75
_N_GOLDEN_FLAT: Final = 32
_N_GOLDEN_TWIST: Final = 22
_N_NEWTON: Final = 14
_N_SCAN: Final = 20
_ROOT_TOL: Final = 1e-10
_G_TOL: Final = 1e-9
_MAX_ROOT_ITER: Final = 60
_V_MIN: Final = 0.02

Thrust = Callable[[NDArray, NDArray, NDArray], NDArray]
"""Extra forward force [N] as a function of (TWS [m s⁻¹], TWA [°], V [m s⁻¹])."""

# --- coefficient tables ------------------------------------------------------------


@dataclass(frozen=True)
class SailTable:
    """ORC sail coefficients against apparent wind angle.

    Attributes
    ----------
    awa_deg : ndarray
        Apparent wind angles [°].
    cd : ndarray
        Viscous drag coefficient C_Dv at each angle [-].
    cl : ndarray
        Maximum lift coefficient C_Lmax at each angle [-].
    kp : float
        ORC quadratic parasitic drag constant [-].
    """

    awa_deg: NDArray[np.float64]
    cd: NDArray[np.float64]
    cl: NDArray[np.float64]
    kp: float


def _data_text(name: str) -> str:
    return resources.files("sailroute.boat").joinpath("data", name).read_text(encoding="utf-8")


@cache
def sail_table(name: str = "main") -> SailTable:
    """Load an ORC sail table shipped in ``sailroute/boat/data/`` (``main``, ``jib``, ``kite``).

    The files are Python-VPP's ``dat/main.dat``, ``jib.dat``, ``kite.dat`` (MIT):
    line 2 holds ``kp``, line 3 the AWA [°], lines 4/5 C_Dv and C_Lmax.
    """
    lines = [ln for ln in _data_text(f"{name}.dat").splitlines() if ln.strip()]

    def row(k: int) -> NDArray[np.float64]:
        return np.array([float(c) for c in lines[k].split(",") if c.strip()])

    return SailTable(awa_deg=row(2), cd=row(3), cl=row(4), kp=float(row(1)[0]))


@cache
def _sail_interp(name: str) -> tuple[PchipInterpolator, PchipInterpolator]:
    t = sail_table(name)
    return PchipInterpolator(t.awa_deg, t.cl), PchipInterpolator(t.awa_deg, t.cd)


@lru_cache(maxsize=1)
def dsyhs_table() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """DSYHS residuary-resistance coefficients ``(fn, a)``, ``a`` of shape (8, n_fn).

    From ``data/wr.dat`` (Python-VPP, MIT; Fossati table 2.5, after Keuning &
    Sonnenberg 1998): first row the Froude numbers, then a0 ... a7.
    """
    rows = [
        np.array([float(c) for c in ln.split(",") if c.strip()])
        for ln in _data_text("wr.dat").splitlines()
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    fn, a = rows[0], np.vstack(rows[1:9])
    for arr in (fn, a):
        arr.setflags(write=False)  # cached and shared: read-only
    return fn, a


@lru_cache(maxsize=1)
def _dsyhs_interp() -> PchipInterpolator:
    fn, a = dsyhs_table()
    return PchipInterpolator(fn, a, axis=1)


# --- pure physics ------------------------------------------------------------------


def apparent_wind(
    tws_ms: ArrayLike, twa_deg: ArrayLike, bsp_ms: ArrayLike, heel_deg: ArrayLike = 0.0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Apparent wind speed and angle at the sail (thesis eqs 2.3-2.4).

    Parameters
    ----------
    tws_ms, twa_deg, bsp_ms : array_like
        True wind speed [m s⁻¹], true wind angle [°] (0-180), boat speed [m s⁻¹].
    heel_deg : array_like
        Heel Θ [°]; the cross-wind component is seen as ``V_tw sin β cos Θ``.

    Returns
    -------
    aws_ms, awa_deg : ndarray
        ``sqrt((V_tw sin β cos Θ)² + (V_tw cos β + V)²)`` and
        ``atan2(V_tw sin β cos Θ, V_tw cos β + V)`` [°].
    """
    b = np.radians(np.asarray(twa_deg, dtype=float))
    tws = np.asarray(tws_ms, dtype=float)
    y = tws * np.sin(b) * np.cos(np.radians(heel_deg))
    x = tws * np.cos(b) + np.asarray(bsp_ms, dtype=float)
    return np.hypot(x, y), np.degrees(np.arctan2(y, x))


def twist_weight(awa_deg: ArrayLike) -> NDArray[np.float64]:
    """Share of the twist effects (drag penalty, CE drop) at apparent wind angle β [-].

    Twist acts on attached flow: 1 up to β = 70°, falling smoothly (C¹
    smoothstep) to 0 at β = 90°, where the sail is stalled and twisting it
    neither adds induced drag nor moves the centre of effort [A].  Without the
    fade, the extra "drag" of eq 4.4 would count as drive downwind.
    """
    u = np.clip((90.0 - np.asarray(awa_deg, dtype=float)) / 20.0, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def sail_coefficients(
    awa_deg: ArrayLike,
    flat: ArrayLike,
    twist: ArrayLike,
    params: LaserParams,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Lift and drag coefficients of the rig (thesis eq 4.4 on ORC tables).

    ``C_L = f C_Lmax(β)`` and
    ``C_D = C_Dv(β) + C_Dp + f² C_Lmax(β)² ((1 + w(β) C_twist t²) / (π AR_E) + C_Ds)``,
    with C_Lmax and C_Dv the ORC mainsail (and, with a jib, area-weighted jib)
    tables, interpolated with PCHIP in β [°], and w the :func:`twist_weight`.
    Easing below ``ease_flat`` (see :func:`eased_drag`) is not included here.

    Parameters
    ----------
    awa_deg : array_like
        Apparent wind angle β [°], clipped to [0, 180].
    flat, twist : array_like
        Controls f and t [-].
    params : LaserParams
        Rig data (areas, aspect ratio, C_twist, C_Ds, C_Dp).

    Returns
    -------
    cl, cd : ndarray
        Coefficients on the total sail area [-].
    """
    cl0, cdv = base_coefficients(awa_deg, params)
    f = np.asarray(flat, dtype=float)
    t = np.asarray(twist, dtype=float)
    w = twist_weight(awa_deg)
    k = (1.0 + w * params.c_twist * t * t) / (np.pi * params.aspect_ratio) + params.c_ds
    return f * cl0, cdv + params.c_dp + (f * cl0) ** 2 * k


def eased_drag(awa_deg: ArrayLike, flat: ArrayLike, params: LaserParams) -> NDArray[np.float64]:
    """Viscous drag C_Dv + C_Dp of the sail, lowered by easing when flat < ease_flat [-].

    ``C_Dv,eff = C_l + (C_Dv(β) - C_l) min(1, f / ease_flat)`` with the
    luffing value ``C_l = min(C_Dv(0), C_Dv(β))``: a fully eased sail luffs.
    """
    _, cdv = base_coefficients(awa_deg, params)
    cd0 = cdv + params.c_dp
    cdl = np.minimum(base_coefficients(0.0, params)[1] + params.c_dp, cd0)
    if params.ease_flat <= 0:
        return cd0
    r = np.minimum(np.asarray(flat, dtype=float) / params.ease_flat, 1.0)
    return cdl + (cd0 - cdl) * r


def base_coefficients(
    awa_deg: ArrayLike, params: LaserParams
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """C_Lmax(β) and C_Dv(β) of the sail plan (area-weighted main + jib) [-]."""
    a = np.clip(np.asarray(awa_deg, dtype=float), 0.0, 180.0)
    cl_m, cd_m = _sail_interp("main")
    cl, cd = cl_m(a) * params.sail_area_m2, cd_m(a) * params.sail_area_m2
    if params.jib_area_m2 > 0:
        cl_j, cd_j = _sail_interp(params.headsail_table)
        cl = cl + cl_j(a) * params.jib_area_m2
        cd = cd + cd_j(a) * params.jib_area_m2
    area = params.sail_area_m2 + params.jib_area_m2
    return cl / area, cd / area


def windage_drag(aws_ms: ArrayLike, awa_deg: ArrayLike, params: LaserParams) -> NDArray:
    """Hull and crew windage drag along the apparent wind [N] (thesis eq 4.5).

    ``D_w = ½ ρa V_aw² (1 - s) (Cd_f A_f cos² β + Cd_s A_s sin² β)`` with the
    thesis's frontal/side coefficients 1.075/0.954 and shielding s = 20 %.
    """
    b = np.radians(np.asarray(awa_deg, dtype=float))
    cda = (1.0 - params.windage_shielding) * (
        params.windage_cd_front * params.windage_area_front_m2 * np.cos(b) ** 2
        + params.windage_cd_side * params.windage_area_side_m2 * np.sin(b) ** 2
    )
    return 0.5 * params.rho_air * np.asarray(aws_ms, dtype=float) ** 2 * cda


def ittc57_cf(reynolds: ArrayLike) -> NDArray[np.float64]:
    """ITTC-57 friction line ``C_f = 0.075 / (log10 Re - 2)²`` (Re floored at 1e5)."""
    re = np.maximum(np.asarray(reynolds, dtype=float), 1e5)
    return 0.075 / (np.log10(re) - 2.0) ** 2


def friction_resistance(bsp_ms: ArrayLike, params: LaserParams) -> NDArray[np.float64]:
    """Viscous resistance of hull and foils [N] (ITTC-57 with form factors).

    ``R_f = ½ ρw V² [S_h C_f(V 0.7 Lwl / ν)(1 + k) + S_a C_f(V c / ν)(1 + k_a)]``,
    with S_a = both sides of board and rudder.
    """
    v = np.asarray(bsp_ms, dtype=float)
    q = 0.5 * params.rho_water * v * v
    hull = (
        params.hull_wetted_area_m2
        * ittc57_cf(v * 0.7 * params.lwl_m / params.nu_water)
        * (1.0 + params.form_factor)
    )
    s_app = 2.0 * (params.board_area_m2 + params.rudder_area_m2)
    app = (
        s_app
        * ittc57_cf(v * params.appendage_chord_m / params.nu_water)
        * (1.0 + params.appendage_form_factor)
    )
    return q * (hull + app)


def residuary_resistance(bsp_ms: ArrayLike, params: LaserParams) -> NDArray[np.float64]:
    """Residuary (wave) resistance of the canoe body, DSYHS [N].

    ``R_r = ρw g ∇ [a0 + (a1 LCB/Lwl + a2 Cp + a3 ∇^(2/3)/Aw + a4 Bwl/Lwl
    + a5 LCB/LCF + a6 Bwl/Tc + a7 Cm) ∇^(1/3)/Lwl]`` with a_i(Fn) from
    Fossati's table 2.5, PCHIP in Fn.  Above Fn 0.75 (end of the series; a
    planing dinghy goes beyond) ``R_r / (ρw g ∇)`` is held at its Fn 0.75 value,
    and negative regression values are set to 0.
    """
    v = np.asarray(bsp_ms, dtype=float)
    fn = np.clip(v / np.sqrt(params.gravity * params.lwl_m), 0.0, _FN_MAX)
    a = _dsyhs_interp()(fn)
    vol = params.volume_m3
    x = (
        a[1] * params.lcb_fraction
        + a[2] * params.prismatic_coefficient
        + a[3] * vol ** (2.0 / 3.0) / params.waterplane_area_m2
        + a[4] * params.bwl_m / params.lwl_m
        + a[5] * params.lcb_fraction / params.lcf_fraction
        + a[6] * params.bwl_m / params.canoe_draft_m
        + a[7] * params.midship_coefficient
    )
    ratio = np.maximum(a[0] + x * vol ** (1.0 / 3.0) / params.lwl_m, 0.0)
    return params.rho_water * params.gravity * vol * ratio


def hull_resistance(bsp_ms: ArrayLike, params: LaserParams) -> NDArray[np.float64]:
    """Upright resistance without the induced part [N].

    ``hull_model="dsyhs"``: :func:`friction_resistance` + :func:`residuary_resistance`;
    ``"thesis"``: ``½ ρw V² · hull_drag_area_m2`` (thesis eq 4.19).
    """
    v = np.asarray(bsp_ms, dtype=float)
    if params.hull_model == "thesis":
        return 0.5 * params.rho_water * v * v * params.hull_drag_area_m2
    return friction_resistance(v, params) + residuary_resistance(v, params)


def induced_resistance(
    side_force_n: ArrayLike, bsp_ms: ArrayLike, params: LaserParams
) -> NDArray[np.float64]:
    """Induced resistance of the foils carrying the side force [N].

    ``R_i = Y² / (½ ρw V² π T_eff²)`` (Python-VPP's form, with T_eff the
    board's draft unless :attr:`~LaserParams.effective_draft_m` is set).
    """
    v = np.asarray(bsp_ms, dtype=float)
    te = params.effective_draft_m or params.max_draft_m
    y = np.asarray(side_force_n, dtype=float)
    with np.errstate(divide="ignore"):
        return y * y / (0.5 * params.rho_water * v * v * np.pi * te * te)


def crew_righting_moment(
    crew_position: ArrayLike, params: LaserParams, heel_deg: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Crew righting moment ``y_c m_c g (B/2 + e) cos Θ`` [N m] (thesis eq 2.30-2.31).

    The thesis's arm is Y_max = B/2; a hiking sailor's centre of mass is
    ``hiking_extension_m`` further out.
    """
    return (
        np.asarray(crew_position, dtype=float)
        * params.max_righting_moment_nm
        * np.cos(np.radians(heel_deg))
    )


def ce_height(
    flat: ArrayLike, twist: ArrayLike, params: LaserParams, awa_deg: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Centre-of-effort height above the water for the controls [m].

    ``z = z_foot + (z_CE - z_foot)(1 - 0.203 (1 - f) - c_t w(β) t)``: flattening
    lowers the CE as in the ORC VPP, twist unloads the head (faded out by
    :func:`twist_weight` beyond β = 70°).
    """
    z0 = _ce0(params)
    return params.sail_foot_height_m + (z0 - params.sail_foot_height_m) * (
        1.0
        - params.flat_ce_drop * (1.0 - np.asarray(flat, dtype=float))
        - params.twist_ce_drop * twist_weight(awa_deg) * np.asarray(twist, dtype=float)
    )


def _ce0(params: LaserParams) -> float:
    if params.jib_area_m2 > 0:
        return (
            params.sail_area_m2 * params.ce_height_m + params.jib_area_m2 * params.jib_ce_height_m
        ) / (params.sail_area_m2 + params.jib_area_m2)
    return params.ce_height_m


def righting_moment(heel_deg: ArrayLike, params: LaserParams) -> NDArray[np.float64]:
    """Righting moment of a heeling (keel)boat [N m]: ``Δ g GZ(Θ) + crew on the rail``."""
    h = np.asarray(heel_deg, dtype=float)
    gz = np.interp(h, params.gz_heel_deg, params.gz_m)
    return params.displacement_kg * params.gravity * gz + (
        params.crew_mass_kg * params.gravity * params.crew_arm_m * np.cos(np.radians(h))
    )


# --- the steady-state solver -------------------------------------------------------------


@dataclass(frozen=True)
class PointSolution:
    """Steady state at each (TWS, TWA) point; arrays of the broadcast shape.

    Attributes
    ----------
    speed_ms : ndarray
        Boat speed [m s⁻¹] (0 where no steady sailing exists: the no-go zone).
    flat, twist : ndarray
        Chosen controls [-] (NaN where the speed is 0).
    crew_position : ndarray
        ``y_c`` [-]: heeling moment / largest crew righting moment (hiking
        model; > 1 only when ``overpowered``).
    heel_deg : ndarray
        Heel [°] (0 in the hiking model).
    awa_deg, aws_ms : ndarray
        Apparent wind at the sail [°, m s⁻¹].
    drive_n, side_force_n, resistance_n, induced_n : ndarray
        Sail + windage drive, side force, hull resistance and induced
        resistance [N] (drive = resistance + induced at equilibrium).
    heeling_moment_nm : ndarray
        [N m].
    overpowered : ndarray of bool
        The moment limit could not be met even fully depowered.
    """

    speed_ms: NDArray[np.float64]
    flat: NDArray[np.float64]
    twist: NDArray[np.float64]
    crew_position: NDArray[np.float64]
    heel_deg: NDArray[np.float64]
    awa_deg: NDArray[np.float64]
    aws_ms: NDArray[np.float64]
    drive_n: NDArray[np.float64]
    side_force_n: NDArray[np.float64]
    resistance_n: NDArray[np.float64]
    induced_n: NDArray[np.float64]
    heeling_moment_nm: NDArray[np.float64]
    overpowered: NDArray[np.bool_]


class _Ctx:
    """Forces at a fixed boat speed for a batch of points (internal)."""

    def __init__(
        self, p: LaserParams, tws: NDArray, twa: NDArray, v: NDArray, heel: NDArray | float
    ) -> None:
        self.p = p
        aws, awa = apparent_wind(tws, twa, v, heel)
        self.aws, self.awa = aws, awa
        cl0, cdv = base_coefficients(awa, p)
        b = np.radians(awa)
        self.sb, self.cb = np.sin(b), np.cos(b)
        self.qa = 0.5 * p.rho_air * aws * aws * (p.sail_area_m2 + p.jib_area_m2)
        self.cl0 = cl0
        self.cd0 = cdv + p.c_dp
        # luffing sail: the table's drag at AWA 0, but never more than trimmed
        self.cdl = np.minimum(float(base_coefficients(0.0, p)[1]) + p.c_dp, self.cd0)
        self.inv_ease = 1.0 / p.ease_flat if p.ease_flat > 0 else 0.0
        self.k0 = 1.0 / (np.pi * p.aspect_ratio) + p.c_ds
        w = twist_weight(awa)
        self.kt = w * p.c_twist / (np.pi * p.aspect_ratio)
        dw = windage_drag(aws, awa, p)
        self.wx = dw * self.cb
        self.wy = dw * self.sb
        self.rh = hull_resistance(v, p)
        te = p.effective_draft_m or p.max_draft_m
        self.inv_di = 1.0 / (0.5 * p.rho_water * v * v * np.pi * te * te)
        z0 = _ce0(p)
        span = z0 - p.sail_foot_height_m
        self.arm0 = p.sail_foot_height_m + span * (1.0 - p.flat_ce_drop) + p.clr_depth_m
        self.arm_f = span * p.flat_ce_drop
        self.arm_t = span * p.twist_ce_drop * w
        self.warm = 0.5 * p.sail_foot_height_m + p.clr_depth_m
        self.cos_heel = np.cos(np.radians(heel))

    def take(self, mask: NDArray[np.bool_]) -> _Ctx:
        out = object.__new__(_Ctx)
        for k, val in self.__dict__.items():
            out.__dict__[k] = val[mask] if isinstance(val, np.ndarray) and val.ndim else val
        return out

    def moment(self, x: NDArray, t: NDArray | float) -> tuple[NDArray, NDArray]:
        """Heeling moment and its derivative with respect to flat at twist ``t``."""
        k = self.k0 + self.kt * t * t
        r = np.minimum(x * self.inv_ease, 1.0) if self.inv_ease else np.ones_like(x)
        dr = np.where(x * self.inv_ease < 1.0, self.inv_ease, 0.0)
        cl2 = self.cl0 * self.cl0
        ys = self.qa * (
            x * self.cl0 * self.cb
            + (self.cdl + (self.cd0 - self.cdl) * r + x * x * cl2 * k) * self.sb
        )
        dys = self.qa * (
            self.cl0 * self.cb + ((self.cd0 - self.cdl) * dr + 2.0 * x * cl2 * k) * self.sb
        )
        arm = self.arm0 + self.arm_f * x - self.arm_t * t
        return ys * arm + self.wy * self.warm, dys * arm + ys * self.arm_f

    def forces(self, x: NDArray | float, t: NDArray | float) -> tuple[NDArray, ...]:
        """Drive, side force (perpendicular to the mast), surplus and heeling moment."""
        cl = x * self.cl0
        r = np.minimum(x * self.inv_ease, 1.0) if self.inv_ease else 1.0
        cd = self.cdl + (self.cd0 - self.cdl) * r + cl * cl * (self.k0 + self.kt * t * t)
        fx = self.qa * (cl * self.sb - cd * self.cb) - self.wx
        fs = self.qa * (cl * self.cb + cd * self.sb)
        fy = (fs + self.wy) * self.cos_heel
        surplus = fx - self.rh - fy * fy * self.inv_di
        moment = fs * (self.arm0 + self.arm_f * x - self.arm_t * t) + self.wy * self.warm
        return fx, fy, surplus, moment


def _best_controls(
    p: LaserParams, ctx: _Ctx, rm_max: NDArray | float
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Best (flat, twist) at a fixed speed: returns surplus, flat, twist, overpowered."""
    n = ctx.cl0.shape
    lo = np.full(n, p.flat_min)
    hi = np.ones(n)
    x_u = golden_max(lambda x: ctx.forces(x, 0.0)[2], lo, hi, _N_GOLDEN_FLAT)
    _, _, s_u, m_u = ctx.forces(x_u, 0.0)
    x_best, t_best, s_best = x_u, np.zeros(n), s_u
    over = np.zeros(n, dtype=bool)
    bind = m_u > rm_max
    if not np.any(bind):
        return s_best, x_best, t_best, over
    sub = ctx.take(bind)
    rm = rm_max[bind] if isinstance(rm_max, np.ndarray) and np.ndim(rm_max) else rm_max
    xu = x_u[bind]

    def on_limit(t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        # largest flat in [flat_min, x_u] with moment <= rm: safeguarded Newton on the
        # (piecewise cubic) moment, started at x_u
        lo = np.full(xu.shape, p.flat_min)
        hi = xu.copy()
        infeasible = sub.moment(lo, t)[0] > rm
        x = hi
        for _ in range(_N_NEWTON):
            m, d = sub.moment(x, t)
            f = m - rm
            hi = np.where(f > 0, x, hi)
            lo = np.where(f > 0, lo, x)
            with np.errstate(divide="ignore", invalid="ignore"):
                xn = x - f / d
            bad = ~((xn > lo) & (xn < hi))
            x = np.where(bad, 0.5 * (lo + hi), xn)
        x = np.where(infeasible, p.flat_min, np.where(sub.moment(x, t)[0] > rm, lo, x))
        return x, sub.forces(x, t)[2], infeasible

    tmax = p.twist_max
    if tmax > 0:
        t_opt = golden_max(
            lambda t: on_limit(t)[1], np.zeros(xu.shape), np.full(xu.shape, tmax), _N_GOLDEN_TWIST
        )
    else:
        t_opt = np.zeros(xu.shape)
    candidates = [np.zeros(xu.shape), t_opt, np.full(xu.shape, tmax)]  # ties keep t = 0
    best_s = np.full(xu.shape, -np.inf)
    best_x = np.zeros(xu.shape)
    best_t = np.zeros(xu.shape)
    best_inf = np.zeros(xu.shape, dtype=bool)
    for t in candidates:
        x, s, inf = on_limit(t)
        # an infeasible setting only counts when nothing is feasible
        score = np.where(inf, s - 1e12, s)
        better = score > np.where(best_inf, best_s - 1e12, best_s)
        best_s = np.where(better, s, best_s)
        best_x = np.where(better, x, best_x)
        best_t = np.where(better, t, best_t)
        best_inf = np.where(better, inf, best_inf)
    s_best = s_best.copy()
    x_best = x_best.copy()
    s_best[bind], x_best[bind], t_best[bind], over[bind] = best_s, best_x, best_t, best_inf
    return s_best, x_best, t_best, over


def _max_heel(p: LaserParams) -> float:
    return min(p.max_heel_deg or p.gz_heel_deg[-1], p.gz_heel_deg[-1])


def _heel_for(p: LaserParams, moment: NDArray) -> NDArray:
    """Heel at which the righting-moment curve equals ``moment`` (keelboat model)."""
    grid = np.linspace(p.gz_heel_deg[0], _max_heel(p), 401)
    rm = righting_moment(grid, p)
    rm = np.maximum.accumulate(rm)
    return np.interp(moment, rm, grid)


def _surplus_at(
    p: LaserParams, tws: NDArray, twa: NDArray, v: NDArray
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray, _Ctx]:
    """g(V): best surplus at speed V, with the controls, overpowered flag, heel and state."""
    if p.stability == "hiking":
        ctx = _Ctx(p, tws, twa, v, 0.0)
        s, x, t, over = _best_controls(p, ctx, p.max_righting_moment_nm)
        return s, x, t, over, np.zeros_like(v), ctx
    # keelboat: heel from the righting-arm curve by fixed-point iteration, the
    # moment limit is the righting moment at the largest tabulated heel
    heel = np.zeros_like(v)
    rm_max = float(righting_moment(_max_heel(p), p))
    for _ in range(6):
        ctx = _Ctx(p, tws, twa, v, heel)
        s, x, t, over = _best_controls(p, ctx, rm_max)
        m = ctx.forces(x, t)[3]
        heel = _heel_for(p, m)
    ctx = _Ctx(p, tws, twa, v, heel)
    s = ctx.forces(x, t)[2]
    return s, x, t, over, heel, ctx


def solve_point(
    params: LaserParams, tws_ms: ArrayLike, twa_deg: ArrayLike, thrust: Thrust | None = None
) -> PointSolution:
    """Steady-state speed and sail setting at each (TWS, TWA).

    Parameters
    ----------
    params : LaserParams
        Boat (see :mod:`sailroute.boat.laser`).
    tws_ms : array_like
        True wind speed at the centre-of-effort height [m s⁻¹], ``>= 0``.
    twa_deg : array_like
        True wind angle [°], any sign (folded to 0-180); broadcast with ``tws_ms``.
    thrust : callable, optional
        Extra forward force [N] ``thrust(tws_ms, twa_deg, v_ms)`` added to the surge
        balance (the race model's kinetics, :mod:`sailroute.boat.kinetics`); the
        force fields of the result stay those of the sail and hull alone.

    Returns
    -------
    PointSolution
        Arrays of the broadcast shape.

    Raises
    ------
    InputError
        If the parameters are invalid or inputs are not finite.
    """
    problems = validate(params)
    if problems:
        raise InputError("VPP parameters: " + "; ".join(problems))
    if params.kite_area_m2 > 0:
        # two sail sets: main + jib and main + kite; keep the faster at each point
        upwind = _solve_point(replace(params, kite_area_m2=0.0), tws_ms, twa_deg, thrust)
        kite = _solve_point(
            replace(
                params,
                jib_area_m2=params.kite_area_m2,
                jib_ce_height_m=params.kite_ce_height_m,
                headsail_table="kite",
                kite_area_m2=0.0,
            ),
            tws_ms,
            twa_deg,
            thrust,
        )
        use = kite.speed_ms > upwind.speed_ms
        return PointSolution(
            **{k: np.where(use, getattr(kite, k), getattr(upwind, k)) for k in upwind.__dict__}
        )
    return _solve_point(params, tws_ms, twa_deg, thrust)


def _solve_point(
    params: LaserParams, tws_ms: ArrayLike, twa_deg: ArrayLike, thrust: Thrust | None = None
) -> PointSolution:
    tws_b, twa_b = np.broadcast_arrays(
        np.asarray(tws_ms, dtype=float), np.asarray(twa_deg, dtype=float)
    )
    shape = tws_b.shape
    tws = tws_b.ravel().copy()
    twa = fold_twa(twa_b.ravel())
    if not (np.all(np.isfinite(tws)) and np.all(np.isfinite(twa))) or np.any(tws < 0):
        raise InputError("VPP: TWS and TWA must be finite and TWS >= 0")
    n = tws.size
    speed = np.zeros(n)
    active = (tws > 0) & (twa > 0)
    idx = np.flatnonzero(active)
    if idx.size:
        speed[idx] = _solve_speed(params, tws[idx], twa[idx], thrust)
    # final state at the solution
    moving = speed > 0
    v = np.where(moving, speed, _V_MIN)
    _, x, t, over, heel, ctx = _surplus_at(params, tws, twa, v)
    fx, fy, _, m = ctx.forces(x, t)
    nan = np.where(moving, 1.0, np.nan)
    rm = (
        params.max_righting_moment_nm
        if params.stability == "hiking"
        else float(righting_moment(_max_heel(params), params))
    )
    res = PointSolution(
        speed_ms=speed,
        flat=x * nan,
        twist=t * nan,
        crew_position=m / rm * nan,
        heel_deg=heel * nan,
        awa_deg=ctx.awa * nan,
        aws_ms=ctx.aws * nan,
        drive_n=fx * nan,
        side_force_n=fy * nan,
        resistance_n=ctx.rh * nan,
        induced_n=fy * fy * ctx.inv_di * nan,
        heeling_moment_nm=m * nan,
        overpowered=over & moving,
    )
    return PointSolution(**{k: np.reshape(getattr(res, k), shape) for k in res.__dict__})


def _solve_speed(
    p: LaserParams, tws: NDArray, twa: NDArray, thrust: Thrust | None = None
) -> NDArray:
    """Largest root of g(V) (+ ``thrust(tws, twa, V)`` if given) per point (0 if none)."""

    def surplus(t: NDArray, a: NDArray, v: NDArray) -> NDArray:
        s = _surplus_at(p, t, a, v)[0]
        return s if thrust is None else s + thrust(t, a, v)

    n = tws.size
    vmax = 1.5 * tws + 1.0
    for _ in range(4):  # make sure g(vmax) < 0
        g_top = surplus(tws, twa, vmax)
        if not np.any(g_top >= 0):
            break
        vmax = np.where(g_top >= 0, 2.0 * vmax, vmax)
    frac = (np.arange(1, _N_SCAN + 1) / _N_SCAN) ** 1.5
    grid = _V_MIN + (vmax[:, None] - _V_MIN) * frac[None, :]  # (n, K), increasing
    g = surplus(np.repeat(tws, _N_SCAN), np.repeat(twa, _N_SCAN), grid.ravel()).reshape(n, _N_SCAN)
    pos = g >= 0
    has = np.asarray(pos.any(axis=1))  # (an array: numpy's stubs say "bool or array")
    # last grid point with g >= 0; the root lies between it and the next point
    last = _N_SCAN - 1 - np.argmax(pos[:, ::-1], axis=1)
    lo_v = grid[np.arange(n), last]
    lo_g = g[np.arange(n), last]
    # no grid point with g >= 0: a narrow window near the no-go fold may lie between grid
    # points; maximise g around the best grid point and keep the peak if it is >= 0
    miss = np.flatnonzero(~has)
    if miss.size:
        # skip points whose samples are too negative for any peak between them to reach 0
        k = np.argmax(g[miss], axis=1)
        gk = g[miss, k]
        spread = np.maximum(
            np.abs(gk - g[miss, np.maximum(k - 1, 0)]),
            np.abs(gk - g[miss, np.minimum(k + 1, _N_SCAN - 1)]),
        )
        miss = miss[gk + 2.0 * spread >= 0]
    if miss.size:
        k = np.argmax(g[miss], axis=1)
        a = grid[miss, np.maximum(k - 1, 0)]
        b = grid[miss, np.minimum(k + 1, _N_SCAN - 1)]
        tm, am = tws[miss], twa[miss]
        peak = golden_max(lambda v: surplus(tm, am, v), a, b, _N_GOLDEN_FLAT)
        g_peak = surplus(tm, am, peak)
        found = g_peak >= 0
        has[miss[found]] = True
        last[miss[found]] = k[found]
        lo_v[miss[found]] = peak[found]
        lo_g[miss[found]] = g_peak[found]
    out = np.zeros(n)
    sel = np.flatnonzero(has & (last < _N_SCAN - 1))
    top = np.flatnonzero(has & (last == _N_SCAN - 1))
    out[top] = vmax[top]
    if sel.size == 0:
        return out
    a = lo_v[sel]
    b = grid[sel, last[sel] + 1]
    ga = lo_g[sel]
    gb = g[sel, last[sel] + 1]
    ts, ta = tws[sel], twa[sel]
    side = np.zeros(sel.size)
    result = a.copy()
    act = np.arange(sel.size)  # points still iterating
    for _ in range(_MAX_ROOT_ITER):
        aa, bb, ga_, gb_ = a[act], b[act], ga[act], gb[act]
        c = np.where(ga_ != gb_, (aa * gb_ - bb * ga_) / (gb_ - ga_), 0.5 * (aa + bb))
        c = np.clip(c, np.minimum(aa, bb), np.maximum(aa, bb))
        gc = surplus(ts[act], ta[act], c)
        pos_c = gc >= 0
        # Illinois: halve the retained end's value when the same end is kept twice
        a[act] = np.where(pos_c, c, aa)
        b[act] = np.where(pos_c, bb, c)
        ga[act] = np.where(pos_c, gc, np.where(side[act] == -1, 0.5 * ga_, ga_))
        gb[act] = np.where(pos_c, np.where(side[act] == 1, 0.5 * gb_, gb_), gc)
        side[act] = np.where(pos_c, 1, -1)
        done = (np.abs(b[act] - a[act]) < _ROOT_TOL) | (np.abs(gc) < _G_TOL)
        result[act] = np.where(np.abs(gc) < _G_TOL, c, a[act])
        act = act[~done]
        if act.size == 0:
            break
    result[act] = a[act]
    out[sel] = result  # g >= 0 there (or |g| < 1e-9 N): within tolerance of the root
    return out


def solve_polar(
    params: LaserParams,
    tws_ms: ArrayLike,
    twa_deg: ArrayLike,
    *,
    name: str | None = None,
    interpolation: str = "pchip",
    thrust: Thrust | None = None,
) -> Polar:
    """Polar of the boat on a (TWA, TWS) grid.

    Parameters
    ----------
    params : LaserParams
        Boat.
    tws_ms : array_like, shape (n,)
        Strictly increasing TWS columns [m s⁻¹].
    twa_deg : array_like, shape (m,)
        Strictly increasing TWA rows in [0, 180] [°].
    name : str, optional
        Polar name (default ``params.name``).
    interpolation : {"pchip", "linear"}
        Interpolation method of the result.
    thrust : callable, optional
        Extra forward force [N], see :func:`solve_point`.

    Returns
    -------
    Polar
        ``speed_ms[i, j]`` is the steady speed at ``twa_deg[i]``, ``tws_ms[j]``.
    """
    tws = np.asarray(tws_ms, dtype=float)
    twa = np.asarray(twa_deg, dtype=float)
    sol = solve_point(params, tws[None, :], twa[:, None], thrust)
    return Polar.from_arrays(
        twa, tws, sol.speed_ms, name=name or params.name, interpolation=interpolation
    )
