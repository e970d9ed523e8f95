"""Ensemble scenarios (members:): loading, the spread of leg times, sides, CLI, NetCDF members."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.course.load import build_boat, build_wind, load_course
from sailroute.errors import InputError
from sailroute.planning.route import compare_scenarios, default_scenario, plan_course
from sailroute.report.ensemble import SIDES, route_side, summarize_ensemble
from tests.conftest import ROOT

TEMPLATE = yaml.safe_load((ROOT / "courses" / "windward-leeward-template.yaml").read_text())
DIRS = (262.0, 266.0, 270.0, 274.0, 278.0)


def write_course(tmp_path: Path, scenarios: dict, name: str = "ens.yaml") -> Path:
    data = {k: v for k, v in TEMPLATE.items() if k != "scenarios"}
    data["template"] = {**data["template"], "laps": 1}  # start - 1 - finish: fast
    data["scenarios"] = scenarios
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def members(dirs=DIRS) -> list[dict]:
    return [{"type": "uniform", "tws_kn": 12, "twd_deg": d} for d in dirs]


def test_members_expand_to_scenarios_and_the_ensemble_keeps_its_name(tmp_path) -> None:
    c = load_course(
        write_course(
            tmp_path,
            {
                "spread": {"members": members(), "description": "five directions"},
                "steady": {"type": "uniform", "tws_kn": 12, "twd_deg": 270},
            },
        )
    )
    assert list(c.scenarios) == [f"spread#{k}" for k in range(1, 6)] + ["steady"]
    assert c.ensembles == {"spread": tuple(f"spread#{k}" for k in range(1, 6))}
    assert c.scenario_names == ("spread", "steady")
    assert default_scenario(c) == "spread"
    assert c.scenarios["spread#4"].wind.twd_deg == 274.0  # type: ignore[union-attr]
    with pytest.raises(InputError, match="'spread' is an ensemble of 5 members"):
        plan_course(c, "spread")


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"members": members(), "wind": members()[0]}, "give exactly one of `wind:"),
        ({"members": members()[:1]}, "an ensemble needs at least 2 members; got 1"),
        (
            {"members": [members()[0], {"tws_kn": 3}]},
            "scenarios.e.members[1]: the wind spec has no `type`",
        ),
        (
            {"members": {"dim": "number", "wind": {"type": "uniform", "tws_kn": 3, "twd_deg": 0}}},
            "members along a dimension need `type: netcdf`",
        ),
    ],
)
def test_member_problems_name_the_key(tmp_path, spec, message) -> None:
    with pytest.raises(InputError) as e:
        load_course(write_course(tmp_path, {"e": spec}))
    assert message in str(e.value)


def test_spread_is_the_percentiles_of_the_members_routed_alone(tmp_path) -> None:
    c = load_course(write_course(tmp_path, {"spread": {"members": members()}}))
    _, plans = compare_scenarios(c, ["spread"])
    s = summarize_ensemble("spread", plans)
    alone = np.array(
        [[leg.time_s for leg in plan_course(c, f"spread#{k}").plan.legs] for k in range(1, 6)]
    )
    np.testing.assert_array_equal(s.times_s, alone)
    table = np.column_stack([alone, alone.sum(axis=1)])
    np.testing.assert_allclose(
        s.spread(), np.percentile(table, [0, 10, 50, 90, 100], axis=0).T, rtol=0, atol=1e-9
    )
    assert s.spread()[-1, 0] == pytest.approx(alone.sum(axis=1).min())
    shares = s.side_shares()
    np.testing.assert_allclose(shares.sum(axis=1), 1.0)
    boat = build_boat(c)
    assert [row[0] for row in s.sides] == [
        route_side(p, 0, build_wind(c, p.scenario), boat) for p in plans
    ]
    assert set(np.ravel(s.sides)) <= set(SIDES)
    # steady, uniform winds: whichever side a route took, the other side's layline extreme
    # is as fast, so no beat or run counts as a side (a route taken alone still has one)
    assert {row[0] for row in s.sides} == {"tie"}
    assert {route_side(p, 0) for p in plans} <= {"left", "right"}


def test_cli_plan_on_an_ensemble_writes_the_spread(tmp_path) -> None:
    course = write_course(tmp_path, {"spread": {"members": members()}})
    res = CliRunner().invoke(app, ["plan", str(course), "-q", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert "ensemble spread: 5 members" in res.output
    doc = json.loads((tmp_path / "o" / "ensemble.json").read_text())
    assert doc["members"] == [f"spread#{k}" for k in range(1, 6)]
    totals = doc["member_total_s"]
    assert doc["total_s"]["min"] == pytest.approx(min(totals))
    assert doc["total_s"]["median"] == pytest.approx(float(np.median(totals)))
    assert (tmp_path / "o" / "spread#3" / "plan.json").is_file()
    from sailroute.report.page_render import read_figure

    fig = read_figure((tmp_path / "o" / "report.html").read_text(encoding="utf-8"))
    assert [
        t["name"]
        for t in fig["data"]
        if t.get("legendgroup", "").startswith("route") and t["mode"] == "lines"
    ] == doc["members"]
    cmp = CliRunner().invoke(
        app, ["compare-scenarios", str(course), "-q", "--no-plots", "--out", str(tmp_path / "c")]
    )
    assert cmp.exit_code == 0, cmp.output
    assert (tmp_path / "c" / "spread" / "ensemble.json").is_file()


def _member_netcdf(path: Path, speeds: list[float]) -> None:
    import netCDF4

    lats, lons = np.arange(42.9, 43.25, 0.05), np.arange(6.0, 6.45, 0.05)
    with netCDF4.Dataset(str(path), "w") as ds:
        ds.createDimension("time", 2)
        ds.createDimension("number", len(speeds))
        ds.createDimension("lat", lats.size)
        ds.createDimension("lon", lons.size)
        t = ds.createVariable("time", "f8", ("time",))
        t.units = "hours since 2024-06-01 10:00:00"
        t[:] = [0.0, 6.0]
        la = ds.createVariable("lat", "f8", ("lat",))
        la.standard_name, la.units, la[:] = "latitude", "degrees_north", lats
        lo = ds.createVariable("lon", "f8", ("lon",))
        lo.standard_name, lo.units, lo[:] = "longitude", "degrees_east", lons
        shape = (2, len(speeds), lats.size, lons.size)
        u = np.broadcast_to(np.array(speeds)[None, :, None, None], shape)
        for name, std, arr in (("u10", "eastward_wind", u), ("v10", "northward_wind", 0 * u)):
            v = ds.createVariable(name, "f4", ("time", "number", "lat", "lon"))
            v.standard_name, v.units = std, "m/s"
            v[:] = arr


def test_netcdf_member_dimension_gives_one_member_per_index(tmp_path) -> None:
    from sailroute.course.load import build_specs

    _member_netcdf(tmp_path / "ens.nc", [4.0, 6.0, 8.0])
    spec = {"members": {"dim": "number", "wind": {"type": "netcdf", "path": "ens.nc"}}}
    c = load_course(write_course(tmp_path, {"nc": spec}))
    assert c.ensembles == {"nc": ("nc#1", "nc#2", "nc#3")}
    _, winds = build_specs(c, list(c.scenarios))
    t0 = c.start_epoch
    for k, speed in enumerate([4.0, 6.0, 8.0], 1):
        u, v = winds[f"nc#{k}"].sample(t0, 0.0, 0.0)  # westerly: blows towards +x
        assert float(np.hypot(u, v)) == pytest.approx(speed, rel=1e-6)
    bad = {"members": {"dim": "members", "wind": {"type": "netcdf", "path": "ens.nc"}}}
    with pytest.raises(InputError, match=r"ens\.nc has no dimension 'members'; it has time"):
        load_course(write_course(tmp_path, {"nc": bad}, "bad.yaml"))
    one = {"type": "netcdf", "path": "ens.nc", "select": {"number": 5}}
    c2 = load_course(write_course(tmp_path, {"one": one}, "one.yaml"))
    with pytest.raises(
        InputError,
        match=r"select number: 5 is out of range; that dimension "
        r"has indices 0 \.\. 2",
    ):
        build_specs(c2, ["one"])
