"""``sailroute polar fit LOG...``: a fleet's logs in, a learned polar's files out; bad input
gives one line each and writes nothing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.cli import app
from sailroute.units import KNOT

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
    res = runner.invoke(app, ["polar", "fit", *map(str, paths), *extra, "--out", str(out)])
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
