"""Race polar against real races: downwind/upwind time ratio and totals, per race.

Usage::

    python benchmarks/race_polar_validation.py [--boat ilca7] [--boat ilca7-steady] [--sensitivity]
    python benchmarks/race_polar_validation.py --smoke   # ilca7 on Snipe P01 only, 30 s steps

For each race it routes the course with the built-in boat in the race's reported
wind (uniform) and compares with the observed leg times:

* **Hyères 2018 R1** (ILCA 7; ``courses/hyeres-r1.yaml``, scenario ``constant``,
  5.61 m/s from 108°): winner and top-10 leg times from the thesis (Fig 5.22/5.25).
* **Snipe Valencia 2025 P01 / P02** (Snipe; the ILCA is a stand-in, no Snipe polar
  exists in open data): marks and reported wind (TWD 110°, 6 kn P01 / 8 kn P02,
  the sailors' estimate) from ``../shared/data/real/races/snipe-valencia-2025``;
  rounding times from its README (both boats, mean).

The ratio is ``(downwind time / downwind legs) / (upwind time / upwind legs)``
with the same legs for model and observation, so leg lengths cancel.  Snipe:
runs B1->S1 (twice) against the second beat S1->B1 (the first beat includes the
start); the model routes the same marks.  Nothing here feeds back into the
model's parameters: this only measures.
"""

from __future__ import annotations

import argparse
import dataclasses
from datetime import datetime

from sailroute.course.load import course_from_mapping, load_course
from sailroute.course.model import Course, frozen_mapping
from sailroute.planning.route import plan_course

SNIPE = {
    # race: (TWS kn, B1 lat, B1 lon, observed [(run1, beat2, run2) per boat] from README times)
    "P01": (
        6.0,
        39.40691,
        -0.31500,
        [
            ("11:31:49", "11:37:14", "11:44:40", "11:49:10"),
            ("11:31:52", "11:37:16", "11:44:27", "11:48:49"),
        ],
    ),
    "P02": (
        8.0,
        39.40615,
        -0.31310,
        [
            ("12:15:58", "12:21:29", "12:30:34", "12:36:32"),
            ("12:15:51", "12:21:20", "12:29:46", "12:35:35"),
        ],
    ),
}
S1 = (39.40921, -0.32253)


def _s(hms: str) -> float:
    t = datetime.strptime(hms, "%H:%M:%S")
    return t.hour * 3600 + t.minute * 60 + t.second


def snipe_observed(race: str) -> tuple[float, float]:
    """Mean run and beat times [s] over both boats (runs B1->S1, beat S1->B1)."""
    runs, beats = [], []
    for b1, s1, b1b, fin in SNIPE[race][3]:
        runs += [_s(s1) - _s(b1), _s(fin) - _s(b1b)]
        beats.append(_s(b1b) - _s(s1))
    return sum(runs) / len(runs), sum(beats) / len(beats)


VARIANTS = {
    "race (defaults)": {},
    "pump_efficiency 0.5": {"pump_efficiency": 0.5},
    "pump_efficiency 0.87": {"pump_efficiency": 0.87},
    "sea_age_h 2": {"sea_age_h": 2.0},
    "sea_age_h 4": {"sea_age_h": 4.0},
    "fetch_m 10 km": {"fetch_m": 10_000.0},
    "upwind_efficiency 0.925 (P90)": {"upwind_efficiency": 0.925},
    "upwind_efficiency 1 (none)": {"upwind_efficiency": 1.0},
}
"""Race-model variants for ``--sensitivity``: one parameter moved across its plausible range."""


def snipe_course(race: str, boat: str | dict, dt_s: float = 10.0) -> Course:
    tws, lat, lon, _ = SNIPE[race]
    return course_from_mapping(
        {
            "name": f"Snipe Valencia 2025 {race} (ILCA stand-in)",
            "start_time": "2025-06-21T12:00:00+00:00",
            "time_limit_min": 90,
            "marks": {"S1": {"lat": S1[0], "lon": S1[1]}, "B1": {"lat": lat, "lon": lon}},
            "legs": [
                {"from": "S1", "to": "B1", "rounding": "port"},
                {"to": "S1", "rounding": "port"},
                {"to": "B1", "rounding": "port"},
                {"to": "S1", "rounding": "port"},
            ],
            "boat": {"builtin": boat} if isinstance(boat, str) else boat,
            "routing": {
                "router": "isochrone",
                "tack_penalty_s": 5.0,
                "gybe_penalty_s": 5.0,
                "dt_s": dt_s,
            },
            "scenarios": {"reported": {"wind": {"type": "uniform", "tws_kn": tws, "twd_deg": 110}}},
        },
        source=f"<snipe {race}>",
    )


def ratios(boat: dict) -> tuple[float, float, float, float]:
    """Hyères total error vs the winner and the dn/up ratio errors (Hyères, P01, P02)."""
    hy = dataclasses.replace(load_course("courses/hyeres-r1.yaml"), boat_spec=frozen_mapping(boat))
    t = [leg.time_s for leg in plan_course(hy, "constant").plan.legs]
    ref = hy.references["winner"]
    out = [
        sum(t) / sum(ref) - 1,
        (t[1] + t[3]) / (t[0] + t[2]) / ((ref[1] + ref[3]) / (ref[0] + ref[2])) - 1,
    ]
    for race in SNIPE:
        legs = [leg.time_s for leg in plan_course(snipe_course(race, boat)).plan.legs]
        run_o, beat_o = snipe_observed(race)
        out.append((legs[1] + legs[3]) / 2 / legs[2] / (run_o / beat_o) - 1)
    return tuple(out)


def sensitivity() -> None:
    """Print the acceptance numbers for each race-model variant."""
    print("| variant | Hyères total vs winner | Hyères dn/up | Snipe P01 dn/up | Snipe P02 dn/up |")
    print("|---|---|---|---|---|")
    for name, kin in VARIANTS.items():
        r = ratios({"vpp": {"class": "ilca7"}, "kinetics": kin or "race"})
        print(f"| {name} | " + " | ".join(f"{x:+.1%}" for x in r) + " |")


def smoke_row(boat: str) -> None:
    """The Snipe P01 row with 30 s steps (``--smoke``)."""
    legs = [leg.time_s for leg in plan_course(snipe_course("P01", boat, dt_s=30.0)).plan.legs]
    run_m, beat_m = (legs[1] + legs[3]) / 2, legs[2]
    run_o, beat_o = snipe_observed("P01")
    print(
        f"| {boat} | Snipe P01 (--smoke, 30 s steps) | 6 kn 110° | {run_m / beat_m:.3f} | "
        f"{run_o / beat_o:.3f} | {run_m / beat_m / (run_o / beat_o) - 1:+.1%} | "
        f"run {run_m:.0f} s, beat {beat_m:.0f} s | run {run_o:.0f} s, beat {beat_o:.0f} s | "
        f"run {run_m / run_o - 1:+.1%}, beat {beat_m / beat_o - 1:+.1%} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--boat", action="append", default=None)
    ap.add_argument(
        "--sensitivity",
        action="store_true",
        help="also move each race-model parameter across its range",
    )
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="ilca7 on Snipe P01 only, 30 s steps (checks the script runs)",
    )
    args = ap.parse_args()
    boats = ["ilca7"] if args.smoke else args.boat or ["ilca7", "ilca7-steady"]
    print(
        "| boat | race | wind | model dn/up | observed dn/up | ratio error | model total | "
        "observed total | total error |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for boat in boats:
        if args.smoke:
            smoke_row(boat)
            continue
        hy = load_course("courses/hyeres-r1.yaml")
        hy = dataclasses.replace(hy, boat_spec=frozen_mapping({"builtin": boat}))
        t = [leg.time_s for leg in plan_course(hy, "constant").plan.legs]
        model = (t[1] + t[3]) / (t[0] + t[2])
        for who, ref in (("winner", hy.references["winner"]), ("top10", hy.references["top10"])):
            obs = (ref[1] + ref[3]) / (ref[0] + ref[2])
            print(
                f"| {boat} | Hyères R1 vs {who} | 10.9 kn 108° | {model:.3f} | {obs:.3f} | "
                f"{model / obs - 1:+.1%} | {sum(t):.0f} s | {sum(ref):.0f} s | "
                f"{sum(t) / sum(ref) - 1:+.1%} |"
            )
        for race in SNIPE:
            legs = [leg.time_s for leg in plan_course(snipe_course(race, boat)).plan.legs]
            run_m, beat_m = (legs[1] + legs[3]) / 2, legs[2]
            run_o, beat_o = snipe_observed(race)
            wind = f"{SNIPE[race][0]:.0f} kn 110°"
            print(
                f"| {boat} | Snipe {race} | {wind} | {run_m / beat_m:.3f} | "
                f"{run_o / beat_o:.3f} | {run_m / beat_m / (run_o / beat_o) - 1:+.1%} | "
                f"run {run_m:.0f} s, beat {beat_m:.0f} s | run {run_o:.0f} s, beat {beat_o:.0f} s"
                f" | run {run_m / run_o - 1:+.1%}, beat {beat_m / beat_o - 1:+.1%} |"
            )
    if args.sensitivity:
        print()
        sensitivity()


if __name__ == "__main__":
    main()
