"""Structure check of the VPP on the YD-41 against WinVPP (Python-VPP's benchmark).

The same force model and solver as the Laser, fed a keelboat: main + jib (and main + kite,
keeping the faster set), heel from the righting-arm curve instead of hiking.  This checks
the sail tables, DSYHS/ITTC resistance, induced drag and the solver on a boat with a
published reference polar; it is a structural check, not a tight tolerance: the YD-41 inputs
lack LCB/LCF, waterplane area and crew data (assumed below) and WinVPP's model differs in
detail (reefing, heel-dependent resistance, kite handling).

Measured (all 224 points, TWS 3-10 m/s): RMS error 5.9 %, mean -1.3 %, max 21 % (10 m/s,
TWA 89 deg, +21 %: no reefing); per TWS RMS 8.5 / 4.7 / 3.7 / 3.5 / 3.7 / 4.7 / 9.5 % for 3..10 m/s.
Best beat: 3 m/s 41.3 deg / 3.99 kn (WinVPP 44.6 / 4.10); 10 m/s 32.5 deg / 6.78 kn (39.4 /
6.02): no reefing and no heel-dependent resistance make it point too high in strong wind.
"""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.boat import vpp
from sailroute.boat.laser import LaserParams
from sailroute.boat.polar import Polar
from sailroute.units import KNOT
from tests.conftest import TESTS_DATA

TWS_BLOCKS = (3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0)

# Python-VPP README / runVPP.py geometry; [A] marks this test's assumptions
YD41 = LaserParams(
    name="YD-41",
    hull_mass_kg=5820.0,  # 6500 kg total incl. 680 kg crew [A: 8 x 85 kg]
    crew_mass_kg=680.0,
    loa_m=12.5,
    beam_m=4.2,
    lwl_m=11.9,
    bwl_m=3.18,
    prismatic_coefficient=6.05 / (1.051 * 11.9),  # vol / (Amax Lwl)
    midship_coefficient=1.051 / (3.18 * 0.4),  # Amax / (Bwl Tc)
    waterplane_coefficient=0.70,  # [A]
    lcb_fraction=0.53,  # [A]
    lcf_fraction=0.555,  # [A]
    wetted_area_m2=28.2,
    board_area_m2=1.9 * 0.89,  # keel span x mean chord
    rudder_area_m2=1.15 * 0.35,
    appendage_chord_m=0.8,
    max_draft_m=2.3,
    effective_draft_m=1.8 * 1.9,  # Python-VPP: T_eff = 1.8 x keel span
    clr_depth_m=0.43 * 2.3,  # Python-VPP: 0.43 Tmax
    sail_area_m2=0.5 * 16.6 * 5.6 * 1.1,  # P E / 2 (1 + roach)
    ce_height_m=16.6 / 3 * 1.1 + 1.0,  # P/3 (1 + roach) + BAD
    sail_foot_height_m=1.0,
    effective_span_m=23.0,  # ORC: (b + HBI) x 1.03 x kheff(~1.15) [A]
    jib_area_m2=0.5 * 16.2 * 5.4,  # I LPG / 2
    jib_ce_height_m=16.2 / 3 + 1.8,  # I/3 + HBI
    kite_area_m2=150.0,
    kite_ce_height_m=9.55,
    c_twist=0.0,
    c_ds=0.0148,  # ORC kp, area-weighted main/jib
    twist_max=0.0,
    flat_min=0.4,
    ease_flat=0.0,
    windage_cd_front=0.816,  # Python-VPP windage coefficient
    windage_cd_side=0.816,
    windage_area_front_m2=1.5 * 4.2,  # freeboard x Boa / Loa
    windage_area_side_m2=1.5 * 12.5,
    windage_shielding=0.0,
    stability="heel",
    gz_heel_deg=(0.0, 10.0, 20.0, 30.0, 40.0),
    gz_m=(0.0, 0.40, 0.73, 0.96, 1.10),  # Python-VPP dat/rm.dat
    crew_arm_m=2.0,  # [A] crew on the rail
    max_heel_deg=25.0,  # [A]
    hiking_extension_m=0.0,
)


def reference() -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(TWS [m/s], TWA [deg], speed [kn]) blocks of YD41.dat, each sorted by TWA."""
    d = np.loadtxt(TESTS_DATA / "boat" / "YD41.dat").reshape(7, 32, 2)
    out = []
    for tws, block in zip(TWS_BLOCKS, d, strict=True):
        block = block[np.argsort(block[:, 0])]
        out.append((tws, np.degrees(block[:, 0]), block[:, 1]))
    return out


def relative_errors(blocks: list[tuple[float, np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    return [vpp.solve_point(YD41, tws, twa).speed_ms / KNOT / ref - 1.0 for tws, twa, ref in blocks]


def test_yd41_polar_moderate_winds() -> None:
    blocks = [b for b in reference() if b[0] in (4.0, 6.0, 8.0)]
    errs = relative_errors(blocks)
    for (tws, _, _), e in zip(blocks, errs, strict=True):
        rms = float(np.sqrt(np.mean(e**2)))
        # measured 4.7 / 3.5 / 4.7 %
        assert rms < 0.06, f"TWS {tws}: RMS error {rms:.3f}"
        assert abs(float(np.mean(e))) < 0.04
        assert float(np.max(np.abs(e))) < 0.12


def test_yd41_beat_optimum_against_readme() -> None:
    # README: best beat at 3 m/s about 44.6 deg / VMG 4.10 kn; at 10 m/s 39.4 deg / 6.02 kn.
    # Measured here: 3 m/s 41.3 deg / 3.99 kn (-2.7 %); 10 m/s 32.5 deg / 6.78 kn (+12.6 %):
    # in strong wind this model points higher and faster because it cannot reef and its
    # resistance ignores heel (WinVPP has both); the bounds below document that gap.
    twa = np.arange(0.0, 180.1, 2.0)
    found = {}
    for tws in (3.0, 10.0):
        sol = vpp.solve_point(YD41, tws, twa)
        p = Polar.from_arrays(twa, np.array([tws]), sol.speed_ms[:, None])
        ang, vmg = p.vmg_upwind(tws)
        found[tws] = (float(ang), float(vmg) / KNOT)
    assert found[3.0][0] == pytest.approx(44.6, abs=4.0)
    assert found[3.0][1] == pytest.approx(4.10, rel=0.05)
    assert 39.4 - 10.0 < found[10.0][0] < 39.4
    assert 6.02 < found[10.0][1] < 6.02 * 1.15


@pytest.mark.slow
def test_yd41_polar_all_winds() -> None:
    errs = np.concatenate(relative_errors(reference()))
    rms = float(np.sqrt(np.mean(errs**2)))
    assert rms < 0.07  # measured 5.9 %
    assert abs(float(np.mean(errs))) < 0.03  # measured -1.3 %
    assert float(np.max(np.abs(errs))) < 0.25  # measured 21 % (10 m/s, TWA 89 deg)
