"""The Signal K source against a plain WebSocket server (``websockets``): deltas decoded,
a dropped connection reconnected with back-off."""

from __future__ import annotations

import json
import math
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

import pytest
from websockets.sync.server import ServerConnection, serve

from sailroute.commands.live import start_live
from sailroute.live.engine import LiveSettings
from tests.live.feed import approach, trieste


def _delta(row) -> str:
    ts = datetime.fromtimestamp(row.t, UTC).isoformat().replace("+00:00", "Z")
    return json.dumps(
        {
            "context": "vessels.urn:mrn:imo:mmsi:230000000",
            "updates": [
                {
                    "timestamp": ts,
                    "values": [
                        {
                            "path": "navigation.position",
                            "value": {"latitude": row.lat, "longitude": row.lon},
                        },
                        {"path": "navigation.speedOverGround", "value": row.sog_kn * 1852 / 3600},
                        {
                            "path": "navigation.courseOverGroundTrue",
                            "value": math.radians(row.cog_deg),
                        },
                        {
                            "path": "environment.wind.directionTrue",
                            "value": math.radians(row.twd_deg),
                        },
                        {"path": "environment.wind.speedTrue", "value": row.tws_kn * 1852 / 3600},
                    ],
                }
            ],
        }
    )


def test_signalk_stream_reconnects(tmp_path: Path) -> None:
    course = trieste()
    rows = approach(course, 30)
    sent = {"n": 0, "connections": 0}

    def handler(ws: ServerConnection) -> None:
        sent["connections"] += 1
        ws.send(
            json.dumps(
                {"name": "test", "version": "2", "self": "vessels.urn:mrn:imo:mmsi:230000000"}
            )
        )
        while sent["n"] < len(rows):
            ws.send(_delta(rows[sent["n"]]))
            sent["n"] += 1
            time.sleep(0.02)
            if sent["connections"] == 1 and sent["n"] == 10:
                return  # the first connection drops after 10 deltas

    with serve(handler, "127.0.0.1", 0) as server:
        port = server.socket.getsockname()[1]
        threading.Thread(target=server.serve_forever, daemon=True).start()
        log = tmp_path / "live.jsonl"
        engine = start_live(
            course,
            boat="self",
            source=f"signalk://127.0.0.1:{port}",
            scenario="mean",
            port=None,
            nmea_port=None,
            log=log,
            leg=4,
            every_s=1000,
            worker=False,
            settings=LiveSettings(side=False),
        )
        try:
            end = time.monotonic() + 15
            while time.monotonic() < end and engine.n_readings < len(rows):
                time.sleep(0.05)
        finally:
            engine.close()
            server.shutdown()
    records = [json.loads(line) for line in log.read_text().splitlines()]
    fixes = [r for r in records if r["kind"] == "input"]
    assert [f["t"] for f in fixes] == [r.t for r in rows]  # every delta once, in order
    assert fixes[-1]["twd_deg"] == pytest.approx(65.0) and fixes[-1]["sog_ms"] == pytest.approx(2.0)
    ups = [r["up"] for r in records if r["kind"] == "link"]
    assert ups[:3] == [True, False, True] and sent["connections"] == 2
    assert engine.n_drops >= 1
