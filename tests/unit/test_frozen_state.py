"""Frozen dataclasses keep derived values as cached properties, not as fields set with
``object.__setattr__``; they are built complete (their ``__post_init__`` only validates);
the caches that stay at module level hold read-only data."""

from __future__ import annotations

import ast
import dataclasses
import pickle
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

import sailroute
from sailroute.boat.polar import Polar
from sailroute.boat.vpp import dsyhs_table
from sailroute.course.load import load_course
from sailroute.course.model import ScenarioSpec, frozen_mapping
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.track.model import Track
from sailroute.wind.blended import BlendedWind
from sailroute.wind.current import DiamondCurrent, UniformCurrent
from sailroute.wind.grid import GridWind
from sailroute.wind.specs import UniformWindSpec, WrfWindSpec
from sailroute.wind.stations import StationWind
from sailroute.wind.uniform import UniformWind
from tests.conftest import ROOT

T0 = 1_524_567_600.0


@pytest.mark.parametrize(
    "cls", [Polar, UniformCurrent, DiamondCurrent, UniformWind, GridWind, StationWind, BlendedWind]
)
def test_every_field_is_an_input(cls: type) -> None:
    # no derived state as init=False fields patched in by __post_init__
    assert [f.name for f in dataclasses.fields(cls) if not f.init] == []


def grid_wind(**kw: object) -> GridWind:
    x, y = np.meshgrid(np.linspace(-1000.0, 1000.0, 5), np.linspace(-800.0, 800.0, 4))
    u = np.full((2, 4, 5), 3.0)
    return GridWind([T0, T0 + 3600.0], x, y, u, -u, **kw)  # type: ignore[arg-type]


def test_grid_wind_state_is_built_when_made_and_rebuilt_by_replace() -> None:
    with pytest.raises(InputError, match="times must be finite and strictly increasing"):
        GridWind(
            [T0, T0], *np.meshgrid([0.0, 1.0], [0.0, 1.0]), np.zeros((2, 2, 2)), np.zeros((2, 2, 2))
        )
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
    p = Polar.from_arrays(twa, tws, np.array([[0.0, 0.0], [1.0, 2.0], [0.5, 1.0]]))
    doubled = 2.0 * p.speed_ms
    doubled.setflags(write=False)
    q = dataclasses.replace(p, speed_ms=doubled)
    assert float(p.speed(4.0, 90.0)) == pytest.approx(2.0)
    assert float(q.speed(4.0, 90.0)) == pytest.approx(4.0)
    assert vars(p)["_dense"] is not vars(q)["_dense"]


def test_cached_package_tables_are_read_only() -> None:
    fn, a = dsyhs_table()
    assert not fn.flags.writeable and not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        a[0, 0] = 1.0


def _object_setattr_calls(tree: ast.AST) -> list[int]:
    """Lines of ``object.__setattr__(...)`` calls in ``tree``."""
    return [
        n.lineno
        for n in ast.walk(tree)
        if isinstance(n, ast.Call)
        and isinstance(n.func, ast.Attribute)
        and n.func.attr == "__setattr__"
        and isinstance(n.func.value, ast.Name)
        and n.func.value.id == "object"
    ]


def test_the_scan_finds_object_setattr() -> None:
    code = "class A:\n    def f(self):\n        object.__setattr__(self, 'x', 1)\n"
    assert _object_setattr_calls(ast.parse(code)) == [3]


def test_no_frozen_dataclass_is_patched_with_object_setattr() -> None:
    package = ROOT / "sailroute"
    assert sailroute.__file__ is not None and package.samefile(Path(sailroute.__file__).parent)
    found = [
        f"{path.relative_to(ROOT)}:{line}"
        for path in sorted(package.rglob("*.py"))
        for line in _object_setattr_calls(ast.parse(path.read_text(encoding="utf-8")))
    ]
    assert found == []


# --- Polar: the constructor validates, Polar.from_arrays coerces ---------------------------

TWA3, TWS1, SPD31 = [0.0, 90.0, 180.0], [5.0], [[0.0], [2.0], [1.0]]


def _read_only(values: list[float]) -> np.ndarray:
    arr = np.array(values)
    arr.setflags(write=False)
    return arr


def test_polar_from_arrays_copies_lists_to_read_only_float_arrays() -> None:
    spd = np.array(SPD31)
    p = Polar.from_arrays(TWA3, (5,), spd, name="p", interpolation="linear")
    spd[1, 0] = 9.0
    for arr in (p.twa_deg, p.tws_ms, p.speed_ms):
        assert arr.dtype == np.float64 and not arr.flags.writeable
    assert (p.name, p.interpolation, float(p.speed(5.0, 90.0))) == ("p", "linear", 2.0)


@pytest.mark.parametrize(
    ("args", "field", "got"),
    [
        ((TWA3, np.array(TWS1), np.array(SPD31)), "twa_deg", "got a list"),
        (
            (_read_only(TWA3), np.array([5]), np.array(SPD31)),
            "tws_ms",
            "got an ndarray of dtype int64",
        ),
        (
            (np.array(TWA3), np.array(TWS1), np.array(SPD31)),
            "twa_deg",
            r"got a writable ndarray \(the polar would change if the caller's array did\)",
        ),
    ],
)
def test_polar_constructor_refuses_unfrozen_tables_and_names_the_factory(
    args: tuple[object, object, object], field: str, got: str
) -> None:
    with pytest.raises(
        InputError,
        match=(
            rf"^polar 'x': {field} must be a read-only float64 ndarray, {got}; build the "
            r"polar with Polar\.from_arrays\(twa_deg, tws_ms, speed_ms, name=\.\.\., "
            r"interpolation=\.\.\.\), which copies lists and arrays to read-only float64 "
            r"arrays$"
        ),
    ):
        Polar(*args, name="x")  # type: ignore[arg-type]


def test_polar_constructor_takes_another_polars_tables_unchanged() -> None:
    p = Polar.from_arrays(TWA3, TWS1, SPD31)
    q = Polar(p.twa_deg, p.tws_ms, p.speed_ms, name="q")
    assert q.speed_ms is p.speed_ms and q.with_name("r").twa_deg is p.twa_deg


# --- Track, ScenarioSpec, Course: built with read-only mappings and tuples -----------------


def _track(**kw: object) -> Track:
    t = np.array([0.0, 1.0])
    return Track(t, t, t, **kw)  # type: ignore[arg-type]


def test_track_defaults_and_slices_are_read_only() -> None:
    tr = _track(channels=MappingProxyType({"sog_ms": np.array([1.0, 2.0])}), notes=("n",))
    part = tr.between(0.5, 1.0)
    assert isinstance(_track().channels, MappingProxyType)
    assert isinstance(part.channels, MappingProxyType) and part.notes == ("n",)
    assert part.channels["sog_ms"].tolist() == [2.0]


def test_track_refuses_plain_dict_and_list() -> None:
    with pytest.raises(
        TypeError,
        match=(
            r"^Track\.channels must be a read-only mapping \(types\.MappingProxyType\), got "
            r"dict; pass MappingProxyType\(dict\(channels\)\)$"
        ),
    ):
        _track(channels={})
    with pytest.raises(
        TypeError,
        match=r"^Track\.notes must be a tuple of str, got list; "
        r"pass tuple\(notes\)$",
    ):
        _track(notes=["gap"])


FROZEN_HINT = (
    r"must be a read-only mapping \(types\.MappingProxyType\), got dict; wrap it "
    r"with sailroute\.course\.model\.frozen_mapping\(\.\.\.\), or load the course "
    r"with sailroute\.course\.load\.load_course, whose builder does$"
)


def test_scenario_spec_refuses_plain_mappings() -> None:
    wind = UniformWindSpec(tws_ms=5.0, twd_deg=90.0)
    assert ScenarioSpec("a", wind).references == {}
    with pytest.raises(
        TypeError,
        match=r"^ScenarioSpec\.wind must be a parsed wind spec \(a dataclass of "
        r"sailroute\.wind\.specs\), got mappingproxy; parse the mapping with "
        r"sailroute\.wind\.specs\.parse_wind_spec\(\.\.\.\), or load the course",
    ):
        ScenarioSpec("a", frozen_mapping({"type": "uniform"}))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^ScenarioSpec\.current must be a parsed current spec"):
        ScenarioSpec("a", wind, current=wind)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^ScenarioSpec\.references " + FROZEN_HINT):
        ScenarioSpec("a", wind, references={})


def test_loaded_course_is_read_only_and_replace_refuses_plain_values() -> None:
    course = load_course(ROOT / "courses" / "hyeres-r1.yaml")
    for name in ("marks", "lines", "gates", "boat_spec", "scenarios", "references"):
        assert isinstance(getattr(course, name), MappingProxyType), name
    spec = next(iter(course.scenarios.values()))
    assert isinstance(spec.wind, WrfWindSpec | UniformWindSpec)  # parsed at load, frozen
    assert isinstance(spec.references, MappingProxyType)
    assert isinstance(course.legs, tuple)
    again = pickle.loads(pickle.dumps(course))  # process workers get a copy
    assert isinstance(again.marks, MappingProxyType) and list(again.marks) == list(course.marks)
    with pytest.raises(TypeError, match=r"^Course\.marks " + FROZEN_HINT):
        dataclasses.replace(course, marks=dict(course.marks))
    with pytest.raises(
        TypeError,
        match=r"^Course\.legs must be a tuple of LegSpec, got list; "
        r"pass tuple\(legs\)$",
    ):
        dataclasses.replace(course, legs=list(course.legs))
