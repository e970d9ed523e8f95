"""The compiled step kernels for the tests that compare them with the NumPy step."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from sailroute.routing import isochrone_aot, isochrone_fast


@pytest.fixture(scope="session")
def aot_module() -> Any:
    """The ahead-of-time module of the step kernels, built where the router keeps it
    (numba's cache folder) unless it is there already: about 12 s of CPU once, as on a
    first compiled use after an install."""
    pytest.importorskip("numba")
    folder = isochrone_fast._cache_folder()
    if folder is None or not isochrone_aot.can_build():
        pytest.skip("the kernels cannot be compiled ahead of time here (no C compiler)")
    module = isochrone_aot.load(folder)
    if module is None:
        isochrone_aot.build(folder, isochrone_fast._just_in_time())
        module = isochrone_aot.load(folder)
    assert module is not None
    return module


@pytest.fixture(params=["jit", "aot"])
def compiled_kernels(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> Iterator[str]:
    """The compiled steps of a test through numba's just-in-time kernels, then through
    the module compiled ahead of time, every call of which must fit its signatures (a
    call handed on to the just-in-time kernels fails the test)."""
    pytest.importorskip("numba")
    if request.param == "jit":
        kernels: Any = isochrone_fast._just_in_time()
    else:
        module = request.getfixturevalue("aot_module")
        kernels = isochrone_aot.Kernels(module, _no_handing_on)
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", kernels)
    yield request.param


def _no_handing_on() -> Any:
    pytest.fail("a call the ahead-of-time kernels were not compiled for (SIGNATURES)")
