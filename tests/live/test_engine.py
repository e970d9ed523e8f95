"""The live engine on the reading defects it had: each test feeds what once misled it."""

from __future__ import annotations

import json
import math
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from websockets.sync.server import ServerConnection, serve

from sailroute.commands.live import run_live_command, start_live
from sailroute.course.load import build_specs, load_course
from sailroute.errors import InputError
from sailroute.live.convert import Row
from sailroute.live.engine import LiveEngine, LiveSettings
from sailroute.live.nmeaout import ROUTE_ID, sentence
from sailroute.live.sources import MAX_LINE, NmeaFileSource, SignalKSource, parse_source
from tests.live.feed import (
    TRIESTE,
    FeedServer,
    ais_sentence,
    approach,
    lines_of,
    sailed_track,
    trieste,
    write_feed,
)


def _engine(tmp_path: Path, scenario: str = "mean", **kw) -> LiveEngine:
    """An engine fed by the test (``feed``) without its threads: its link is up."""
    course = kw.pop("course", None) or trieste()
    boat, winds = build_specs(course, [scenario])
    eng = LiveEngine(
        course,
        winds[scenario],
        boat,
        course.routing,
        kw.pop("source", None) or NmeaFileSource(tmp_path / "none.nmea"),
        kw.pop("settings", LiveSettings(side=False)),
        port=kw.pop("port", None),
        nmea_port=kw.pop("nmea_port", None),
        log=tmp_path / "live.jsonl",
        sailor=kw.pop("sailor", "self"),
        **kw,
    )
    eng._feeds[0].linked = True
    return eng


def _sk_delta(row: Row, sog: str = "1.0", context: str = "vessels.self") -> str:
    """A Signal K delta of ``row``'s position and SOG (``sog`` as written in the JSON)."""
    ts = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(row.t))
    return (
        '{"context":"' + context + '","updates":[{"timestamp":"' + ts + '","values":['
        '{"path":"navigation.position","value":{"latitude":' + repr(row.lat) + ","
        '"longitude":' + repr(row.lon) + '}},{"path":"navigation.speedOverGround",'
        '"value":' + sog + "}]}]}"
    )


def _run_signalk(
    tmp_path: Path, messages: list[str], want: int, host: str = "127.0.0.1"
) -> LiveEngine:
    """Serve ``messages`` on a WebSocket at ``host`` and run an engine on it until it has
    ``want`` readings (10 s at most)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family)
    sock.bind((host, 0))
    sock.listen()

    def handler(ws: ServerConnection) -> None:
        for m in messages:
            ws.send(m)
        time.sleep(1.0)

    with serve(handler, sock=sock) as server:
        port = server.socket.getsockname()[1]
        threading.Thread(target=server.serve_forever, daemon=True).start()
        where = f"[{host}]" if ":" in host else host
        eng = _engine(tmp_path, source=parse_source(f"signalk://{where}:{port}"))
        eng.start()
        end = time.monotonic() + 10
        while time.monotonic() < end and eng.n_readings < want:
            time.sleep(0.05)
        eng.close()
        server.shutdown()
    return eng


def _records(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def _steady(course, seconds: int, tws_kn: float = 4.8) -> list[str]:
    return lines_of(approach(course, seconds, speed_ms=0.5, tws_kn=tws_kn))


def test_a_sentence_without_checksum_is_not_used(tmp_path: Path) -> None:
    """An MWD without a checksum was used; now it is counted and no wind comes from it."""
    eng = _engine(tmp_path)
    rows = approach(eng.course, 20)
    for r in rows:
        for line in lines_of([r]):
            eng.feed(line.split("*")[0] if "MWD" in line else line)
    st = eng.state()
    assert st["wind"] is None and st["counts"]["no_checksum"] == 20
    eng.close()


def test_impossible_wind_never_reaches_the_estimate(tmp_path: Path) -> None:
    """Five valid-checksum MWDs of 80 kn among 4.8 kn ones moved the 60-s mean to 7.3 kn
    and triggered a re-plan; now they are held out (bounds) and the wind stays 4.8 kn."""
    eng = _engine(tmp_path)
    lines = _steady(eng.course, 60)
    bad = sentence("IIMWD,65.0,T,,M,80.00,N,41.16,M").strip()
    mwd = 0
    for line in lines:
        eng.feed(line)
        if line[3:6] == "MWD":
            mwd += 1
            if mwd > 30 and mwd % 5 == 0 and mwd <= 55:
                eng.feed(bad)
    st = eng.state()
    assert st["counts"]["gate_bounds"] == 5 and eng._wind.n_changes == 0
    assert st["wind"]["tws_ms"] * 3600 / 1852 == pytest.approx(4.8, abs=0.01)
    eng.close()
    rejects = [r for r in _records(tmp_path / "live.jsonl") if r["kind"] == "reject"]
    assert [r["why"] for r in rejects] == ["bounds"] * 5 and rejects[0]["tws_ms"] > 41


def test_positions_and_speeds_off_the_scale_are_not_logged_as_readings(tmp_path: Path) -> None:
    """lat 91, lon 1000 and a speed of 5e29 were logged as readings; now the first two are
    malformed (NMEA) or left out (Signal K), the speed held out, and none is an input."""
    eng = _engine(tmp_path)
    for line in _steady(eng.course, 5):
        eng.feed(line)
    eng.feed(sentence("GPRMC,094430.00,A,9100.0000,N,01338.5333,E,4.2,37.0,150218,,,A").strip())
    eng.feed(sentence("GPRMC,094506.00,A,4534.0000,N,01340.4000,E,5e29,37.0,150218,,,A").strip())
    eng.close()
    recs = _records(tmp_path / "live.jsonl")
    inputs = [r for r in recs if r["kind"] == "input"]
    assert all(abs(r.get("lat", 0)) <= 90 and r.get("sog_ms", 0) < 40 for r in inputs)
    assert recs[-1]["counts"]["malformed"] == 1 and recs[-1]["counts"]["gate_bounds"] == 1


def test_one_fix_from_another_clock_does_not_freeze_the_position(tmp_path: Path) -> None:
    """One RMC dated 2030 made every later (2018) fix "another clock" for the rest of the
    run; now it is held out and the later fixes move the boat."""
    eng = _engine(tmp_path)
    rows = approach(eng.course, 30, speed_ms=2.0)
    for k, r in enumerate(rows):
        for line in lines_of([r]):
            eng.feed(line)
        if k == 10:
            eng.feed(lines_of([Row(1_900_000_000.0, r.lat, r.lon, 4.0, 37.0)])[0])
    st = eng.state()
    assert st["t"] == rows[-1].t and st["position"]["lat"] == pytest.approx(rows[-1].lat)
    assert st["counts"]["gate_time"] == 1
    eng.close()


def test_no_single_message_ends_a_source(tmp_path: Path) -> None:
    """A ZDA of the year 9999999999 and a 401-digit number ended the source thread, and the
    run with it; now the file is read to its end and every fix after them arrives."""
    course = trieste()
    rows = approach(course, 30)
    lines = lines_of(rows)
    lines.insert(20, sentence("GPZDA,094430.00,15,02,9999999999,,").strip())
    lines.insert(40, sentence("IIMWD,65.0,T,," + "9" * 401 + ",N,1.8,M").strip())
    path = tmp_path / "f.nmea"
    path.write_text("\r\n".join(lines) + "\r\n", encoding="ascii")
    log = tmp_path / "live.jsonl"
    run_live_command(
        course,
        boat="self",
        source=str(path),
        scenario="mean",
        speed=200,
        port=None,
        nmea_port=None,
        log=log,
        duration_s=20,
        every_s=1000,
        leg=4,
        worker=False,
        settings=LiveSettings(side=False),
    )
    recs = _records(log)
    assert len([r for r in recs if r["kind"] == "input" and "lat" in r]) == 30
    assert recs[-1]["counts"]["malformed"] == 2


def test_a_message_that_raises_is_counted_and_the_source_goes_on(tmp_path: Path) -> None:
    """Whatever raises inside one message (here: a decoder that fails on a poisoned line)
    is counted and logged once, and the next messages are read."""
    eng = _engine(tmp_path)
    real = eng._feeds[0].decoder.feed

    def poisoned(text: str):
        if "POISON" in text:
            raise RuntimeError("poisoned")
        return real(text)

    eng._feeds[0].decoder.feed = poisoned  # type: ignore[method-assign]
    lines = _steady(eng.course, 10)
    for line in lines[:20] + ["$POISON"] * 3 + lines[20:]:
        eng.feed(line)
    assert eng.n_errors == 3 and eng.state()["position"]["t"] == eng.course.start_epoch + 9
    eng.close()
    errors = [r for r in _records(tmp_path / "live.jsonl") if r["kind"] == "error"]
    assert len(errors) == 1 and "RuntimeError: poisoned" in errors[0]["message"]


def test_deep_and_huge_signalk_messages_do_not_end_the_stream(tmp_path: Path) -> None:
    """A 100 000-deep message and a 401-digit number through a Signal K WebSocket: counted
    or left out, and the deltas after them arrive."""
    rows = approach(trieste(), 10)
    messages = [
        '{"self":"vessels.self"}',
        '{"updates":' + "[" * 100_000 + "]" * 100_000 + "}",
        _sk_delta(rows[0], "9" * 401),
        *(_sk_delta(r) for r in rows[1:]),
    ]
    _run_signalk(tmp_path, messages, len(rows))
    recs = _records(tmp_path / "live.jsonl")
    fixes = [r for r in recs if r["kind"] == "input" and "lat" in r]
    assert len(fixes) == len(rows) and "sog_ms" not in fixes[0] and fixes[1]["sog_ms"] == 1.0
    assert recs[-1]["counts"]["malformed"] == 1


def test_ipv6_signalk_url() -> None:
    """``signalk://[::1]:3000`` became ``ws://::1:3000/...``, which never connects."""
    sk = parse_source("signalk://[::1]:3000")
    assert isinstance(sk, SignalKSource)
    assert sk.url == "ws://[::1]:3000/signalk/v1/stream?subscribe=all"
    assert parse_source("nmea+tcp://[::1]:10110").label == "nmea+tcp://[::1]:10110"


def test_ipv6_signalk_server_connects(tmp_path: Path) -> None:
    try:
        with socket.socket(socket.AF_INET6) as s:
            s.bind(("::1", 0))
    except OSError:
        pytest.skip("no IPv6 loopback on this machine")
    rows = approach(trieste(), 5)
    eng = _run_signalk(tmp_path, [_sk_delta(r) for r in rows], len(rows), host="::1")
    assert eng.n_readings == len(rows)


def test_a_long_tcp_line_is_dropped_without_holding_it(tmp_path: Path) -> None:
    """An 8 MB line without an end over nmea+tcp was held whole (32 MB stalled the input
    for 6.5 s); now it is dropped as it comes, counted once, and the fixes after it come
    through."""
    course = trieste()
    lines = lines_of(approach(course, 15))
    feed = FeedServer([*lines[:10], "$GP" + "X" * 8_000_000, *lines[10:]], rate=200.0)
    eng = _engine(tmp_path, source=parse_source(f"nmea+tcp://127.0.0.1:{feed.port}"))
    longest = [0]
    real = eng.feed

    def spy(text: str, which: int = 0) -> None:
        longest[0] = max(longest[0], len(text))
        real(text, which)

    eng.feed = spy  # type: ignore[method-assign]
    eng.start()
    try:
        assert feed.finished.wait(20)
        time.sleep(0.3)
    finally:
        eng.close()
        feed.close()
    assert longest[0] <= MAX_LINE
    recs = _records(tmp_path / "live.jsonl")
    assert recs[-1]["counts"]["too_long"] == 1
    assert len([r for r in recs if r["kind"] == "input" and "lat" in r]) == 15


def test_a_replay_does_not_wait_out_a_jump_of_its_clock(tmp_path: Path) -> None:
    """A one-year jump of the file's clock was waited out; now an 8-s file at real time
    takes about 8 s, and the fix from the other year is held out."""
    course = trieste()
    rows = approach(course, 8)
    jumped = Row(rows[4].t + 365 * 86400.0, rows[4].lat, rows[4].lon, 1.0, 37.0)
    path = write_feed(tmp_path / "f.nmea", [*rows[:4], jumped, *rows[4:]])
    eng = _engine(tmp_path, source=NmeaFileSource(path, 1.0))
    w0 = time.monotonic()
    eng.start()
    eng.wait(30)
    took = time.monotonic() - w0
    eng.close()
    assert took < 15.0
    assert _records(tmp_path / "live.jsonl")[-1]["counts"]["gate_time"] == 1


def test_a_mark_name_outside_ascii_is_routed_and_sent(tmp_path: Path) -> None:
    """A course whose windward mark is "Bóia" stopped every re-plan (UnicodeEncodeError in
    the NMEA out); now the route goes to the plotter with the mark as BIA."""
    text = TRIESTE.read_text(encoding="utf-8").replace('"1"', '"Bóia"')
    path = tmp_path / "course.yaml"
    path.write_text(text.replace("../data/", str(TRIESTE.parent.parent / "data") + "/"), "utf-8")
    course = load_course(path)
    eng = _engine(tmp_path, course=course, nmea_port=0)
    assert eng.nmea is not None
    plotter = socket.create_connection(("127.0.0.1", eng.nmea.port), timeout=5)
    for line in lines_of(approach(course, 5, to="Bóia")):
        eng.feed(line)
    with eng._lock:
        due = eng._due()
    assert due is not None
    plan = eng.replan(due[1])
    assert plan is not None and "Bóia" in [w[0] for w in plan.waypoints]
    plotter.settimeout(2.0)
    got = plotter.recv(65536).decode("ascii")
    plotter.close()
    eng.close()
    assert f",{ROUTE_ID}," in got and ",BIA*" in got


def test_the_log_is_never_an_input(tmp_path: Path) -> None:
    """``--log`` could overwrite the recording being replayed or the course file."""
    course = trieste()
    feed = write_feed(tmp_path / "f.nmea", approach(course, 5))
    for log in (feed, TRIESTE, TRIESTE.parent.parent / "data" / "trieste-coach-2018-02-15.csv"):
        with pytest.raises(InputError, match="the same file as the input"):
            start_live(TRIESTE, source=str(feed), log=log, port=None, nmea_port=None, worker=False)


def test_a_busy_nmea_port_takes_the_next_free_one(tmp_path: Path) -> None:
    """The default NMEA port clashed with a Signal K server's (exit 2); now the next free
    port is taken and the run says so."""
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        eng = _engine(tmp_path, nmea_port=port)
        assert eng.nmea is not None and eng.nmea.port != port
        assert eng.notes == [f"NMEA port {port} is busy: using {eng.nmea.port}"]
        eng.close()


def test_the_scenario_running_out_falls_back_to_the_measured_wind(tmp_path: Path) -> None:
    """The course's ``measured`` scenario ends at 10:47:30 UTC; a re-plan at 10:40 needs
    wind to about 11:05.  It failed (87 of 125 re-plans on the real log); now it routes
    in the measured wind alone and says so."""
    eng = _engine(tmp_path, scenario="measured")
    t0 = eng.course.start_epoch + 55 * 60.0
    for line in lines_of(approach(eng.course, 15, t0=t0, twd=lambda s: 70.0)):
        eng.feed(line)
    with eng._lock:
        due = eng._due()
    assert due is not None
    plan = eng.replan(due[1])
    assert plan is not None and "routed in the measured wind only" in plan.wind_note
    assert "does not cover the route from" in plan.wind_note
    st = eng.state()
    assert st["measured_only"] and st["error"] == ""
    assert math.isfinite(plan.time_to_finish_s) and plan.time_to_finish_s > 0
    eng.close()


def test_page_token_and_commands(tmp_path: Path) -> None:
    """The page's changes need its token; with a token for all (a page served beyond this
    machine) so does every page request.  The coach sets the boat, its position and the
    leg."""
    import urllib.error
    import urllib.request

    from sailroute.live.web import PageServer, loopback

    eng = _engine(tmp_path, port=0, sailor=None)
    assert eng.page is not None
    base = f"http://127.0.0.1:{eng.page.port}"
    for line in _steady(eng.course, 3):
        eng.feed(line)

    def post(cmd: str, body: dict, token: str | None) -> tuple[int, dict]:
        q = "" if token is None else f"?token={token}"
        req = urllib.request.Request(
            f"{base}/api/{cmd}{q}", json.dumps(body).encode(), method="POST"
        )
        try:
            with urllib.request.urlopen(req) as r:
                return r.status, json.load(r)
        except urllib.error.HTTPError as e:
            return e.code, {}

    assert eng.state()["boat"]["why_not"].startswith("no boat chosen")
    assert post("boat", {"boat": "self"}, None)[0] == 403
    assert post("boat", {"boat": "self"}, "wrong")[0] == 403
    assert post("boat", {"boat": "211000001"}, eng.page.token) == (
        200,
        {"done": "routing urn:mrn:imo:mmsi:211000001"},
    )
    assert post("leg", {"leg": 9}, eng.page.token)[0] == 400
    assert post("leg", {"leg": 3}, eng.page.token) == (200, {"done": "leg 3 of 4"})
    assert eng.legs.leg == 2
    m = eng.course.frame.to_latlon(*eng.course.marks["4s"].xy)
    assert post("position", {"lat": float(m[0]), "lon": float(m[1])}, eng.page.token)[0] == 200
    where = eng.state()["boat"]["where"]
    assert where["how"] == "page" and where["lat"] == pytest.approx(float(m[0]))
    with urllib.request.urlopen(f"{base}/") as r:
        assert eng.page.token in r.read().decode()  # the page carries it
    eng.close()
    assert loopback("127.0.0.1") and loopback("::1") and not loopback("0.0.0.0")
    strict = PageServer(lambda: {"ok": 1}, 0, token="s3cret", token_for_all=True)
    try:
        with pytest.raises(urllib.error.HTTPError, match="403"):
            urllib.request.urlopen(f"http://127.0.0.1:{strict.port}/state.json")
        with urllib.request.urlopen(f"http://127.0.0.1:{strict.port}/state.json?token=s3cret") as r:
            assert json.load(r) == {"ok": 1}
    finally:
        strict.close()


def test_a_closed_tab_is_not_a_traceback(capfd: pytest.CaptureFixture[str]) -> None:
    """A client that resets its connection mid-answer printed a BrokenPipeError traceback
    per closed tab."""
    import struct

    from sailroute.live.web import PageServer

    big = {"x": "y" * 2_000_000}
    srv = PageServer(lambda: big, 0)
    try:
        for _ in range(5):
            c = socket.create_connection(("127.0.0.1", srv.port))
            c.sendall(b"GET /state.json HTTP/1.1\r\nHost: x\r\n\r\n")
            c.recv(100)
            c.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            c.close()  # a reset, not a close
        time.sleep(0.5)
    finally:
        srv.close()
    err = capfd.readouterr().err
    assert "Traceback" not in err and "BrokenPipe" not in err and "ConnectionReset" not in err


def test_the_sailors_boat_from_ais_is_routed_not_the_coach_boat(tmp_path: Path) -> None:
    """The coach boat (the instruments) waits 300 m off; an AIS target sails to mark 1:
    the route starts at the target, dead-reckoned to the data clock."""
    eng = _engine(tmp_path, sailor="211000001")
    course = eng.course
    coach = approach(course, 40, speed_ms=0.0, start_back_m=300.0)
    boat = approach(course, 40, speed_ms=2.0)
    for k, (c, b) in enumerate(zip(coach, boat, strict=True)):
        for line in lines_of([c]):
            eng.feed(line)
        if k % 10 == 0:  # a class B report every 10 s
            sec = int(b.t) % 60
            eng.feed(ais_sentence(211000001, b.lat, b.lon, b.sog_kn, b.cog_deg, None, sec))
    with eng._lock:
        due = eng._due()
    assert due is not None
    req = due[1]
    x, y = course.frame.to_xy(boat[-1].lat, boat[-1].lon)  # 9 s after the last report
    assert math.hypot(req.x - float(x), req.y - float(y)) < 1.0
    cx, cy = course.frame.to_xy(coach[-1].lat, coach[-1].lon)
    assert math.hypot(req.x - float(cx), req.y - float(cy)) > 200.0
    st = eng.state()
    assert st["boat"]["where"]["how"] == "dead reckoning" and st["boat"]["where"]["age_s"] == 9.0
    assert [v["label"] for v in st["vessels"]] == ["211000001"]
    eng.close()
    boats = [r for r in _records(tmp_path / "live.jsonl") if r["kind"] == "boat"]
    assert len(boats) == 4 and boats[0]["vessel"] == "urn:mrn:imo:mmsi:211000001"
    want = [boat[k].lat for k in (0, 10, 20, 30)]
    assert np.allclose([r["lat"] for r in boats], want, atol=2e-6)  # 1/10 000 minute


def test_a_rounding_of_the_sailors_boat_re_plans_at_once(tmp_path: Path) -> None:
    """The sailor's boat (AIS) goes round mark 1: the leg advances and the next re-plan
    is due at once (``rounding``), on leg 2, without waiting for the interval."""
    eng = _engine(tmp_path, sailor="247000001", settings=LiveSettings(side=False, every_s=1e6))
    course = eng.course
    boat, winds = build_specs(course, ["mean"])
    polar = boat.routing_polar()
    assert polar is not None
    t, x, y = sailed_track(course, winds["mean"], polar, step_s=2.0)
    lat, lon = course.frame.to_latlon(x, y)
    coach = approach(course, int(t[-1] - t[0]), speed_ms=0.0, t0=float(t[0]))
    reasons = []
    k = 0
    for row in coach:
        for line in lines_of([row]):
            eng.feed(line)
        while k < t.size and t[k] <= row.t:
            eng.feed(ais_sentence(247000001, lat[k], lon[k], None, None, None, int(t[k]) % 60))
            k += 1
            with eng._lock:
                due = eng._due()
            if due is not None:
                reasons.append((due[0], due[1].leg))
                with eng._lock:
                    eng._in_flight -= 1  # not computed here: the trigger is what is tested
        if eng.legs.leg == 2:
            break
    assert reasons[0] == ("first", 0) and reasons[1:] == [("rounding", 1), ("rounding", 2)]
    eng.close()
