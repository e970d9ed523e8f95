"""Benchmark: course import (GPX, CSV, KML, race XML) and route export (GPX, KML, NMEA).

    python benchmarks/bench_course_io.py [--repeat 5] [--smoke]

The course is the shipped ``courses/windward-leeward-template.yaml`` (``L3``: 7 marks,
6 legs), routed once in its uniform wind (not timed).  Its marks and legs are written as
a GPX route, a CSV, a KML file and a race XML (``<Race>``, the SailGP layout) in a
temporary folder; each is imported with ``run_course_import_command`` (read, write the
course file, load it back and build its boat and wind: what ``sailroute course import``
does).  With ``../shared/data/real`` present, the four SailGP Auckland race XMLs are
imported too.  Export is ``route.gpx``, ``route.kml`` and ``route.nmea`` of the plan.

Prints the machine's load average (``os.getloadavg``) before and after, then the best of
``--repeat`` wall times [ms].  Target: each import and the export under 1 s.
``--smoke``: one repetition (a check that the script runs, for CI).
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

from sailroute.commands.course_import import run_course_import_command  # noqa: E402
from sailroute.course.load import load_course  # noqa: E402
from sailroute.course.model import Course  # noqa: E402
from sailroute.planning.route import plan_course  # noqa: E402
from sailroute.report.files import write_gpx  # noqa: E402
from sailroute.report.route_export import write_kml, write_nmea  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_polar import best_of  # noqa: E402  (one timing rule for the benchmarks)

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "windward-leeward-template.yaml"
SHARED_XML = (
    ROOT.parent / "shared" / "data" / "real" / "races" / "sailgp-auckland-2025" / "Race_XMLs"
)
WIND = {"wind_twd_deg": 270.0, "wind_tws_kn": 10.0}


def sequence(course: Course) -> list[tuple[str, str, str]]:
    """``(name, type, rounding)`` of the course's points in sailing order."""
    out: list[tuple[str, str, str]] = []

    def feature(name: str, side: str | None, role: str) -> None:
        if name in course.marks:
            out.append((name, "mark", side or "port"))
            return
        f = course.feature(name)
        kind = "gate" if name in course.gates else role
        out.extend([(f.a.name, kind, ""), (f.b.name, kind, "")])

    feature(course.legs[0].from_name, None, "start")
    for k, leg in enumerate(course.legs):
        feature(leg.to_name, leg.rounding, "finish" if k == len(course.legs) - 1 else "gate")
    return out


def write_inputs(course: Course, d: Path) -> dict[str, Path]:
    """The course as a GPX route, a CSV, a KML file and a race XML."""
    seq = sequence(course)
    m = course.marks
    gpx = "".join(
        f'<rtept lat="{m[n].lat}" lon="{m[n].lon}"><name>{n}</name>'
        f"<type>{t if t != 'mark' else s}</type></rtept>\n"
        for n, t, s in seq
    )
    (d / "c.gpx").write_text(
        '<gpx version="1.1" creator="bench" xmlns="http://www.topografix'
        f'.com/GPX/1/1"><rte>\n{gpx}</rte></gpx>\n'
    )
    rows = ["name,lat,lon,type,rounding"] + [
        f"{n},{m[n].lat},{m[n].lon},{t},{s if t == 'mark' else ''}" for n, t, s in seq
    ]
    (d / "c.csv").write_text("\n".join(rows) + "\n")
    pms = "".join(
        f'<Placemark><name>{n}</name><ExtendedData><Data name="type"><value>{t}</value>'
        f"</Data></ExtendedData><Point><coordinates>{m[n].lon},{m[n].lat}</coordinates>"
        "</Point></Placemark>\n"
        for n, t, _ in seq
    )
    (d / "c.kml").write_text(
        f'<kml xmlns="http://www.opengis.net/kml/2.2"><Document>\n{pms}</Document></kml>\n'
    )
    cms, corners, k = [], [], 0
    i = 0
    while i < len(seq):
        n, t, s = seq[i]
        k += 1
        pair = [seq[i]] if t == "mark" else [seq[i], seq[i + 1]]
        marks = "".join(
            f'<Mark SeqID="{j + 1}" Name="{p[0]}" TargetLat="{m[p[0]].lat}" '
            f'TargetLng="{m[p[0]].lon}" />'
            for j, p in enumerate(pair)
        )
        cms.append(f'<CompoundMark CompoundMarkID="{k}" Name="{n}">{marks}</CompoundMark>')
        rounding = ("Port" if s == "port" else "Stbd") if t == "mark" else "SP"
        corners.append(f'<Corner SeqID="{k}" CompoundMarkID="{k}" Rounding="{rounding}" />')
        i += len(pair)
    (d / "c.xml").write_text(
        f'<Race><RaceStartTime Start="{course.start_time.isoformat()}" /><RaceID>1</RaceID>'
        f"<Course>{''.join(cms)}</Course><CompoundMarkSequence>{''.join(corners)}"
        "</CompoundMarkSequence></Race>\n"
    )
    return {"gpx": d / "c.gpx", "csv": d / "c.csv", "kml": d / "c.kml", "racexml": d / "c.xml"}


def main() -> None:
    """Time the imports and the export and print them."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5, help="repetitions (best is kept)")
    ap.add_argument("--smoke", action="store_true", help="one repetition (checks the script)")
    args = ap.parse_args()
    if args.smoke:
        args.repeat = 1
    print(
        f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())} "
        f"({os.cpu_count()} CPUs)"
    )
    course = load_course(COURSE)
    plan = plan_course(course).plan
    t0 = course.start_time.isoformat()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for fmt, src in write_inputs(course, d).items():

            def run(src: Path = src) -> object:
                return run_course_import_command(
                    src, out=d / "out.yaml", start_time=t0, boat="ilca7", **WIND
                )

            n_legs = len(run().data.legs)  # type: ignore[attr-defined]
            print(
                f"import {fmt:<8} {best_of(run, args.repeat) * 1e3:8.1f} ms  "
                f"({len(course.marks)} marks, {n_legs} legs)"
            )
        if SHARED_XML.is_dir():
            for xml in sorted(SHARED_XML.glob("*.xml")):

                def run_xml(src: Path = xml) -> object:
                    return run_course_import_command(src, out=d / "out.yaml", **WIND)

                print(f"import SailGP {xml.name} {best_of(run_xml, args.repeat) * 1e3:8.1f} ms")

        def export() -> None:
            write_gpx(d / "route.gpx", plan)
            write_kml(d / "route.kml", plan)
            write_nmea(d / "route.nmea", plan)

        n_pts = sum(len(pl.result.track) for pl in plan.legs)
        print(
            f"export gpx+kml+nmea {best_of(export, args.repeat) * 1e3:8.1f} ms  "
            f"({len(plan.legs)} legs, {n_pts} track points)"
        )
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
