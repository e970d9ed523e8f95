"""Boat performance polar: boat speed as a function of TWS and TWA.

Conventions: TWS [m s⁻¹], TWA [°] (sign ignored, folded into ``[0, 180]``),
boat speed [m s⁻¹].  See ``docs/nomenclature.md`` and ``docs/design/boat.md``.

Two interpolation methods are offered:

``"pchip"`` (default, for routing)
    A C¹ shape-preserving surface: monotone piecewise-cubic Hermite (PCHIP,
    Fritsch-Carlson) along TWA in every TWS column, then PCHIP along TWS in
    every row of the result.  PCHIP never overshoots the table (no spurious
    maxima between nodes).  The surface is sampled once on a dense regular
    grid (0.5° x ≈0.05 m s⁻¹) and lookups are bilinear on that grid with index
    arithmetic, so a lookup costs a few array operations.
``"linear"``
    Plain bilinear interpolation on the table nodes, identical to OpenCPN's
    ``Polar::Speed`` and libweatherrouting's ``get_speed`` inside the table.

Edge semantics (both methods, documented in ``docs/design/boat.md``):

* TWS below the lowest column tapers to 0 at TWS = 0 (a zero column is added
  at TWS 0 when the table lacks one); TWS above the highest column is clamped
  to that column; negative TWS counts as 0.
* TWA below the first row tapers to 0 at TWA = 0 and TWA above the last row
  tapers to 0 at TWA = 180 (zero rows are added where the table lacks them):
  a table that omits angles says the boat does not sail there.
* There is no hard no-go cut: inside the no-go zone the table's (low) speeds
  are used.  Upwind, sailing closer than :meth:`Polar.vmg_upwind`'s angle is
  never optimal, which is how the no-go zone shows up in routing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.numerics import clip, golden_max, pchip
from sailroute.units import KNOT

INTERPOLATIONS: Final = ("pchip", "linear")
"""Valid values of :attr:`Polar.interpolation`."""

DENSE_TWA_STEP_DEG: Final = 0.5
"""TWA spacing of the dense lookup table of the ``"pchip"`` method [°]."""
DENSE_TWS_STEP_MS: Final = 0.05
"""Largest TWS spacing of the dense lookup table [m s⁻¹]."""
_MAX_DENSE_TWS: Final = 2000

MAX_BOAT_SPEED_KN: Final = 70.0
"""Highest boat speed a polar may hold [kn] (36.0 m s⁻¹): above the outright sailing
speed record (65.45 kn, Vestas Sailrocket 2, 2012), so no real boat is refused, while
a km/h table of a fast boat read as knots (an F50's 85 km/h as "85 kn") is."""
MAX_BOAT_SPEED_MS: Final = MAX_BOAT_SPEED_KN * KNOT
""":data:`MAX_BOAT_SPEED_KN` in m s⁻¹."""
MAX_TWS_KN: Final = 80.0
"""Highest TWS column a polar may hold [kn] (41.2 m s⁻¹): well above hurricane force
(64 kn), where no polar is measured or computed."""
MAX_TWS_MS: Final = MAX_TWS_KN * KNOT
""":data:`MAX_TWS_KN` in m s⁻¹."""
MIN_AXIS_STEP: Final = 1e-6
"""Smallest spacing of adjacent TWA rows [°] and TWS columns [m s⁻¹], counting the
taper rows at TWA 0 and 180 and the column at TWS 0 that the polar adds: closer nodes
(e.g. TWA 1e-320) make the PCHIP slopes infinite."""

_VMG_SEARCH_STEP_DEG: Final = 0.5
_GOLDEN_ITERATIONS: Final = 64


def fold_twa(twa_deg: ArrayLike) -> NDArray[np.float64]:
    """Fold any signed angle [°] to ``|wrap180(twa)|`` in ``[0, 180]``."""
    return 180.0 - np.abs(np.mod(np.asarray(twa_deg, dtype=float), 360.0) - 180.0)


def axis_spacing_problem(values: ArrayLike, axis: str) -> str | None:
    """Why a TWA or TWS axis has nodes too close together, or None if it is fine.

    Parameters
    ----------
    values : array_like
        Strictly increasing TWA [°] (``axis="TWA"``) or TWS [m s⁻¹] (``"TWS"``).
    axis : {"TWA", "TWS"}
        Which axis: TWA counts the taper rows the polar adds at 0 and 180 [°], TWS
        the column it adds at 0 [m s⁻¹].

    Returns
    -------
    str or None
        ``"TWA 0 and 1e-320 are closer than 1e-06 deg ..."`` when two adjacent
        nodes differ by less than :data:`MIN_AXIS_STEP`, else None.
    """
    v = np.asarray(values, dtype=float)
    unit = "deg" if axis == "TWA" else "m/s"
    ext = v
    if v.size and v[0] > 0:
        ext = np.concatenate([[0.0], ext])
    if axis == "TWA" and v.size and v[-1] < 180:
        ext = np.concatenate([ext, [180.0]])
    close = np.flatnonzero(np.diff(ext) < MIN_AXIS_STEP)
    if not close.size:
        return None
    a, b = float(ext[close[0]]), float(ext[close[0] + 1])
    edges = (
        "TWA 0 and 180 count: the polar adds zero-speed rows there"
        if axis == "TWA"
        else "TWS 0 counts: the polar adds a zero-speed column there"
    )
    return (
        f"{axis} {a!r} and {b!r} {unit} are closer than {MIN_AXIS_STEP:g} {unit} ({edges}); "
        f"adjacent {axis} values must differ by at least {MIN_AXIS_STEP:g} {unit}: merge "
        "them or round the value"
    )


def _frozen_copy(values: ArrayLike) -> NDArray[np.float64]:
    """A read-only float64 copy of ``values``."""
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


def _frozen_array_problem(value: object) -> str | None:
    """What keeps ``value`` from being a :class:`Polar` table, or None if it can be."""
    if not isinstance(value, np.ndarray):
        return f"a {type(value).__name__}"
    if value.dtype != np.float64:
        return f"an ndarray of dtype {value.dtype}"
    if value.flags.writeable:
        return "a writable ndarray (the polar would change if the caller's array did)"
    return None


@dataclass(frozen=True, eq=False)
class Polar:
    """Polar table with vectorised interpolation.

    Build one with :meth:`Polar.from_arrays` (any array-likes); the constructor itself
    takes the three tables only as read-only float64 arrays (e.g. another polar's) and
    raises :class:`~sailroute.errors.InputError` for anything else.

    Parameters
    ----------
    twa_deg : ndarray, shape (m,)
        Strictly increasing true wind angles [°] within ``[0, 180]``, at least
        :data:`MIN_AXIS_STEP` apart (and from 0 and 180); read-only float64.
    tws_ms : ndarray, shape (n,)
        Strictly increasing true wind speeds [m s⁻¹], ``>= 0``, at least
        :data:`MIN_AXIS_STEP` apart (and from 0); read-only float64.
    speed_ms : ndarray, shape (m, n)
        Boat speed [m s⁻¹] at each (TWA, TWS) node, ``>= 0``; read-only float64.
        Neither an all-zero table nor speeds above :data:`MAX_BOAT_SPEED_MS` (or TWS
        above :data:`MAX_TWS_MS`) are refused here: analytic test boats use them; the
        file readers (:mod:`sailroute.boat.io`) refuse all three.
    name : str
        Label (boat name or source file).
    interpolation : {"pchip", "linear"}
        ``"pchip"``: smooth monotone C¹ surface (default, for routing);
        ``"linear"``: plain bilinear on the nodes (peer-tool compatible).

    Notes
    -----
    Outside the table: TWS below the lowest column tapers to 0 at TWS 0, above
    the highest column it is clamped; TWA below the first row tapers to 0 at
    TWA 0 and above the last row to 0 at TWA 180.  See the module docstring.
    """

    twa_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    name: str = ""
    interpolation: str = "pchip"

    def __post_init__(self) -> None:
        where = f"polar {self.name!r}" if self.name else "polar"
        for label in ("twa_deg", "tws_ms", "speed_ms"):
            problem = _frozen_array_problem(getattr(self, label))
            if problem:
                raise InputError(
                    f"{where}: {label} must be a read-only float64 ndarray, got {problem}; "
                    "build the polar with Polar.from_arrays(twa_deg, tws_ms, speed_ms, "
                    "name=..., interpolation=...), which copies lists and arrays to "
                    "read-only float64 arrays"
                )
        twa, tws, spd = self.twa_deg, self.tws_ms, self.speed_ms
        if twa.ndim != 1 or tws.ndim != 1 or spd.shape != (twa.size, tws.size):
            raise InputError(
                f"{where}: speed table has shape {spd.shape}, expected "
                f"(len(twa), len(tws)) = ({twa.size}, {tws.size})"
            )
        if twa.size < 2 or tws.size < 1:
            raise InputError(f"{where}: need at least 2 TWA rows and 1 TWS column")
        if not np.all(np.isfinite(twa)) or np.any(np.diff(twa) <= 0) or twa[0] < 0 or twa[-1] > 180:
            raise InputError(f"{where}: TWA values must increase strictly within [0, 180]")
        if not np.all(np.isfinite(tws)) or np.any(np.diff(tws) <= 0) or tws[0] < 0:
            raise InputError(f"{where}: TWS values must increase strictly and be >= 0")
        if not np.all(np.isfinite(spd)) or np.any(spd < 0):
            raise InputError(f"{where}: boat speeds must be finite and >= 0")
        for problem in (axis_spacing_problem(twa, "TWA"), axis_spacing_problem(tws, "TWS")):
            if problem:
                raise InputError(f"{where}: {problem}")
        if self.interpolation not in INTERPOLATIONS:
            raise InputError(
                f"{where}: interpolation must be one of {', '.join(map(repr, INTERPOLATIONS))}; "
                f"got {self.interpolation!r}"
            )

    # --- construction helpers -------------------------------------------------

    @classmethod
    def from_arrays(
        cls,
        twa_deg: ArrayLike,
        tws_ms: ArrayLike,
        speed_ms: ArrayLike,
        name: str = "",
        interpolation: str = "pchip",
    ) -> Polar:
        """A polar from any array-likes (lists, tuples, writable arrays).

        The usual way to build a :class:`Polar`: the three tables are copied to
        read-only float64 arrays, so later changes to the caller's arrays cannot
        reach the polar (or its cached lookup table).  The dataclass constructor
        ``Polar(...)`` itself accepts only read-only float64 arrays (e.g. another
        polar's) and says so otherwise.

        Parameters
        ----------
        twa_deg : array_like, shape (m,)
            True wind angles [°]; see :class:`Polar`.
        tws_ms : array_like, shape (n,)
            True wind speeds [m s⁻¹].
        speed_ms : array_like, shape (m, n)
            Boat speed [m s⁻¹] at each (TWA, TWS) node.
        name : str
            Label (boat name or source file).
        interpolation : {"pchip", "linear"}
            Interpolation method; see :class:`Polar`.

        Returns
        -------
        Polar
            The validated polar.

        Raises
        ------
        InputError
            If the tables break a rule of :class:`Polar` (shape, order, range, spacing).
        """
        return cls(
            _frozen_copy(twa_deg),
            _frozen_copy(tws_ms),
            _frozen_copy(speed_ms),
            name=name,
            interpolation=interpolation,
        )

    def with_interpolation(self, interpolation: str) -> Polar:
        """Same table with another interpolation method (a new :class:`Polar`)."""
        return replace(self, interpolation=interpolation)

    def with_name(self, name: str) -> Polar:
        """Same table under another name (a new :class:`Polar`)."""
        return replace(self, name=name)

    # --- lookups ----------------------------------------------------------------

    def speed(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        """Boat speed [m s⁻¹] at TWS [m s⁻¹] and TWA [°].

        Parameters
        ----------
        tws_ms : array_like
            True wind speed [m s⁻¹]; negative values count as calm.
        twa_deg : array_like
            True wind angle [°], any sign and range (folded to ``[0, 180]``).
            Broadcast against ``tws_ms``.

        Returns
        -------
        ndarray
            Boat speed [m s⁻¹], the broadcast shape of the inputs.  NaN inputs
            give NaN.
        """
        if self.interpolation == "linear":
            return self._speed_linear(tws_ms, twa_deg)
        inv_twa, inv_tws, tws_max, n_twa, n_tws, cells = self._dense
        a = np.abs(np.asarray(twa_deg, dtype=float))
        if np.any(a > 360.0):  # NaN-safe: NaN > 360 is False
            a = np.mod(a, 360.0)
        a = np.minimum(a, 360.0 - a) * inv_twa
        w = clip(np.asarray(tws_ms, dtype=float), 0.0, tws_max) * inv_tws
        with np.errstate(invalid="ignore"):
            i = np.minimum(a.astype(np.intp), n_twa - 2)
            j = np.minimum(w.astype(np.intp), n_tws - 2)
        i = np.maximum(i, 0)
        j = np.maximum(j, 0)
        fa = a - i
        fw = w - j
        c = np.take(cells, i * (n_tws - 1) + j, axis=0)
        lo = c[..., 0] + fw * (c[..., 1] - c[..., 0])
        hi = c[..., 2] + fw * (c[..., 3] - c[..., 2])
        return lo + fa * (hi - lo)

    def dense_table(self) -> tuple[float, float, float, int, int, NDArray[np.float64]] | None:
        """What :meth:`speed` interpolates in for the ``"pchip"`` method (None for
        ``"linear"``): ``(n_twa - 1) / 180`` [1/°], ``(n_tws - 1) / top TWS`` [s/m], the
        top TWS [m s⁻¹], the dense grid's ``n_twa`` and ``n_tws`` nodes, and its cells
        (row ``i (n_tws - 1) + j``: the speeds [m s⁻¹] at its corners ``(i, j)``,
        ``(i, j + 1)``, ``(i + 1, j)``, ``(i + 1, j + 1)``; read-only).  A compiled
        lookup (the isochrone's, ``sailroute/routing/isochrone_jit.py``) repeats
        :meth:`speed`'s arithmetic on it."""
        return None if self.interpolation == "linear" else self._dense

    def _speed_linear(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        tws = np.asarray(tws_ms, dtype=float)
        a = fold_twa(twa_deg)
        twa_ax, tws_ax, tab = self._extended
        with np.errstate(invalid="ignore"):
            i = clip(np.searchsorted(twa_ax, a, side="right") - 1, 0, twa_ax.size - 2)
            fa = clip((a - twa_ax[i]) / (twa_ax[i + 1] - twa_ax[i]), 0.0, 1.0)
            if tws_ax.size == 1:
                return (1 - fa) * tab[i, 0] + fa * tab[i + 1, 0] + 0.0 * tws
            j = clip(np.searchsorted(tws_ax, tws, side="right") - 1, 0, tws_ax.size - 2)
            fw = clip((tws - tws_ax[j]) / (tws_ax[j + 1] - tws_ax[j]), 0.0, 1.0)
        fa = np.where(np.isnan(a), np.nan, fa)
        fw = np.where(np.isnan(tws), np.nan, fw)
        return (
            (1 - fa) * (1 - fw) * tab[i, j]
            + fa * (1 - fw) * tab[i + 1, j]
            + (1 - fa) * fw * tab[i, j + 1]
            + fa * fw * tab[i + 1, j + 1]
        )

    @cached_property
    def _extended(self) -> tuple[NDArray, NDArray, NDArray]:
        """Table with the taper rows/column added (zero at TWA 0, TWA 180, TWS 0)."""
        twa, tws, tab = self.twa_deg, self.tws_ms, self.speed_ms
        if twa[0] > 0:
            twa = np.concatenate([[0.0], twa])
            tab = np.vstack([np.zeros((1, tab.shape[1])), tab])
        if twa[-1] < 180:
            twa = np.concatenate([twa, [180.0]])
            tab = np.vstack([tab, np.zeros((1, tab.shape[1]))])
        if tws[0] > 0:
            tws = np.concatenate([[0.0], tws])
            tab = np.hstack([np.zeros((tab.shape[0], 1)), tab])
        return twa, tws, tab

    @cached_property
    def _dense(self) -> tuple[float, float, float, int, int, NDArray]:
        """Dense regular PCHIP table (built once, on first use)."""
        twa, tws, tab = self._extended
        n_twa = round(180.0 / DENSE_TWA_STEP_DEG) + 1
        twa_d = np.linspace(0.0, 180.0, n_twa)
        by_twa = pchip(twa, tab, twa_d, axis=0)
        tws_max = float(tws[-1])
        if tws.size == 1 or tws_max <= 0:
            n_tws = 2
            tws_max = max(tws_max, 1.0)
            dense = np.repeat(by_twa[:, :1], 2, axis=1)
        else:
            n_tws = min(int(np.ceil(tws_max / DENSE_TWS_STEP_MS)), _MAX_DENSE_TWS) + 1
            tws_d = np.linspace(0.0, tws_max, n_tws)
            dense = pchip(tws, by_twa, tws_d, axis=1)
        dense = np.where(dense > 1e-12, dense, 0.0)  # exact zeros at the taper rows
        # corner values of every cell, contiguous: one gather per lookup
        cells = np.stack(
            [dense[:-1, :-1], dense[:-1, 1:], dense[1:, :-1], dense[1:, 1:]], axis=-1
        ).reshape(-1, 4)
        cells.setflags(write=False)
        return (
            (n_twa - 1) / 180.0,
            (n_tws - 1) / tws_max,
            tws_max,
            n_twa,
            n_tws,
            cells,
        )

    # --- VMG --------------------------------------------------------------------

    def vmg_upwind(self, tws_ms: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Best upwind VMG angle and VMG at each TWS.

        Parameters
        ----------
        tws_ms : array_like
            True wind speed [m s⁻¹].

        Returns
        -------
        twa_deg, vmg_ms : ndarray
            The TWA in ``[0, 90]`` [°] that maximises ``speed(tws, twa) cos(twa)``
            and that maximum [m s⁻¹], same shape as ``tws_ms``.  The optimum
            is continuous (not a table node): a 0.5° search brackets it and a
            golden-section search refines it to ~1e-10°, so
            ``vmg == speed(tws, twa) * cos(twa)`` exactly.  Where the polar
            gives no positive VMG (calm) the angle is 0 and the VMG 0.
        """
        return self._vmg(tws_ms, upwind=True)

    def vmg_downwind(self, tws_ms: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Best downwind VMG angle in ``[90, 180]`` [°] and VMG [m s⁻¹] (positive).

        Same method as :meth:`vmg_upwind`, maximising ``-speed cos(twa)``.
        Where the polar gives no positive VMG (calm) the angle is 180 and the
        VMG 0.
        """
        return self._vmg(tws_ms, upwind=False)

    def _vmg(self, tws_ms: ArrayLike, upwind: bool) -> tuple[NDArray, NDArray]:
        tws_in = np.asarray(tws_ms, dtype=float)
        tws = tws_in.reshape(-1)
        sign = 1.0 if upwind else -1.0
        lo_lim, hi_lim = (0.0, 90.0) if upwind else (90.0, 180.0)
        grid = np.linspace(lo_lim, hi_lim, round(90.0 / _VMG_SEARCH_STEP_DEG) + 1)
        cosg = np.cos(np.radians(grid))
        vmg_grid = self.speed(tws[:, None], grid[None, :]) * (sign * cosg)[None, :]
        k = np.argmax(vmg_grid, axis=1)
        lo = grid[np.maximum(k - 1, 0)]
        hi = grid[np.minimum(k + 1, grid.size - 1)]

        def f(x: NDArray) -> NDArray:
            return self.speed(tws, x) * (sign * np.cos(np.radians(x)))

        ang = golden_max(f, lo, hi, _GOLDEN_ITERATIONS)
        val = f(ang)
        best_grid = vmg_grid[np.arange(tws.size), k]
        use_grid = best_grid > val
        ang = np.where(use_grid, grid[k], ang)
        val = np.where(use_grid, best_grid, val)
        calm = ~(val > 0)
        ang = np.where(calm, lo_lim if upwind else hi_lim, ang)
        val = np.where(calm, 0.0, val)
        return ang.reshape(tws_in.shape), val.reshape(tws_in.shape)

    # --- the BoatModel protocol (sailroute.boat.model) -------------------------------

    def steady_speed(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        """Boat speed [m s⁻¹] at TWS [m s⁻¹] and TWA [°]: :meth:`speed` (a polar's speeds
        are steady)."""
        return self.speed(tws_ms, twa_deg)

    def vmg_angles_deg(self, tws_ms: float) -> tuple[float, float]:
        """Upwind and downwind best-VMG TWA [°] at ``tws_ms`` [m s⁻¹] (:meth:`vmg_upwind`,
        :meth:`vmg_downwind`)."""
        return float(self.vmg_upwind(tws_ms)[0]), float(self.vmg_downwind(tws_ms)[0])

    def routing_polar(self) -> Polar:
        """The polar a polar router samples: this one."""
        return self

    def dynamics(self) -> None:
        """None: a polar has steady speeds only (no momentum model)."""
        return None

    def max_speed(self, tws_ms: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """TWA [°] of the highest boat speed and that speed [m s⁻¹], on a 0.5° grid."""
        tws = np.asarray(tws_ms, dtype=float)
        grid = np.linspace(0.0, 180.0, 361)
        sp = self.speed(tws.reshape(-1)[:, None], grid[None, :])
        k = np.argmax(sp, axis=1)
        return grid[k].reshape(tws.shape), sp[np.arange(k.size), k].reshape(tws.shape)
