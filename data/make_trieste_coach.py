"""Convert the Anemomind coach-boat log to the canonical station CSV schema.

Source: ../shared/data/real/wind/anemomind-coach-trieste/coach_wind_1hz.csv (itself a
CSV conversion of jpilet/anemomind datasets/astradata/Coach/log1Hz20180215_0957.log,
commit c54b198, MIT-style licence).  Output: data/trieste-coach-2018-02-15.csv with

    time (ISO 8601, +01:00), station (coach), lat, lon, speed (knots), direction (deg, from)

Assumption: the logger clock is local civil time, CET = UTC+01:00 in February (the
source does not state it).  Rows are kept as logged, including 14 repeated
timestamps from the logger's 1 s clock (read them with ``resample_s``).

    python data/make_trieste_coach.py [source.csv]
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE = (
    HERE.parents[1]
    / "shared"
    / "data"
    / "real"
    / "wind"
    / "anemomind-coach-trieste"
    / ("coach_wind_1hz.csv")
)
OUT = HERE / "trieste-coach-2018-02-15.csv"
OFFSET = "+01:00"


def main(source: Path = SOURCE, out: Path = OUT) -> Path:
    with open(source, newline="") as f:
        rows = list(csv.DictReader(f))
    with open(out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["time", "station", "lat", "lon", "speed", "direction"])
        for r in rows:
            w.writerow(
                [
                    r["datetime_local"] + OFFSET,
                    "coach",
                    r["lat"],
                    r["lon"],
                    r["tws_kn"],
                    r["twd_deg"],
                ]
            )
    return out


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else SOURCE))
