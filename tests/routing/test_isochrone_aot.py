"""The step kernels compiled ahead of time: their signatures, the checks of every call,
the module's name and place, loading, building and the way back to numba's kernels.

Routes through the module are compared with the NumPy step in test_isochrone_jit.py (the
fixture ``compiled_kernels``)."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sailroute.routing import isochrone_aot, isochrone_fast
from sailroute.routing.batch import route_leg_batch
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Start, Target
from sailroute.wind.perturbed import PerturbedWind
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar
from tests.routing.winds import T0

numba = pytest.importorskip("numba")

ROOT = Path(__file__).resolve().parents[2]
LINE = Start((-150.0, 0.0), (150.0, 0.0), name="start")
MARK = Target("mark", (60.0, 700.0), rounding="port", name="1")


def with_engine(settings: RoutingSettings, engine: str) -> RoutingSettings:
    return dataclasses.replace(
        settings, isochrone=dataclasses.replace(settings.isochrone, engine=engine)
    )


def test_the_signatures_are_the_ones_numbas_dispatchers_compile_for_the_driver(monkeypatch):
    # a leg and members in perturbed winds through the just-in-time kernels: the types
    # numba's dispatchers see from the drivers are the types the module is compiled for
    # (read-only or not aside)
    jit = isochrone_fast._just_in_time()
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", jit)
    settings = with_engine(RoutingSettings(), "numba")
    wind = UniformWind(4.4, 0.0)
    route_isochrone(LINE, MARK, T0, wind, laser_like_polar(), settings)
    members = [PerturbedWind(wind, speed_add_ms=0.3), PerturbedWind(wind, direction_offset_deg=4.0)]
    route_leg_batch(LINE, MARK, [T0, T0], members, laser_like_polar(), settings)
    for name in isochrone_fast.STEP_KERNELS:
        want = isochrone_aot.signature(name)
        seen = [
            tuple(t.copy(readonly=False) if isinstance(t, numba.types.Array) else t for t in s)
            for s in getattr(jit, name).signatures
        ]
        assert want.args in seen, name
        ret = getattr(jit, name).overloads[getattr(jit, name).signatures[0]].signature
        assert ret.return_type == want.return_type, name


@pytest.mark.parametrize(
    ("types", "args", "fits"),
    [
        ("f8:1 i8 f8", (np.zeros(3), 2, 1.5), True),
        ("f8:1 i8 f8", (np.zeros(3), np.int64(2), np.float64(1.5)), True),
        ("f8:1", (np.zeros(3, dtype=np.float32),), False),  # another dtype
        ("f8:2", (np.zeros(3),), False),  # another number of dimensions
        ("f8:2", (np.zeros((3, 4))[:, ::2],), False),  # a strided view
        ("f8:1", ([0.0, 1.0],), False),  # not an array
        ("f8", (2,), False),  # numba would type an int as int64
        ("i8", (True,), False),  # and a bool as a boolean
        ("f4 f4", (np.float32(1), np.float32(2)), True),
        ("f4", (1.0,), False),  # float64 where the kernel takes float32
        ("(f8:1 b1:2) i8", ((np.zeros(2), np.zeros((2, 2), dtype=bool)), 0), True),
        ("(f8:1 b1:2) i8", ([np.zeros(2), np.zeros((2, 2), dtype=bool)], 0), False),
        ("(f8:1 b1:2) i8", ((np.zeros(2), np.zeros((2, 2))), 0), False),
        ("f8:1 f8:1", (np.zeros(3),), False),  # an argument short
    ],
)
def test_a_call_fits_only_the_types_it_was_compiled_for(types, args, fits):
    assert isochrone_aot.check(types)(*args) is fits


def test_a_call_that_does_not_fit_goes_to_the_just_in_time_kernels():
    class Module:
        @staticmethod
        def sector_winners(*args):
            return "ahead of time"

    class Jit:
        @staticmethod
        def sector_winners(*args):
            return "just in time"

    for name in isochrone_aot.SIGNATURES:
        setattr(Module, name, getattr(Module, name, staticmethod(lambda *a: None)))
    kernels = isochrone_aot.Kernels(Module, lambda: Jit)  # type: ignore[arg-type]
    ok = (
        3,
        np.zeros((2, 2), dtype=np.int64),
        np.zeros(2),
        np.zeros(2, dtype=np.float32),
        np.float32(1.0),
        np.float32(0.0),
        np.zeros(2),
        np.zeros(2, dtype=np.int64),
    )
    assert kernels.sector_winners(*ok) == "ahead of time"
    strided = (*ok[:2], np.zeros(4)[::2], *ok[3:])
    assert kernels.sector_winners(*strided) == "just in time"
    assert kernels.sector_winners(*ok[:4], 1.0, *ok[5:]) == "just in time"  # a float64


def test_the_modules_name_follows_the_kernels_source(monkeypatch, tmp_path):
    kernels, this = tmp_path / "isochrone_jit.py", tmp_path / "isochrone_aot.py"
    kernels.write_text("a = 1\n")
    this.write_text("b = 2\n")
    monkeypatch.setattr(isochrone_aot, "_SOURCES", (kernels, this))
    name = isochrone_aot.module_name()
    assert name.startswith("_isochrone_step_") and len(name) == len("_isochrone_step_") + 16
    assert isochrone_aot.module_name() == name  # the same source, the same module
    kernels.write_text("a = 2\n")
    assert isochrone_aot.module_name() != name  # a changed kernel: another module
    path = isochrone_aot.module_path(tmp_path)
    assert path.parent == tmp_path and path.name.startswith(isochrone_aot.module_name())


def test_a_missing_or_damaged_module_loads_as_none(tmp_path, aot_module):
    assert isochrone_aot.load(None) is None
    assert isochrone_aot.load(tmp_path) is None
    isochrone_aot.module_path(tmp_path).write_bytes(b"not a shared library")
    assert isochrone_aot.load(tmp_path) is None
    assert all(callable(getattr(aot_module, name)) for name in isochrone_aot.SIGNATURES)


def test_without_a_compiler_or_with_a_failed_build_numbas_kernels_serve(monkeypatch, tmp_path):
    monkeypatch.setattr(isochrone_aot.shutil, "which", lambda name: None)
    assert not isochrone_aot.can_build()
    monkeypatch.undo()

    def broken(folder, kernels):
        raise OSError("no C compiler")

    jit = isochrone_fast._just_in_time()
    monkeypatch.setattr(isochrone_fast, "_PYCACHE", tmp_path)  # nothing built there
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(isochrone_aot, "can_build", lambda: True)
    monkeypatch.setattr(isochrone_aot, "build", broken)
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", None)
    monkeypatch.setattr(isochrone_fast._Usage, "build_failed", False)
    assert isochrone_fast.kernels() is jit
    assert isochrone_fast._Usage.build_failed  # and not tried again in this process
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", None)
    monkeypatch.setattr(isochrone_aot, "build", lambda *a: pytest.fail("built again"))
    assert isochrone_fast.kernels() is jit


def test_the_module_is_built_where_there_is_none_then_loaded(monkeypatch, tmp_path, aot_module):
    built = []

    def build(folder, kernels):  # the module built before, put in place
        built.append(folder)
        isochrone_aot.module_path(folder).write_bytes(Path(aot_module.__file__).read_bytes())

    monkeypatch.setattr(isochrone_fast, "_PYCACHE", tmp_path)
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(isochrone_aot, "build", build)
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", None)
    monkeypatch.setattr(isochrone_fast._Usage, "build_failed", False)
    first = isochrone_fast.kernels()
    assert isinstance(first, isochrone_aot.Kernels) and built == [tmp_path]
    assert Path(first.module.__file__) == isochrone_aot.module_path(tmp_path)
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", None)
    assert isinstance(isochrone_fast.kernels(), isochrone_aot.Kernels) and len(built) == 1


def test_a_new_process_routes_through_the_module_without_importing_numba(aot_module, tmp_path):
    # the module where the router looks (numba's cache folder): `auto` takes it for a
    # single plan, imports no numba, and the leg times are the NumPy step's
    code = (
        "import json, sys\n"
        "from sailroute.course.load import load_course\n"
        "from sailroute.planning.route import plan_course\n"
        "from sailroute.routing import isochrone_fast\n"
        "c = load_course(sys.argv[1])\n"
        "times = [leg.time_s for leg in plan_course(c).plan.legs]\n"
        "print(json.dumps([times, type(isochrone_fast._Usage.kernels).__name__,\n"
        "                  'numba' in sys.modules]))\n"
    )
    course = str(ROOT / "courses" / "hyeres-r1.yaml")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run(
        [sys.executable, "-c", code, course], env=env, capture_output=True, text=True, check=True
    )
    times, kind, numba_imported = json.loads(out.stdout)
    assert (kind, numba_imported) == ("Kernels", False)
    from sailroute.course.load import load_course
    from sailroute.planning.route import plan_course

    c = load_course(course)
    numpy_run = plan_course(dataclasses.replace(c, routing=with_engine(c.routing, "numpy")))
    assert times == [leg.time_s for leg in numpy_run.plan.legs]


def test_the_cpu_is_read_from_the_first_processor_of_cpuinfo(tmp_path):
    info = tmp_path / "cpuinfo"
    info.write_text(
        "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC\n"
        "cpu MHz\t\t: 2596.1\nflags\t\t: fpu sse2  avx2\n\n"
        "processor\t: 1\nvendor_id\t: AuthenticAMD\nflags\t\t: fpu sse2 avx2 avx512f\n"
    )
    assert isochrone_aot.host_cpu(info) == (
        "vendor_id : AuthenticAMD\nmodel name : AMD EPYC\nflags : fpu sse2 avx2"
    )  # the clock speed, which varies, is left out
    assert isochrone_aot.host_cpu(tmp_path / "none") == ""


def test_another_cpu_gets_another_module(monkeypatch):
    monkeypatch.setattr(isochrone_aot, "host_cpu", lambda: "flags : sse2 avx2")
    avx2 = isochrone_aot.module_name()
    monkeypatch.setattr(isochrone_aot, "host_cpu", lambda: "flags : sse2")
    assert isochrone_aot.module_name() != avx2


def test_the_module_is_compiled_for_this_cpus_features_or_a_generic_one():
    from numba.core import codegen

    class CC:
        target_cpu = ""

    plain = codegen.AOTCPUCodegen._customize_tm_features
    cc = CC()
    with isochrone_aot._for_this_cpu(cc, known=False):
        assert cc.target_cpu == "generic"
        assert codegen.AOTCPUCodegen._customize_tm_features is plain
    with isochrone_aot._for_this_cpu(cc, known=True):
        assert cc.target_cpu == "host"
        gen = codegen.AOTCPUCodegen.__new__(codegen.AOTCPUCodegen)
        assert gen._customize_tm_features() == gen._get_host_cpu_features() != ""
    assert codegen.AOTCPUCodegen._customize_tm_features is plain
