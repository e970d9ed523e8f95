"""``sailroute live`` and ``sailroute live-convert`` on the command line."""

from __future__ import annotations

import json
from pathlib import Path

import pynmea2
from typer.testing import CliRunner

from sailroute.cli import app
from tests.conftest import COURSES, TESTS_DATA

COURSE = str(COURSES / "trieste-coach-wl.yaml")
TALLINN = TESTS_DATA / "live" / "tallinn-2023-09-27.nmea"


def test_live_replays_a_file_to_its_end(tmp_path: Path) -> None:
    """A recorded file at high speed: the page (with its token) and NMEA ports are
    announced, the run ends at the file's end with a summary, the log is written.  The
    Tallinn boat is 1700 km from the Trieste marks: every fix is held out as far from the
    course area, counted in the summary and logged with the reason, and nothing is
    routed from there."""
    log = tmp_path / "live.jsonl"
    res = CliRunner().invoke(
        app,
        [
            "live",
            COURSE,
            "--source",
            str(TALLINN),
            "--boat",
            "self",
            "--scenario",
            "measured",
            "--speed",
            "2000",
            "--port",
            "0",
            "--nmea-port",
            "0",
            "--log",
            str(log),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "page: http://127.0.0.1:" in res.output and "/?token=" in res.output
    assert "NMEA 0183 out" in res.output
    assert "0 with a bad checksum, 0 without one, 0 malformed" in res.output
    assert "readings held out: 253 (0 bounds, 253 far, 0 jump, 0 time)" in res.output
    assert "re-plans: 0" in res.output
    records = [json.loads(line) for line in log.read_text().splitlines()]
    far = [r for r in records if r["kind"] == "reject"]
    assert len(far) == 253 and {r["why"] for r in far} == {"far"}
    assert not [r for r in records if r["kind"] in ("plan", "input") and "lat" in r]
    assert records[-1]["kind"] == "end" and records[-1]["counts"]["gate_far"] == 253


def test_live_bad_source_is_exit_2(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["live", COURSE, "--source", str(tmp_path / "none.nmea")])
    assert res.exit_code == 2
    assert "--source" in res.output and "no such file" in res.output
    assert "Traceback" not in res.output
    res = CliRunner().invoke(app, ["live", COURSE, "--source", "nmea+tcp://h:1", "--leg", "9"])
    assert res.exit_code == 2 and "--leg 9: the course has legs 1..4" in res.output


def test_live_convert(tmp_path: Path) -> None:
    csv = tmp_path / "log.csv"
    csv.write_text(
        "time,lat,lng,sog,cog,hdg,awa,aws,tack\n"
        "2023-09-27 14:31:57+00:00,59.5,24.8,7.1,123.8,288.0,55.0,18.9,-1.0\n"
    )
    out = tmp_path / "log.nmea"
    res = CliRunner().invoke(app, ["live-convert", str(csv), "--format", "tallinn", "-o", str(out)])
    assert res.exit_code == 0, res.output
    lines = out.read_text().splitlines()
    for line in lines:
        pynmea2.parse(line, check=True)  # a checksum that pynmea2 verifies
    assert lines == [
        "$GPRMC,143157.00,A,5930.0000,N,02448.0000,E,7.10,123.8,270923,,,A*6D",
        "$IIHDT,288.0,T*20",
        "$IIMWV,305.0,R,18.90,N,A*3B",  # port tack: 55° over port = 305° clockwise
    ]
    csv.write_text("time,lat\nyesterday,59.5\n")
    res = CliRunner().invoke(app, ["live-convert", str(csv), "--format", "tallinn", "-o", str(out)])
    assert res.exit_code == 2 and f"{csv}:2: not a row of the Tallinn race log" in res.output


def test_help_lists_the_options() -> None:
    res = CliRunner().invoke(app, ["live", "--help"])
    assert res.exit_code == 0
    for text in (
        "--source SOURCE",
        "--boat BOAT",
        "--boat-source SOURCE",
        "--host ADDRESS",
        "--accept-no-checksum",
        "--every S",
        "--speed X",
        "--nmea-port",
        "--log FILE",
        "--duration S",
        "--router [isochrone|griddp|spline]",
        "-h, --help",
    ):
        assert text in res.output, text
    assert "<float>" not in res.output and "<int>" not in res.output
    conv = CliRunner().invoke(app, ["live-convert", "-h"])
    assert conv.exit_code == 0 and "--format [trieste|tallinn]" in conv.output
