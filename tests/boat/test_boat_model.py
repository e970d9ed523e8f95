"""Both boat models satisfy the routers' :class:`~sailroute.boat.model.BoatModel`."""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.boat.dynamic import DynamicBoat
from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar

TWA = np.array([0, 40, 60, 90, 120, 150, 180.0])
POLAR = Polar.from_arrays(
    TWA,
    np.array([2, 4, 6, 8.0]),
    np.outer([0, 0.7, 0.85, 0.97, 0.97, 0.8, 0.6], 0.5 * np.array([2, 4, 6, 8.0])),
    name="small",
)
BOAT = DynamicBoat()


def test_polar_and_dynamic_boat_are_boat_models() -> None:
    assert isinstance(POLAR, BoatModel)
    assert isinstance(BOAT, BoatModel)
    assert not isinstance("laser", BoatModel)
    assert not isinstance(BOAT.table(), BoatModel)


def test_each_model_says_how_it_is_routed() -> None:
    assert POLAR.routing_polar() is POLAR and POLAR.dynamics() is None
    assert BOAT.routing_polar() is None and BOAT.dynamics() is BOAT


def test_steady_speeds() -> None:
    tws, twa = np.array([[3.0], [7.0]]), np.array([[45.0, -100.0, 170.0]])
    np.testing.assert_array_equal(POLAR.steady_speed(tws, twa), POLAR.speed(tws, twa))
    # the dynamic model's steady speed scales with TWS (speed/TWS depends on TWA only)
    v = BOAT.steady_speed(tws, twa)
    np.testing.assert_allclose(v[1] / v[0], 7.0 / 3.0, rtol=1e-12)


def test_vmg_angles() -> None:
    up, down = POLAR.vmg_angles_deg(5.0)
    assert up == float(POLAR.vmg_upwind(5.0)[0]) and down == float(POLAR.vmg_downwind(5.0)[0])
    assert 0.0 < up < 90.0 < down <= 180.0
    # Dębski's toy boat: best upwind VMG at TWA 41.65° (class docstring), dead downwind
    up, down = BOAT.vmg_angles_deg(12.0)
    assert up == pytest.approx(41.65, abs=0.05)
    assert down == pytest.approx(180.0)
    assert BOAT.vmg_angles_deg(3.0) == (up, down)
