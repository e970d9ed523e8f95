"""Laser/ILCA VPP: physics building blocks, equilibrium, optimality, thesis sanity targets."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from sailroute.boat import vpp
from sailroute.boat.build import vpp_polar
from sailroute.boat.laser import CLASSES, ILCA4, ILCA6, ILCA7, params_from_mapping
from sailroute.errors import InputError
from sailroute.units import KNOT

TWA_GRID = tuple(float(a) for a in np.arange(0.0, 180.1, 2.5))
KN8 = 8 * KNOT  # the thesis's Fig 4.7 wind speed, 4.116 m/s


# --- building blocks ---------------------------------------------------------------------


def test_apparent_wind_triangle() -> None:
    # beam reach at boat speed = TWS: AWS = sqrt(2) TWS at 45 deg
    aws, awa = vpp.apparent_wind(5.0, 90.0, 5.0)
    assert aws == pytest.approx(5.0 * math.sqrt(2)) and awa == pytest.approx(45.0)
    # dead run: AWS = TWS - V from astern
    aws, awa = vpp.apparent_wind(5.0, 180.0, 2.0)
    assert aws == pytest.approx(3.0) and awa == pytest.approx(180.0)
    # heel reduces the cross component by cos(heel) (eq 2.3)
    aws, awa = vpp.apparent_wind(4.0, 90.0, 0.0, heel_deg=60.0)
    assert aws == pytest.approx(2.0) and awa == pytest.approx(90.0)


def test_ittc57_friction_line() -> None:
    assert float(vpp.ittc57_cf(1e7)) == pytest.approx(0.075 / 25.0)
    assert float(vpp.ittc57_cf(1e9)) == pytest.approx(0.075 / 49.0)


def test_sail_coefficients_follow_orc_table_and_eq_4_4() -> None:
    table = vpp.sail_table("main")
    assert table.awa_deg[0] == 0.0 and table.awa_deg[-1] == 180.0 and table.kp == 0.01379
    p = ILCA7
    k0 = 1.0 / (math.pi * p.aspect_ratio) + p.c_ds
    for a, cd, cl in zip(table.awa_deg, table.cd, table.cl, strict=True):
        got_cl, got_cd = vpp.sail_coefficients(a, 1.0, 0.0, p)
        assert float(got_cl) == pytest.approx(cl, abs=1e-12)
        assert float(got_cd) == pytest.approx(cd + cl * cl * k0, abs=1e-12)
    # flat scales the lift; full twist multiplies the induced part by (1 + C_twist)
    cl1, cd1 = vpp.sail_coefficients(28.0, 0.5, 1.0, p)
    cl_t = 1.42681  # main.dat C_Lmax at 28 deg
    assert float(cl1) == pytest.approx(0.5 * cl_t)
    induced = (0.5 * cl_t) ** 2 * ((1 + p.c_twist) / (math.pi * p.aspect_ratio) + p.c_ds)
    assert float(cd1) == pytest.approx(0.02586 + induced)


def test_dsyhs_residuary_at_a_table_node() -> None:
    # independent evaluation of Keuning & Sonnenberg's regression with the Fn = 0.40 column
    a = [-0.0064, -0.4034, -0.1250, 0.0273, -0.1341, 0.3578, 0.0045, 0.1115]
    p = ILCA7
    vol = p.volume_m3
    x = (
        a[1] * p.lcb_fraction
        + a[2] * p.prismatic_coefficient
        + a[3] * vol ** (2 / 3) / p.waterplane_area_m2
        + a[4] * p.bwl_m / p.lwl_m
        + a[5] * p.lcb_fraction / p.lcf_fraction
        + a[6] * p.bwl_m / p.canoe_draft_m
        + a[7] * p.midship_coefficient
    )
    want = p.rho_water * p.gravity * vol * (a[0] + x * vol ** (1 / 3) / p.lwl_m)
    v = 0.40 * math.sqrt(p.gravity * p.lwl_m)
    assert float(vpp.residuary_resistance(v, p)) == pytest.approx(want, rel=1e-12)
    # beyond the series (Fn 0.75) R_r / (rho g vol) is held: R_r constant in V
    v1, v2 = 0.8 * math.sqrt(p.gravity * p.lwl_m), 1.0 * math.sqrt(p.gravity * p.lwl_m)
    assert float(vpp.residuary_resistance(v1, p)) == float(vpp.residuary_resistance(v2, p))


def test_thesis_hull_model_is_the_drag_area() -> None:
    p = replace(ILCA7, hull_model="thesis")
    assert float(vpp.hull_resistance(2.0, p)) == pytest.approx(0.5 * 1025.0 * 4.0 * 0.025)


def test_crew_righting_moment_and_ce() -> None:
    p = ILCA7
    # eq 2.30-2.31 with the hiking extension: 80 kg * g * (1.37/2 + 0.45)
    assert float(vpp.crew_righting_moment(1.0, p)) == pytest.approx(80 * 9.81 * 1.135)
    assert float(vpp.crew_righting_moment(0.5, p, 60.0)) == pytest.approx(80 * 9.81 * 1.135 / 4)
    assert float(vpp.ce_height(1.0, 0.0, p)) == pytest.approx(2.68)
    assert float(vpp.ce_height(0.0, 0.0, p)) == pytest.approx(0.6 + 2.08 * (1 - 0.203))


def test_induced_resistance() -> None:
    p = ILCA7
    assert float(vpp.induced_resistance(200.0, 2.0, p)) == pytest.approx(
        200.0**2 / (0.5 * 1025 * 4.0 * math.pi * 0.787**2)
    )


# --- the solver ------------------------------------------------------------------------------


def solved(params=ILCA7):
    tws = np.array([2.0, 3.0, 4.0, 5.61, 8.0, 10.0, 12.0])
    twa = np.arange(30.0, 180.1, 15.0)
    return tws, twa, vpp.solve_point(params, tws[None, :], twa[:, None])


def test_equilibrium_and_constraints_hold_at_the_solution() -> None:
    _, _, s = solved()
    assert np.all(s.speed_ms > 0)
    # surge balance (eq 2.5): drive = hull + induced resistance
    np.testing.assert_allclose(s.drive_n, s.resistance_n + s.induced_n, atol=1e-8)
    # roll balance: the crew never needs to be further out than fully hiked
    assert np.all(s.crew_position <= 1.0 + 1e-9)
    assert not s.overpowered.any()
    # no depowering while the crew has moment to spare: twist only when fully hiked
    slack = s.crew_position < 0.999
    assert np.all(s.twist[slack] == 0.0)
    assert np.all(s.heel_deg == 0.0)  # the hiking model sails flat


@pytest.mark.parametrize(
    ("tws", "twa"), [(3.0, 45.0), (5.61, 40.0), (8.0, 60.0), (12.0, 90.0), (10.0, 150.0)]
)
def test_speed_is_optimal_against_a_brute_force_control_grid(tws: float, twa: float) -> None:
    # independent of the solver's searches: at V* + 1 mm/s no (flat, twist) on a fine grid
    # balances the resistance within the moment limit; at V* - 1 cm/s one does (the grid's
    # 0.0005 flat step costs up to ~0.3 N near the moment limit, as much as 3 mm/s of speed)
    p = ILCA7
    v_star = float(vpp.solve_point(p, tws, twa).speed_ms)
    f = np.linspace(0.0, 1.0, 2001)[:, None]
    t = np.linspace(0.0, 1.0, 101)[None, :]

    def best_surplus(v: float) -> float:
        aws, awa = vpp.apparent_wind(tws, twa, v)
        cl, cd = vpp.sail_coefficients(awa, f, t, p)
        # easing below ease_flat lowers the viscous drag (docs/vpp.md)
        cd = cd - vpp.eased_drag(awa, 1.0, p) + vpp.eased_drag(awa, f, p)
        q = 0.5 * p.rho_air * aws**2 * p.sail_area_m2
        b = math.radians(float(awa))
        dw = float(vpp.windage_drag(aws, awa, p))
        fx = q * (cl * math.sin(b) - cd * math.cos(b)) - dw * math.cos(b)
        fs = q * (cl * math.cos(b) + cd * math.sin(b))
        fy = fs + dw * math.sin(b)
        arm = vpp.ce_height(f, t, p, awa) + p.clr_depth_m
        moment = fs * arm + dw * math.sin(b) * (0.5 * p.sail_foot_height_m + p.clr_depth_m)
        surplus = fx - vpp.hull_resistance(v, p) - vpp.induced_resistance(fy, v, p)
        return float(np.max(np.where(moment <= p.max_righting_moment_nm, surplus, -np.inf)))

    assert best_surplus(v_star + 1e-3) < 0
    assert best_surplus(v_star - 1e-2) > 0


def test_solve_polar_and_input_checks() -> None:
    pol = vpp.solve_polar(ILCA7, [3.0, 5.0], [0.0, 45.0, 90.0, 180.0])
    assert pol.speed_ms.shape == (4, 2) and pol.name == "ILCA 7"
    assert np.all(pol.speed_ms[0] == 0.0)  # head to wind
    s = vpp.solve_point(ILCA7, 4.0, [-60.0, 60.0, 300.0])  # signs fold
    assert s.speed_ms[0] == s.speed_ms[1] == s.speed_ms[2]
    with pytest.raises(InputError, match="TWS and TWA must be finite"):
        vpp.solve_point(ILCA7, -1.0, 40.0)
    with pytest.raises(InputError, match="sail_area_m2: expected a finite number > 0"):
        vpp.solve_point(replace(ILCA7, sail_area_m2=0.0), 4.0, 40.0)


def test_dense_sweep_is_robust() -> None:
    # TWS 2-12 m/s x TWA 30-180: finite everywhere, positive for the default boat
    tws = np.arange(2.0, 12.01, 0.5)
    twa = np.arange(30.0, 180.1, 2.0)
    s = vpp.solve_point(ILCA7, tws[None, :], twa[:, None]).speed_ms
    assert np.all(np.isfinite(s)) and np.all(s > 0.5)
    # more wind never slows the boat until the sailor is fully hiked (below ~7 m/s), and
    # never on broad reaches and runs (TWA >= 130), where the moment limit does not bind
    d = np.diff(s, axis=1)
    assert np.all(d[:, tws[1:] <= 7.0] > 0)
    assert np.all(d[twa >= 130] > 0)
    # smooth in TWA: no jumps between 2-degree neighbours away from the no-go edge
    assert np.max(np.abs(np.diff(s[twa >= 36], axis=0))) < 0.35


@pytest.mark.parametrize("name", ["ilca6", "ilca4"])
def test_dense_sweep_other_classes(name: str) -> None:
    tws = np.array([2.0, 4.0, 6.0, 8.0, 10.0, 11.0, 12.0])
    twa = np.arange(30.0, 180.1, 3.0)
    s = vpp.solve_point(CLASSES[name], tws[None, :], twa[:, None]).speed_ms
    assert np.all(np.isfinite(s)) and np.all(s >= 0)
    # the 58 kg ILCA 4 sailor cannot hold TWA 30 above ~11 m/s (no steady state: the no-go
    # widens); from TWA 33 on every point sails
    assert np.all(s[twa >= 33] > 0.5)


# --- sanity targets from the thesis and the literature ----------------------------------------


def test_thesis_fig_4_7_at_8_knots() -> None:
    p = vpp_polar(ILCA7, (KN8,), TWA_GRID)
    a = np.arange(0.0, 180.1, 1.0)
    s = p.speed(KN8, a)
    # no-go zone: no steady sailing below ~20 deg, VMG optimum just above 40 deg (thesis: the
    # maximum VMG "is found after the 40 deg", sub-routes at 45 deg)
    assert np.all(s[a <= 20] == 0.0)
    up_a, _ = p.vmg_upwind(KN8)
    assert 40.0 <= float(up_a) <= 46.0
    # outside the no-go zone speeds lie in the thesis's [2, 3.3] m/s band from 40 to 145 deg
    band = (a >= 40) & (a <= 145)  # measured: 1.998 m/s at 150 deg
    assert s[band].min() >= 2.0 and s.max() <= 3.3
    # fastest point of sail: thesis 90-115 deg; this model peaks at 80 deg in 8 kn and the 90 deg
    # speed is within 2 % of the maximum (see docs/vpp.md, "deviations")
    assert 75.0 <= a[np.argmax(s)] <= 115.0
    assert p.speed(KN8, 90.0) >= 0.98 * s.max()
    # dead run: 1.8 m/s, below the thesis's 2 m/s; the thesis value is not a steady state of
    # this force model (next test)
    assert 1.7 <= p.speed(KN8, 180.0) < 2.0


def test_thesis_run_speed_is_not_a_steady_state() -> None:
    # thesis race speeds at 5.61 m/s: run 3.26 m/s.  At that speed dead downwind the apparent
    # wind is 2.35 m/s: full sail drag (C_D 1.34 on 7.06 m^2) plus windage gives < 40 N while
    # the hull needs > 100 N, so no sail setting holds 3.26 m/s (kinetics and surfing do).
    p = ILCA7
    aws, awa = vpp.apparent_wind(5.61, 180.0, 3.26)
    _, cd = vpp.sail_coefficients(awa, 1.0, 0.0, p)
    drive = 0.5 * p.rho_air * aws**2 * p.sail_area_m2 * float(cd) + float(
        vpp.windage_drag(aws, awa, p)
    )
    assert drive < 40.0 < 100.0 < float(vpp.hull_resistance(3.26, p))
    # docs/vpp.md quotes 34 N of drive against 144 N (this VPP's hull) and 136 N with the
    # thesis's own drag area (eq 4.19): the conclusion does not depend on the hull model
    assert drive == pytest.approx(34.0, abs=0.5)
    assert float(vpp.hull_resistance(3.26, p)) == pytest.approx(144.0, abs=0.5)
    thesis_hull = float(vpp.hull_resistance(3.26, replace(p, hull_model="thesis")))
    assert thesis_hull == pytest.approx(0.5 * 1025.0 * 3.26**2 * 0.025) and thesis_hull > 130.0
    assert float(vpp.solve_point(p, 5.61, 180.0).speed_ms) == pytest.approx(2.40, abs=0.005)


def test_implied_race_speeds_at_5_61_ms() -> None:
    # thesis §2/§6, constant 5.61 m/s scenario: upwind VMG 1.72 m/s including tack losses
    # (winner 1.84-1.94), beam reach 3.44 m/s (winner 3.9-4.3)
    p = vpp_polar(ILCA7, (5.61,), TWA_GRID)
    _, vmg = p.vmg_upwind(5.61)
    assert 1.72 <= float(vmg) <= 2.1
    assert 3.44 <= float(p.speed(5.61, 91.0)) <= 4.3
    # the values docs/vpp.md quotes: beat VMG 2.02, beam reach 3.76 (90 deg), run 2.40 m/s
    assert float(vmg) == pytest.approx(2.02, abs=0.005)
    assert float(p.speed(5.61, 90.0)) == pytest.approx(3.76, abs=0.005)
    assert float(p.speed(5.61, 180.0)) == pytest.approx(2.40, abs=0.005)


def test_crew_mass_effect_sign_and_size() -> None:
    tws = (2.5, 3.0, 8.0, 10.0)
    grid = tuple(float(a) for a in np.arange(0.0, 180.1, 2.5))
    pol = {m: vpp_polar(replace(ILCA7, crew_mass_kg=m), tws, grid) for m in (70.0, 80.0, 90.0)}

    def upwind(m: float, w: float) -> float:
        return float(pol[m].vmg_upwind(w)[1])

    def race_delta_s(w: float, m: float) -> float:
        # change of a 1-hour windward-leeward race (80 kg reference) for a sailor of m kg
        u0, d0 = upwind(80.0, w), float(pol[80.0].vmg_downwind(w)[1])
        u1, d1 = upwind(m, w), float(pol[m].vmg_downwind(w)[1])
        leg = 3600.0 / (1 / u0 + 1 / d0)
        return leg * (1 / u1 + 1 / d1) - 3600.0

    # heavier is faster upwind in strong wind, slower in light wind (as in the thesis)
    assert upwind(90.0, 10.0) > upwind(70.0, 10.0)
    assert upwind(90.0, 2.5) < upwind(70.0, 2.5)
    # Day (2017): 10 kg changes a 1-hour race by more than 60 s.  Here, in 8 m/s, +10 kg saves
    # 49 s and -10 kg costs 69 s; in 3 m/s +10 kg costs 8 s.  Assert sign and order of magnitude.
    assert -150.0 < race_delta_s(8.0, 90.0) < -30.0
    assert 30.0 < race_delta_s(8.0, 70.0) < 150.0
    assert 0.0 < race_delta_s(3.0, 90.0) < 30.0


def test_classes_are_ordered_by_sail_area() -> None:
    # at equal crew weight the smaller rigs are slower in light wind
    p7 = vpp_polar(replace(ILCA7, crew_mass_kg=68.0), (3.0,), TWA_GRID)
    p6 = vpp_polar(ILCA6, (3.0,), TWA_GRID)
    p4 = vpp_polar(replace(ILCA4, crew_mass_kg=68.0), (3.0,), TWA_GRID)
    for a in (45.0, 90.0, 150.0):
        assert p7.speed(3.0, a) > p6.speed(3.0, a) > p4.speed(3.0, a)
    assert ILCA6.sail_area_m2 == 5.76 and ILCA4.sail_area_m2 == 4.70


def test_params_from_mapping_reports_every_problem() -> None:
    p = params_from_mapping({"class": "ilca6", "crew_mass_kg": 61}, where="b.yaml")
    assert p.sail_area_m2 == 5.76 and p.crew_mass_kg == 61.0
    with pytest.raises(InputError) as exc:
        params_from_mapping(
            {"class": "ilca9", "crew_mass": 70, "beam_m": "wide", "gz_m": [1, "x"]},
            where="b.yaml",
            key="boat.vpp",
        )
    msg = str(exc.value)
    assert msg.startswith("b.yaml: 4 problems")
    for part in (
        "boat.vpp.class: expected one of 'ilca4', 'ilca6', 'ilca7'; got 'ilca9'",
        "boat.vpp.crew_mass: unknown key",
        "boat.vpp.beam_m: expected a number",
        "boat.vpp.gz_m: expected a list of numbers",
    ):
        assert part in msg
    with pytest.raises(InputError, match=r"b\.yaml: hull_model: expected one of 'dsyhs', 'thesis'"):
        params_from_mapping({"hull_model": "planing"}, where="b.yaml")


def test_docs_vpp_results_table_matches_the_shipped_polar() -> None:
    # docs/vpp.md "Results and validation" quotes the built-in steady ILCA 7 polar
    import re
    from pathlib import Path

    from sailroute.boat.build import builtin_polar

    text = (Path(__file__).resolve().parents[2] / "docs" / "vpp.md").read_text()
    rows = re.findall(
        r"^\| (\d+) \| ([\d.]+)° \| ([\d.]+) \| ([\d.]+) \(([\d.]+)°\) \| "
        r"([\d.]+)(?: m/s)? at ([\d.]+)° \|$",
        text,
        flags=re.M,
    )
    assert [int(r[0]) for r in rows] == [2, 4, 6, 8, 10, 12]
    p = builtin_polar("ilca7-steady")
    for tws, beat_a, beat_v, run_v, run_a, fast_v, fast_a in rows:
        w = float(tws)
        ua, uv = p.vmg_upwind(w)
        da, dv = p.vmg_downwind(w)
        ma, mv = p.max_speed(w)
        assert float(ua) == pytest.approx(float(beat_a), abs=0.05)
        assert float(uv) == pytest.approx(float(beat_v), abs=0.005)
        assert float(dv) == pytest.approx(float(run_v), abs=0.005)
        assert float(da) == pytest.approx(float(run_a), abs=0.5)
        assert float(mv) == pytest.approx(float(fast_v), abs=0.005)
        assert float(ma) == pytest.approx(float(fast_a), abs=0.25)
