"""Regenerate the small real-data excerpts in this folder from ../shared/data/real.

Run from the repository root:  python tests/data/wind/make_crops.py
Only files whose licence permits redistribution are cropped (see README.md).
"""

from __future__ import annotations

import csv
from pathlib import Path

import netCDF4

HERE = Path(__file__).resolve().parent
REAL = HERE.parents[2].parent / "shared" / "data" / "real"


def crop_wrf(
    src: Path, dst: Path, *, j: slice, i: slice, nlev: int, note: str, variables: tuple[str, ...]
) -> None:
    """Copy a window of a wrfout file, keeping dimensions, attributes and staggering."""
    with netCDF4.Dataset(src) as s, netCDF4.Dataset(dst, "w", format="NETCDF4") as d:
        d.setncatts({k: s.getncattr(k) for k in s.ncattrs()})
        d.setncattr("SAILROUTE_CROP", note)
        ny = len(range(*j.indices(s.dimensions["south_north"].size)))
        nx = len(range(*i.indices(s.dimensions["west_east"].size)))
        sizes = {
            "south_north": ny,
            "west_east": nx,
            "south_north_stag": ny + 1,
            "west_east_stag": nx + 1,
            "bottom_top": nlev,
            "bottom_top_stag": nlev + 1,
        }
        for name, dim in s.dimensions.items():
            if name in ("soil_layers_stag",):
                continue
            d.createDimension(name, None if dim.isunlimited() else sizes.get(name, dim.size))
        for name in variables:
            v = s.variables[name]
            idx = []
            for dim in v.dimensions:
                if dim == "south_north":
                    idx.append(j)
                elif dim == "west_east":
                    idx.append(i)
                elif dim == "south_north_stag":
                    idx.append(slice(j.start, j.stop + 1))
                elif dim == "west_east_stag":
                    idx.append(slice(i.start, i.stop + 1))
                elif dim == "bottom_top":
                    idx.append(slice(0, nlev))
                elif dim == "bottom_top_stag":
                    idx.append(slice(0, nlev + 1))
                else:
                    idx.append(slice(None))
            out = d.createVariable(name, v.dtype, v.dimensions, zlib=True, complevel=6)
            out.setncatts({k: v.getncattr(k) for k in v.ncattrs()})
            out[:] = v[tuple(idx)]


def crop_result(src: Path, dst: Path, *, j: slice, i: slice, nlev: int) -> None:
    """wrf-python's expected diagnostics (time 0) for the same window."""
    with netCDF4.Dataset(src) as s, netCDF4.Dataset(dst, "w", format="NETCDF4") as d:
        d.setncattr(
            "SAILROUTE_CROP",
            f"south_north {j.start}:{j.stop}, west_east "
            f"{i.start}:{i.stop}, bottom_top 0:{nlev} of ci_result_file.nc",
        )
        ny, nx = j.stop - j.start, i.stop - i.start
        d.createDimension("u_v", 2)
        d.createDimension("bottom_top", nlev)
        d.createDimension("south_north", ny)
        d.createDimension("west_east", nx)
        d.createDimension("lat_lon", 2)
        d.createDimension("x_y", 2)
        for name, dims, idx in (
            ("uvmet10", ("u_v", "south_north", "west_east"), (slice(None), j, i)),
            ("ua", ("bottom_top", "south_north", "west_east"), (slice(0, nlev), j, i)),
            ("va", ("bottom_top", "south_north", "west_east"), (slice(0, nlev), j, i)),
            ("z", ("bottom_top", "south_north", "west_east"), (slice(0, nlev), j, i)),
            ("ll", ("lat_lon",), (slice(None),)),
            ("xy", ("x_y",), (slice(None),)),
        ):
            v = s.variables[name]
            out = d.createVariable(name, v.dtype, dims, zlib=True, complevel=6)
            out.setncatts({k: v.getncattr(k) for k in v.ncattrs() if k != "_FillValue"})
            out[:] = v[idx]


def excerpt_csv(src: Path, dst: Path, rows: list[range]) -> None:
    with open(src, newline="") as f:
        lines = f.read().splitlines()
    keep = [lines[0]] + [lines[k + 1] for r in rows for k in r]
    dst.write_text("\n".join(keep) + "\n")


def excerpt_ndbc_txt(src: Path, dst: Path, times: set[str]) -> None:
    lines = src.read_text().splitlines()
    keep = lines[:2]
    for ln in lines[2:]:
        f = ln.split()
        stamp = f"{f[0]}-{f[1]}-{f[2]}T{f[3]}:{f[4]}:00Z"
        if stamp in times:
            keep.append(ln)
    dst.write_text("\n".join(keep) + "\n")


def main() -> None:
    ci = REAL / "wrf" / "wrf-python-ci"
    base = ("Times", "XLAT", "XLONG", "U10", "V10", "HGT", "U", "V", "PH", "PHB")
    crop_wrf(
        ci / "ci_test_file.nc",
        HERE / "wrfpython_ci_crop.nc",
        j=slice(0, 16),
        i=slice(0, 24),
        nlev=2,
        variables=base,
        note="south_north 0:16, west_east 0:24, bottom_top 0:2 of wrf-python "
        "test/ci_tests/ci_test_file.nc (commit 59018ff)",
    )
    crop_result(
        ci / "ci_result_file.nc",
        HERE / "wrfpython_ci_result_crop.nc",
        j=slice(0, 16),
        i=slice(0, 24),
        nlev=2,
    )
    sal = REAL / "wrf" / "salem"
    crop_wrf(
        sal / "wrf_d01_allvars_cropped.nc",
        HERE / "salem_lambert_crop.nc",
        j=slice(0, 8),
        i=slice(0, 10),
        nlev=2,
        variables=(*base, "COSALPHA", "SINALPHA"),
        note="all 10 x 8 columns, bottom_top 0:2, 12 of 147 variables of salem-sample-data "
        "salem-test/grid/wrf_d01_allvars_cropped.nc (commit 8ad39d1)",
    )
    nd = REAL / "wind" / "ndbc-41008-cwind"
    rows = [range(96, 127), range(4240, 4256)]
    excerpt_csv(nd / "41008_cwind_2018.csv", HERE / "ndbc_41008_excerpt.csv", rows)
    with open(HERE / "ndbc_41008_excerpt.csv", newline="") as f:
        stamps = {r["time_utc"] for r in csv.DictReader(f)}
    excerpt_ndbc_txt(nd / "41008.cwind.txt", HERE / "ndbc_41008_excerpt.cwind.txt", stamps)
    co = REAL / "wind" / "anemomind-coach-trieste"
    excerpt_csv(co / "coach_wind_1hz.csv", HERE / "coach_wind_1hz_excerpt.csv", [range(0, 900)])
    print("wrote", sorted(p.name for p in HERE.iterdir() if p.suffix in (".nc", ".csv", ".txt")))


if __name__ == "__main__":
    main()
