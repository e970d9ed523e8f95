"""``sailroute live`` end to end on a real TCP feed: re-plans, page, NMEA out, faults."""

from __future__ import annotations

import _thread
import itertools
import json
import socket
import threading
import time
import urllib.request
from pathlib import Path

import numpy as np
import pynmea2
import pytest

from sailroute.commands.live import run_live_command, start_live
from sailroute.live.engine import LiveSettings
from sailroute.live.nmeaout import sentence
from sailroute.track.read import read_track
from tests.live.feed import FeedServer, approach, lines_of, trieste, write_feed


def _records(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def _plans(path: Path) -> list[dict]:
    return [r for r in _records(path) if r["kind"] == "plan"]


def test_tcp_feed_replans_page_and_nmea_out(tmp_path: Path) -> None:
    """A boat closing on mark 1 on the third leg (4 -> 1): every re-plan's time to the mark
    is shorter; the page and the NMEA port show the latest re-plan; the log ends with the
    run's totals."""
    course = trieste()
    feed = FeedServer(lines_of(approach(course, 100, speed_ms=2.5)), rate=20.0)
    log = tmp_path / "live.jsonl"
    engine = start_live(
        course,
        boat="self",
        source=f"nmea+tcp://127.0.0.1:{feed.port}",
        scenario="mean",
        every_s=20,
        port=0,
        nmea_port=0,
        log=log,
        leg=3,
        worker=False,
        settings=LiveSettings(side=False),
    )
    assert engine.nmea is not None and engine.page is not None
    plotter = socket.create_connection(("127.0.0.1", engine.nmea.port), timeout=5)
    try:
        assert feed.finished.wait(20)
        engine.wait(1.0)
        with urllib.request.urlopen(f"http://127.0.0.1:{engine.page.port}/state.json") as r:
            state = json.load(r)
        with urllib.request.urlopen(f"http://127.0.0.1:{engine.page.port}/") as r:
            page = r.read().decode()
        plotter.settimeout(1.0)
        received = b""
        while True:
            try:
                chunk = plotter.recv(65536)
            except TimeoutError:
                break
            if not chunk:
                break
            received += chunk
    finally:
        engine.close()
        feed.close()
        plotter.close()
    plans = _plans(log)
    assert len(plans) >= 3 and {p["leg"] for p in plans} == {2}
    to_mark = [p["time_to_mark_s"] for p in plans]
    assert all(b < a for a, b in itertools.pairwise(to_mark)), to_mark
    # the boat closes at 2.5 m/s: 20 s of data time later the mark is nearer by ~20 s or more
    assert to_mark[0] - to_mark[-1] > 0.5 * (plans[-1]["t"] - plans[0]["t"])
    # the page shows a logged re-plan (one more may have finished after the page was read)
    assert state["plan"]["number"] in {p["number"] for p in plans[-2:]}
    assert state["counts"]["bad"] == 0 and state["position"]["sog_ms"] == pytest.approx(2.5, 0.01)
    assert "state.json" in page and "<svg" in page
    sentences = [pynmea2.parse(s) for s in received.decode("ascii").split("\r\n") if s]
    kinds = {s.sentence_type for s in sentences}
    assert {"WPL", "RTE", "RMB", "APB"} <= kinds
    routes = [s for s in sentences if s.sentence_type == "RTE"]
    assert {r.data[3] for r in routes} == {"sailroute"}  # one route, updated in place
    wpl = [s.waypoint_id for s in sentences if s.sentence_type == "WPL"]
    assert routes[-1].data[4:] == wpl[-len(routes[-1].data[4:]) :]  # the last re-plan's
    rmb = [s for s in sentences if s.sentence_type == "RMB"][-1]
    assert float(rmb.data[9]) > 0  # range to the next waypoint [nm]
    records = _records(log)
    assert records[-1]["kind"] == "end" and records[-1]["plans"] == len(plans)
    assert sum(r["kind"] == "input" for r in records) == records[-1]["readings"]
    # the log reads back as a track (what `sailroute analyze` reads): one point per fix
    fixes = [r for r in records if r["kind"] == "input" and "lat" in r]
    track = read_track(log)
    assert len(track.t_s) == len({r["t"] for r in fixes})
    assert np.allclose(track.lat_deg, [r["lat"] for r in fixes], atol=1e-7)
    assert np.allclose(track.channels["sog_ms"], 2.5, atol=0.01)


def test_wind_shift_changes_the_side_that_pays(tmp_path: Path) -> None:
    """Measured 15° backed of the forecast (65°): the wind veers back ahead, the right
    pays; then measured 15° veered: the left pays.  The shift itself triggers a re-plan."""
    course = trieste()
    rows = approach(course, 80, speed_ms=0.5, twd=lambda s: 50.0 if s < 40 else 80.0)
    log = tmp_path / "live.jsonl"
    res = run_live_command(
        course,
        boat="self",
        source=str(write_feed(tmp_path / "f.nmea", rows)),
        scenario="mean",
        every_s=1000,
        speed=15,
        port=None,
        nmea_port=None,
        log=log,
        duration_s=30,
        leg=3,
        worker=False,
        settings=LiveSettings(fade_s=300, window_s=10),
    )
    plans = _plans(log)
    assert [p["reason"] for p in plans][:1] == ["first"]
    assert any(p["reason"] == "shift" for p in plans[1:])
    assert plans[0]["side"]["side"] == "right" and plans[0]["side"]["gain_s"] > 10
    assert plans[-1]["side"]["side"] == "left" and plans[-1]["side"]["gain_s"] > 10
    # the last re-plan is in the veered wind: the change point restarts the mean there
    assert plans[-1]["wind_twd_deg"] == pytest.approx(80.0, abs=0.5)
    assert res.data is not None and res.data.number == plans[-1]["number"]


def test_dropped_connection_reconnects_and_marks_stale(tmp_path: Path) -> None:
    """The feed drops the link after 20 s of data: the engine reports stale data, connects
    again with back-off, and the rest of the feed arrives."""
    course = trieste()
    rows = approach(course, 60)
    feed = FeedServer(lines_of(rows), rate=20.0, drop_after=20, down_s=1.5)
    log = tmp_path / "live.jsonl"
    engine = start_live(
        course,
        boat="self",
        source=f"nmea+tcp://127.0.0.1:{feed.port}",
        scenario="mean",
        port=None,
        nmea_port=None,
        log=log,
        leg=4,
        every_s=1000,
        worker=False,
        settings=LiveSettings(side=False, stale_s=0.5),
    )
    stale_seen = False
    try:
        end = time.monotonic() + 20
        while not feed.finished.is_set() and time.monotonic() < end:
            stale_seen |= engine.stale() and engine.n_readings > 0
            time.sleep(0.05)
        time.sleep(0.3)
    finally:
        engine.close()
        feed.close()
    assert feed.finished.is_set() and feed.connections == 2
    assert stale_seen and engine.n_drops == 2  # the drop, and the feed's end
    links = [r for r in _records(log) if r["kind"] == "link"]
    ups = [r["up"] for r in links]
    # up, down (then refused tries, with back-off), up again, down at the feed's end
    assert [u for i, u in enumerate(ups) if i == 0 or u != ups[i - 1]] == [True, False, True, False]
    tries = [r["wall"] for r in links if not r["up"]][:-1]
    assert len(tries) >= 2 and all(b - a >= 0.4 for a, b in itertools.pairwise(tries))
    inputs = [r for r in _records(log) if r["kind"] == "input" and "lat" in r]
    assert len(inputs) == 60  # every fix arrived, none twice
    assert inputs[-1]["t"] == pytest.approx(rows[-1].t)


def test_bad_sentences_are_counted_and_skipped(tmp_path: Path) -> None:
    """Bad checksums, sentences without one and malformed sentences are counted, the
    rest is used."""
    course = trieste()
    lines = lines_of(approach(course, 20))
    bad = []
    for i, line in enumerate(lines):
        if i % 10 == 3:  # corrupt one character of the body: the checksum no longer fits
            line = line[:8] + ("9" if line[8] != "9" else "8") + line[9:]
        elif i % 10 == 7:
            line = "$IIMWV,abc,R"  # no checksum, a field that is not a number, too short
        elif i % 10 == 9:
            line = sentence("IIMWV,abc,R").strip()  # a checksum, but not a number
        bad.append(line)
    path = tmp_path / "bad.nmea"
    path.write_text("\n".join(bad) + "\n", encoding="ascii")
    log = tmp_path / "live.jsonl"
    run_live_command(
        course,
        boat="self",
        source=str(path),
        scenario="mean",
        speed=100,
        port=None,
        nmea_port=None,
        log=log,
        duration_s=10,
        leg=4,
        every_s=1000,
        worker=False,
        settings=LiveSettings(side=False),
    )
    end = _records(log)[-1]
    n = len(lines)
    assert end["counts"]["bad_checksum"] == len(range(3, n, 10))
    assert end["counts"]["no_checksum"] == len(range(7, n, 10))
    assert end["counts"]["malformed"] == len(range(9, n, 10))


def test_udp_source(tmp_path: Path) -> None:
    """Datagrams on a UDP port are read like a TCP feed."""
    course = trieste()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    log = tmp_path / "live.jsonl"
    engine = start_live(
        course,
        boat="self",
        source=f"nmea+udp://127.0.0.1:{port}",
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
        time.sleep(0.3)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
            for r in approach(course, 10):
                tx.sendto("\r\n".join(lines_of([r])).encode(), ("127.0.0.1", port))
                time.sleep(0.01)
        time.sleep(0.5)
    finally:
        engine.close()
    fixes = [r for r in _records(log) if r["kind"] == "input" and "lat" in r]
    assert len(fixes) == 10


def test_ctrl_c_ends_cleanly_with_the_log_flushed(tmp_path: Path) -> None:
    """Ctrl-C (KeyboardInterrupt in the main thread) ends the run: result returned, threads
    gone, the log complete to its last line."""
    course = trieste()
    feed = write_feed(tmp_path / "f.nmea", approach(course, 600))
    log = tmp_path / "live.jsonl"
    timer = threading.Timer(1.5, _thread.interrupt_main)

    def announce(line: str) -> None:  # the run is under way: Ctrl-C in 1.5 s
        if line.startswith("page:"):
            timer.start()

    res = run_live_command(
        course,
        boat="self",
        source=str(feed),
        scenario="mean",
        speed=20,
        port=0,
        nmea_port=0,
        log=log,
        leg=4,
        worker=False,
        announce=announce,
        settings=LiveSettings(side=False),
    )
    timer.join()
    records = _records(log)
    assert records[-1]["kind"] == "end"
    assert 10 < records[-1]["readings"] < 600 * 5
    assert "re-plans:" in res.report
    assert not [t for t in threading.enumerate() if t.name.startswith(("live-", "nmea-out"))]
