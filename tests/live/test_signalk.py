"""``sailroute live`` on a real Signal K server (the ``signalk-server`` npm package).

The server replays a recorded NMEA 0183 file (its ``FileStream`` provider) and streams
Signal K deltas over its WebSocket; ``live`` reads them through ``signalk://``.  The
server is the one ``.ci/run`` installs (``npm install --prefix
~/.cache/sailroute-signalk signalk-server@2.23.0``; ``SAILROUTE_SIGNALK`` may name
another ``signalk-server`` executable).
"""

from __future__ import annotations

import contextlib
import itertools
import json
import math
import os
import shutil
import socket
import subprocess
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

from sailroute.live.engine import LiveSettings
from tests.live.feed import approach, trieste, write_feed

SIGNALK_VERSION = "2.23.0"
CACHE = Path.home() / ".cache" / "sailroute-signalk"


def _server_bin() -> Path | None:
    given = os.environ.get("SAILROUTE_SIGNALK")
    if given:
        return Path(given)
    path = CACHE / "node_modules" / ".bin" / "signalk-server"
    return path if path.exists() and shutil.which("node") else None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextlib.contextmanager
def signalk_server(tmp_path: Path, feed: Path, rows_per_s: float, n_rows: int) -> Iterator[int]:
    """A signalk-server on a free port of 127.0.0.1 replaying ``feed`` at ``rows_per_s``
    rows (seconds of data) per second; yields its port, stops it by its PID."""
    exe = _server_bin()
    if exe is None:
        pytest.skip(
            f"signalk-server is not installed (npm install --prefix {CACHE} "
            f"signalk-server@{SIGNALK_VERSION}, as .ci/run does)"
        )
    per_s = len(feed.read_bytes()) / n_rows
    conf = tmp_path / "signalk"
    conf.mkdir()
    (conf / "settings.json").write_text(
        json.dumps(
            {
                "interfaces": {},
                "ssl": False,
                "pipedProviders": [
                    {
                        "id": "replay",
                        "enabled": True,
                        "pipeElements": [
                            {
                                "type": "providers/simple",
                                "options": {
                                    "logging": False,
                                    "type": "FileStream",
                                    "subOptions": {
                                        "dataType": "NMEA0183",
                                        "filename": str(feed),
                                        "keepRunning": False,
                                        "throttleRate": int(per_s * rows_per_s),
                                    },
                                },
                            }
                        ],
                    }
                ],
            }
        )
    )
    port = _free_port()
    env = {**os.environ, "PORT": str(port), "SIGNALK_NODE_CONFIG_DIR": str(conf)}
    with open(tmp_path / "server.log", "w") as out:
        proc = subprocess.Popen(
            [str(exe), "-c", str(conf), "-s", "settings.json"],
            env=env,
            cwd=conf,
            stdout=out,
            stderr=subprocess.STDOUT,
            process_group=0,
        )
    try:
        end = time.monotonic() + 60
        while True:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/signalk", timeout=1):
                    break
            except OSError:
                if proc.poll() is not None or time.monotonic() > end:
                    pytest.fail(
                        "signalk-server did not start: "
                        + (tmp_path / "server.log").read_text()[-2000:]
                    )
                time.sleep(0.3)
        yield port
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)


@pytest.fixture
def signalk(tmp_path: Path) -> Iterator[tuple[int, list]]:
    """A signalk-server replaying a boat closing on mark 1 (120 s at 10x)."""
    rows = approach(trieste(), 120, speed_ms=2.0)
    feed = write_feed(tmp_path / "replay.nmea", rows)
    with signalk_server(tmp_path, feed, 10.0, len(rows)) as port:
        yield port, rows


@pytest.mark.slow
def test_live_from_a_real_signalk_server(signalk: tuple[int, list], tmp_path: Path) -> None:
    """Positions, SOG and the true wind of the recorded file arrive through Signal K (SI
    units, radians converted), and the re-plans (in a worker process, as the command
    line computes them) close on mark 1."""
    from sailroute.commands.live import start_live

    port, rows = signalk
    log = tmp_path / "live.jsonl"
    engine = start_live(
        trieste(),
        boat="self",
        source=f"signalk://127.0.0.1:{port}",
        scenario="mean",
        every_s=15,
        port=None,
        nmea_port=None,
        log=log,
        leg=3,
        settings=LiveSettings(side=False),
    )  # re-plans in a worker process
    try:
        end = time.monotonic() + 40
        while time.monotonic() < end and (engine.n_plans < 3 or engine.stale()):
            time.sleep(0.2)
        if engine.n_plans >= 3:  # data still flowing: read a little more
            time.sleep(1.0)
    finally:
        engine.close()
    records = [json.loads(line) for line in log.read_text().splitlines()]
    fixes = [r for r in records if r["kind"] == "input" and "lat" in r]
    by_t = {round(r.t): r for r in rows}
    assert len(fixes) >= 20
    for f in fixes[:20]:  # each fix is the file's fix of that second
        row = by_t[round(f["t"])]
        assert f["lat"] == pytest.approx(row.lat, abs=2e-6)
        assert f["lon"] == pytest.approx(row.lon, abs=2e-6)
    sog = [r["sog_ms"] for r in records if r["kind"] == "input" and "sog_ms" in r]
    assert sog and sog[-1] == pytest.approx(2.0, abs=0.01)
    wind = [r for r in records if r["kind"] == "input" and "twd_deg" in r]
    assert wind and wind[-1]["twd_deg"] == pytest.approx(65.0, abs=0.2)
    assert wind[-1]["tws_ms"] == pytest.approx(5.0 * 1852 / 3600, abs=0.01)
    plans = [r for r in records if r["kind"] == "plan"]
    assert len(plans) >= 3
    to_mark = [p["time_to_mark_s"] for p in plans]
    assert all(b < a for a, b in itertools.pairwise(to_mark)), to_mark


@pytest.mark.slow
def test_an_ais_target_through_a_real_signalk_server(tmp_path: Path) -> None:
    """The server turns the recording's ``!AIVDM`` reports of the sailor's boat into
    ``vessels.urn:mrn:imo:mmsi:<MMSI>`` deltas; ``live --boat <MMSI>`` routes that boat,
    not the coach boat (whose own position stays 300 m off).  The server stamps AIS
    deltas with its own clock, so the recording is dated now and played at 2x."""
    from sailroute.commands.live import start_live
    from sailroute.live.convert import nmea_lines
    from tests.live.feed import ais_sentence

    course = trieste()
    now = float(int(time.time()))
    coach = approach(course, 50, speed_ms=0.0, start_back_m=300.0, t0=now)
    boat = approach(course, 50, speed_ms=2.0, t0=now)
    lines = []
    for c, b in zip(coach, boat, strict=True):
        lines += list(nmea_lines(c))
        sec = int(b.t) % 60
        lines.append(ais_sentence(247000123, b.lat, b.lon, b.sog_kn, b.cog_deg, None, sec))
    feed = tmp_path / "replay.nmea"
    feed.write_text("\r\n".join(lines) + "\r\n", encoding="ascii")
    log = tmp_path / "live.jsonl"
    with signalk_server(tmp_path, feed, 2.0, len(coach)) as port:
        engine = start_live(
            course,
            source=f"signalk://127.0.0.1:{port}",
            scenario="mean",
            boat="247000123",
            every_s=5,
            port=None,
            nmea_port=None,
            log=log,
            leg=1,
            worker=False,
            settings=LiveSettings(side=False),
        )
        try:
            end = time.monotonic() + 45
            while time.monotonic() < end and engine.n_plans < 2:
                time.sleep(0.2)
        finally:
            engine.close()
    records = [json.loads(line) for line in log.read_text().splitlines()]
    boats = [r for r in records if r["kind"] == "boat"]
    assert len(boats) >= 5 and {r["vessel"] for r in boats} == {"urn:mrn:imo:mmsi:247000123"}
    by_lat = sorted(b.lat for b in boat)
    for r in boats:  # each is one of the reports, to AIS resolution
        k = min(range(len(by_lat)), key=lambda i: abs(by_lat[i] - r["lat"]))
        assert abs(by_lat[k] - r["lat"]) < 2e-6
    plans = [r for r in records if r["kind"] == "plan"]
    assert len(plans) >= 2
    frame = course.frame
    cx, cy = frame.to_xy(coach[0].lat, coach[0].lon)
    for p in plans:  # from the sailor's boat (dead-reckoned), not from the coach boat
        px, py = frame.to_xy(*p["route"][0])
        b = min(boat, key=lambda r: abs(r.t - p["t"]))
        bx, by = frame.to_xy(b.lat, b.lon)
        assert math.hypot(float(px - bx), float(py - by)) < 10.0
        assert math.hypot(float(px - cx), float(py - cy)) > 140.0
