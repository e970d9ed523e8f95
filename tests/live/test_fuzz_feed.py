"""An hour of instrument feed with junk, flipped bits and extreme values in it: every
thread stays up, every route is finite, memory stays flat."""

from __future__ import annotations

import json
import math
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from sailroute.commands.live import start_live
from sailroute.live.convert import Row, nmea_lines
from sailroute.live.engine import LiveSettings
from sailroute.nmea import checksum
from tests.live.feed import ais_sentence, trieste

HOUR = 3600
SPEED = 150.0
EXTREMES = ("1e308", "-1e308", "9" * 401, "nan", "inf", "5e29", "-0", "", "1" * 30, "0x1F")


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * 4096 / 2**20


def clean_hour(course) -> list[str]:
    """The coach boat circling 200 m round a point 350 m below mark 1 at 2.5 m/s, the
    wind oscillating ±10° and ±1 m/s, for an hour from the gun; an AIS target every 5 s."""
    frame = course.frame
    cx, cy = course.marks["1"].xy
    out = []
    for s in range(HOUR):
        a = 2.5 * s / 200.0
        lat, lon = frame.to_latlon(cx - 250.0 + 200.0 * math.sin(a), cy - 250 + 200.0 * math.cos(a))
        row = Row(
            course.start_epoch + s,
            float(lat),
            float(lon),
            2.5 / 0.514444,
            math.degrees(a + math.pi / 2) % 360,
            tws_kn=5.0 + math.sin(s / 300.0),
            twd_deg=65.0 + 10.0 * math.sin(s / 420.0),
        )
        out.extend(nmea_lines(row))
        if s % 5 == 0:
            out.append(
                ais_sentence(247000001, float(lat), float(lon) + 0.001, 4.0, 90.0, None, s % 60)
            )
    return out


def corrupt(lines: list[str], rng: np.random.Generator) -> list[bytes]:
    """Each line as it is (85 %), or: random bytes (4 %), one bit flipped (5 %), a field
    set to an extreme value with the checksum made right again (4 %), a random sentence
    with a right checksum (1 %), an AIS report with a random payload and a right checksum
    (1 %)."""
    out: list[bytes] = []
    for line in lines:
        u = rng.random()
        if u < 0.85:
            out.append(line.encode("ascii"))
        elif u < 0.89:
            n = int(rng.choice([5, 40, 120, 900, 6000]))
            raw = rng.integers(0, 256, n, dtype=np.uint8).tobytes().replace(b"\n", b" ")
            out.append(raw)
        elif u < 0.94:
            b = bytearray(line.encode("ascii"))
            k = int(rng.integers(len(b)))
            b[k] ^= 1 << int(rng.integers(8))
            out.append(bytes(b).replace(b"\n", b" "))
        elif u < 0.98:
            body = line[1:].split("*")[0].split(",")
            k = int(rng.integers(1, len(body)))
            body[k] = str(rng.choice(EXTREMES))
            text = ",".join(body)
            out.append(f"{line[0]}{text}*{checksum(text)}".encode("ascii"))
        elif u < 0.99:
            fields = [str(rng.integers(-(10**6), 10**6)) for _ in range(int(rng.integers(0, 20)))]
            talker = "".join(chr(int(c)) for c in rng.integers(65, 91, 5))
            text = ",".join([talker, *fields])
            out.append(f"${text}*{checksum(text)}".encode("ascii"))
        else:
            payload = "".join(
                chr(int(v) + 48 if v < 40 else int(v) + 56) for v in rng.integers(0, 64, 28)
            )
            text = f"AIVDM,1,1,,A,{payload},0"
            out.append(f"!{text}*{checksum(text)}".encode("ascii"))
    return out


@pytest.mark.slow
def test_an_hour_of_fuzzed_feed(tmp_path: Path) -> None:
    course = trieste()
    rng = np.random.default_rng(2026)
    clean = clean_hour(course)
    path = tmp_path / "fuzzed.nmea"
    path.write_bytes(b"\r\n".join(corrupt(clean, rng)) + b"\r\n")
    log = tmp_path / "live.jsonl"
    rss: list[float] = []
    stop = threading.Event()

    def sample() -> None:
        while not stop.wait(0.25):
            rss.append(_rss_mb())

    sampler = threading.Thread(target=sample, daemon=True)
    engine = start_live(
        course,
        source=str(path),
        scenario="mean",
        boat="self",
        every_s=60.0,
        speed=SPEED,
        port=0,
        nmea_port=0,
        log=log,
        worker=False,
        settings=LiveSettings(side=False),
    )
    sampler.start()
    try:
        alive = []
        while not engine.source_ended.wait(1.0):
            alive.append(all(th.is_alive() for th in engine._threads))
        engine.wait(60)
        plan_thread_alive = engine._threads[-1].is_alive()
    finally:
        engine.close()
        stop.set()
    recs = [json.loads(line) for line in log.read_text().splitlines()]
    end = recs[-1]
    assert end["kind"] == "end"
    # every thread was up throughout, and the source read the file to its last line
    assert alive and all(alive) and plan_thread_alive
    inputs = [r for r in recs if r["kind"] == "input" and "lat" in r]
    assert inputs[-1]["t"] >= course.start_epoch + HOUR - 5
    c = end["counts"]
    assert c["bad_checksum"] + c.get("no_checksum", 0) + c["malformed"] > 0.08 * len(clean)
    # nothing out of bounds was used: every logged input is physical
    for r in inputs:
        assert abs(r["lat"] - 45.566) < 0.2 and 0 <= r.get("sog_ms", 0) < 36
    winds = [r for r in recs if r["kind"] == "input" and "tws_ms" in r]
    assert all(0 <= r["tws_ms"] < 25 for r in winds)
    # re-plans all through the hour, each route finite and in the course area
    plans = [r for r in recs if r["kind"] == "plan"]
    # (at 150x a re-plan of some 0.3 s of CPU spans about a minute of data on a busy machine)
    ts = [p["t"] for p in plans]
    assert len(plans) >= 20 and ts[-1] >= course.start_epoch + HOUR - 300
    assert max(np.diff(ts)) < 600.0, max(np.diff(ts))
    for p in plans:
        pts = np.array(p["route"])
        assert np.isfinite(pts).all() and np.isfinite(p["time_to_finish_s"])
        assert np.all(np.abs(pts[:, 0] - 45.566) < 0.05)
    # memory flat: the second half of the run holds no more than the first half's
    # peak plus 25 MiB (the log is on disk; the vessels seen are capped)
    half = len(rss) // 2
    print(
        f"fuzzed hour: {len(clean)} lines, {len(plans)} re-plans, counts {end['counts']}; "
        f"RSS peak first half {max(rss[:half]):.1f} MiB, second half {max(rss[half:]):.1f} MiB"
    )
    assert len(rss) > 20
    assert max(rss[half:]) < max(rss[:half]) + 25.0, (max(rss[:half]), max(rss[half:]))
    assert end["counts"].get("error", 0) == 0
    time.sleep(0)  # the run ended cleanly: no thread of it is left
    assert not [t for t in threading.enumerate() if t.name.startswith(("live-", "nmea-out"))]
