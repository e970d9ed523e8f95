"""``sailroute polar fit LOG...``: a fleet's logs in, a learned polar's files out; bad input
gives one line each and writes nothing; the boats are counted on stderr (``-q``: not), the
output the same either way."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import Result
from typer.testing import CliRunner

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.cli import app
from sailroute.units import KNOT
from tests.fleetgen import FaultPlan, messy_fleet

runner = CliRunner()
POLAR = builtin_polar("ilca7-steady")
T0 = 1_700_000_000


def write_log(
    path: Path, skill: float, *, seed: int, wind: bool = True, minutes: float = 24.0
) -> Path:
    """A 1 Hz log of a boat sailing ``skill x POLAR`` in a 10 kn wind from the north with
    small shifts: 2-minute boards at 43 deg on alternate tacks, then at 170 deg, 90 s each,
    turning in 6 s; with ``wind`` the TWS/TWD columns (kn, deg)."""
    rng = np.random.default_rng(seed)
    n = int(minutes * 60)
    t = np.arange(n, dtype=float)
    twd = 4.0 * np.sin(2 * np.pi * t / 400.0 + seed)
    tws = 10.0 * KNOT * (1 + 0.05 * np.sin(2 * np.pi * t / 700.0 + seed))
    phase = (t % 1800.0) < 960.0  # beats, then runs
    board = np.where(phase, (t // 120) % 2, (t // 90) % 2) * 2 - 1
    twa = np.where(phase, 43.0, 170.0) * board
    twa = np.convolve(np.pad(twa, 3, mode="edge"), np.ones(7) / 7, mode="valid")  # 6 s turns
    hdg = twd - twa
    v = skill * POLAR.speed(tws, twa) * (1 + 0.01 * rng.standard_normal(n))
    x = np.cumsum(v * np.sin(np.radians(hdg))) + rng.normal(0, 0.5, n)
    y = np.cumsum(v * np.cos(np.radians(hdg))) + rng.normal(0, 0.5, n)
    lat, lon = 43.0 + y / 111_320.0, 6.0 + x / (111_320.0 * np.cos(np.radians(43.0)))
    head = "time,lat,lon" + (",tws_kn,twd_deg" if wind else "")
    rows = [
        f"{np.datetime_as_string(np.datetime64(T0 + k, 's'))}Z,{lat[k]:.7f},{lon[k]:.7f}"
        + (f",{tws[k] / KNOT:.3f},{twd[k] % 360:.2f}" if wind else "")
        for k in range(n)
    ]
    path.write_text(head + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    d = tmp_path_factory.mktemp("fleet")
    return [write_log(d / f"boat{k}.csv", s, seed=k) for k, s in enumerate((0.92, 0.96, 1.0))]


def test_a_fleet_in_a_learned_polar_out(tmp_path: Path, fleet: list[Path]) -> None:
    out = tmp_path / "out"
    res = runner.invoke(
        app, ["polar", "fit", *map(str, fleet), "--out", str(out), "--bootstrap", "30"]
    )
    assert res.exit_code == 0, res.output
    for suffix in ("pol", "csv", "json", "png"):
        assert (out / f"boat0-fleet.{suffix}").is_file()
    assert "level top: P90 of the boats" in res.output and "verdict:" in res.output
    doc = json.loads((out / "boat0-fleet.json").read_text())
    lv = doc["learned"]["levels"]
    assert set(lv) == {"median", "top"} and doc["learned"]["provenance"]["boats"] == [
        "boat0",
        "boat1",
        "boat2",
    ]
    # the beat: the boats sailed 43 deg at 0.92-1.0 of the polar; the median boat is 0.96
    twa = np.asarray(doc["twa_deg"])
    k = int(np.argmin(np.abs(twa - 43.0)))
    tws = np.asarray(doc["tws"])
    j = int(np.argmin(np.abs(tws - 10.0)))
    assert doc["learned"]["cells"]["status"][k][j] == "learned"
    want = 0.96 * float(POLAR.speed(tws[j] * KNOT, twa[k])) / KNOT
    assert lv["median"]["speed"][k][j] == pytest.approx(want, rel=0.03)
    assert lv["top"]["speed"][k][j] > lv["median"]["speed"][k][j]
    top = boat_from_spec(
        {"polar": "out/boat0-fleet.json", "level": "top"}, base_dir=tmp_path, where="c"
    )
    assert top.name == "boat0-fleet (top)"
    assert top.speed_ms[k, j] == pytest.approx(lv["top"]["speed"][k][j] * KNOT, rel=1e-4)


@pytest.mark.parametrize(
    ("logs", "extra", "message"),
    [
        (
            [("a", 1.0, True), ("b", 0.97, True), ("cat", 2.0, True)],
            [],
            "error: logs of different classes: cat sails 2.0",
        ),
        ([("gps", 1.0, False)], [], "no wind in the log and no --course"),
        (
            [("a", 1.0, True), ("b", 0.97, True)],
            ["--min-boats", "3"],
            "error: --min-boats 3: the fleet has 2 boat(s) (a, b); no cell can be sailed by 3",
        ),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(
    tmp_path: Path, logs: list, extra: list[str], message: str
) -> None:
    paths = [
        write_log(tmp_path / f"{n}.csv", s, seed=k, wind=w, minutes=14)
        for k, (n, s, w) in enumerate(logs)
    ]
    out = tmp_path / "out"
    # -q: the error alone (without it the boats counted before the error come first)
    res = runner.invoke(app, ["polar", "fit", *map(str, paths), *extra, "-q", "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert message in res.output and len(res.output.strip().splitlines()) == 1, res.output
    assert not out.exists()


def test_plan_sails_the_learned_polar_and_says_which(tmp_path: Path, fleet: list[Path]) -> None:
    out = tmp_path / "out"
    res = runner.invoke(
        app, ["polar", "fit", *map(str, fleet), "--out", str(out), "--bootstrap", "0"]
    )
    assert res.exit_code == 0, res.output
    course = tmp_path / "wl.yaml"
    course.write_text(
        'name: learned boat\nstart_time: "2024-06-01T14:00:00+02:00"\n'
        "template: {type: windward-leeward, centre: {lat: 43.07, lon: 6.2}, twd_deg: 0, "
        "leg_length_m: 600, laps: 1}\n"
        "boat: {polar: out/boat0-fleet.json, level: top}\n"
        "scenarios: {ten: {type: uniform, tws_kn: 10, twd_deg: 0}}\n",
        encoding="utf-8",
    )
    res = runner.invoke(app, ["plan", str(course), "--out", str(tmp_path / "plan")])
    assert res.exit_code == 0, res.output
    assert "boat polar boat0-fleet.json, level top, steady pace" in res.output
    doc = json.loads((tmp_path / "plan" / "plan.json").read_text())
    assert doc["boat"]["label"] == "polar boat0-fleet.json, level top, steady pace"
    assert doc["boat"]["spec"] == {"polar": "out/boat0-fleet.json", "level": "top"}
    # the beat at the learned top level's VMG: no faster than the best boat's polar
    best = POLAR.vmg_upwind(10.0 * KNOT)[1]
    beat = doc["legs"][1] if doc["legs"][1]["mode"] == "upwind" else doc["legs"][0]
    assert beat["mode"] == "upwind" and beat["time_s"] > 600.0 / best


# --- progress on stderr: the boats counted, nothing else changed --------------------------


@pytest.fixture(scope="module")
def races(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[Path], list[Path], list[str]]:
    """Four boats' GPS tracks (no wind) of a generated race (``tests/fleetgen.py``) and its
    course twice, under two names: two races of the same four boats."""
    d = tmp_path_factory.mktemp("races")
    fl = messy_fleet(0, n_boats=4, minutes=12, faults=FaultPlan.clean(), sample_s=(1, 1))
    course, tracks = fl.write(d, "gpx")
    again = d / "again.yaml"
    text = re.sub(r"^name:.*$", "name: the race again", course.read_text(), count=1, flags=re.M)
    again.write_text(text, encoding="utf-8")
    return tracks, [course, again], [t.name for t in fl.tracks]


RUNS = {"shown": [], "quiet": ["-q"]}


@pytest.fixture(scope="module")
def shown_and_quiet(
    tmp_path_factory: pytest.TempPathFactory, races: tuple[list[Path], list[Path], list[str]]
) -> tuple[Path, dict[str, Result]]:
    """``polar fit`` of the two races, with its progress and with ``-q``."""
    d = tmp_path_factory.mktemp("runs")
    tracks, courses, _ = races
    args = ["polar", "fit", *map(str, tracks), "--bootstrap", "20"]
    args += [a for c in courses for a in ("--course", str(c))]
    res = {tag: runner.invoke(app, [*args, *q, "-o", str(d / tag)]) for tag, q in RUNS.items()}
    for r in res.values():
        assert r.exit_code == 0, r.output
    return d, res


def test_each_race_counts_its_boats_on_stderr(
    shown_and_quiet: tuple[Path, dict[str, Result]],
    races: tuple[list[Path], list[Path], list[str]],
) -> None:
    d, res = shown_and_quiet
    lines = res["shown"].stderr.splitlines()
    names = races[2]
    for k, race in enumerate(("messy fleet (seed 0)", "the race again")):
        where = f"race {k + 1} of 2"
        counted = [ln for ln in lines if ln.startswith(f"{where}, boat ")]
        # a line per boat, each named once in the order given, up to 4 of 4
        got = [re.match(rf"{where}, boat (\d) of 4 done \((\w+)\): ", ln) for ln in counted]
        assert [m.groups() if m else ln for m, ln in zip(got, counted, strict=True)] == [
            (str(i + 1), n) for i, n in enumerate(names)
        ]
        assert all(", about " in ln and ln.endswith(" left") for ln in counted[:-1])
        assert counted[-1].endswith(" elapsed")  # the last: nothing left
        # no boat has instruments: the fleet's wind is inferred first, not counted as a boat
        note = f"{where}, {race}: inferring the wind direction from the 4 tracks (4 without "
        note += "instruments)"
        assert lines.index(note) == lines.index(counted[0]) - 1
    # then what the polar is learned from: the blocks the written polar says it has
    doc = json.loads((d / "shown" / "bel2686-fleet.json").read_text())
    blocks = doc["learned"]["provenance"]["blocks"]
    assert (
        lines[-1]
        == f"learning the polar from {blocks} steady blocks of 4 boat(s) (20 bootstrap replicates)"
    )
    assert len(lines) == 2 * (1 + 4) + 1
    assert " of 4 done" not in res["shown"].stdout


def test_quiet_shows_no_progress(shown_and_quiet: tuple[Path, dict[str, Result]]) -> None:
    _, res = shown_and_quiet
    assert res["quiet"].stderr == "" and res["shown"].stderr != ""


def test_the_progress_changes_no_output(shown_and_quiet: tuple[Path, dict[str, Result]]) -> None:
    d, res = shown_and_quiet
    files = {tag: sorted(p.relative_to(d / tag) for p in (d / tag).rglob("*")) for tag in RUNS}
    assert files["shown"] == files["quiet"] and len(files["shown"]) == 5  # 4 + the manifest
    for rel in files["shown"]:
        assert (d / "shown" / rel).read_bytes() == (d / "quiet" / rel).read_bytes(), rel
    assert res["shown"].stdout.replace(str(d / "shown"), "OUT") == res["quiet"].stdout.replace(
        str(d / "quiet"), "OUT"
    )


def test_logs_without_a_course_count_the_boats_too(tmp_path: Path, fleet: list[Path]) -> None:
    res = runner.invoke(
        app, ["polar", "fit", *map(str, fleet), "--out", str(tmp_path / "o"), "--bootstrap", "0"]
    )
    assert res.exit_code == 0, res.output
    lines = res.stderr.splitlines()
    # each log in its own wind: no wind to infer, the three boats, then the learning
    assert [ln.split(":")[0] for ln in lines[:3]] == [
        f"boat {k + 1} of 3 done (boat{k})" for k in range(3)
    ]
    assert lines[3].startswith("learning the polar from ") and len(lines) == 4
