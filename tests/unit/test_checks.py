"""sailroute.checks: the one validation mechanism of course files, wind specs and boat files."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from sailroute.boat.boatfile import load_boat_file
from sailroute.checks import Checker, Problems, split_where, suggest
from sailroute.course.load import build_boat, load_course
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.wind.build import wind_from_spec

COURSE = """\
name: checks
start_time: "2024-05-01T12:00:00+02:00"
marks:
  pin: {lat: 45.0, lon: 13.0}
  boat: {lat: 45.0, lon: 13.002}
  top: {lat: 45.009, lon: 13.001}
lines:
  start: [pin, boat]
legs:
  - {to: top, rounding: port}
scenarios:
  steady:
    type: uniform
    tws_kn: 10
    twd_deg: 0
"""


def _error(fn, *args, **kw) -> str:
    with pytest.raises(InputError) as e:
        fn(*args, **kw)
    return str(e.value)


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text), encoding="utf-8")
    return p


# ----------------------------------------------------------------------------- did you mean
def test_suggest_is_the_closest_choice_or_nothing() -> None:
    assert suggest("twd", ["tws_kn", "twd_deg"]) == "did you mean 'twd_deg'? "
    assert suggest("crew_mass", ["beam_m", "crew_mass_kg"]) == "did you mean 'crew_mass_kg'? "
    assert suggest("zzz", ["tws_kn", "twd_deg"]) == ""
    assert suggest(1234, [1235, "x"]) == "did you mean '1235'? "  # compared as text


def test_one_did_you_mean_for_course_wind_and_boat_files(tmp_path: Path) -> None:
    # course file: an unknown top-level key
    course = _write(tmp_path, "c.yaml", COURSE + "referencez: {}\n")
    msg = _error(load_course, course)
    assert f"{course}:16: referencez: unknown key; did you mean 'references'? valid keys: " in msg
    # wind spec inside it: an unknown key of the scenario's spec, at its own line
    course = _write(tmp_path, "w.yaml", COURSE.replace("twd_deg: 0", "twd: 0"))
    msg = _error(load_course, course)  # found when the course loads
    assert (
        f"{course}:15: scenarios.steady.twd: unknown key; did you mean 'twd_deg'? "
        "valid keys: type, tws_kn" in msg
    )
    # boat file: an unknown parameter ("weight" is read as "mass")
    boat = _write(tmp_path, "b.yaml", "class: ilca7\ncrew_weight: 80\n")
    msg = _error(load_boat_file, boat)
    assert msg.startswith(f"{boat}:2: crew_weight: unknown key; did you mean 'crew_mass_kg'? ")
    # the same words around the same hint in all three
    for word, choices in [
        ("referencez", ["references"]),
        ("twd", ["twd_deg"]),
        ("crew_mass", ["crew_mass_kg"]),
    ]:
        assert suggest(word, choices) == f"did you mean {choices[0]!r}? "


def test_a_bad_choice_gets_the_same_hint_in_a_course_and_a_wind_spec(tmp_path: Path) -> None:
    course = _write(tmp_path, "c.yaml", COURSE.replace("rounding: port", "rounding: prot"))
    msg = _error(load_course, course)
    assert msg == (
        f"{course}:10: legs[0].rounding: expected one of 'port', 'starboard'; "
        "got 'prot' (did you mean 'port'?)"
    )
    course = _write(
        tmp_path, "w.yaml", COURSE.replace("type: uniform", "type: uniform\n    interpolation: lin")
    )
    msg = _error(load_course, course)  # found when the course loads
    assert msg == (
        f"{course}:14: scenarios.steady.interpolation: expected one of 'linear', "
        "'previous'; got 'lin' (did you mean 'linear'?)"
    )


# ----------------------------------------------------------------------------- lines
def test_a_wind_spec_problem_is_reported_at_its_own_line(tmp_path: Path) -> None:
    # before sailroute.checks, the line was the scenario's (12), not the key's (14)
    course = _write(tmp_path, "c.yaml", COURSE.replace("tws_kn: 10", "tws_kn: ten"))
    msg = _error(load_course, course)  # found when the course loads
    assert msg == f"{course}:14: scenarios.steady.tws_kn: expected a number >= 0; got 'ten'"


def test_a_wind_spec_with_a_wind_key_reports_lines_below_it(tmp_path: Path) -> None:
    text = COURSE.replace(
        """  steady:
    type: uniform
    tws_kn: 10
    twd_deg: 0
""",
        """  steady:
    description: a steady breeze
    wind:
      type: uniform
      tws_kn: 10
      twd_deg: 400
""",
    )
    course = _write(tmp_path, "c.yaml", text)
    msg = _error(load_course, course)  # found when the course loads
    assert (
        msg == f"{course}:17: scenarios.steady.wind.twd_deg: expected a number in [0, 360]; got 400"
    )


def test_a_boat_file_problem_is_reported_at_its_line(tmp_path: Path) -> None:
    boat = _write(tmp_path, "b.yaml", "class: ilca6\n\ncrew_mass_kg: 70\nbeam_m: wide\n")
    assert _error(load_boat_file, boat) == f"{boat}:4: beam_m: expected a number; got 'wide'"


def test_a_course_boat_vpp_problem_is_reported_at_its_own_line(tmp_path: Path) -> None:
    # before sailroute.checks, the line was the `boat:` key's (16), not the parameter's (19)
    course = _write(
        tmp_path, "c.yaml", COURSE + "boat:\n  vpp:\n    class: ilca7\n    beam_m: -1\n"
    )
    msg = _error(build_boat, load_course(course))
    assert msg == f"{course}:19: boat.vpp.beam_m: expected a finite number > 0; got -1.0"


# ----------------------------------------------------------------------------- all at once
def test_every_problem_is_listed_once_under_one_title() -> None:
    p = Problems("x.yaml", {"a": 3, "a.b": 4, "c[1]": 9})
    p.add("a.b", "expected a number; got 'x'")
    p.add("a.z", "unknown key")
    p.add("c[1].d", "missing required key")
    p.add("e", "expected text; got 1")
    with pytest.raises(InputError) as e:
        p.raise_if_any()
    assert str(e.value) == (
        "x.yaml: 4 problems in the course file\n"
        "  - x.yaml:4: a.b: expected a number; got 'x'\n"
        "  - x.yaml:3: a.z: unknown key\n"
        "  - x.yaml:9: c[1].d: missing required key\n"
        "  - x.yaml: e: expected text; got 1"
    )
    p = Problems("x.yaml")
    p.raise_if_any()  # nothing recorded: no error
    p.add("k", "expected true or false; got 'yes'")
    assert _error(p.raise_if_any) == "x.yaml: k: expected true or false; got 'yes'"


def test_a_wind_spec_lists_every_problem_under_its_key_path() -> None:
    msg = _error(
        wind_from_spec,
        {"type": "uniform", "tws_kn": -3, "twd_deg": "north", "clamp": "yes", "table2": []},
        frame=LocalFrame(45.0, 13.0),
        base_dir=Path("."),
        where="c.yaml:12: scenarios.a",
        lines={"scenarios.a.tws_kn": 14},
    )
    assert msg.splitlines() == [
        "c.yaml:12: scenarios.a: 4 problems in the wind spec",
        "  - c.yaml:12: scenarios.a.table2: unknown key; did you mean 'table'? valid keys: "
        "type, tws_kn, tws_ms, twd_deg, table, interpolation, clamp",
        "  - c.yaml:12: scenarios.a.clamp: expected true or false; got 'yes'",
        "  - c.yaml:14: scenarios.a.tws_kn: expected a number >= 0; got -3",
        "  - c.yaml:12: scenarios.a.twd_deg: expected a number in [0, 360]; got 'north'",
    ]


def test_a_course_lists_every_problem_at_once(tmp_path: Path) -> None:
    text = COURSE.replace("lon: 13.002", "lon: east").replace("rounding: port", "rounding: up")
    course = _write(tmp_path, "c.yaml", text + "time_limit_min: 0\n")
    msg = _error(load_course, course)
    assert msg.splitlines() == [
        f"{course}: 3 problems in the course file",
        f"  - {course}:16: time_limit_min: expected a number > 0; got 0",
        f"  - {course}:5: marks.boat.lon: expected a longitude in [-180, 360] degrees; got 'east'",
        f"  - {course}:10: legs[0].rounding: expected one of 'port', 'starboard'; got 'up'",
    ]


# ----------------------------------------------------------------------------- getters
@pytest.mark.parametrize(
    ("value", "bounds", "message"),
    [
        (400, {"lo": 0.0, "hi": 360.0}, "expected a number in [0, 360]; got 400"),
        (0, {"lo": 0.0, "lo_open": True}, "expected a number > 0; got 0"),
        (-1, {"lo": 0.0}, "expected a number >= 0; got -1"),
        (6, {"hi": 5.0}, "expected a number <= 5; got 6"),
        (0, {"lo": 0.0, "hi": 1.0, "lo_open": True}, "expected a number in (0, 1]; got 0"),
        ("ten", {"lo": 0.0}, "expected a number >= 0; got 'ten'"),
        (True, {}, "expected a number; got True"),
        (float("nan"), {}, "expected a number; got nan"),
        (float("inf"), {"lo": 0.0}, "expected a number >= 0; got inf"),
        ([1], {}, "expected a number; got a list"),
        (2, {"lo": 0.0, "hi": 1.0, "what": "a fraction"}, "expected a fraction; got 2"),
    ],
)
def test_number_bounds_messages(value, bounds, message) -> None:
    p = Problems("f.yaml", {"s.k": 7})
    assert Checker(p, "s").number({"k": value}, "k", **bounds) is None
    assert p.items == [f"f.yaml:7: s.k: {message}"]


def test_number_inside_its_bounds_and_absent_keys() -> None:
    p = Problems("f.yaml")
    c = Checker(p, "s")
    assert c.number({"k": 360}, "k", lo=0.0, hi=360.0) == 360.0
    assert c.number({"k": 1}, "k", lo=0.0, lo_open=True) == 1.0
    assert c.number({}, "k", 5.0, lo=0.0) == 5.0
    assert c.number({"k": None}, "k", None) is None  # null is absent: the default
    assert p.items == []
    assert c.number({}, "k", lo=0.0, hi=360.0) is None
    assert p.items == ["f.yaml: s.k: missing required key; expected a number in [0, 360]"]


def test_other_getters_messages() -> None:
    p = Problems("f.yaml")
    c = Checker(p)
    d = {"n": 1.5, "s": " ", "b": "yes", "m": [1], "ch": "linaer", "t": "noon"}
    assert c.integer(d, "n", lo=1) is None
    assert c.string(d, "s") is None
    assert c.boolean(d, "b", True) is True
    assert c.mapping(d, "m") is None
    assert c.choice(d, "ch", ["linear", "nearest"]) is None
    assert c.time(d, "t") is None
    assert c.choice({}, "absent", ["a", "b"]) is None
    c.keys({"kys": 1}, ["keys", "values"], ["values"])
    assert p.items[:5] == [
        "f.yaml: n: expected a whole number >= 1; got 1.5",
        "f.yaml: s: expected non-empty text; got ' '",
        "f.yaml: b: expected true or false; got 'yes'",
        "f.yaml: m: expected a mapping (key: value pairs); got a list",
        "f.yaml: ch: expected one of 'linear', 'nearest'; got 'linaer' (did you mean 'linear'?)",
    ]
    assert p.items[5].startswith("f.yaml: t: ")  # parse_time's own message, with the place
    assert "'noon'" in p.items[5]
    assert p.items[6:] == [
        "f.yaml: absent: missing required key; expected one of 'a', 'b'",
        "f.yaml: kys: unknown key; did you mean 'keys'? valid keys: keys, values",
        "f.yaml: values: missing required key",
    ]


def test_split_where_inverts_the_prefix() -> None:
    p = Problems("courses/x.yaml", {"scenarios.a.wind": 12})
    for path in ("scenarios.a.wind", "scenarios.b", ""):
        file, line, key = split_where(p.prefix(path))
        assert (file, line, key) == ("courses/x.yaml", p.line_of(path), path)
    assert split_where("vpp(boat)") == ("vpp(boat)", None, "")
    below = Problems.below("c.yaml:12: scenarios.a", what="wind spec")
    below.add("scenarios.a.k", "unknown key")
    assert below.items == ["c.yaml:12: scenarios.a.k: unknown key"]
