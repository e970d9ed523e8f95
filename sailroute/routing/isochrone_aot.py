"""The compiled isochrone step ahead of time: the kernels of
:mod:`~sailroute.routing.isochrone_jit` in one extension module, loaded without numba.

Numba's just-in-time cache holds the kernels' machine code, but loading it means
importing numba and its registries: about 0.35 s of CPU in every new process, more than
the compiled steps of one plan take.  Here numba's ahead-of-time compiler
(``numba.pycc``) writes the same kernels, compiled for this CPU as numba's just-in-time
compiler would (:func:`host_cpu`; for a generic CPU of the architecture where the CPU
cannot be told), into a Python extension module; importing that costs a few
milliseconds and imports no numba.  It is built once, where the kernels would otherwise
be compiled (:func:`build`, about 12 s of CPU with a C compiler and Python's headers),
into numba's cache folder, under a name that carries the SHA-1 of the kernels' source,
of :data:`SIGNATURES` and of the CPU (:func:`module_name`): a changed kernel or another
CPU builds a new module.

The module's functions take the argument types of :data:`SIGNATURES` only and, unlike a
numba dispatcher, do not check them (an array of another dtype or a strided view would
be read wrongly), so :class:`Kernels` checks each call's arguments first and hands any
other call to the just-in-time kernels.  The arithmetic is numba's either way: the same
routes bit for bit (``tests/routing/test_isochrone_jit.py`` runs its cases on both).
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.machinery
import importlib.util
import os
import shutil
import sys
import sysconfig
import tempfile
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any, Final

import numpy as np

__all__ = ["SIGNATURES", "Kernels", "build", "can_build", "check", "load", "module_name"]

_FRONT: Final = "(f8:1 f8:1 f8:2 i8:1 f8:2 b1:2 f8:1 f8:1 f8:3 f8:2 f8:3)"
"""The tuple ``front`` (:data:`~sailroute.routing.isochrone_jit.FRONT`)."""

SIGNATURES: Final[dict[str, tuple[str, str]]] = {
    "sample_points": ("none", "f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8 f8:1 f8:1 f8:1 "
                      "f8:2 f8:2 f8:2 f8:2"),
    "wind_states": ("b1", "f8:2 f8:2 f8:1 f8:1 i8:2 f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8:1 f8:2 "
                    "i8:1 f8:2 i8:1 f8:2 b1:2 f8:2 f8:1 f8:2"),
    "support_headings": ("none", "i8:1 f8:1 f8:2 f8:2 f8:2 f8:1 f8:2 f8:2 f8:2"),
    "aim_directions": ("none", "f8:1 f8:1 f8:2 f8:2 f8:2 f8:2 f8:2 f8:2 f8:2 f8:1 f8:1 f8:3 "
                       "f8:3 f8:3"),
    "step_inputs": ("b1", "f8:1 f8:1 f8:1 f8:2 i8:1 f8:2 i8:1 f8:2 b1:2 f8:3 f8:3 f8:3 f8:3 "
                    "f8:2 f8:2 f8:2 f8:2 f8:1 f8:2 f8:1 f8:1 f8:1 f8:2 f8:1 f8:1 f8:1 f8:1 "
                    "i8:1 i8 f8:3 f8:3 f8:1 b1:1 b1:2 f8:2"),
    "dense_speeds": ("none", "f8:2 f8:2 i8:1 f8:1 f8:2 f8:2"),
    "candidates": ("i8", f"i8 i8 i8 i8 i8 f8:1 f8 {_FRONT} f8:2 i8:2 f8:2 f8:2 f8:2 b1:2 f8:1 "
                   "f8:1 f8:1 f8:1 f8:1 b1:1 f8:1 f8:1 f4:1 f4:1 i8:2 f8:1"),
    "sector_winners": ("none", "i8 i8:2 f8:1 f4:1 f4 f4 f8:1 i8:1"),
    "survivors": ("none", f"i8:1 i8:1 i8:1 i8 i8 f8:1 {_FRONT} f8:2 f8:2 f8:2 f8:2 b1:1"),
    "perturbed_winds": ("none", "f8:1 f8:1 f8:1 i8:1 f8:1 f8:1 b1:1 f8:1 f8:1 b1:1 f8:1 f8:1 "
                        "f8:1 f8:1"),
}  # fmt: skip
"""Return and argument types of each step kernel, as the driver
(:mod:`~sailroute.routing.isochrone_fast`) calls it: ``f8``, ``f4``, ``i8`` a float64,
float32 or int64 scalar, ``f8:2`` a C-contiguous float64 array of 2 dimensions (``b1``
bool), ``(...)`` a tuple of such arrays, ``none`` no result."""

_DTYPES: Final = {"f8": np.dtype(np.float64), "f4": np.dtype(np.float32),
                  "i8": np.dtype(np.int64), "b1": np.dtype(np.bool_)}  # fmt: skip

_MODULE_PREFIX: Final = "_isochrone_step_"

_SOURCES: Final = (Path(__file__).with_name("isochrone_jit.py"), Path(__file__))
"""What the module is built from: the kernels and this module's :data:`SIGNATURES`."""


_CPUINFO_KEYS: Final = frozenset(
    {"vendor_id", "cpu family", "model", "model name", "flags", "CPU implementer",
     "CPU architecture", "CPU variant", "CPU part", "Features"}
)  # fmt: skip
"""The lines of ``/proc/cpuinfo`` that say which CPU this is and what it can do."""


def host_cpu(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """This machine's CPU as Linux describes it: the model and feature lines of the first
    processor in ``cpuinfo`` (the features as the kernel sees them, a hypervisor's
    masking included); "" where there is no such file (the module is then compiled for
    a generic CPU of the architecture)."""
    try:
        with cpuinfo.open(encoding="utf-8", errors="replace") as f:
            lines = []
            for line in f:
                if not line.strip():
                    break
                if line.split(":")[0].strip() in _CPUINFO_KEYS:
                    lines.append(" ".join(line.split()))
    except OSError:
        return ""
    return "\n".join(lines)


def module_name() -> str:
    """The extension module's name: a prefix and the first 16 hexadecimal digits of the
    SHA-1 of the kernels' source, of this module and of the CPU it is compiled for
    (:func:`host_cpu`): another kernel or another CPU, another module."""
    digest = hashlib.sha1()
    for path in _SOURCES:
        digest.update(path.read_bytes())
    digest.update(host_cpu().encode())
    return _MODULE_PREFIX + digest.hexdigest()[:16]


def module_path(folder: Path) -> Path:
    """Where the module for the current source lives in ``folder`` (the file name ends in
    this interpreter's extension suffix, e.g. ``.cpython-311-x86_64-linux-gnu.so``)."""
    return folder / (module_name() + importlib.machinery.EXTENSION_SUFFIXES[0])


# --------------------------------------------------------------------------------------
# argument checks


def _parse(types: str) -> list[Any]:
    """``"f8:1 i8 (f8:1 b1:2)"`` as checks: ``(dtype, ndim)`` for an array, a scalar
    type for a scalar, a list for a tuple."""
    out: list[Any] = []
    stack = [out]
    for token in types.replace("(", " ( ").replace(")", " ) ").split():
        if token == "(":
            stack.append([])
        elif token == ")":
            inner = stack.pop()
            stack[-1].append(inner)
        elif ":" in token:
            code, ndim = token.split(":")
            stack[-1].append((_DTYPES[code], int(ndim)))
        else:
            stack[-1].append({"f8": float, "f4": np.float32, "i8": int}[token])
    return out


def check(types: str) -> Callable[..., bool]:
    """A function that says whether its arguments have ``types`` (:data:`SIGNATURES`'
    notation) exactly as numba's dispatcher would type them for that signature: an array
    of that dtype, number of dimensions and C-contiguous; a Python or NumPy float for
    ``f8``, a Python int or NumPy int64 for ``i8`` (not a bool), a NumPy float32 for
    ``f4``; a tuple of such arrays.

    The test is written out as one function per signature and compiled (``exec``), a
    conjunction of attribute tests without a loop: a step's nine calls cost about 25 µs
    of checks instead of 45 µs in a loop over the arguments.
    """
    env: dict[str, Any] = {"ndarray": np.ndarray, "int64": np.int64, "float32": np.float32}
    lines = ["def fits(*args):"]
    _check_lines(_parse(types), "args", "a", lines, env)
    lines.append("    return True")
    exec("\n".join(lines), env)  # the source is built here, from SIGNATURES
    fits: Callable[..., bool] = env["fits"]
    return fits


def _check_lines(
    checks: list[Any], seq: str, prefix: str, lines: list[str], env: dict[str, Any]
) -> None:
    """Append to ``lines`` the statements that return False unless the sequence ``seq``
    holds ``checks`` (:func:`_parse`); the dtypes go into ``env``."""
    names = [f"{prefix}{i}" for i in range(len(checks))]
    lines.append(f"    if len({seq}) != {len(checks)}: return False")
    lines.append(f"    {', '.join(names)}{',' if len(names) == 1 else ''} = {seq}")
    tuples = []
    for name, want in zip(names, checks, strict=True):
        if isinstance(want, tuple):
            env[f"d_{name}"] = want[0]
            test = (
                f"type({name}) is ndarray and {name}.dtype is d_{name} and "
                f"{name}.ndim == {want[1]} and {name}.flags.c_contiguous"
            )
        elif isinstance(want, list):
            test = f"type({name}) is tuple"
            tuples.append((name, want))
        elif want is float:
            test = f"isinstance({name}, float)"  # a Python float or NumPy float64
        elif want is int:
            test = f"(type({name}) is int or type({name}) is int64)"
        else:
            test = f"type({name}) is float32"
        lines.append(f"    if not ({test}): return False")
    for name, want in tuples:
        _check_lines(want, name, f"{name}_", lines, env)


def _checked(
    aot: Callable[..., Any], fits: Callable[..., bool], name: str, jit: Callable[[], Any]
) -> Callable[..., Any]:
    """``aot`` where the arguments ``fit``, else the just-in-time kernel ``name``."""

    def call(*args: Any) -> Any:
        if fits(*args):
            return aot(*args)
        return getattr(jit(), name)(*args)

    call.__name__ = name
    return call


class Kernels:
    """The step kernels of an ahead-of-time module, called as
    :mod:`~sailroute.routing.isochrone_jit`'s are: each checks its arguments and hands a
    call it was not compiled for to the just-in-time kernel (``jit()`` returns
    :mod:`~sailroute.routing.isochrone_jit`, numba imported then).

    Parameters
    ----------
    module : ModuleType
        The loaded extension module (:func:`load`).
    jit : callable
        Returns the just-in-time kernels' module.
    """

    def __init__(self, module: ModuleType, jit: Callable[[], Any]) -> None:
        self.module = module
        for name, (_, args) in SIGNATURES.items():
            setattr(self, name, _checked(getattr(module, name), check(args), name, jit))

    def __getattr__(self, name: str) -> Any:  # the kernels set above; for type checkers
        raise AttributeError(name)


# --------------------------------------------------------------------------------------
# loading and building


def load(folder: Path | None) -> ModuleType | None:
    """The module built for the current source in ``folder``; None where there is none
    (or it does not load: a module of another interpreter or a damaged file)."""
    if folder is None:
        return None
    path = module_path(folder)
    if not path.is_file():
        return None
    spec = importlib.util.spec_from_file_location(path.name.split(".")[0], path)
    if spec is None or spec.loader is None:  # pragma: no cover - a file of another kind
        return None
    try:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except ImportError:
        return None
    if not all(hasattr(module, name) for name in SIGNATURES):
        return None
    return module


def can_build() -> bool:
    """Whether :func:`build` can work here: numba's AOT compiler importable, a C compiler
    on the ``PATH`` and Python's headers installed (checked without importing numba)."""
    if importlib.util.find_spec("numba") is None:
        return False
    if importlib.util.find_spec("numba.pycc") is None:  # pragma: no cover - a later numba
        return False
    cc = (sysconfig.get_config_var("CC") or "cc").split()
    include = sysconfig.get_paths().get("include", "")
    return bool(cc) and shutil.which(cc[0]) is not None and Path(include, "Python.h").is_file()


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Numba's and the C compiler's messages (the AOT compiler's pending deprecation,
    compiler warnings on stderr) kept off the terminal."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sys.stdout.flush()
        sys.stderr.flush()
        saved = [os.dup(1), os.dup(2)]
        try:
            with open(os.devnull, "w") as null:
                os.dup2(null.fileno(), 1)
                os.dup2(null.fileno(), 2)
                yield
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)


def _numba_type(token: Any) -> Any:
    """A parsed check (:func:`_parse`) as numba's type."""
    types: Any = importlib.import_module("numba").types  # untyped here: numba's own API
    if isinstance(token, list):
        return types.Tuple([_numba_type(t) for t in token])
    if isinstance(token, tuple):
        support: Any = importlib.import_module("numba.np.numpy_support")
        return types.Array(support.from_dtype(token[0]), token[1], "C")
    scalar = {float: types.float64, int: types.int64, np.float32: types.float32}
    return scalar[token]


def signature(name: str) -> Any:
    """Numba's signature of the kernel ``name`` (:data:`SIGNATURES`)."""
    types: Any = importlib.import_module("numba").types
    result, args = SIGNATURES[name]
    ret = {"none": types.none, "b1": types.boolean, "i8": types.int64}[result]
    return ret(*(_numba_type(t) for t in _parse(args)))


def build(folder: Path, kernels: ModuleType) -> Path:
    """Compile the step kernels of ``kernels`` (:mod:`~sailroute.routing.isochrone_jit`,
    its functions numba dispatchers) ahead of time into ``folder`` (:func:`module_path`).

    The module is written under a temporary name and renamed into place, so that
    processes building at once each leave a whole module.

    Raises
    ------
    Exception
        Whatever the AOT compiler or the C compiler raise (no compiler, no headers): the
        caller falls back to the just-in-time kernels.
    """
    target = module_path(folder)
    name = target.name.split(".")[0]  # module_name(), hashed once
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder, prefix=".aot-") as tmp, _quiet():
        pycc: Any = importlib.import_module("numba.pycc")  # pending deprecation: _quiet

        cc = pycc.CC(name, source_module=kernels)
        cc.output_dir = tmp
        for kernel in SIGNATURES:
            cc.export(kernel, signature(kernel))(getattr(kernels, kernel).py_func)
        with _for_this_cpu(cc, bool(host_cpu())):
            cc.compile()
        os.replace(Path(tmp) / target.name, target)
    return target


@contextlib.contextmanager
def _for_this_cpu(cc: Any, known: bool) -> Iterator[None]:
    """Compile ``cc`` for this CPU, its model and the features it reports, as numba's
    just-in-time compiler does (about 10 % faster kernels than for a generic CPU), where
    the CPU is ``known`` (:func:`host_cpu`, part of the module's name) and numba's
    ahead-of-time code generator takes the features; else for a generic CPU of the
    architecture.  The features are given as the host reports them (a CPU model alone
    implies features that a virtual machine may not have)."""
    codegen: Any = importlib.import_module("numba.core.codegen")
    aot = getattr(codegen, "AOTCPUCodegen", None)
    if not known or aot is None or not hasattr(aot, "_customize_tm_features"):
        cc.target_cpu = "generic"
        yield
        return
    cc.target_cpu = "host"
    plain = aot._customize_tm_features
    aot._customize_tm_features = lambda self: self._get_host_cpu_features()
    try:
        yield
    finally:
        aot._customize_tm_features = plain
