"""Wind on a (curvilinear) structured grid in time: the field behind WRF sources.

Sampling is done in *index space*.  A WRF grid is regular in its own map
projection, not in the course's local frame, so a least-squares polynomial
``(x, y) -> (i, j)`` of the lowest degree (1 = affine, up to 5) that reproduces
every cell centre to within ``map_tolerance_cells`` (default 0.01 cells = 1 % of
DX) is fitted once.  A sample point's fractional indices then give bilinear
(or nearest-cell) weights, and times are interpolated linearly between slices,
or frozen per block of ``time_step_s`` (thesis's 60/30/10-min scenarios).

Everything is vectorised; u and v travel together as one complex array so each
corner costs one gather.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.timeutil import iso
from sailroute.wind.base import Coverage, prepare_points

if TYPE_CHECKING:
    from sailroute.geo import LocalFrame

MAX_MAP_DEGREE = 5


@dataclass(frozen=True)
class IndexMap:
    """Polynomial map from local ``(x, y)`` [m] to fractional grid indices ``(i, j)``.

    Attributes
    ----------
    degree : int
        Total polynomial degree.
    x0, y0, scale : float
        Normalisation: the polynomial is evaluated at ``((x - x0)/scale, (y - y0)/scale)``.
    ci, cj : ndarray
        Coefficients of the monomials ``X^p Y^q`` (``p + q <= degree``, ``p``-major order).
    residual_cells : float
        Largest misfit at the cell centres it was fitted on [cells].
    """

    degree: int
    x0: float
    y0: float
    scale: float
    ci: NDArray[np.float64]
    cj: NDArray[np.float64]
    residual_cells: float

    def __call__(self, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        """Fractional indices ``(i, j)`` of local points ``(x, y)`` [m]."""
        X = (x - self.x0) * (1.0 / self.scale)
        Y = (y - self.y0) * (1.0 / self.scale)
        if self.degree == 1:
            ci, cj = self.ci, self.cj  # monomials: 1, Y, X
            return ci[0] + ci[1] * Y + ci[2] * X, cj[0] + cj[1] * Y + cj[2] * X
        fi = np.zeros_like(X)
        fj = np.zeros_like(X)
        k = 0
        xp = np.ones_like(X)
        for p in range(self.degree + 1):
            term = xp
            for q in range(self.degree + 1 - p):
                if q:
                    term = term * Y
                fi += self.ci[k] * term
                fj += self.cj[k] * term
                k += 1
            if p < self.degree:
                xp = xp * X
        return fi, fj


def _monomials(X: NDArray, Y: NDArray, degree: int) -> NDArray:
    cols = []
    for p in range(degree + 1):
        for q in range(degree + 1 - p):
            cols.append(X**p * Y**q)
    return np.stack(cols, axis=-1)


def fit_index_map(
    x: NDArray, y: NDArray, *, tolerance_cells: float = 0.01, name: str = "grid"
) -> IndexMap:
    """Fit the lowest-degree polynomial ``(x, y) -> (i, j)`` within ``tolerance_cells``.

    Parameters
    ----------
    x, y : ndarray, shape (ny, nx)
        Local coordinates of the cell centres [m]; ``i`` runs along axis 1, ``j`` along axis 0.
    tolerance_cells : float
        Largest accepted misfit at any cell centre [cells].
    name : str
        Label for the error message.

    Returns
    -------
    IndexMap

    Raises
    ------
    WindDataError
        If even degree 5 misfits by more than the tolerance (a huge or folded grid).
    """
    ny, nx = x.shape
    jj, ii = np.mgrid[0:ny, 0:nx]
    x0, y0 = float(np.mean(x)), float(np.mean(y))
    scale = float(max(np.ptp(x), np.ptp(y), 1.0))
    X = ((x - x0) / scale).ravel()
    Y = ((y - y0) / scale).ravel()
    best = None
    for degree in range(1, MAX_MAP_DEGREE + 1):
        nterms = (degree + 1) * (degree + 2) // 2
        if nterms > X.size:
            break
        A = _monomials(X, Y, degree)
        ci, *_ = np.linalg.lstsq(A, ii.ravel().astype(float), rcond=None)
        cj, *_ = np.linalg.lstsq(A, jj.ravel().astype(float), rcond=None)
        res = float(max(np.max(np.abs(A @ ci - ii.ravel())), np.max(np.abs(A @ cj - jj.ravel()))))
        best = IndexMap(degree, x0, y0, scale, ci, cj, res)
        if res <= tolerance_cells:
            return best
    raise WindDataError(
        f"{name}: the grid cannot be mapped to the local frame to within {tolerance_cells:g} "
        f"cells (best misfit {best.residual_cells if best else float('nan'):.3g} cells); "
        "crop the data to the course area (a smaller `margin_m`) or check XLAT/XLONG"
    )


@dataclass(frozen=True, eq=False)
class _GridState:
    """What a :class:`GridWind` derives from its inputs (built once, when it is made)."""

    t: NDArray  # slice times [epoch s]
    uv: NDArray  # u + i v, shape (nt, ny * nx) [m s⁻¹]
    map: IndexMap  # local frame -> grid indices
    cov: Coverage
    has_nan: bool  # some winds are NaN (allow_nan)


@dataclass(frozen=True, eq=False)
class GridWind:
    """Wind on a structured grid of cell centres, at a series of times.

    Parameters
    ----------
    times : array_like, shape (nt,)
        Epoch seconds [s] of the slices, strictly increasing.
    x, y : array_like, shape (ny, nx)
        Local coordinates of the cell centres [m] (a smooth, non-folded grid
        whose axis 1 runs roughly east and axis 0 roughly north).
    u, v : array_like, shape (nt, ny, nx)
        Local-frame wind components [m s⁻¹].
    interpolation : {"linear", "nearest"}
        In space: bilinear in grid-index space, or the nearest cell centre.
    time_step_s : float, optional
        Freeze the wind per block of this length [s]: a time ``t`` uses the field
        at ``floor(t / time_step_s) * time_step_s`` (UTC-aligned block start,
        clipped to the data), held constant through the block.  ``None``: linear
        in time between slices.
    clamp : bool
        Clamp points to the coverage instead of raising
        :class:`~sailroute.errors.OutOfCoverageError`.
    name : str
        Label used in messages.
    info : mapping
        Provenance and diagnostics (file, levels, map residual, ...).
    map_tolerance_cells : float
        Accepted misfit of the local-frame index map [cells].
    frame : LocalFrame, optional
        The local frame ``x``/``y`` are in.  Lets messages give positions in
        latitude/longitude and :meth:`to_xarray` write true east/north winds.
    source_span : (float, float), optional
        Time span of the whole file [epoch s] when only some slices were read;
        named in coverage messages.
    allow_nan : bool
        Accept NaN winds (land or masked cells of a sea-only product).  Sampling
        where the interpolation touches such a cell raises
        :class:`~sailroute.errors.OutOfCoverageError` naming the place; without
        this flag NaN winds are refused when the field is built.
    steady : bool
        Only for a single time slice: hold it at all times (time coverage
        unbounded) instead of covering just that instant.

    Notes
    -----
    Coverage is the time span of the slices and the largest axis-aligned box
    inside the grid's footprint (the cell centres on the outer ring bound it).
    """

    times: ArrayLike
    x: ArrayLike
    y: ArrayLike
    u: ArrayLike
    v: ArrayLike
    interpolation: str = "linear"
    time_step_s: float | None = None
    clamp: bool = False
    name: str = "gridded wind"
    info: Mapping[str, Any] = field(default_factory=dict)
    map_tolerance_cells: float = 0.01
    frame: LocalFrame | None = None
    source_span: tuple[float, float] | None = None
    allow_nan: bool = False
    steady: bool = False

    def __post_init__(self) -> None:
        self._state  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _state(self) -> _GridState:
        """Arrays, index map and coverage derived from the inputs (checked here)."""
        t = np.asarray(self.times, dtype=float).ravel()
        x = np.asarray(self.x, dtype=float)
        y = np.asarray(self.y, dtype=float)
        u = np.asarray(self.u, dtype=float)
        v = np.asarray(self.v, dtype=float)
        if x.ndim != 2 or x.shape != y.shape or min(x.shape) < 2:
            raise InputError(
                f"{self.name}: x and y must be 2-D arrays of the same shape with at least "
                f"2 x 2 cells, got {x.shape} and {y.shape}"
            )
        if u.shape != (t.size, *x.shape) or v.shape != u.shape:
            raise InputError(
                f"{self.name}: u and v must have shape (times, ny, nx) = "
                f"{(t.size, *x.shape)}, got {u.shape} and {v.shape}"
            )
        if t.size == 0 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
            raise InputError(f"{self.name}: times must be finite and strictly increasing")
        for label, a in (("x", x), ("y", y), ("u", u), ("v", v)):
            ok = np.isfinite(a) | (np.isnan(a) if self.allow_nan and label in "uv" else False)
            if not np.all(ok):
                hint = (
                    ""
                    if label in "xy"
                    else (
                        "; pass allow_nan=True to keep NaN (land) cells as holes that routing "
                        "must not cross"
                    )
                )
                raise InputError(f"{self.name}: {label} contains NaN or infinite values{hint}")
        if self.steady and t.size != 1:
            raise InputError(
                f"{self.name}: steady=True holds a single time slice at all "
                f"times, but there are {t.size} slices"
            )
        if self.interpolation not in ("linear", "nearest"):
            raise InputError(
                f"{self.name}: interpolation {self.interpolation!r}; expected 'linear' or 'nearest'"
            )
        if self.time_step_s is not None and not (self.time_step_s > 0):
            raise InputError(
                f"{self.name}: time_step_s must be a positive number of seconds or None, "
                f"got {self.time_step_s!r}"
            )
        # The outer ring bounds the footprint; axis 1 must run east, axis 0 north.
        xmin, xmax = float(np.max(x[:, 0])), float(np.min(x[:, -1]))
        ymin, ymax = float(np.max(y[0, :])), float(np.min(y[-1, :]))
        if not (xmin < xmax and ymin < ymax):
            raise WindDataError(
                f"{self.name}: the grid's first axis must run south to north and its second "
                "west to east in the local frame (a grid rotated by more than ~45 degrees or "
                "mirrored is not supported)"
            )
        imap = fit_index_map(x, y, tolerance_cells=self.map_tolerance_cells, name=self.name)
        uv = np.ascontiguousarray((u + 1j * v).reshape(t.size, -1))
        t0, t1 = (-np.inf, np.inf) if self.steady else (float(t[0]), float(t[-1]))
        cov = Coverage(
            t0, t1, xmin, xmax, ymin, ymax, frame=self.frame, source_span=self.source_span
        )
        return _GridState(t, uv, imap, cov, bool(np.isnan(uv).any()))

    @property
    def coverage(self) -> Coverage:
        """Time span of the slices and the box inside the grid footprint."""
        return self._state.cov

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(nt, ny, nx)``."""
        ny, nx = np.shape(self.x)
        return (self._state.t.size, ny, nx)

    @property
    def index_map(self) -> IndexMap:
        """The fitted local-frame -> grid-index map."""
        return self._state.map

    def grid_indices(self, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Fractional grid indices ``(i, j)`` (column, row) of local points [m]."""
        return self._state.map(np.asarray(x, dtype=float), np.asarray(y, dtype=float))

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and local ``x, y`` [m] (broadcast).

        Raises
        ------
        OutOfCoverageError
            Outside the coverage (unless ``clamp``), NaN points, or points whose
            interpolation touches a NaN (land) cell of an ``allow_nan`` field.
        """
        return self._sample(t, x, y, refuse_nan=True)

    def sample_with_holes(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray, NDArray]:
        """As :meth:`sample`, but NaN where the data hold no wind (for statistics over an area)."""
        return self._sample(t, x, y, refuse_nan=False)

    def _sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike, *, refuse_nan: bool
    ) -> tuple[NDArray, NDArray]:
        t, x, y = prepare_points(self._state.cov, t, x, y, clamp=self.clamp, name=self.name)
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        nt, ny, nx = self.shape
        tt = self._state.t
        if self.time_step_s is not None:
            t = np.clip(np.floor(t / self.time_step_s) * self.time_step_s, tt[0], tt[-1])
        fi, fj = self._state.map(x, y)
        np.clip(fi, 0.0, nx - 1.0, out=fi)
        np.clip(fj, 0.0, ny - 1.0, out=fj)
        uv = self._state.uv
        if nt == 1:
            k = np.zeros(t.shape, dtype=np.intp)
            wt = None
        else:
            k = np.searchsorted(tt, t, side="right") - 1
            np.clip(k, 0, nt - 2, out=k)
            wt = (t - tt[k]) / (tt[k + 1] - tt[k])
            np.clip(wt, 0.0, 1.0, out=wt)
        ncell = ny * nx
        flat = uv.ravel()
        if self.interpolation == "nearest":
            cell = np.rint(fj).astype(np.intp) * nx + np.rint(fi).astype(np.intp)
            base = k * ncell + cell
            out = flat.take(base)
            if wt is not None:
                out = out + wt * (flat.take(base + ncell) - out)
        else:
            i0 = np.minimum(fi.astype(np.intp), nx - 2)
            j0 = np.minimum(fj.astype(np.intp), ny - 2)
            wx = fi - i0
            wy = fj - j0
            base = k * ncell + j0 * nx + i0
            out = _bilinear(flat, base, nx, wx, wy)
            if wt is not None:
                out = out + wt * (_bilinear(flat, base + ncell, nx, wx, wy) - out)
        if self._state.has_nan and refuse_nan:
            self._refuse_nan(out, t, x, y)
        return out.real.reshape(shape).copy(), out.imag.reshape(shape).copy()

    def _refuse_nan(self, out: NDArray, t: NDArray, x: NDArray, y: NDArray) -> None:
        bad = np.isnan(out)
        if not bad.any():
            return
        k = int(np.argmax(bad))
        where = f"x {x[k]:.0f} m, y {y[k]:.0f} m"
        if self.frame is not None:
            la, lo = self.frame.to_latlon(x[k], y[k])
            where = f"lat {float(la):.5f}, lon {float(lo):.5f} ({where})"
        raise OutOfCoverageError(
            f"{self.name}: the data hold no wind (NaN: land or masked cells) at "
            f"{int(bad.sum())} of {bad.size} sample points, first at {where}, "
            f"{iso(float(t[k]))}. The route would cross cells without wind data; move the "
            "course (or its bounding box) away from the masked area, or use data that are "
            "complete there."
        )

    def to_xarray(self) -> Any:
        """The field as an :class:`xarray.Dataset` (needs the ``xarray`` extra).

        Returns
        -------
        xarray.Dataset
            Dimensions ``(time, j, i)`` (rows south to north, columns west to east).
            Data variables ``u``, ``v``: local-frame components [m s⁻¹]; with a
            :attr:`frame` also ``eastward_wind``/``northward_wind`` (true east/north,
            CF standard names) and ``lat``/``lon`` coordinates, so the dataset is CF
            and :func:`sailroute.wind.cf.open_netcdf` reads it back.  Coordinates
            ``time`` (UTC, ``datetime64[ns]``), ``x``/``y`` [m].  Attributes: the
            field's name, frame origin, interpolation and ``time_step_s``.
        """
        from sailroute.wind._xr import require_xarray

        xr = require_xarray("GridWind.to_xarray()")
        nt, ny, nx = self.shape
        uv = self._state.uv.reshape(nt, ny, nx)
        x = np.asarray(self.x, dtype=float)
        y = np.asarray(self.y, dtype=float)
        dims = ("time", "j", "i")
        ms = {"units": "m s-1"}
        data: dict[str, Any] = {
            "u": (dims, uv.real.copy(), {**ms, "long_name": "wind towards +x (local frame)"}),
            "v": (dims, uv.imag.copy(), {**ms, "long_name": "wind towards +y (local frame)"}),
        }
        coords: dict[str, Any] = {
            "time": ("time", (self._state.t * 1e9).astype("int64").astype("datetime64[ns]")),
            "x": (("j", "i"), x, {"units": "m", "long_name": "metres east of the origin"}),
            "y": (("j", "i"), y, {"units": "m", "long_name": "metres north of the origin"}),
        }
        attrs: dict[str, Any] = {
            "title": self.name,
            "interpolation": self.interpolation,
            "source": "sailroute GridWind",
        }
        if self.time_step_s is not None:
            attrs["time_step_s"] = float(self.time_step_s)
        if self.frame is not None:
            from sailroute.wind.rotation import rotate_clockwise

            lat, lon = self.frame.to_latlon(x, y)
            gn = self.frame.grid_north_deg(lat, lon)
            ue, ve = rotate_clockwise(uv.real, uv.imag, -gn)
            coords["lat"] = (
                ("j", "i"),
                lat,
                {"standard_name": "latitude", "units": "degrees_north"},
            )
            coords["lon"] = (
                ("j", "i"),
                lon,
                {"standard_name": "longitude", "units": "degrees_east"},
            )
            data["eastward_wind"] = (dims, ue, {**ms, "standard_name": "eastward_wind"})
            data["northward_wind"] = (dims, ve, {**ms, "standard_name": "northward_wind"})
            attrs["frame_lat0"] = float(self.frame.lat0)
            attrs["frame_lon0"] = float(self.frame.lon0)
            attrs["Conventions"] = "CF-1.8"
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _bilinear(flat: NDArray, base: NDArray, nx: int, wx: NDArray, wy: NDArray) -> NDArray:
    """Bilinear blend of the 4 cells whose lower-left corner is ``base`` (flat index)."""
    a = flat.take(base)
    b = flat.take(base + 1)
    c = flat.take(base + nx)
    d = flat.take(base + nx + 1)
    lo = a + wx * (b - a)
    hi = c + wx * (d - c)
    return lo + wy * (hi - lo)
