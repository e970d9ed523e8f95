"""Height correction: power/log laws, exponent fit, destaggering and WRF level heights."""

from __future__ import annotations

import math

import netCDF4
import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.wind.height import (
    destagger,
    fit_power_exponent,
    log_law,
    log_law_factor,
    mass_level_heights,
    power_law,
    power_law_exponent,
)
from tests.conftest import WIND_DATA


def test_power_law_thesis_example() -> None:
    # Thesis eq 2.1 with 1/7 from 10 m to the Laser CE at 2.68 m:
    # (0.268)^(1/7) = exp(ln(0.268) / 7) = exp(-0.188113) = 0.828524.
    assert power_law(10.0, 10.0, 2.68, 1 / 7) == pytest.approx(10 * 0.268 ** (1 / 7), rel=1e-14)
    assert power_law(10.0, 10.0, 2.68, 1 / 7) == pytest.approx(8.28524, abs=1e-5)
    np.testing.assert_allclose(power_law([1.0, 2.0], 5.0, 5.0, 0.3), [1.0, 2.0])


def test_log_law_value_and_identity() -> None:
    z0 = 2e-4
    expected = math.log(2.68 / z0) / math.log(10.0 / z0)
    assert log_law_factor(10.0, 2.68, z0) == pytest.approx(expected, rel=1e-14)
    assert log_law(7.0, 10.0, 10.0, z0) == pytest.approx(7.0)
    with pytest.raises(InputError, match="roughness"):
        log_law_factor(10.0, 1e-5, z0)


def test_exponent_fit_recovers_alpha_and_flags_unusable() -> None:
    alpha = np.array([0.05, 0.14, 0.3])
    s1 = np.array([4.0, 5.0, 6.0])
    s2 = s1 * (25.0 / 7.5) ** alpha
    np.testing.assert_allclose(power_law_exponent(s1, 7.5, s2, 25.0), alpha, rtol=1e-12)
    # Calm at one level, a negative exponent and one above the range are unusable.
    a, ok = fit_power_exponent([0.2, 5.0, 5.0, 5.0], 7.5, [3.0, 4.0, 5.0 * 3.33**0.9, 6.0], 25.0)
    assert ok.tolist() == [False, False, False, True]
    assert a[1] < 0
    with pytest.raises(InputError, match="positive"):
        power_law(1.0, 0.0, 2.0, 0.1)


def test_destagger_and_heights_match_wrf_python_ci_results() -> None:
    """Known answers from wrf-python's CI (ua = destaggered U; z = height of mass levels)."""
    with (
        netCDF4.Dataset(WIND_DATA / "wrfpython_ci_crop.nc") as ds,
        netCDF4.Dataset(WIND_DATA / "wrfpython_ci_result_crop.nc") as ref,
    ):
        ua = destagger(ds["U"][0], axis=-1)
        va = destagger(ds["V"][0], axis=-2)
        z = mass_level_heights(ds["PH"][0], ds["PHB"][0], ds["HGT"][0])
        # wrf-python works in float32: 1e-4 m/s is a few ulps of the winds; the heights
        # (~30 and ~100 m) come from geopotentials of ~1e3 m2/s2 summed in float32, which
        # leaves up to ~3 mm, so 5 mm (5e-5 relative) is the tolerance.
        np.testing.assert_allclose(ua, ref["ua"][:], atol=1e-4)
        np.testing.assert_allclose(va, ref["va"][:], atol=1e-4)
        np.testing.assert_allclose(z, ref["z"][:], atol=5e-3)  # HGT = 0 over water
    assert z[0].min() > 25.0 and z[0].max() < 35.0  # lowest mass level ~30 m in this run


def test_mass_level_heights_from_known_full_levels() -> None:
    g = 9.81
    zw = np.array([0.0, 15.0, 35.0])  # full levels -> mass levels 7.5 and 25 m
    ph = np.broadcast_to(zw[:, None, None] * g * 0.25, (3, 2, 2))
    phb = np.broadcast_to(zw[:, None, None] * g * 0.75, (3, 2, 2))
    z = mass_level_heights(ph, phb, np.zeros((2, 2)))
    np.testing.assert_allclose(z[:, 0, 0], [7.5, 25.0], rtol=1e-14)
    z_hill = mass_level_heights(ph + 100 * g, phb, np.full((2, 2), 100.0))
    np.testing.assert_allclose(z_hill, z, atol=1e-12)
