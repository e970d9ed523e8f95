"""Optional xarray support: the lazy import, and an xarray Dataset seen as a netCDF4 Dataset.

The NetCDF readers (:mod:`sailroute.wind.wrf`, :mod:`sailroute.wind.cf`) are written
against the small part of the ``netCDF4.Dataset`` interface they use: ``variables``
(``dimensions``, ``shape``, ``ndim``, attributes, orthogonal ``[...]`` indexing),
``dimensions``, ``ncattrs()``/``getncattr()`` and the context manager.
:class:`XarrayAsNetCDF` offers the same for an in-memory :class:`xarray.Dataset`, so
one reader serves files and datasets.  xarray itself is an optional extra
(``pip install 'sailroute[xarray]'``): imported only here, and only when asked for.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Mapping
from typing import Any, ParamSpec, TypeVar

import numpy as np

from sailroute.errors import InputError, WindDataError

P = ParamSpec("P")
R = TypeVar("R")


def require_xarray(what: str) -> Any:
    """Import xarray, or raise an :class:`InputError` that says how to install it.

    Parameters
    ----------
    what : str
        The feature that needs it (for the message).
    """
    try:
        import xarray
    except ImportError:
        raise InputError(
            f"{what} needs the optional package xarray, which is not installed; install it "
            "with `pip install 'sailroute[xarray]'` (or `pip install xarray`)"
        ) from None
    return xarray


def is_xarray_dataset(obj: Any) -> bool:
    """True for an :class:`xarray.Dataset`, without importing xarray when it is not loaded."""
    import sys

    xr = sys.modules.get("xarray")
    return xr is not None and isinstance(obj, xr.Dataset)


class _Var:
    """One xarray variable behind the netCDF4.Variable interface."""

    def __init__(self, name: str, var: Any) -> None:
        self._name = name
        self._var = var
        self.dimensions: tuple[str, ...] = tuple(str(d) for d in var.dims)
        self.shape: tuple[int, ...] = tuple(int(n) for n in var.shape)
        self.ndim = len(self.shape)
        self.dtype = var.dtype
        attrs = dict(var.attrs)
        # decoded CF times keep their units in .encoding; expose them like netCDF4 would
        for key in ("units", "calendar"):
            if key not in attrs and key in getattr(var, "encoding", {}):
                attrs[key] = var.encoding[key]
        self._attrs = attrs

    def ncattrs(self) -> list[str]:
        return list(self._attrs)

    def getncattr(self, key: str) -> Any:
        return self._attrs[key]

    def __getattr__(self, key: str) -> Any:
        attrs = self.__dict__.get("_attrs", {})
        if key in attrs:
            return attrs[key]
        raise AttributeError(key)

    def __getitem__(self, index: Any) -> np.ndarray:
        a = self._var[index] if index != () else self._var
        return np.asarray(a.values)


class XarrayAsNetCDF:
    """An :class:`xarray.Dataset` with the netCDF4.Dataset interface the readers use.

    Parameters
    ----------
    ds : xarray.Dataset
        The dataset (coordinates count as variables, as in a file).
    label : str
        Name used in messages in place of a file name.
    """

    def __init__(self, ds: Any, label: str = "xarray.Dataset") -> None:
        self._ds = ds
        self.label = label
        self.variables: Mapping[str, _Var] = {
            str(k): _Var(str(k), v) for k, v in ds.variables.items()
        }
        self.dimensions: Mapping[str, int] = {str(k): int(n) for k, n in ds.sizes.items()}
        self._attrs = dict(ds.attrs)

    def ncattrs(self) -> list[str]:
        return list(self._attrs)

    def getncattr(self, key: str) -> Any:
        return self._attrs[key]

    def set_auto_mask(self, flag: bool) -> None:
        """No-op: xarray has already decoded fill values to NaN."""

    def __enter__(self) -> XarrayAsNetCDF:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def __iter__(self) -> Iterator[str]:
        return iter(self.variables)


SOURCE_ATTR = "sailroute_source"
"""Dataset attribute naming the file an in-memory dataset came from (set for GRIB)."""

_GRIB_SUFFIXES = (".grib", ".grb", ".grib2", ".grb2")


def open_dataset(source: Any, kind: str, expected: str) -> tuple[Any, str]:
    """A netCDF4-like dataset and its label, for a path or an xarray Dataset.

    Parameters
    ----------
    source : str, Path or xarray.Dataset
        The file, or a dataset already in memory.
    kind : str
        What the file is, for messages (``"NetCDF"``, ``"WRF"``).
    expected : str
        What a readable file holds, for messages (``"a WRF wrfout NetCDF file"``).

    Raises
    ------
    InputError
        The file does not exist.
    WindDataError
        It is empty, not NetCDF (a GRIB file is pointed to ``type: grib``), or a classic
        NetCDF file whose header does not fit in it
        (:func:`~sailroute.wind.ncheader.check_classic_header`).
    """
    from pathlib import Path

    if is_xarray_dataset(source):
        label = str(source.attrs.get(SOURCE_ATTR, "xarray.Dataset"))
        return XarrayAsNetCDF(source, label=label), label
    import netCDF4

    p = Path(source)
    if not p.is_file():
        raise InputError(
            f"{p}: {kind} file not found; check the `path` (relative to the course file's folder)"
        )
    if p.stat().st_size == 0:
        raise WindDataError(f"{p}: the file is empty (0 bytes); expected {expected}")
    from sailroute.wind.ncheader import check_classic_header

    check_classic_header(p)
    try:
        ds = netCDF4.Dataset(str(p), "r")
    except UnicodeDecodeError:  # a damaged file: the names of its variables are not text
        raise WindDataError(
            f"{p}: cannot be read as NetCDF (variable or attribute names that "
            f"are not UTF-8: the file is damaged); expected {expected}."
        ) from None
    except RuntimeError as exc:  # the library found the file damaged after opening it
        raise WindDataError(
            f"{p}: cannot be read as NetCDF ({exc}: the file is damaged); expected {expected}."
        ) from None
    except OSError as exc:
        hint = (
            " GRIB files are read with `type: grib`." if p.suffix.lower() in _GRIB_SUFFIXES else ""
        )
        raise WindDataError(
            f"{p}: cannot be read as NetCDF ({exc}); expected {expected}.{hint}"
        ) from None
    ds.set_auto_mask(True)
    return ds, str(p)


def damaged_as_wind_error(fn: Callable[P, R]) -> Callable[P, R]:
    """Decorate a reader whose first argument is a file (or dataset): a ``RuntimeError`` of
    the netCDF library while it reads (``NetCDF: HDF error`` of a damaged file) becomes a
    :class:`~sailroute.errors.WindDataError` naming the file."""

    @functools.wraps(fn)
    def read(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return fn(*args, **kwargs)
        except RuntimeError as exc:
            src = args[0] if args else "the file"
            label = "xarray.Dataset" if is_xarray_dataset(src) else str(src)
            raise WindDataError(
                f"{label}: cannot read the NetCDF data ({exc}: the file is "
                "damaged); copy or download it again"
            ) from None

    return read
