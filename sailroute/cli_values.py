"""Option values of the command line converted without pydantic, as typer converts them.

typer 0.29 converts each parameter's value with a pydantic ``TypeAdapter`` that it builds
the first time the parameter is parsed (``typer._coercion.build_runtime_param``):
importing pydantic and building the adapters of a command's parameters took about 0.1 s
of CPU, a tenth of a ``sailroute plan``.  :func:`use_plain_coercion` gives each parameter
whose annotation is one the commands declare (``str``, ``int``, ``float``, ``bool``, a
``Literal`` of choices, ``list[str]``, without ``min``/``max``, a parser or a file type) a
converter of its own.  It converts the values it is sure of itself (a plain decimal
number, one of the words of a boolean, one of the choices, any text) and hands anything
else (``"abc"``, ``" 4 "``, ``"nan"``, ``"1_000"``, a choice that is not one) to typer's
own conversion, which gives typer's value or typer's error message.  The values are
compared with typer's, input by input, in ``tests/test_cli_values.py``.  Where typer is
not a version checked that way (:data:`CHECKED_TYPER`) or lacks the internals used, every
parameter keeps typer's conversion.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Final, get_args, get_origin

CHECKED_TYPER: Final = ("0.29",)
"""typer versions (major.minor) whose conversion ``tests/test_cli_values.py`` compares."""

DEFER: Final = object()
"""What a converter returns for a value it leaves to typer."""

_INT: Final = re.compile(r"[+-]?[0-9]{1,18}")
_FLOAT: Final = re.compile(
    r"[+-]?(?:[0-9]{1,20}(?:\.[0-9]{0,20})?|\.[0-9]{1,20})(?:[eE][+-]?[0-9]{1,3})?"
)
_BOOL: Final = {
    "1": True,
    "0": False,
    "true": True,
    "false": False,
    "t": True,
    "f": False,
    "yes": True,
    "no": False,
    "y": True,
    "n": False,
    "on": True,
    "off": False,
}
"""The words of a boolean (any case) and their values, as pydantic reads them."""

Converter = Callable[[Any, Any], Any]
"""``(value, click context) -> converted value or DEFER``."""

try:
    from typer import __version__ as _typer_version
    from typer._coercion import RuntimeParam, build_runtime_param
    from typer._param_types import coerce_cli_choice
    from typer._typing import is_literal_type, literal_values
    from typer.core import _TyperParameter
except ImportError:  # another typer: its own conversion for every parameter
    _CHECKED = False
else:
    _CHECKED = ".".join(_typer_version.split(".")[:2]) in CHECKED_TYPER and hasattr(
        _TyperParameter, "get_runtime_param"
    )

    @dataclass(frozen=True)
    class PlainRuntimeParam(RuntimeParam):
        """typer's conversion contract for one parameter (``None``, and the check of
        multiple values, are the base class's), the value converted by ``convert`` or,
        where it defers, by typer's own conversion of ``descriptor``."""

        convert: Converter
        descriptor: Any

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            out = self.convert(value, ctx)
            if out is DEFER:
                typers = build_runtime_param(self.descriptor)
                return typers._coerce_value(value, param=param, ctx=ctx)
            return out


def _str(value: Any, ctx: Any) -> Any:
    return value if type(value) is str else DEFER


def _number(kind: type[int] | type[float], plain: re.Pattern[str]) -> Converter:
    """A number of ``kind`` as is, or text that matches ``plain`` (a decimal that Python
    and pydantic read alike) as ``kind(text)``."""

    def convert(value: Any, ctx: Any) -> Any:
        if type(value) is kind:
            return value
        if type(value) is str and plain.fullmatch(value):
            return kind(value)
        return DEFER

    return convert


def _bool(value: Any, ctx: Any) -> Any:
    if type(value) is bool:
        return value
    if type(value) is not str:
        return DEFER
    word = value.strip()  # typer's own step before pydantic: blank is False
    if not word:
        return False
    return _BOOL.get(word.lower(), DEFER) if word.isascii() else DEFER


def _choice(choices: tuple[Any, ...], case_sensitive: bool) -> Converter:
    def convert(value: Any, ctx: Any) -> Any:
        if type(value) is not str:
            return DEFER
        try:
            return coerce_cli_choice(value, choices=choices, case_sensitive=case_sensitive, ctx=ctx)
        except ValueError:  # not a choice: typer's message
            return DEFER

    return convert


def _listed(item: Converter) -> Converter:
    def convert(value: Any, ctx: Any) -> Any:
        if not isinstance(value, (list, tuple)):
            return DEFER
        out = [item(v, ctx) for v in value]
        return DEFER if any(v is DEFER for v in out) else out

    return convert


_LEAVES: Final[dict[Any, Converter]] = {
    str: _str,
    int: _number(int, _INT),
    float: _number(float, _FLOAT),
    bool: _bool,
}


def converter(annotation: Any, info: Any) -> Converter | None:
    """The converter of a parameter's annotation and its ``typer.models.ParameterInfo``
    (None: one typer converts itself)."""
    if (
        info.parser is not None
        or info.min is not None
        or info.max is not None
        or info.clamp
        or info.formats is not None
    ):
        return None
    if get_origin(annotation) is list:
        args = get_args(annotation)
        leaf = converter(args[0], info) if len(args) == 1 else None
        return None if leaf is None else _listed(leaf)
    if isinstance(annotation, type):
        return _LEAVES.get(annotation)
    if is_literal_type(annotation):
        choices = literal_values(annotation)
        if all(type(c) is str for c in choices):
            return _choice(choices, info.case_sensitive)
    return None


def plain_runtime_param(descriptor: Any) -> Any | None:
    """A ``typer._coercion.RuntimeParam`` for a parameter's ``type_descriptor`` that
    converts without pydantic and hands what it leaves to typer's own (None: a parameter
    typer converts itself)."""
    if not _CHECKED or descriptor.file_annotation is not None:
        return None
    convert = converter(descriptor.annotation, descriptor.parameter_info)
    if convert is None:
        return None
    return PlainRuntimeParam(
        parameter_info=descriptor.parameter_info,
        annotation=descriptor.annotation,
        convert=convert,
        descriptor=descriptor,
    )


def use_plain_coercion(params: Iterable[Any]) -> None:
    """Give every typer parameter of ``params`` not yet parsed whose annotation
    :func:`converter` knows the converter without pydantic (nothing where typer is not
    checked; the others, e.g. click's ``--help``, are left alone)."""
    for p in params:
        if getattr(p, "_runtime_param", DEFER) is not None:  # not typer's, or built
            continue
        runtime = plain_runtime_param(p.type_descriptor)
        if runtime is not None:
            p._runtime_param = runtime
