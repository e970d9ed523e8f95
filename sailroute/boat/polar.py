"""Boat performance polar: boat speed as a function of TWS and TWA.

Conventions: TWS [m s⁻¹], TWA [°] (sign ignored, folded into ``[0, 180]``),
boat speed [m s⁻¹].  See ``docs/nomenclature.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.units import wrap180


@dataclass(frozen=True, eq=False)
class Polar:
    """Polar table with vectorised interpolation.

    Parameters
    ----------
    twa_deg : ndarray, shape (m,)
        Strictly increasing true wind angles [°] within ``[0, 180]``.
    tws_ms : ndarray, shape (n,)
        Strictly increasing true wind speeds [m s⁻¹], ``>= 0``.
    speed_ms : ndarray, shape (m, n)
        Boat speed [m s⁻¹] at each (TWA, TWS) node.
    name : str
        Label (boat name or source file).

    Notes
    -----
    Interpolation is bilinear in (TWA, TWS).  Outside the table:

    * TWS below the lowest column tapers linearly to 0 at TWS = 0 (a boat does
      not sail in no wind); above the highest column the last column is used
      (clamp);
    * TWA below the first row tapers linearly to 0 at TWA = 0 (head to wind);
      above the last row the last row is used.
    """

    twa_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    name: str = ""

    def __post_init__(self) -> None:
        twa = np.asarray(self.twa_deg, dtype=float)
        tws = np.asarray(self.tws_ms, dtype=float)
        spd = np.asarray(self.speed_ms, dtype=float)
        where = f"polar {self.name!r}" if self.name else "polar"
        if twa.ndim != 1 or tws.ndim != 1 or spd.shape != (twa.size, tws.size):
            raise InputError(
                f"{where}: speed table has shape {spd.shape}, expected "
                f"(len(twa), len(tws)) = ({twa.size}, {tws.size})"
            )
        if twa.size < 2 or tws.size < 1:
            raise InputError(f"{where}: need at least 2 TWA rows and 1 TWS column")
        if np.any(np.diff(twa) <= 0) or twa[0] < 0 or twa[-1] > 180:
            raise InputError(f"{where}: TWA values must increase strictly within [0, 180]")
        if np.any(np.diff(tws) <= 0) or tws[0] < 0:
            raise InputError(f"{where}: TWS values must increase strictly and be >= 0")
        if not np.all(np.isfinite(spd)) or np.any(spd < 0):
            raise InputError(f"{where}: boat speeds must be finite and >= 0")
        object.__setattr__(self, "twa_deg", twa)
        object.__setattr__(self, "tws_ms", tws)
        object.__setattr__(self, "speed_ms", spd)

    def speed(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        """Boat speed [m s⁻¹] at TWS [m s⁻¹] and TWA [°] (any sign, broadcast)."""
        tws = np.asarray(tws_ms, dtype=float)
        a = np.abs(wrap180(twa_deg))
        # extended axes with zero at TWA 0 and TWS 0 where the table does not start there
        twa_ax, tws_ax, tab = self._extended()
        i = np.clip(np.searchsorted(twa_ax, a, side="right") - 1, 0, twa_ax.size - 2)
        fa = np.clip((a - twa_ax[i]) / (twa_ax[i + 1] - twa_ax[i]), 0.0, 1.0)
        if tws_ax.size == 1:
            return (1 - fa) * tab[i, 0] + fa * tab[i + 1, 0]
        j = np.clip(np.searchsorted(tws_ax, tws, side="right") - 1, 0, tws_ax.size - 2)
        fw = np.clip((tws - tws_ax[j]) / (tws_ax[j + 1] - tws_ax[j]), 0.0, 1.0)
        return (
            (1 - fa) * (1 - fw) * tab[i, j]
            + fa * (1 - fw) * tab[i + 1, j]
            + (1 - fa) * fw * tab[i, j + 1]
            + fa * fw * tab[i + 1, j + 1]
        )

    def _extended(self) -> tuple[NDArray, NDArray, NDArray]:
        cache = self.__dict__.get("_ext")
        if cache is not None:
            return cache
        twa, tws, tab = self.twa_deg, self.tws_ms, self.speed_ms
        if twa[0] > 0:
            twa = np.concatenate([[0.0], twa])
            tab = np.vstack([np.zeros((1, tab.shape[1])), tab])
        if tws[0] > 0:
            tws = np.concatenate([[0.0], tws])
            tab = np.hstack([np.zeros((tab.shape[0], 1)), tab])
        ext = (twa, tws, tab)
        object.__setattr__(self, "_ext", ext)
        return ext

    def best_vmg(
        self, tws_ms: ArrayLike, upwind: bool = True, step_deg: float = 0.05
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Optimal VMG angle and VMG at each TWS, by dense search.

        Parameters
        ----------
        tws_ms : array_like
            True wind speed [m s⁻¹].
        upwind : bool
            Upwind (maximise ``bsp cos twa``) or downwind (maximise ``-bsp cos twa``).
        step_deg : float
            Search resolution [°].

        Returns
        -------
        twa_deg, vmg_ms : ndarray
            Best angle [°] and the VMG [m s⁻¹] (positive) at that angle.
        """
        tws = np.atleast_1d(np.asarray(tws_ms, dtype=float))
        angles = np.arange(0.0, 180.0 + step_deg / 2, step_deg)
        sp = self.speed(tws[:, None], angles[None, :])
        vmg = sp * np.cos(np.radians(angles))[None, :] * (1.0 if upwind else -1.0)
        k = np.argmax(vmg, axis=1)
        shape = np.shape(tws_ms)
        return angles[k].reshape(shape), vmg[np.arange(tws.size), k].reshape(shape)
