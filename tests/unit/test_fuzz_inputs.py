"""Fuzzing the input readers, ``plan``, ``course import``, ``live-convert`` and the live
decoders with mutated copies of small valid files (hypothesis).

The starting files are small valid inputs of the project (``tests/data``, ``data/``, the built-in
polars) or written here (a 3 x 3 CF NetCDF grid in the classic and the NetCDF-4 format;
the bytes of the classic one are mutated, the numbers of both).
Each example mutates one of them, either its numbers (a number replaced by 0, -1, 1e20, 1e309,
nan, inf, a 400-digit integer, an empty cell, ...) or its bytes (bytes replaced, deleted,
inserted or duplicated, the file truncated; inserted bytes favour the structural ones:
quotes, separators, line breaks, brackets, anchors, NUL), and feeds it to a reader, or to
``sailroute plan`` in-process.

The property: the reader returns, or raises the project's input error (exit code 2) with
a message whose first line is not empty; ``plan`` exits 0, 2 (bad input, ``error: ...``)
or 3 (a leg that cannot be routed, documented in docs/usage.md), writes nothing when it
fails, and never prints a traceback or "internal error".  ``course import`` (GPX, CSV,
KML, race XML) and ``live-convert`` (the Trieste and Tallinn logs) return or raise the
input error too, and leave the folder with nothing but the input when they fail (no
course or replay file, no draft).  The live decoders (NMEA 0183 sentences, Signal K
deltas) never raise: every line or message gives readings or none, and every value of a
reading is finite, a latitude within ±90° and a longitude within ±180°.  Each example
runs under a hard time limit (``SIGALRM``): a hang fails the test.

The default suite runs a few examples per reader (derandomized: the same ones every run,
about ten seconds in all); ``pytest -m slow tests/unit/test_fuzz_inputs.py`` runs many
more, also the same every run (CI runs them), and with ``SAILROUTE_FUZZ_RANDOM=1`` fresh
random examples each time.  ``--hypothesis-show-statistics`` shows how
many examples each test ran and how they ended (``ok`` / ``input error``).
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from sailroute.boat.io import read_polar, write_polar_csv, write_polar_json
from sailroute.boat.polar import Polar
from sailroute.cli import app
from sailroute.commands.course_import import run_course_import_command
from sailroute.course.load import load_course
from sailroute.errors import SailrouteError
from sailroute.geo import LocalFrame
from sailroute.live.convert import convert_log
from sailroute.live.decode import NmeaDecoder, Reading, SignalKDecoder
from sailroute.nmea import frame
from sailroute.track.read import read_track
from sailroute.wind.cf import open_netcdf
from sailroute.wind.ndbc import read_ndbc
from sailroute.wind.stations import read_stations
from tests.conftest import COURSES, ROOT, TESTS_DATA, WIND_DATA

READER_LIMIT_S = 20.0
"""Hard limit of one reader example [s] (they take milliseconds)."""
PLAN_LIMIT_S = 90.0
"""Hard limit of one ``plan`` example [s] (they take about a second)."""

_COMMON = {"database": None, "suppress_health_check": list(HealthCheck)}
FAST = settings(max_examples=40, deadline=timedelta(seconds=10), derandomize=True, **_COMMON)
FAST_PLAN = settings(max_examples=6, deadline=timedelta(seconds=60), derandomize=True, **_COMMON)
# CI runs the slow tests: the same examples every run there (a red CI must be
# reproducible); SAILROUTE_FUZZ_RANDOM=1 draws fresh ones, to explore by hand
_FIXED = os.environ.get("SAILROUTE_FUZZ_RANDOM", "") != "1"
LONG = settings(max_examples=2000, deadline=timedelta(seconds=10), derandomize=_FIXED, **_COMMON)
LONG_PLAN = settings(
    max_examples=150, deadline=timedelta(seconds=60), derandomize=_FIXED, **_COMMON
)


class Hang(BaseException):
    """An example ran past its time limit (a BaseException: no reader may swallow it)."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` in the main thread after ``seconds``."""

    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"no answer within {seconds:g} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def outcome(read: Callable[[], Any], limit_s: float = READER_LIMIT_S) -> str:
    """Run ``read``: ``"ok"``, or ``"input error"`` for the project's input error (exit
    code 2) with a message; anything else fails (it propagates)."""
    with time_limit(limit_s):
        try:
            read()
        except SailrouteError as exc:
            assert exc.exit_code == 2, f"exit code {exc.exit_code}: {exc}"
            assert str(exc).split("\n")[0].strip(), "empty message"
            assert "Traceback" not in str(exc)
            return "input error"
    return "ok"


# ------------------------------------------------------------------------- mutations
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
ODD_NUMBERS = (
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "1e20",
    "-1e20",
    "1e308",
    "1e309",
    "-1e309",
    "1e-320",
    "nan",
    "NaN",
    "inf",
    "-inf",
    ".inf",
    "9" * 400,
    "",
    ".",
    "1e",
    "--1",
    "0x1A",
    "1_0",
    "1,5",
    "\u0663",
)
STRUCTURE = (
    b'"',
    b"'",
    b",",
    b";",
    b"\t",
    b"\n",
    b"\r",
    b" ",
    b"#",
    b":",
    b"{",
    b"}",
    b"[",
    b"]",
    b"&a",
    b"*a",
    b"<",
    b">",
    b"\x00",
    b"\xff",
    b"\xef\xbb\xbf",
    b"\\",
    b"- ",
    b"!!",
    b"%",
)


VALUE = re.compile(r"(?<![\w.:-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.:-])")
"""A number standing alone (not part of a date, a time or a name), as in YAML values."""


@st.composite
def number_mutations(
    draw: st.DrawFn,
    text: str,
    pattern: re.Pattern[str] = NUMBER,
    kinds: tuple[str, ...] = ("odd", "float", "int", "twice", "scaled", "nudged", "nudged"),
) -> str:
    """``text`` with one to four of its numbers replaced: by an odd value, any float or
    integer, the number written twice, or the number scaled by 0.5 .. 2 or nudged by up
    to 1e-4 of itself (a mark moves by up to some 500 m): plausible values, so that
    some mutated files are still valid."""
    spans = [m.span() for m in pattern.finditer(text)]
    if not spans:
        return text
    picks = draw(st.lists(st.integers(0, len(spans) - 1), min_size=1, max_size=4, unique=True))
    for k in sorted(picks, reverse=True):
        a, b = spans[k]
        old = text[a:b]
        kind = draw(st.sampled_from(kinds))
        if kind == "odd":
            new = draw(st.sampled_from(ODD_NUMBERS))
        elif kind == "float":
            new = repr(draw(st.floats(allow_nan=False)))
        elif kind == "int":
            new = str(draw(st.integers(-(10**6), 10**6)))
        elif kind == "twice":
            new = old * 2
        elif kind == "scaled":
            new = f"{float(old) * draw(st.floats(0.5, 2.0)):.6g}"
        else:
            new = f"{float(old) * (1.0 + draw(st.floats(-1e-4, 1e-4))):.10g}"
        text = text[:a] + new + text[b:]
    return text


@st.composite
def byte_mutations(draw: st.DrawFn, data: bytes) -> bytes:
    """``data`` with one to four byte-level edits."""
    b = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["replace", "delete", "insert", "duplicate", "truncate"]))
        i = draw(st.integers(0, max(len(b) - 1, 0)))
        n = draw(st.integers(1, 16))
        if op == "replace" and b:
            b[i : i + n] = draw(st.binary(min_size=n, max_size=n))
        elif op == "delete":
            del b[i : i + n]
        elif op == "insert":
            b[i:i] = draw(st.one_of(st.sampled_from(STRUCTURE), st.binary(min_size=1, max_size=8)))
        elif op == "duplicate":
            b[i:i] = b[i : i + draw(st.integers(1, 400))]
        else:
            b = b[:i]
    return bytes(b)


def mutated(files: dict[str, bytes]) -> st.SearchStrategy[tuple[str, bytes]]:
    """``(file name, mutated content)``: numbers or bytes of one of ``files``."""

    def one(name: str) -> st.SearchStrategy[tuple[str, bytes]]:
        data = files[name]
        text = data.decode("utf-8", errors="surrogateescape")
        by_number = number_mutations(text).map(
            lambda t: t.encode("utf-8", errors="surrogateescape")
        )
        return st.tuples(st.just(name), st.one_of(by_number, byte_mutations(data)))

    return st.sampled_from(sorted(files)).flatmap(one)


def head(path: Path, lines: int) -> bytes:
    return b"".join(path.read_bytes().splitlines(keepends=True)[:lines])


@contextmanager
def written(name: str, data: bytes) -> Iterator[Path]:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / name
        p.write_bytes(data)
        yield p


# ------------------------------------------------------------------------- starting files
COURSE_FILES = {
    "minimal.yaml": (TESTS_DATA / "course" / "minimal.yaml").read_bytes(),
    "windward-leeward-template.yaml": (COURSES / "windward-leeward-template.yaml").read_bytes(),
    "hyeres-r1.yaml": (COURSES / "hyeres-r1.yaml").read_bytes(),
}


def _polar_files() -> dict[str, bytes]:
    builtin = ROOT / "sailroute" / "boat" / "data" / "ilca7.pol"
    polar = read_polar(builtin)
    small = Polar.from_arrays(
        polar.twa_deg[::4], polar.tws_ms[::3], polar.speed_ms[::4, ::3], name="ilca7"
    )
    with tempfile.TemporaryDirectory() as d:
        csv_text = write_polar_csv(small, Path(d) / "p_kn.csv", "kn").read_bytes()
        json_text = write_polar_json(small, Path(d) / "p.json", "kn").read_bytes()
    return {
        "ilca7.pol": builtin.read_bytes(),
        "p_kn.csv": csv_text,
        "p.json": json_text,
        "orc.json": (TESTS_DATA / "boat" / "BUL_BUL7888.json").read_bytes(),
    }


POLAR_FILES = _polar_files()
STATION_FILES = {
    "coach.csv": head(ROOT / "data" / "trieste-coach-2018-02-15.csv", 21),
    "ndbc.csv": head(WIND_DATA / "ndbc_41008_excerpt.csv", 20),
    "ndbc.cwind.txt": head(WIND_DATA / "ndbc_41008_excerpt.cwind.txt", 20),
}


def _gpx_sample(points: int = 8) -> bytes:
    text = (ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx").read_text()
    cut = 0
    for _ in range(points):
        cut = text.index("</trkpt>", cut) + len("</trkpt>")
    return (text[:cut] + "\n    </trkseg>\n  </trk>\n</gpx>\n").encode()


TRACK_FILES = {
    "coach.csv": head(WIND_DATA / "coach_wind_1hz_excerpt.csv", 30),
    "snipe.gpx": _gpx_sample(),
}


def write_grid(
    path: Path, fmt: str, lat: Any, lon: Any, hours: Any, u: Any, v: Any, units: str = "m s-1"
) -> None:
    """A CF NetCDF file of 10 m wind on a lat/lon grid."""
    import netCDF4

    with netCDF4.Dataset(path, "w", format=fmt) as ds:
        for name, values in (("time", hours), ("latitude", lat), ("longitude", lon)):
            ds.createDimension(name, len(values))
            var = ds.createVariable(name, "f8", (name,))
            var.standard_name = name
            var.units = {
                "time": "hours since 2024-05-01 09:00:00",
                "latitude": "degrees_north",
                "longitude": "degrees_east",
            }[name]
            var[:] = values
        for name, std, values in (("u10", "eastward_wind", u), ("v10", "northward_wind", v)):
            var = ds.createVariable(name, "f4", ("time", "latitude", "longitude"))
            var.standard_name, var.units = std, units
            var[:] = values


def _grid_files() -> dict[str, bytes]:
    out = {}
    with tempfile.TemporaryDirectory() as d:
        for fmt in ("NETCDF3_CLASSIC", "NETCDF4"):
            p = Path(d) / f"{fmt}.nc"
            write_grid(
                p,
                fmt,
                45.0 + 0.01 * np.arange(3),
                13.0 + 0.01 * np.arange(3),
                [0.0, 1.0, 2.0],
                np.full((3, 3, 3), 1.0),
                np.full((3, 3, 3), -5.0),
            )
            out[f"{fmt}.nc"] = p.read_bytes()
    return out


GRID_FILES = _grid_files()
FRAME = LocalFrame(45.01, 13.01)
T_RACE = 1714554000.0  # 2024-05-01T09:00:00Z + 1 h


def _read_grid(p: Path) -> None:
    wind = open_netcdf(p, FRAME, clamp=True)
    u, v = wind.sample(np.array([T_RACE]), np.array([0.0]), np.array([0.0]))
    assert np.shape(u) == (1,) and np.shape(v) == (1,)


# ------------------------------------------------------------------------- readers
def _course(case: tuple[str, bytes]) -> str:
    name, data = case
    with written(name, data) as p:
        return outcome(lambda: load_course(p))


def _polar(case: tuple[str, bytes]) -> str:
    name, data = case
    with written(name, data) as p:
        return outcome(lambda: read_polar(p))


def _stations(case: tuple[str, bytes]) -> str:
    name, data = case
    position = (41.0, -80.0) if name.startswith("ndbc") else None
    unit = None if name == "ndbc.csv" else "kn"  # a plain `speed` column
    with written(name, data) as p:
        if name.endswith(".cwind.txt"):  # NDBC realtime text: its own reader
            return outcome(lambda: read_ndbc(p, position=(41.0, -80.0)))
        return outcome(lambda: read_stations(p, position=position, speed_unit=unit))


def _track(case: tuple[str, bytes]) -> str:
    name, data = case
    columns = {"time": "datetime_local"} if name == "coach.csv" else None
    with written(name, data) as p:
        return outcome(lambda: read_track(p, time_zone="+01:00", columns=columns))


def _grid_bytes(case: tuple[str, bytes]) -> str:
    name, data = case
    with written(name, data) as p:
        return outcome(lambda: _read_grid(p))


FLOATS = st.one_of(
    st.floats(-1e3, 1e3), st.sampled_from([np.nan, np.inf, -np.inf, 1e20, -1e20, 0.0])
)


@st.composite
def grid_numbers(draw: st.DrawFn) -> dict[str, Any]:
    """A small grid whose coordinates, times, winds and units are drawn (often invalid)."""
    ny, nx, nt = draw(st.integers(1, 4)), draw(st.integers(1, 4)), draw(st.integers(1, 3))

    def axis(n: int, start: float, step: float) -> list[float]:
        base = [start + step * k for k in range(n)]
        return draw(st.one_of(st.just(base), st.lists(FLOATS, min_size=n, max_size=n)))

    return {
        "fmt": draw(st.sampled_from(["NETCDF3_CLASSIC", "NETCDF4"])),
        "lat": axis(ny, 45.0, 0.01),
        "lon": axis(nx, 13.0, 0.01),
        "hours": axis(nt, 0.0, 1.0),
        "u": draw(
            st.one_of(
                st.just(np.full((nt, ny, nx), 2.0)),
                st.lists(FLOATS, min_size=nt * ny * nx, max_size=nt * ny * nx).map(
                    lambda a: np.reshape(a, (nt, ny, nx))
                ),
            )
        ),
        "v": np.full((nt, ny, nx), -5.0),
        "units": draw(st.sampled_from(["m s-1", "knots", "km/h", "furlongs", ""])),
    }


def _grid_numbers(g: dict[str, Any]) -> str:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "grid.nc"
        write_grid(p, g["fmt"], g["lat"], g["lon"], g["hours"], g["u"], g["v"], g["units"])
        return outcome(lambda: _read_grid(p))


# ------------------------------------------------------------------------- course import
_POINTS = [  # name, lat, lon, type, rounding: a start line, a mark, a gate, a finish
    ("pin", 45.0, 13.0, "start", ""),
    ("boat", 45.0, 13.002, "start", ""),
    ("top", 45.009, 13.001, "mark", "port"),
    ("g1", 45.0015, 13.0005, "gate", ""),
    ("g2", 45.0015, 13.0015, "gate", ""),
    ("f1", 45.0005, 13.0, "finish", ""),
    ("f2", 45.0005, 13.002, "finish", ""),
]
_ROCK = [(45.004, 13.004), (45.004, 13.005), (45.005, 13.005), (45.005, 13.004)]
_AREA = [(44.995, 12.995), (44.995, 13.007), (45.012, 13.007), (45.012, 12.995)]


def _import_files() -> dict[str, bytes]:
    def gpx_type(t: str, r: str) -> str:
        return r or t

    wpts = "".join(
        f'<wpt lat="{la}" lon="{lo}"><name>{n}</name><type>{gpx_type(t, r)}</type></wpt>\n'
        for n, la, lo, t, r in _POINTS
    )
    rte = wpts.replace("<wpt", "<rtept").replace("</wpt>", "</rtept>")
    csv_text = "name,lat,lon,type,rounding\n" + "".join(
        f"{n},{la},{lo},{t},{r}\n" for n, la, lo, t, r in _POINTS
    )

    def ring(points: list[tuple[float, float]]) -> str:
        return " ".join(f"{lo},{la},0" for la, lo in [*points, points[0]])

    pms = "".join(
        f'<Placemark><name>{n}</name><ExtendedData><Data name="type"><value>{t}</value>'
        f'</Data><Data name="rounding"><value>{r}</value></Data></ExtendedData>'
        f"<Point><coordinates>{lo},{la},0</coordinates></Point></Placemark>\n"
        for n, la, lo, t, r in _POINTS[2:]
    )
    kml = (
        '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">'
        "<Document><name>club</name>\n<Folder><Placemark><name>Start</name><LineString>"
        "<coordinates>13.0,45.0 13.002,45.0</coordinates></LineString></Placemark>\n"
        f"{pms}</Folder>\n"
        "<Placemark><name>Boundary</name><Polygon><outerBoundaryIs><LinearRing><coordinates>"
        f"{ring(_AREA)}</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>\n"
        "<Placemark><name>rock</name><Polygon><outerBoundaryIs><LinearRing><coordinates>"
        f"{ring(_ROCK)}</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark>\n"
        "</Document></kml>\n"
    )

    def limits(name: str, points: list[tuple[float, float]]) -> str:
        return (
            f'  <CourseLimit name="{name}">\n'
            + "".join(
                f'    <Limit SeqID="{k + 1}" Lat="{la}" Lon="{lo}" />\n'
                for k, (la, lo) in enumerate(points)
            )
            + "  </CourseLimit>\n"
        )

    race = (
        '<?xml version="1.0" encoding="utf-8"?>\n<Race>\n  <RaceID>25011905</RaceID>\n'
        '  <RaceStartTime Start="2025-01-19T16:08:00+13:00" Postpone="False" />\n'
        "  <Course>\n"
        '    <CompoundMark CompoundMarkID="1" Name="SL">\n'
        '      <Mark SeqID="1" Name="SL1" TargetLat="45.0" TargetLng="13.0" />\n'
        '      <Mark SeqID="2" Name="SL2" TargetLat="45.0" TargetLng="13.002" />\n'
        "    </CompoundMark>\n"
        '    <CompoundMark CompoundMarkID="2" Name="M1">\n'
        '      <Mark SeqID="1" Name="M1" TargetLat="45.009" TargetLng="13.001" />\n'
        "    </CompoundMark>\n"
        '    <CompoundMark CompoundMarkID="3" Name="LG">\n'
        '      <Mark SeqID="1" Name="LG1" TargetLat="45.0015" TargetLng="13.0005" />\n'
        '      <Mark SeqID="2" Name="LG2" TargetLat="45.0015" TargetLng="13.0015" />\n'
        "    </CompoundMark>\n"
        '    <CompoundMark CompoundMarkID="4" Name="FL">\n'
        '      <Mark SeqID="1" Name="FL1" TargetLat="45.0005" TargetLng="13.0" />\n'
        '      <Mark SeqID="2" Name="FL2" TargetLat="45.0005" TargetLng="13.002" />\n'
        "    </CompoundMark>\n  </Course>\n  <CompoundMarkSequence>\n"
        '    <Corner SeqID="1" CompoundMarkID="1" Rounding="SP" ZoneSize="3" />\n'
        '    <Corner SeqID="2" CompoundMarkID="2" Rounding="Port" ZoneSize="3" />\n'
        '    <Corner SeqID="3" CompoundMarkID="3" Rounding="PS" ZoneSize="3" />\n'
        '    <Corner SeqID="4" CompoundMarkID="4" Rounding="SP" ZoneSize="3" />\n'
        "  </CompoundMarkSequence>\n"
        + limits("Boundary", _AREA)
        + limits("AY", _ROCK)
        + "</Race>\n"
    )
    head = '<?xml version="1.0"?>\n<gpx version="1.1" creator="t" xmlns="http://www.topografix.com/GPX/1/1">\n'
    return {
        "waypoints.gpx": (
            head + f"<metadata><name>club</name></metadata>\n{wpts}</gpx>\n"
        ).encode(),
        "route.gpx": (head + f"<rte><name>club</name>\n{rte}</rte>\n</gpx>\n").encode(),
        "marks.csv": csv_text.encode(),
        "club.kml": kml.encode(),
        "race.xml": race.encode(),
    }


IMPORT_FILES = _import_files()
IMPORT_FORMATS = {
    "gpx": ("waypoints.gpx", "route.gpx"),
    "csv": ("marks.csv",),
    "kml": ("club.kml",),
    "racexml": ("race.xml",),
}


def _import(case: tuple[str, bytes]) -> str:
    """``course import`` of one file into its folder: the course file, or nothing new."""
    name, data = case
    with written(name, data) as p:
        out = p.parent / "course.yaml"
        start = None if name.endswith(".xml") else "2024-05-01T10:00:00+02:00"
        result = outcome(
            lambda: run_course_import_command(
                p, out=out, wind_twd_deg=200.0, wind_tws_kn=10.0, start_time=start
            )
        )
        left = sorted(f.name for f in p.parent.iterdir())
        assert left == sorted([name, *(["course.yaml"] if result == "ok" else [])]), left
        return result


# ------------------------------------------------------------------------- live-convert
TALLINN_LOG = (
    "time,lat,lng,sog,cog,hdg,awa,aws,tack,dpt\n"
    "2023-09-27 14:31:56+00:00,59.4766293,24.8130137,4.8,329.0,,57.0,18.3,-1.0,10.7\n"
    "2023-09-27 14:31:57+00:00,59.4766110,24.8130674,7.098,123.76,288.0,55.0,18.9,-1.0,10.8\n"
    "2023-09-27 14:32:04+00:00,59.4765720,24.8134001,6.91,121.5,287.0,52.0,18.1,-1.0,10.9\n"
    "2023-09-27 14:32:11+00:00,59.4765102,24.8137453,7.02,120.2,,49.0,17.6,1.0,11.0\n"
)
LOG_FILES = {
    "trieste.csv": head(WIND_DATA / "coach_wind_1hz_excerpt.csv", 12),
    "tallinn.csv": TALLINN_LOG.encode(),
}


def _live_convert(case: tuple[str, bytes]) -> str:
    """``live-convert`` of one log into its folder: the replay file, or nothing new."""
    name, data = case
    with written(name, data) as p:
        out = p.parent / "replay.nmea"
        result = outcome(lambda: convert_log(p, name.removesuffix(".csv"), out))
        left = sorted(f.name for f in p.parent.iterdir())
        assert left == sorted([name, *(["replay.nmea"] if result == "ok" else [])]), left
        return result


# ------------------------------------------------------------------------- live decoders
_MORE_SENTENCES = (  # the other sentences the decoder reads, framed with their checksums
    "GPGGA,144024.00,5928.5950,N,02447.9290,E,1,08,0.9,3.0,M,18.0,M,,",
    "GPGLL,5928.5945,N,02447.9285,E,144025.00,A,A",
    "GPVTG,256.9,T,,M,5.75,N,10.65,K,A",
    "HCHDG,120.0,,,7.1,E",
    "GPZDA,144026.00,27,09,2023,00,00",
    "IIMWV,40.0,T,8.1,M,A",
)
NMEA_FILES = {
    "trieste.nmea": head(TESTS_DATA / "live" / "trieste-coach-2018-02-15.nmea", 15),
    "tallinn.nmea": head(TESTS_DATA / "live" / "tallinn-2023-09-27.nmea", 9)
    + "".join(frame(b) + "\r\n" for b in _MORE_SENTENCES).encode(),
}
_SK_HELLO = {"name": "signalk-server", "version": "2.0.0", "self": "vessels.urn:mrn:imo:mmsi:1"}
_SK_DELTA = {
    "context": "vessels.urn:mrn:imo:mmsi:1",
    "updates": [
        {
            "timestamp": "2024-05-01T10:00:01.000Z",
            "values": [
                {"path": "navigation.position", "value": {"latitude": 45.01, "longitude": 13.02}},
                {"path": "navigation.speedOverGround", "value": 3.1},
                {"path": "navigation.courseOverGroundTrue", "value": 0.61},
                {"path": "navigation.headingTrue", "value": 0.58},
                {"path": "environment.wind.angleApparent", "value": -0.71},
                {"path": "environment.wind.speedApparent", "value": 6.2},
            ],
        },
        {
            "timestamp": "2024-05-01T10:00:01.500Z",
            "values": [
                {"path": "environment.wind.directionTrue", "value": 4.9},
                {"path": "environment.wind.speedTrue", "value": 5.1},
                {"path": "environment.wind.angleTrueWater", "value": 1.2},
                {"path": "navigation.speedThroughWater", "value": 2.9},
            ],
        },
    ],
}
SIGNALK_FILES = {
    "deltas.jsonl": "\n".join(
        json.dumps(m) for m in (_SK_HELLO, _SK_DELTA, {**_SK_DELTA, "context": "vessels.ais"})
    ).encode()
}


def _check_readings(readings: list[Reading]) -> str:
    """Every value of every reading finite, positions on the globe; ``"readings"`` or
    ``"none"``."""
    for r in readings:
        for key, v in r.as_dict().items():
            assert math.isfinite(v), (key, v, r)
        assert r.lat is None or -90.0 <= r.lat <= 90.0, r
        assert r.lon is None or -180.0 <= r.lon <= 180.0, r
    return "readings" if readings else "none"


def _nmea(case: tuple[str, bytes]) -> str:
    """Each line of the mutated file fed to one decoder, as a TCP source decodes it."""
    dec = NmeaDecoder()
    out: list[Reading] = []
    with time_limit(READER_LIMIT_S):
        for raw in case[1].split(b"\n"):
            r = dec.feed(raw.decode("ascii", "replace"))
            if r is not None:
                out.append(r)
    return _check_readings(out)


def _signalk(case: tuple[str, bytes]) -> str:
    """Each line of the mutated file fed to one decoder as a WebSocket message."""
    dec = SignalKDecoder()
    out: list[Reading] = []
    with time_limit(READER_LIMIT_S):
        for raw in case[1].split(b"\n"):
            out += dec.feed(raw.decode("utf-8", "replace"))
    return _check_readings(out)


# ------------------------------------------------------------------------- plan
PLAN_COURSE = COURSE_FILES["minimal.yaml"].decode()
runner = CliRunner()


def _plan(text: str) -> str:
    with tempfile.TemporaryDirectory() as d:
        course, out = Path(d) / "course.yaml", Path(d) / "out"
        course.write_text(text, encoding="utf-8", errors="surrogateescape")
        with time_limit(PLAN_LIMIT_S):
            res = runner.invoke(app, ["plan", str(course), "-q", "--no-plots", "--out", str(out)])
        assert "Traceback" not in res.output and "internal error" not in res.output, res.output
        assert res.exit_code in (0, 2, 3), (res.exit_code, res.output, res.exception)
        if res.exit_code:
            assert res.stderr.startswith("error: "), res.stderr
            assert not out.exists()
        else:
            assert (out / "plan.json").is_file()
        return {0: "ok", 2: "input error", 3: "routing error"}[res.exit_code]


# ------------------------------------------------------------------------- the tests
CASES = {
    "course": (_course, mutated(COURSE_FILES)),
    "polar": (_polar, mutated(POLAR_FILES)),
    "stations": (_stations, mutated(STATION_FILES)),
    "track": (_track, mutated(TRACK_FILES)),
    # bytes of the classic file only: a damaged NetCDF-4 (HDF5) file can hang inside the
    # HDF5 library at open, where no Python signal reaches (a 107-byte shorter file with a
    # few bytes of its superblock replaced did); its numbers are mutated below
    "netcdf_bytes": (
        _grid_bytes,
        byte_mutations(GRID_FILES["NETCDF3_CLASSIC.nc"]).map(lambda b: ("NETCDF3_CLASSIC.nc", b)),
    ),
    "netcdf_numbers": (_grid_numbers, grid_numbers()),
    **{
        f"import_{fmt}": (_import, mutated({n: IMPORT_FILES[n] for n in names}))
        for fmt, names in IMPORT_FORMATS.items()
    },
    "live_convert": (_live_convert, mutated(LOG_FILES)),
    "nmea": (_nmea, mutated(NMEA_FILES)),
    "signalk": (_signalk, mutated(SIGNALK_FILES)),
    # plan: mostly plausible values, so that many examples are routed
    "plan": (
        _plan,
        number_mutations(
            PLAN_COURSE, VALUE, ("odd", "float", "scaled", "nudged", "nudged", "nudged", "nudged")
        ),
    ),
}


def test_unmutated_files_are_valid():
    """Unmutated, every starting file reads (mutations start from a valid file), and plan
    routes."""
    for case, files in (
        ("course", COURSE_FILES),
        ("polar", POLAR_FILES),
        ("stations", STATION_FILES),
        ("track", TRACK_FILES),
        ("netcdf_bytes", GRID_FILES),
    ):
        for name, data in files.items():
            if name != "hyeres-r1.yaml":  # names wind files beside it, absent in a tmp folder
                assert CASES[case][0]((name, data)) == "ok", (case, name)
    for fmt, names in IMPORT_FORMATS.items():
        for name in names:
            assert _import((name, IMPORT_FILES[name])) == "ok", (fmt, name)
    for name, data in LOG_FILES.items():
        assert _live_convert((name, data)) == "ok", name
    for name, data in NMEA_FILES.items():
        assert _nmea((name, data)) == "readings", name
    assert _signalk(("deltas.jsonl", SIGNALK_FILES["deltas.jsonl"])) == "readings"
    assert _plan(PLAN_COURSE) == "ok"


# one test per reader, so that --hypothesis-show-statistics counts each
@FAST
@given(CASES["course"][1])
def test_course_yaml(x: Any) -> None:
    event(_course(x))


@FAST
@given(CASES["polar"][1])
def test_polar(x: Any) -> None:
    event(_polar(x))


@FAST
@given(CASES["stations"][1])
def test_station_csv(x: Any) -> None:
    event(_stations(x))


@FAST
@given(CASES["track"][1])
def test_track(x: Any) -> None:
    event(_track(x))


@FAST
@given(CASES["netcdf_bytes"][1])
def test_netcdf_bytes(x: Any) -> None:
    event(_grid_bytes(x))


@FAST
@given(CASES["netcdf_numbers"][1])
def test_netcdf_numbers(x: Any) -> None:
    event(_grid_numbers(x))


@FAST_PLAN
@given(CASES["plan"][1])
def test_plan(x: Any) -> None:
    event(_plan(x))


@FAST
@given(CASES["import_gpx"][1])
def test_course_import_gpx(x: Any) -> None:
    event(_import(x))


@FAST
@given(CASES["import_csv"][1])
def test_course_import_csv(x: Any) -> None:
    event(_import(x))


@FAST
@given(CASES["import_kml"][1])
def test_course_import_kml(x: Any) -> None:
    event(_import(x))


@FAST
@given(CASES["import_racexml"][1])
def test_course_import_race_xml(x: Any) -> None:
    event(_import(x))


@FAST
@given(CASES["live_convert"][1])
def test_live_convert(x: Any) -> None:
    event(_live_convert(x))


@FAST
@given(CASES["nmea"][1])
def test_nmea_decoder(x: Any) -> None:
    event(_nmea(x))


@FAST
@given(CASES["signalk"][1])
def test_signalk_decoder(x: Any) -> None:
    event(_signalk(x))


# the same, with many fresh random examples each run: pytest -m slow
@pytest.mark.slow
@LONG
@given(CASES["course"][1])
def test_course_yaml_long(x: Any) -> None:
    event(_course(x))


@pytest.mark.slow
@LONG
@given(CASES["polar"][1])
def test_polar_long(x: Any) -> None:
    event(_polar(x))


@pytest.mark.slow
@LONG
@given(CASES["stations"][1])
def test_station_csv_long(x: Any) -> None:
    event(_stations(x))


@pytest.mark.slow
@LONG
@given(CASES["track"][1])
def test_track_long(x: Any) -> None:
    event(_track(x))


@pytest.mark.slow
@LONG
@given(CASES["netcdf_bytes"][1])
def test_netcdf_bytes_long(x: Any) -> None:
    event(_grid_bytes(x))


@pytest.mark.slow
@LONG
@given(CASES["netcdf_numbers"][1])
def test_netcdf_numbers_long(x: Any) -> None:
    event(_grid_numbers(x))


@pytest.mark.slow
@LONG_PLAN
@given(CASES["plan"][1])
def test_plan_long(x: Any) -> None:
    event(_plan(x))


@pytest.mark.slow
@LONG
@given(CASES["import_gpx"][1])
def test_course_import_gpx_long(x: Any) -> None:
    event(_import(x))


@pytest.mark.slow
@LONG
@given(CASES["import_csv"][1])
def test_course_import_csv_long(x: Any) -> None:
    event(_import(x))


@pytest.mark.slow
@LONG
@given(CASES["import_kml"][1])
def test_course_import_kml_long(x: Any) -> None:
    event(_import(x))


@pytest.mark.slow
@LONG
@given(CASES["import_racexml"][1])
def test_course_import_race_xml_long(x: Any) -> None:
    event(_import(x))


@pytest.mark.slow
@LONG
@given(CASES["live_convert"][1])
def test_live_convert_long(x: Any) -> None:
    event(_live_convert(x))


@pytest.mark.slow
@LONG
@given(CASES["nmea"][1])
def test_nmea_decoder_long(x: Any) -> None:
    event(_nmea(x))


@pytest.mark.slow
@LONG
@given(CASES["signalk"][1])
def test_signalk_decoder_long(x: Any) -> None:
    event(_signalk(x))
