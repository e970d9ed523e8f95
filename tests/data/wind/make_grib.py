"""Write ``wind_10m_synthetic.grib2``: a small GRIB 2 file of 10 m wind for the GRIB tests.

Run from the repository root: ``python tests/data/wind/make_grib.py`` (needs the ``grib``
extra: eccodes).  Everything in the file is computed here, no third-party data: two
forecast steps (2014-10-07 12:00Z + 0 h and + 1 h) of ``10u``/``10v`` on a 13 x 17
regular 0.05 deg latitude/longitude grid (42.7..43.3 N, 6.6..7.4 E, stored north to
south as GRIB does by default), packed with 16 bits per value, built from eccodes'
own ``regular_ll_sfc_grib2`` sample.  The winds are linear in latitude/longitude, so
tests know the answer at every point:

    u = 5 + 10 (lat - 43) + step_h,   v = -3 + 20 (lon - 7) - step_h   [m/s]
"""

from pathlib import Path

import eccodes as ec
import numpy as np

OUT = Path(__file__).with_name("wind_10m_synthetic.grib2")


def main() -> None:
    lats = np.round(np.arange(43.3, 42.69, -0.05), 2)
    lons = np.round(np.arange(6.6, 7.41, 0.05), 2)
    lat, lon = np.meshgrid(lats, lons, indexing="ij")
    with open(OUT, "wb") as out:
        for step in (0, 1):
            for short, vals in (
                ("10u", 5 + 10 * (lat - 43) + step),
                ("10v", -3 + 20 * (lon - 7) - step),
            ):
                h = ec.codes_grib_new_from_samples("regular_ll_sfc_grib2")
                for key, value in (
                    ("Ni", lons.size),
                    ("Nj", lats.size),
                    ("latitudeOfFirstGridPointInDegrees", float(lats[0])),
                    ("latitudeOfLastGridPointInDegrees", float(lats[-1])),
                    ("longitudeOfFirstGridPointInDegrees", float(lons[0])),
                    ("longitudeOfLastGridPointInDegrees", float(lons[-1])),
                    ("iDirectionIncrementInDegrees", 0.05),
                    ("jDirectionIncrementInDegrees", 0.05),
                    ("dataDate", 20141007),
                    ("dataTime", 1200),
                    ("stepUnits", 1),
                    ("forecastTime", step),
                    ("shortName", short),
                    ("bitsPerValue", 16),
                ):
                    ec.codes_set(h, key, value)
                ec.codes_set_values(h, vals.ravel())
                ec.codes_write(h, out)
                ec.codes_release(h)


if __name__ == "__main__":
    main()
