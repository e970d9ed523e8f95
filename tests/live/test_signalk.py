"""``sailroute live`` on a real Signal K server (the ``signalk-server`` npm package).

The server replays a recorded NMEA 0183 file (its ``FileStream`` provider) and streams
Signal K deltas over its WebSocket; ``live`` reads them through ``signalk://``.  The
server is the one ``.ci/run`` installs (``npm install --prefix
~/.cache/sailroute-signalk signalk-server@2.23.0``; ``SAILROUTE_SIGNALK`` may name
another ``signalk-server`` executable).
"""

from __future__ import annotations

import itertools
import json
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


@pytest.fixture
def signalk(tmp_path: Path) -> Iterator[tuple[int, list]]:
    """A signalk-server on a free port replaying a boat closing on mark 1 (120 s at 10x)."""
    exe = _server_bin()
    if exe is None:
        pytest.skip(
            f"signalk-server is not installed (npm install --prefix {CACHE} "
            f"signalk-server@{SIGNALK_VERSION}, as .ci/run does)"
        )
    course = trieste()
    rows = approach(course, 120, speed_ms=2.0)
    feed = write_feed(tmp_path / "replay.nmea", rows)
    per_s = len(feed.read_bytes()) / len(rows)
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
                                        "throttleRate": int(per_s * 10),
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
        yield port, rows
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)


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
