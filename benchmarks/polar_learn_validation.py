"""Leave-one-race-out validation of polars learned from a fleet (``sailroute polar fit``).

Usage::

    .venv/bin/python benchmarks/polar_learn_validation.py [--members 20] [--bootstrap 100]
    .venv/bin/python benchmarks/polar_learn_validation.py --only sailgp --members 0
    .venv/bin/python benchmarks/polar_learn_validation.py --only 49erfx
    .venv/bin/python benchmarks/polar_learn_validation.py --smoke  # Snipe P01 -> P02, no bands

For each held-out race the polar is learned (``run_fit_command``, the same code as the
command line) on the other races of the same fleet, and the held-out race is planned in
its own wind with the learned median level: ``pace: steady`` (the table as learned from
steady sailing) and ``pace: race`` (scaled per point of sail by the fleet's pace over
whole legs in the learning races, ``docs/polar-fit.md``).  The plan's leg times are
compared with the times the boats sailed (their mean over the boats), leg by leg and in
total.  Band coverage: the bands of ``plan --ensemble`` with ``--members`` members
(:func:`sailroute.bands.route.band_summary`; the course's boat the learned median level at
its race pace) from the polar's uncertainty alone (each member draws the table), the
wind's alone (SailGP: the spread of the legs' measured mean wind about the race's;
Snipe and 49erFX: the default 1 kn, 5 deg) and both; an observed leg (each boat's) is covered when
it lies within the members' P10-P90 of that leg.

* **SailGP Auckland 2025** (F50, 3 boats x races 25011905-08, measured wind; read in
  place from ``../shared/data/real/races/sailgp-auckland-2025``, licence none stated,
  nothing copied).  Courses from the race XMLs (``sailroute course import``); race 08's
  XML holds the marks clustered within 250 m (as laid after the race: no boat comes
  within 250 m of its M1), so race 08 is timed on race 07's course with its own start
  time (the boats' logged positions at each leg change match race 07's marks).  Observed
  legs 2-6 from each log's leg counter (``TRK_LEG_NUM``; leg 1 holds the start, the
  finish legs end in data gaps); the race's wind is the three logs' measured mean from
  the gun to the last leg end.  Learned on the other three races, each in turn.
* **Snipe Valencia 2025** (2 boats, P01 and P02, GPS only; MIT): learned on one race
  (wind inferred from the tracks, TWS the sailors' estimate), planned on the other in its
  sailors' estimate (6 / 8 kn from 110 deg); observed runs 1 and 2 and beat 2 from
  ``benchmarks/race_polar_validation.py``.  The polar of one race holds one TWS column,
  so it is learned with ``--shape builtin:ilca7 --tws-bins 4,6,8,10`` (the ILCA's shape
  scaled to the Snipe per point of sail) to plan the other race's wind.
* **49erFX Worlds 2019 F13** (25 boats at 1 Hz, GPS only, no marks; read in place from
  ``../shared/data/real/races/49erfx-worlds-2019-f13``, licence none stated, nothing
  copied): the course from all 25 tracks (``sailroute course infer``: start, windward
  mark, leeward gate, a second windward mark, finish; the gun inferred, the direction
  the mean of the wind inferred from the tracks), each boat's legs from its roundings
  there (a leg a boat's log does not time is left out of the mean).  The fleet is split
  in finishing order into places 1, 3, 5, ... and 2, 4, 6, ... (:func:`alternate`: each
  half spans the fleet); the polar is learned on one half (its wind: the direction
  inferred from that half's tracks) and planned against the other's mean legs, and the
  other way round.  The tracks carry no wind and the data give no speed, so both the
  learning and the plan use a nominal 12 kn (:data:`FX_TWS_KN`): the learned table sits
  in that column and the plan reads it there, so the leg times do not depend on it (the
  same at 10 and 14 kn); the TWS spread of the bands reads the one column's taper below
  it (speeds falling to 0 at TWS 0) and its clamp above.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))

from race_polar_validation import SNIPE, _s  # noqa: E402

from sailroute.bands.route import band_summary, spec_for  # noqa: E402
from sailroute.commands.course_import import run_course_import_command  # noqa: E402
from sailroute.commands.course_infer import run_course_infer_command  # noqa: E402
from sailroute.commands.polar_fit import run_fit_command  # noqa: E402
from sailroute.course.load import load_course  # noqa: E402
from sailroute.course.model import Course  # noqa: E402
from sailroute.course.specs import build_specs  # noqa: E402
from sailroute.course.uncertainty import uncertainty_from_mapping  # noqa: E402
from sailroute.planning.route import plan_course, settings_for  # noqa: E402
from sailroute.track import read_track  # noqa: E402
from sailroute.units import KNOT, circular_mean_deg  # noqa: E402
from tests.analysis.windfleet import leg_counter_changes  # noqa: E402

SHARED = ROOT.parent / "shared" / "data" / "real" / "races"
SAILGP = SHARED / "sailgp-auckland-2025"
SNIPE_DIR = SHARED / "snipe-valencia-2025"
FX_DIR = SHARED / "49erfx-worlds-2019-f13"
FX_COLUMNS = {"lat": "Latitude [Deg N]", "lon": "Longitude [Deg E]", "time": "TimeStamp"}
FX_TWS_KN = 12.0
"""The 49erFX race's nominal wind speed [kn]: the tracks carry no wind and its README gives
none.  The polar is learned in it and the race planned in it, so the plan does not depend
on it (the same leg times to the second at 10, 12 and 14 kn)."""
F50 = ROOT.parent / "shared" / "data" / "real" / "polars" / "sailgp-f50"
BOATS = ("NZL", "AUS", "GBR")
XMLS = {"05": "25011905_03-13-55", "06": "25011906_03-35-13", "07": "25011907_03-56-34"}
LEGS = slice(1, 6)  # legs 2-6 of a SailGP race
DEFAULT_SPREAD = {"tws_kn": 1.0, "twd_deg": 5.0}
"""A wind without a measurement (a sailors' estimate, a direction from the tracks):
sailroute's default spread (1 kn, 5 deg at 1 sigma, ``DEFAULT_UNCERTAINTY``; its 6-min
shifts left out, as for SailGP)."""


def leg_counter(boat: str, race: str) -> list[float]:
    """Times [epoch s] the log's TRK_LEG_NUM of race ``2501190<race>`` steps up."""
    return leg_counter_changes(SAILGP / "Boat_logs" / f"data_{boat}.csv", "250119" + race)


def with_boat_and_wind(src: Path, dest: Path, boat: str, tws_kn: float, twd_deg: float) -> Course:
    """A copy of a course file with another boat and one uniform scenario ``race``."""
    text = src.read_text(encoding="utf-8")
    keep = [
        ln for ln in text.split("\n") if not ln.startswith(("boat:", "scenarios:", "  uniform:"))
    ]
    keep = [ln for ln in keep if not ln.startswith("  sailor:")]
    body = "\n".join(keep).rstrip("\n")
    dest.write_text(
        f"{body}\nboat: {boat}\nscenarios:\n  race: {{type: uniform, tws_kn: {tws_kn:.3f}, "
        f"twd_deg: {twd_deg:.2f}}}\n",
        encoding="utf-8",
    )
    return load_course(dest)


def sailgp_courses(tmp: Path) -> dict[str, Path]:
    """Course files of races 05-08 (race 08 on race 07's marks, its own start)."""
    out = {}
    for race, stem in XMLS.items():
        dest = tmp / f"sailgp-{race}.yaml"
        run_course_import_command(
            SAILGP / "Race_XMLs" / f"{stem}.xml", out=dest, wind_twd_deg=60, wind_tws_kn=20
        )
        out[race] = dest
    r08 = out["07"].read_text(encoding="utf-8")
    r08 = r08.replace('name: "race 25011907"', 'name: "race 25011908"').replace(
        'start_time: "2025-01-19T16:50:00+13:00"', 'start_time: "2025-01-19T17:14:00+13:00"'
    )
    out["08"] = tmp / "sailgp-08.yaml"
    out["08"].write_text(r08, encoding="utf-8")
    return out


def logged_wind(gun: float, end: float) -> tuple[float, float]:
    """The three logs' mean TWS [kn] and TWD [deg] from ``gun`` to ``end``."""
    tws, twd = [], []
    for b in BOATS:
        tr = read_track(SAILGP / "Boat_logs" / f"data_{b}.csv", time_zone="UTC")
        m = (tr.t_s >= gun) & (tr.t_s <= end)
        tws.append(tr.channels["tws_ms"][m])
        twd.append(tr.channels["twd_deg"][m])
    s, d = np.concatenate(tws), np.concatenate(twd)
    return float(np.nanmean(s)) / KNOT, float(circular_mean_deg(d[np.isfinite(d)]))


BAND_KINDS = ("polar", "wind", "wind + polar")
"""The bands compared: the learned polar's uncertainty alone (the wind fixed), the
wind's alone (the polar fixed), both."""


def band(
    course: Course, uncertainty: dict[str, float], members: int, seed: int
) -> dict[str, Any] | None:
    """Per kind of band (:data:`BAND_KINDS`) the P10 and P90 of the members' leg times [s],
    shape (legs, 2), and the one-at-a-time widths of the race [s] of ``wind + polar``
    (None without members).  The bands are ``sailroute plan --ensemble``'s
    (:func:`sailroute.bands.route.band_summary`): the course's boat is the learned polar,
    so the members draw it (``uncertainty: {polar: true}``, the default)."""
    if members <= 0:
        return None
    out: dict[str, Any] = {}
    settings = settings_for(course)
    boat, winds = build_specs(course, ["race"])
    for kind in BAND_KINDS:
        raw: dict[str, Any] = {"members": members, "seed": seed, "polar": "polar" in kind}
        if "wind" in kind:
            if not uncertainty:
                continue
            raw.update(uncertainty)
        spec, _ = spec_for(replace(course, uncertainty=uncertainty_from_mapping(raw)))
        b = band_summary(
            course, "race", spec, wind=winds["race"], boat=boat, settings=settings,
            oat=kind == "wind + polar",
        )  # fmt: skip
        out[kind] = b.bands()[:-1][:, [0, 2]]
        if kind == "wind + polar":
            out["widths"] = {k: float(v[-1]) for k, v in b.oat_widths().items()}
    return out


def wind_spread(bounds: dict[str, list[float]], tws_kn: float, twd_deg: float) -> dict[str, float]:
    """The spread of the legs' measured mean wind about the race's mean: the RMS deviation
    of the legs' mean TWS [kn] and of their mean TWD [deg] (legs 2-6 of each boat, the three
    logs' wind in each boat's leg), as ``uncertainty`` keys (1 sigma)."""
    tracks = [read_track(SAILGP / "Boat_logs" / f"data_{b}.csv", time_zone="UTC") for b in BOATS]
    tws, twd = [], []
    for ch in bounds.values():
        for a, z in zip(
            ch[LEGS.start : LEGS.stop], ch[LEGS.start + 1 : LEGS.stop + 1], strict=True
        ):
            s = np.concatenate([t.channels["tws_ms"][(t.t_s >= a) & (t.t_s <= z)] for t in tracks])
            d = np.concatenate([t.channels["twd_deg"][(t.t_s >= a) & (t.t_s <= z)] for t in tracks])
            tws.append(float(np.nanmean(s)) / KNOT)
            twd.append(float(circular_mean_deg(d[np.isfinite(d)])))
    dev = (np.asarray(twd) - twd_deg + 180.0) % 360.0 - 180.0
    return {
        "tws_kn": round(float(np.sqrt(np.mean((np.asarray(tws) - tws_kn) ** 2))), 3),
        "twd_deg": round(float(np.sqrt(np.mean(dev**2))), 2),
    }


def race_boat(learned: Path) -> str:
    """The learned median level at its race pace, as a course's ``boat``."""
    return f"{{polar: {learned}, level: median, pace: race}}"


def plan_legs(course: Course) -> list[float]:
    return [leg.time_s for leg in plan_course(course, "race").plan.legs]


def row(
    name: str,
    obs: dict[str, list[float]],
    legs: slice,
    plans: dict[str, list[float]],
    bands: dict[str, Any] | None,
) -> dict[str, Any]:
    """The numbers of one held-out race."""
    o = np.asarray(list(obs.values()), dtype=float)
    mean = np.nanmean(o, axis=0)  # a leg a boat's log does not time is left out
    out: dict[str, Any] = {"name": name, "observed_s": float(mean.sum()), "boats": len(obs)}
    for k, t in plans.items():
        tt = np.asarray(t, dtype=float)[legs]
        out[k] = (float(tt.sum()), float(tt.sum() / mean.sum() - 1.0), tt / mean - 1.0)
    for kind in BAND_KINDS:
        if bands is not None and kind in bands:
            b = bands[kind][legs]
            inside = (o >= b[:, 0]) & (o <= b[:, 1])
            out[f"cover {kind}"] = (int(inside.sum()), int(np.isfinite(o).sum()))
    if bands is not None and "widths" in bands:
        out["widths"] = bands["widths"]
    return out


def sailgp(tmp: Path, members: int, boot: int) -> list[dict[str, Any]]:
    if not SAILGP.is_dir():
        print(f"SailGP: {SAILGP} not present: left out")
        return []
    courses = sailgp_courses(tmp)
    logs = [SAILGP / "Boat_logs" / f"data_{b}.csv" for b in BOATS]
    rows = []
    for held in courses:
        obs, bounds = {}, {}
        for b in BOATS:
            ch = leg_counter(b, held)
            if len(ch) >= 7:
                obs[b] = list(np.diff(ch)[LEGS])
                bounds[b] = ch
        c0 = load_course(courses[held])
        ends = [leg_counter(b, held) for b in BOATS]
        end = max(e[6] for e in ends if len(e) >= 7)
        tws, twd = logged_wind(c0.start_epoch, end)
        out = tmp / f"learn-{held}"
        run_fit_command(
            logs,
            courses=[courses[k] for k in courses if k != held],
            time_zone="UTC",
            bootstrap=boot,
            out_dir=out,
            name="f50-fleet",
        )
        learned = out / "f50-fleet.json"
        plans = {}
        for tag, spec in (
            ("steady", f"{{polar: {learned}, level: median, pace: steady}}"),
            ("race", f"{{polar: {learned}, level: median, pace: race}}"),
            ("shipped F50", f"{{polar: {F50 / '2502_m8_APW_HSB2_HSRW.kph.csv'}}}"),
        ):
            c = with_boat_and_wind(courses[held], tmp / f"held-{held}.yaml", spec, tws, twd)
            plans[tag] = plan_legs(c)
        spread = wind_spread(bounds, tws, twd)
        c = with_boat_and_wind(
            courses[held], tmp / f"held-{held}.yaml", race_boat(learned), tws, twd
        )
        bands = band(c, spread, members, 1)
        r = row(f"SailGP 250119{held} (learned on the other 3)", obs, LEGS, plans, bands)
        r["wind"] = (
            f"{tws:.1f} kn {twd:.0f} deg (legs' sd {spread['tws_kn']:.1f} kn, "
            f"{spread['twd_deg']:.0f} deg)"
        )
        rows.append(r)
    return rows


def snipe_course(race: str, tmp: Path) -> Path:
    """The Snipe course of ``race`` (P01 is the shipped course; P02 the same layout with
    its own windward mark and start)."""
    p01 = ROOT / "courses" / "snipe-valencia-p01.yaml"
    if race == "P01":
        return p01
    _, lat, lon, _ = SNIPE["P02"]
    text = p01.read_text(encoding="utf-8").replace(
        'start_time: "2025-06-21T11:23:30Z"', 'start_time: "2025-06-21T12:06:29Z"'
    )
    text = text.replace("B1: {lat: 39.40691, lon: -0.31500}", f"B1: {{lat: {lat}, lon: {lon}}}")
    text = text.replace("tws_kn: 6,", "tws_kn: 8,").replace("race 1 (P01)", "race 2 (P02)")
    dest = tmp / "snipe-p02.yaml"
    dest.write_text(text, encoding="utf-8")
    return dest


def snipe(tmp: Path, members: int, boot: int, both: bool = True) -> list[dict[str, Any]]:
    if not SNIPE_DIR.is_dir():
        print(f"Snipe: {SNIPE_DIR} not present: left out")
        return []
    rows = []
    for learn, held in (("P01", "P02"), ("P02", "P01"))[: 2 if both else 1]:
        logs = sorted(SNIPE_DIR.glob(f"2025-06-21-*-{learn}.gpx"))
        out = tmp / f"snipe-{learn}"
        run_fit_command(
            logs,
            courses=[snipe_course(learn, tmp)],
            bootstrap=boot,
            out_dir=out,
            name="snipe-fleet",
            shape="builtin:ilca7",
            tws_bins="4,6,8,10",
        )
        learned = out / "snipe-fleet.json"
        tws = SNIPE[held][0]
        obs = {
            f"boat {k + 1}": [_s(s1) - _s(b1), _s(b1b) - _s(s1), _s(fin) - _s(b1b)]
            for k, (b1, s1, b1b, fin) in enumerate(SNIPE[held][3])
        }
        plans = {}
        src = snipe_course(held, tmp)
        for tag, spec in (
            ("steady", f"{{polar: {learned}, level: median, pace: steady}}"),
            ("race", f"{{polar: {learned}, level: median, pace: race}}"),
            ("ILCA 7 stand-in", "{builtin: ilca7}"),
        ):
            c = with_boat_and_wind(src, tmp / f"snipe-held-{held}.yaml", spec, tws, 110.0)
            plans[tag] = plan_legs(c)
        c = with_boat_and_wind(src, tmp / f"snipe-held-{held}.yaml", race_boat(learned), tws, 110.0)
        bands = band(c, DEFAULT_SPREAD, members, 1)
        r = row(f"Snipe {held} (learned on {learn})", obs, slice(1, 4), plans, bands)
        r["wind"] = f"{tws:.0f} kn 110 deg (sailors' estimate)"
        rows.append(r)
    return rows


def alternate(order: Sequence[int]) -> tuple[list[int], list[int]]:
    """Two halves of a fleet in finishing order: places 1, 3, 5, ... and 2, 4, 6, ..., so
    that each spans the fleet from its winner to its last."""
    return list(order[0::2]), list(order[1::2])


def fx(tmp: Path, members: int, boot: int) -> list[dict[str, Any]]:
    """The 49erFX race: its course inferred from all the tracks, the polar learned on one
    half of the fleet (:func:`alternate`) and the race planned against the other's legs."""
    if not FX_DIR.is_dir():
        print(f"49erFX: {FX_DIR} not present: left out")
        return []
    paths = {p.stem: p for p in sorted(FX_DIR.glob("*.csv"))}
    course = tmp / "fx.yaml"
    ic = run_course_infer_command(
        list(paths.values()), out=course, wind_tws_kn=FX_TWS_KN, columns=FX_COLUMNS,
        speed_unit="kn", time_zone="UTC", name="49erFX Worlds 2019 F13",
    ).data  # fmt: skip
    marks = np.asarray(ic.leg_roundings, dtype=float)  # legs x boats [epoch s]
    legs = np.diff(np.vstack([np.full(marks.shape[1], ic.gun.t), marks]), axis=0).T
    finished = [k for k in np.argsort(marks[-1]) if np.isfinite(marks[-1][k])]
    halves = alternate(finished)
    tag = ("odd places", "even places")
    cols = ",".join(f"{k}={v}" for k, v in FX_COLUMNS.items())
    rows = []
    for learn, held in ((0, 1), (1, 0)):
        out = tmp / f"fx-{learn}"
        run_fit_command(
            [paths[ic.boats[k]] for k in halves[learn]], courses=[course], columns=cols,
            speed_unit="kn", time_zone="UTC", bootstrap=boot, out_dir=out, name="49erfx-fleet",
        )  # fmt: skip
        learned = out / "49erfx-fleet.json"
        plans = {}
        for pace in ("steady", "race"):
            spec = f"{{polar: {learned}, level: median, pace: {pace}}}"
            c = with_boat_and_wind(course, tmp / "fx-held.yaml", spec, FX_TWS_KN, ic.twd_deg)
            plans[pace] = plan_legs(c)
        c = with_boat_and_wind(
            course, tmp / "fx-held.yaml", race_boat(learned), FX_TWS_KN, ic.twd_deg
        )
        bands = band(c, DEFAULT_SPREAD, members, 1)
        obs = {ic.boats[k]: list(legs[k]) for k in halves[held]}
        name = f"49erFX F13, {tag[held]} (learned on the {tag[learn]})"
        r = row(name, obs, slice(0, legs.shape[1]), plans, bands)
        r["wind"] = f"{FX_TWS_KN:.0f} kn (nominal) {ic.twd_deg:.0f} deg (inferred from the tracks)"
        rows.append(r)
    return rows


def print_table(rows: Sequence[dict[str, Any]]) -> None:
    print(
        "| held-out race | wind | observed (mean of boats) | "
        + " | ".join(f"{k}: plan (error)" for k in ("steady", "race"))
        + " | reference polar | per-leg error, race pace | inside P10-P90: "
        + " / ".join(BAND_KINDS)
        + " | race band width by source |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    keep = ("steady", "race", "widths", *(f"cover {k}" for k in BAND_KINDS))
    for r in rows:
        ref = next((k for k in r if isinstance(r[k], tuple) and k not in keep), None)
        cov = " / ".join(
            f"{r[f'cover {k}'][0]}/{r[f'cover {k}'][1]}" if f"cover {k}" in r else "-"
            for k in BAND_KINDS
        )
        widths = ", ".join(f"{k} {v:.0f} s" for k, v in r.get("widths", {}).items())
        print(
            f"| {r['name']} | {r['wind']} | {r['observed_s']:.0f} s ({r['boats']} boats) | "
            + " | ".join(f"{r[k][0]:.0f} s ({r[k][1]:+.1%})" for k in ("steady", "race"))
            + (f" | {ref}: {r[ref][0]:.0f} s ({r[ref][1]:+.1%}) | " if ref else " | - | ")
            + ", ".join(f"{e:+.0%}" for e in r["race"][2])
            + f" | {cov} | {widths or '-'} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--members", type=int, default=20, help="members of the bands (0: none)")
    ap.add_argument("--bootstrap", type=int, default=100, help="bootstrap replicates")
    ap.add_argument("--only", default="", help="sailgp, snipe or 49erfx")
    ap.add_argument("--smoke", action="store_true", help="Snipe P01 -> P02, no members")
    args = ap.parse_args()
    if args.smoke:
        args.only, args.members, args.bootstrap = "snipe", 0, 10
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="polar-learn-") as d:
        tmp = Path(d)
        rows = []
        if args.only in ("", "sailgp"):
            rows += sailgp(tmp, args.members, args.bootstrap)
        if args.only in ("", "snipe"):
            rows += snipe(tmp, args.members, args.bootstrap, both=not args.smoke)
        if args.only in ("", "49erfx"):
            rows += fx(tmp, args.members, args.bootstrap)
        if rows:
            print_table(rows)
        for kind in BAND_KINDS:
            cov = [r[f"cover {kind}"] for r in rows if f"cover {kind}" in r]
            if cov:
                print(
                    f"legs inside P10-P90, {kind} uncertainty (learned median level, race "
                    f"pace): {sum(c[0] for c in cov)} of {sum(c[1] for c in cov)}"
                )
    load = Path("/proc/loadavg").read_text(encoding="utf-8").strip()
    print(f"run time {time.perf_counter() - t0:.0f} s; load {load} (a shared 2-core machine)")


if __name__ == "__main__":
    main()
