"""``sailroute vpp`` through typer's CliRunner: outputs, consistency with the API, bad input."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.boat.build import vpp_polar
from sailroute.boat.io import read_polar
from sailroute.boat.kinetics import RACE
from sailroute.boat.laser import ILCA6, ILCA7
from sailroute.cli import app
from sailroute.units import KNOT

runner = CliRunner()


def table_rows(output: str) -> dict[float, list[float]]:
    """Rows of the printed speed table: TWA -> speeds."""
    rows = {}
    for line in output.splitlines():
        cells = line.split()
        if len(cells) > 2 and all(c.replace(".", "", 1).isdigit() for c in cells):
            rows[float(cells[0])] = [float(c) for c in cells[1:]]
    return rows


def test_vpp_default_boat_writes_readable_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    res = runner.invoke(app, ["vpp", "--tws", "4,8,12", "--twa-step", "15", "--out", str(out)])
    assert res.exit_code == 0, res.output
    for suffix in ("pol", "csv", "json", "png"):
        assert (out / f"ilca7.{suffix}").is_file()
    assert (out / "ilca7.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the default is the race polar, the model of the built-in ilca7 that plan routes with
    assert res.output.startswith("race polar (the VPP with wave riding and pumping")
    api = vpp_polar(
        ILCA7,
        tuple(v * KNOT for v in (4.0, 8.0, 12.0)),
        tuple(float(a) for a in range(0, 181, 15)),
        kinetics=RACE,
    )
    # every written format reads back to the API's polar (knots, 6 decimals)
    for suffix in ("pol", "csv", "json"):
        back = read_polar(out / f"ilca7.{suffix}")
        np.testing.assert_array_equal(back.twa_deg, api.twa_deg)
        np.testing.assert_allclose(back.speed_ms, api.speed_ms, atol=1e-6 * KNOT)
    # the printed table equals the API's values (2 decimals, knots)
    rows = table_rows(res.output)
    assert set(rows) == set(api.twa_deg)
    for a, speeds in rows.items():
        i = int(np.flatnonzero(api.twa_deg == a)[0])
        np.testing.assert_allclose(speeds, api.speed_ms[i] / KNOT, atol=0.005 + 1e-9)
    # best VMG lines agree with the API
    beat = next(ln for ln in res.output.splitlines() if ln.strip().startswith("beat TWA"))
    np.testing.assert_allclose(
        [float(v) for v in beat.split()[3:]], api.vmg_upwind(api.tws_ms)[0], atol=0.05 + 1e-9
    )
    doc = json.loads((out / "ilca7.json").read_text())
    assert doc["vpp_params"]["crew_mass_kg"] == 80.0 and doc["speed_unit"] == "kn"


def test_vpp_boat_file_options_and_units(tmp_path: Path) -> None:
    boat = tmp_path / "radial.yaml"
    boat.write_text("class: ilca6\nname: My radial\ncrew_mass_kg: 60\n")
    res = runner.invoke(
        app,
        [
            "vpp",
            str(boat),
            "--crew-mass",
            "64",
            "--tws",
            "3,6",
            "--twa-step",
            "30",
            "--unit",
            "m/s",
            "--kinetics",
            "steady",
            "--out",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    assert res.output.startswith("steady VPP (no wave riding or pumping")
    assert "My radial: boat speed [m/s]" in res.output
    back = read_polar(tmp_path / "radial.csv")  # units in the CSV header: m/s
    api = vpp_polar(
        replace(ILCA6, name="My radial", crew_mass_kg=64.0),
        (3.0, 6.0),
        tuple(float(a) for a in range(0, 181, 30)),
    )
    np.testing.assert_allclose(back.speed_ms, api.speed_ms, atol=1e-6)


def test_vpp_bad_input_exits_2_and_names_the_key(tmp_path: Path) -> None:
    boat = tmp_path / "b.yaml"
    boat.write_text("class: ilca7\ncrew_weight: 80\n")
    res = runner.invoke(app, ["vpp", str(boat), "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert "b.yaml:2: crew_weight: unknown key; did you mean 'crew_mass_kg'?" in res.output
    boat.write_text("class: [ilca7\n")
    res = runner.invoke(app, ["vpp", str(boat), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "b.yaml:2:1: YAML syntax error" in res.output
    res = runner.invoke(app, ["vpp", "--tws", "4,x", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "--tws: item 2 ('x') is not a number" in res.output
    res = runner.invoke(app, ["vpp", "--unit", "km/h", "--out", str(tmp_path)])
    assert res.exit_code == 2  # refused by the parser, the choices named
    assert "Invalid value for '--unit': 'km/h' is not one of 'kn', 'm/s'" in res.output
    res = runner.invoke(app, ["vpp", str(tmp_path / "none.yaml"), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "boat file not found" in res.output


@pytest.mark.parametrize(
    ("content", "args", "message"),
    [
        (None, ["--tws", ""], "--tws: no wind speed given; give comma-separated wind speeds"),
        (None, ["--tws", "8,4"], "--tws: wind speeds must increase"),
        (None, ["--tws", "4,-6"], "--tws: item 2 ('-6') must be a positive, finite speed"),
        # the readers' TWS limit (80 kn) at the writer's input: every file written reads back
        (
            None,
            ["--tws", "4,1000"],
            "--tws: item 2 (1000 kn) is above 80 kn, stronger than any wind a polar is made for",
        ),
        (None, ["--tws", "2,50", "--unit", "m/s"], "--tws: item 2 (50 m/s) is above 41.2 m/s"),
        (None, ["--crew-mass", "-70"], "--crew-mass: expected a sailor mass in 20-200 kg"),
        (None, ["--twa-step", "0"], "--twa-step: expected a step between 0.1 and 90 degrees"),
        (b"crew_mass_kg: -70\n", [], "b.yaml:1: crew_mass_kg: expected a finite number > 0"),
        (b"crew_mass_kg: 5\n", [], "b.yaml:1: crew_mass_kg: expected a sailor mass in 20-200 kg"),
        (b"class: ilca7\nname: \xff\n", [], "b.yaml: not a UTF-8 text file"),
        (
            b"crew_mass_kg: 80\nclass: ilca6\ncrew_mass_kg: 90\n",
            [],
            "b.yaml:3: crew_mass_kg: the key appears twice (lines 1 and 3)",
        ),
        (b"- ilca7\n", [], "b.yaml: a boat file is a mapping like 'class: ilca7'"),
        (b"stability: heel\n", [], "b.yaml: gz_m: stability 'heel' needs a righting-arm curve"),
        (b"sail_area_m2: 1e6\nbeam_m: wide\n", [], "b.yaml:2: beam_m: expected a number"),
    ],
)
def test_vpp_bad_input_table(
    tmp_path: Path, content: bytes | None, args: list[str], message: str
) -> None:
    """Every bad input: exit code 2, one message naming the file/line/key or option."""
    cmd = ["vpp", "--out", str(tmp_path / "out")]
    if content is not None:
        boat = tmp_path / "b.yaml"
        boat.write_bytes(content)
        cmd.insert(1, str(boat))
    res = runner.invoke(app, [*cmd, *args])
    assert res.exit_code == 2, (res.output, res.exception)
    assert message in res.output
    assert "Traceback" not in res.output
    assert "1e6" not in res.output  # YAML 1.2 scalars: 1e6 is a number, as in course files
    assert not (tmp_path / "out").exists()  # nothing written on bad input


def test_vpp_missing_file_and_folder(tmp_path: Path) -> None:
    res = runner.invoke(app, ["vpp", str(tmp_path / "none.yaml"), "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert "none.yaml: boat file not found; check the path, or leave BOAT.yaml out" in res.output
    res = runner.invoke(app, ["vpp", str(tmp_path), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "is a folder; expected a boat file" in res.output
