"""Frozen dataclasses keep derived values as cached properties, not as fields set with
``object.__setattr__``; the caches that stay at module level hold read-only data."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.boat.vpp import dsyhs_table
from sailroute.current import DiamondCurrent, UniformCurrent
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.wind.blended import BlendedWind
from sailroute.wind.grid import GridWind
from sailroute.wind.stations import StationWind
from sailroute.wind.uniform import UniformWind

T0 = 1_524_567_600.0


@pytest.mark.parametrize("cls", [Polar, UniformCurrent, DiamondCurrent, UniformWind, GridWind,
                                 StationWind, BlendedWind])
def test_every_field_is_an_input(cls: type) -> None:
    # derived state used to be init=False fields patched in by __post_init__
    assert [f.name for f in dataclasses.fields(cls) if not f.init] == []


def grid_wind(**kw: object) -> GridWind:
    x, y = np.meshgrid(np.linspace(-1000.0, 1000.0, 5), np.linspace(-800.0, 800.0, 4))
    u = np.full((2, 4, 5), 3.0)
    return GridWind([T0, T0 + 3600.0], x, y, u, -u, **kw)  # type: ignore[arg-type]


def test_grid_wind_state_is_built_when_made_and_rebuilt_by_replace() -> None:
    with pytest.raises(InputError, match="times must be finite and strictly increasing"):
        GridWind([T0, T0], *np.meshgrid([0.0, 1.0], [0.0, 1.0]), np.zeros((2, 2, 2)),
                 np.zeros((2, 2, 2)))
    w = grid_wind()
    assert "_state" in vars(w)  # built by __post_init__, not on first sample
    with pytest.raises(OutOfCoverageError):
        w.sample(T0 + 7200.0, 0.0, 0.0)
    c = dataclasses.replace(w, clamp=True)
    assert c.coverage == w.coverage and c.clamp
    u, v = c.sample(T0 + 7200.0, 0.0, 0.0)
    assert (float(u), float(v)) == (3.0, -3.0)


def test_uniform_sources_sample_their_tables() -> None:
    w = UniformWind([4.0, 6.0], [0.0, 0.0], times=[T0, T0 + 100.0])
    assert float(w.sample(T0 + 50.0, 0.0, 0.0)[1]) == pytest.approx(-5.0)
    cur = DiamondCurrent(T0, [0.0, 1.0], [90.0, 90.0], [1.0, 3.0])
    assert float(cur.sample(T0 + 1800.0, 0.0, 0.0)[0]) == pytest.approx(2.0)
    assert (cur.coverage.t0, cur.coverage.t1) == (T0, T0 + 3600.0)
    assert float(UniformCurrent(2.0, 180.0).sample(T0, 0.0, 0.0)[1]) == pytest.approx(-2.0)
    with pytest.raises(InputError, match="hours must increase strictly"):
        DiamondCurrent(T0, [1.0, 0.0], [90.0, 90.0], [1.0, 1.0])


def test_polar_lookup_tables_are_per_instance() -> None:
    twa, tws = np.array([0.0, 90.0, 180.0]), np.array([2.0, 4.0])
    p = Polar(twa, tws, np.array([[0.0, 0.0], [1.0, 2.0], [0.5, 1.0]]))
    q = dataclasses.replace(p, speed_ms=2.0 * p.speed_ms)
    assert float(p.speed(4.0, 90.0)) == pytest.approx(2.0)
    assert float(q.speed(4.0, 90.0)) == pytest.approx(4.0)
    assert vars(p)["_dense"] is not vars(q)["_dense"]


def test_cached_package_tables_are_read_only() -> None:
    fn, a = dsyhs_table()
    assert not fn.flags.writeable and not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        a[0, 0] = 1.0
