"""Strategy figures, JSON summary, the study API and the ``sailroute strategy`` command."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.backend import _cupy_or_none
from sailroute.boat.build import builtin_polar
from sailroute.cli import app
from sailroute.commands.strategy import parse_objective, parse_shift, run_strategy_command
from sailroute.errors import InputError
from sailroute.report import strategy as report
from sailroute.report.strategy import write_strategy_outputs
from sailroute.strategy.montecarlo import simulate
from sailroute.strategy.sdp import BeatGrid, solve_expected_time
from sailroute.strategy.shiftmodel import DriftDiffusionShift, OUShift
from sailroute.strategy.study import StrategySettings, run_strategy
from sailroute.units import KNOT
from tests.conftest import ROOT, SHARED_REAL, TESTS_DATA, requires_shared

ILCA7 = builtin_polar("ilca7")
COACH = SHARED_REAL / "wind" / "anemomind-coach-trieste" / "coach_wind_1hz.csv"
COACH_EXCERPT = TESTS_DATA / "wind" / "coach_wind_1hz_excerpt.csv"
SMALL = dict(length_m=400.0, half_width_m=200.0, lateral_m=4.0, row_m=10.0, runs=300)


@pytest.fixture(scope="module")
def steady_policy():
    grid = BeatGrid(length_m=400.0, half_width_m=200.0, lateral_m=4.0)
    return solve_expected_time(ILCA7, 10 * KNOT, OUShift(0.0, 600.0), grid, 5.0)


def test_policy_classes_of_the_one_tack_route(steady_policy) -> None:
    # steady wind, on starboard at the start: continue at the centreline on row 0; on the
    # left layline (one tack: 20 rows at 8 m per row = 160 m) the policy says tack
    cls = report.policy_classes(steady_policy, 0.0, 1)
    g = steady_policy.grid
    ix0 = (g.n_x - 1) // 2
    assert cls[0, ix0] == 0
    sim = simulate(steady_policy, 1, seed=1)
    x_turn = sim.x_m[0].min()
    r_turn = int(np.argmin(sim.x_m[0]))
    ix = round(float(x_turn + g.half_width_m) / g.lateral_m)
    assert cls[r_turn, ix] == 1
    assert cls[r_turn - 1, ix + 2] == 0  # one row earlier, still short of the layline
    assert set(np.unique(cls)) <= {0, 1, 2}


def test_figures_have_their_artists(steady_policy, tmp_path) -> None:
    fig = report.plot_policy_map(steady_policy, thetas_deg=(-10.0, 10.0))
    assert len(fig.axes) == 2
    assert all(len(ax.images) == 1 for ax in fig.axes)
    sim = simulate(steady_policy, 50, seed=1)
    fig = report.plot_spaghetti(sim, n_tracks=20)
    assert len(fig.axes[0].lines) == 20 + 5 + 1  # tracks, five bands, the mark
    fig = report.plot_leg_times({"a": sim.leg_time_s, "b": sim.leg_time_s + 1.0}, (100.0,))
    ax1, ax2 = fig.axes
    assert len(ax1.get_legend().get_texts()) == 2
    assert len(ax2.patches) == 2  # one step histogram per policy
    p = report.save_figure(fig, tmp_path / "t.png")
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_ecdf_counts_failures_as_late() -> None:
    x, f = report.ecdf(np.array([3.0, 1.0, np.inf, 2.0]))
    np.testing.assert_array_equal(x, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(f, [0.25, 0.5, 0.75])


def test_write_json_maps_non_finite_to_null(tmp_path) -> None:
    p = report.write_json(
        {"a": math.inf, "b": [np.float64(1.5), np.nan], "c": np.int64(3)}, tmp_path / "s.json"
    )
    assert json.loads(p.read_text()) == {"a": None, "b": [1.5, None], "c": 3}


def test_parse_objective() -> None:
    assert parse_objective("expected") == ()
    assert parse_objective("deadline=800") == (800.0,)
    assert parse_objective("Deadline=800,850.5") == (800.0, 850.5)
    for bad in ("deadline=", "deadline=-3", "fastest", "deadline=abc"):
        with pytest.raises(InputError, match="--objective"):
            parse_objective(bad)


def test_run_strategy_with_deadline_writes_everything(tmp_path) -> None:
    st = StrategySettings(deadlines_s=(190.0,), n_r=40, n_theta=48, interpolation="linear", **SMALL)
    res = run_strategy(ILCA7, OUShift(10.0, 600.0), st)
    s = res.summary
    e = s["expected_time_policy"]
    mc = e["monte_carlo"]
    # the SDP value and its own Monte Carlo agree (4 standard errors)
    assert abs(mc["mean_s"] - e["expected_time_s"]) < 4 * mc["se_mean_s"]
    assert e["lattice_one_tack_s"] >= e["steady_wind_one_tack_s"]
    d = s["deadline"]
    ra = d["risk_aware"]["190"]
    assert 0.0 <= ra["w_at_start"] <= 1.0
    assert d["grid"]["ds_s"] * round(5.0 / d["grid"]["ds_s"]) == pytest.approx(5.0)
    files = write_strategy_outputs(res, tmp_path / "out")
    names = sorted(p.name for p in files.values())
    assert names == [
        "deadline_policy.png",
        "deadline_tracks.png",
        "leg_times.png",
        "policy_map.png",
        "spaghetti.png",
        "summary.json",
    ]
    saved = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert saved["seed"] == 1 and saved["runs"] == 300
    assert saved["deadline"]["engine"] == "auto"
    # the NumPy engine gives the same policy, so the same simulated probabilities
    d_np = run_strategy(ILCA7, OUShift(10.0, 600.0), replace(st, deadline_engine="numpy")).summary[
        "deadline"
    ]
    assert d_np["engine"] == "numpy"
    assert d_np["risk_aware"] == d["risk_aware"]


def test_drift_diffusion_shift_given_directly_in_minutes(tmp_path) -> None:
    # 0.6 °/min drift and 3 °/√min diffusion are 0.01 °/s and 3/√60 °/√s; the study's
    # SDP runs on that model (the chain diagnostics have no stationary target for it)
    res = run_strategy_command(
        shift="Drift_Diffusion",
        drift_deg_per_min=0.6,
        diffusion_deg_per_sqrt_min=3.0,
        out_dir=tmp_path,
        plots=False,
        length_m=200.0,
        half_width_m=100.0,
        runs=50,
    ).data
    assert res.model == DriftDiffusionShift(0.01, 3.0 / math.sqrt(60.0))
    assert res.policy.model == res.model
    assert res.summary["shift_model"]["kind"] == "drift-diffusion"
    assert math.isnan(res.summary["chain"]["diagnostics_at_stage_time"]["target_sd_deg"])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"shift": "brownian"}, "--shift 'brownian': expected 'ou'"),
        ({"shift": "drift-diffusion"}, "needs --diffusion-deg-per-sqrt-min"),
        ({"shift": "drift-diffusion", "diffusion_deg_per_sqrt_min": -1.0}, "finite and >= 0"),
    ],
)
def test_shift_model_errors_teach(kwargs, message, tmp_path) -> None:
    with pytest.raises(InputError, match=message):
        run_strategy_command(out_dir=tmp_path, plots=False, runs=10, **kwargs)
    assert parse_shift(" OU ") == "ou"


def test_deadline_objective_needs_a_tack_penalty() -> None:
    st = StrategySettings(deadlines_s=(190.0,), tack_penalty_s=0.0, **SMALL)
    with pytest.raises(InputError, match="tack penalty"):
        run_strategy(ILCA7, OUShift(10.0, 600.0), st)


def test_cli_strategy_expected(tmp_path) -> None:
    out = tmp_path / "o"
    res = CliRunner().invoke(
        app,
        [
            "strategy",
            "--length-m",
            "400",
            "--half-width-m",
            "200",
            "--runs",
            "200",
            "--sigma-deg",
            "8",
            "--timescale-min",
            "5",
            "--out",
            str(out),
            "--no-plots",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "expected-time policy" in res.stdout
    s = json.loads((out / "summary.json").read_text())
    assert s["shift_model"] == {
        "kind": "ou",
        "sigma_deg": 8.0,
        "timescale_s": 300.0,
        "mean_deg": 0.0,
    }
    assert s["settings"]["length_m"] == 400.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--objective", "deadline=soon"], "--objective"),
        (["--start-tack", "left"], "--start-tack"),
        (["--polar", "builtin:optimist"], "unknown built-in boat"),
        (["--length-m", "405"], "whole"),
        (["--fit-from", "nowhere.csv"], "not found"),
        (["--seed", "-1"], "--seed -1: expected an integer >= 0"),
        (["--fit-from", str(ROOT / "data" / "trieste-coach-2018-02-15.csv")], "speed_unit"),
        pytest.param(
            ["--objective", "deadline=300", "--deadline-engine", "cupy"],
            "engine 'cupy' needs CuPy and an NVIDIA GPU",
            marks=pytest.mark.skipif(_cupy_or_none() is not None, reason="a GPU is here"),
        ),
        (["--deadline-engine", "gpu"], "--deadline-engine"),
    ],
)
def test_cli_strategy_errors_exit_2_without_traceback(args, message, tmp_path) -> None:
    res = CliRunner().invoke(app, ["strategy", "--runs", "10", "--out", str(tmp_path), *args])
    assert res.exit_code == 2
    assert message in res.output
    assert "Traceback" not in res.output


def test_cli_notes_a_chain_too_coarse_for_sigma(tmp_path) -> None:
    # σ = 3° on 5° bins: the chain's stationary sd is 3.8° (+27 %), which the report says
    res = CliRunner().invoke(
        app,
        [
            "strategy",
            "--length-m",
            "200",
            "--half-width-m",
            "100",
            "--runs",
            "50",
            "--sigma-deg",
            "3",
            "--out",
            str(tmp_path),
            "--no-plots",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "note: the shift chain's sd is 3.8°" in res.stdout


@requires_shared
def test_cli_fits_the_shift_from_a_station_file(tmp_path) -> None:
    res = CliRunner().invoke(
        app,
        [
            "strategy",
            "--length-m",
            "200",
            "--half-width-m",
            "100",
            "--runs",
            "50",
            "--fit-from",
            str(COACH),
            "--fit-timezone",
            "+01:00",
            "--out",
            str(tmp_path),
            "--no-plots",
        ],
    )
    assert res.exit_code == 0, res.output
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["shift_model"]["sigma_deg"] == pytest.approx(s["fit"]["ou"]["sigma_deg"])
    assert s["shift_model"]["timescale_s"] == pytest.approx(s["fit"]["ou"]["timescale_s"])
    assert "fitted from" in res.stdout


def test_drift_diffusion_fitted_from_a_station_file(tmp_path) -> None:
    # the committed 15 min excerpt of the coach-boat log: the fitted Brownian model, not the
    # OU one, drives the study
    res = run_strategy_command(
        shift="drift-diffusion",
        fit_from=str(COACH_EXCERPT),
        fit_timezone="+01:00",
        out_dir=tmp_path,
        plots=False,
        length_m=200.0,
        half_width_m=100.0,
        runs=50,
    )
    dd = res.data.summary["fit"]["drift_diffusion"]
    assert res.data.model == DriftDiffusionShift(dd["drift_deg_per_s"], dd["sigma_deg_per_sqrt_s"])
    assert "diffusion" in res.report and "°/√min" in res.report


def test_cli_fits_the_shipped_coach_log_given_its_speed_unit(tmp_path) -> None:
    # the shipped log's speed column is in knots with no unit in its header: the CLI can now
    # say so (it failed with "declare it with speed_unit:" and had no option to)
    res = CliRunner().invoke(
        app,
        [
            "strategy",
            "--length-m",
            "200",
            "--half-width-m",
            "100",
            "--runs",
            "50",
            "--fit-from",
            str(ROOT / "data" / "trieste-coach-2018-02-15.csv"),
            "--fit-speed-unit",
            "kn",
            "--out",
            str(tmp_path),
            "--no-plots",
        ],
    )
    assert res.exit_code == 0, res.output
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["fit"]["ou"]["sigma_deg"] == pytest.approx(28.4, abs=0.05)  # docs/strategy.md
