"""The command line's values converted without pydantic (``sailroute/cli_values.py``) are
typer's: the same value (type and bits) or the same error message, for every parameter of
every command and a table of inputs; typer's own conversion where typer is not checked."""

from __future__ import annotations

import random
import struct
from collections.abc import Iterator
from typing import Any

import pytest
import typer.main
from typer._adapters import try_build_adapter
from typer._click import Context
from typer._click.exceptions import BadParameter
from typer._coercion import AdapterRuntimeParam, build_runtime_param
from typer.models import OptionInfo
from typer.testing import CliRunner

from sailroute import cli_values
from sailroute.cli import app
from tests.conftest import python_c

TABLE = (
    # numbers
    *("3", "3.0", "3.5", "3.0000", "3.00001", "1e3", "1E3", "1.5e3", "1e+3", "2.5e-3", "1e400"),
    *("1e-400", "4.9e-324", "2.4e-324", "1.7976931348623157e308", "1.8e308", "-1", "+7"),
    *("-0", "+0", "-0.0", "0012", "0.1", ".5", "5.", "-.5", "99999999999999999999999"),
    *("123456789012345678", "1234567890123456789", "0.30000000000000004441"),
    # not plain decimals: typer's own conversion
    *("nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1_000", "0x10", "0b1", "1e", "e7"),
    *("--7", "+-7", "3.5.1", "1e3.5", "١٢", "１２", "\u00b2", "3\u00a0", " 4 ", "\t4\n", "4\x1c"),
    # text, booleans, choices, paths
    *("", " ", "abc", "true", "True", "TRUE", "tRuE", "yes", "YES", "on", "off", "Off", "1"),
    *("0", "t", "F", "y", "n", "no", "nO", "false", "  true ", "tru", "tr", "ye", "o", "of"),
    *("2", "truee", "\u0130"),
    *("isochrone", "ISOCHRONE", "griddp", "spline", "kn", "KN", "m/s", "M/S", "numpy"),
    *("cupy", "auto", "port", "starboard", "golden", "drift-diffusion", "racexml"),
    *("~", "~/x.yaml", "~user/a", "./a b/c.yaml", "-", "a=b", "time=when", "\ud800", "é"),
)
"""Inputs tried on every parameter (valid, invalid and edge cases for each annotation)."""


def _fuzz(n: int, seed: int) -> list[str]:
    """Random strings near the grammar of the numbers (signs, points, exponents, blanks)
    and long decimals whose rounding to a float is delicate."""
    rng = random.Random(seed)
    alphabet = "0123456789" * 3 + "+-..eE_ \tnaif"
    out = ["".join(rng.choice(alphabet) for _ in range(rng.randint(1, 10))) for _ in range(n)]
    for _ in range(n):
        digits = "".join(rng.choice("0123456789") for _ in range(rng.randint(1, 20)))
        cut = rng.randint(0, len(digits))
        sign = rng.choice(["", "-", "+"])
        exp = rng.choice(["", f"e{rng.randint(-340, 320)}", f"E+{rng.randint(0, 330)}"])
        out.append(f"{sign}{digits[:cut]}.{digits[cut:]}{exp}")
        out.append(f"{sign}{digits}{exp}")
    return out


def _params() -> Iterator[tuple[str, Any, Context]]:
    """(command path, parameter, context) for every parameter of every command, the
    root's and typer's own (help, shell completion) included."""
    root = typer.main.get_command(app)

    def walk(cmd: Any, path: str) -> Iterator[tuple[str, Any, Context]]:
        ctx = Context(cmd)
        for p in cmd.get_params(ctx):
            yield path, p, ctx
        for name, sub in getattr(cmd, "commands", {}).items():
            yield from walk(sub, f"{path} {name}")

    return walk(root, "sailroute")


PARAMS = list(_params())


def _bits(v: Any) -> Any:
    """A value with its floats as their bits (-0.0 and NaN's sign count)."""
    if isinstance(v, float):
        return struct.pack("<d", v)
    if isinstance(v, (list, tuple)):
        return (type(v), tuple(_bits(x) for x in v))
    return (type(v), v)


def _outcome(runtime: Any, value: Any, param: Any, ctx: Context) -> tuple[str, Any]:
    """What a conversion gives: the value (its bits) or the message the user sees."""
    try:
        return "value", _bits(runtime.coerce(value, param=param, ctx=ctx))
    except BadParameter as exc:
        return "error", (exc.message, exc.format_message())


def _inputs(param: Any, text: str) -> list[Any]:
    """What click hands the conversion for ``text``: the string, or a tuple of strings
    for a parameter of several values."""
    if param.multiple or param.nargs == -1:
        return [(text,), (text, "x"), ("x", text)]
    return [text]


def _differences(param: Any, ctx: Context, texts: list[str]) -> list[str]:
    descriptor = param.type_descriptor
    plain = cli_values.plain_runtime_param(descriptor)
    typers = build_runtime_param(descriptor)
    assert plain is not None, f"{param.name}: typer's own conversion"
    # typer's conversion is a pydantic TypeAdapter's (try_build_adapter)
    assert isinstance(typers, AdapterRuntimeParam)
    assert try_build_adapter(descriptor.annotation, descriptor.parameter_info) is not None
    bad = []
    for text in texts:
        for value in _inputs(param, text):
            ours, theirs = _outcome(plain, value, param, ctx), _outcome(typers, value, param, ctx)
            if ours != theirs:
                bad.append(f"{param.name} {value!r}: {ours} != typer's {theirs}")
    return bad


def test_every_parameter_has_a_converter_and_its_defaults_need_no_typer() -> None:
    # so that parsing a command line never imports pydantic for a valid value
    assert len(PARAMS) > 100
    for path, p, ctx in PARAMS:
        runtime = cli_values.plain_runtime_param(p.type_descriptor)
        assert runtime is not None, f"{path} {p.name}: {p.type_descriptor.annotation}"
        if p.default is not None:
            assert runtime.convert(p.default, ctx) is not cli_values.DEFER, (path, p.name)


def test_the_table_converts_as_typer_on_every_parameter() -> None:
    bad = [d for _, p, ctx in PARAMS for d in _differences(p, ctx, list(TABLE))]
    assert not bad, "\n".join(bad[:20])


def test_random_inputs_convert_as_typer_on_each_kind_of_parameter() -> None:
    kinds: dict[Any, tuple[Any, Context]] = {}  # one parameter of each scalar type
    for _, p, ctx in PARAMS:
        if p.type_descriptor.annotation in (str, int, float, bool):
            kinds.setdefault(p.type_descriptor.annotation, (p, ctx))
    assert len(kinds) == 4
    texts = _fuzz(700, seed=7)
    as_float = cli_values.converter(float, OptionInfo())
    assert as_float is not None
    # most are plain decimals, converted without typer: the comparison tries both paths
    assert sum(as_float(t, None) is not cli_values.DEFER for t in texts) > 1000
    bad = [d for p, ctx in kinds.values() for d in _differences(p, ctx, texts)]
    assert not bad, "\n".join(bad[:20])


def test_values_typer_reads_differently_are_left_to_it() -> None:
    info = OptionInfo()
    as_float = cli_values.converter(float, info)
    as_int = cli_values.converter(int, info)
    assert as_float is not None and as_int is not None
    for text in ("nan", "-nan", "inf", " 4 ", "1_000", "3.0", "1e3"):
        expected = cli_values.DEFER if text not in ("3.0", "1e3") else float(text)
        assert as_float(text, None) is expected or as_float(text, None) == expected
    for text in ("3.0", "1e3", " 4 ", "1_000", "1234567890123456789"):
        assert as_int(text, None) is cli_values.DEFER
    assert as_int("-0012", None) == -12 and type(as_int("7", None)) is int
    assert struct.pack("<d", as_float("-0", None)) == struct.pack("<d", -0.0)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["plan", "c.yaml", "--router", "nope"], "'--router' / '-r': 'nope' is not one of"),
        (["plan", "c.yaml", "-r", "GRIDDP", "--ensemble", "abc"], "'--ensemble': Input should"),
        (["plan", "c.yaml", "--ensemble", "2.5"], "be a valid integer, unable to parse string"),
        (["plan", "c.yaml", "--backend", ""], "'--backend': '' is not one of 'numpy', 'cupy'"),
        (["plan", "c.yaml", "-s", "~/x", "--ensemble", "0012"], "c.yaml"),
        (["vpp", "--crew-mass", "abc"], "'--crew-mass': Input should be a valid number"),
        (["vpp", "--twa-step", " 4 ", "--unit", "KN", "--kinetics", "x"], "'x' is not one of"),
        (["strategy", "--shift", "OU", "--tws-kn", "1e3", "--seed", "1e3"], "'--seed': Input"),
        (["strategy", "--tws-kn", "-0", "--start-tack", "PORT", "--runs", ""], "'--runs': Input"),
    ],
)
def test_a_command_line_reads_the_same_with_typer_own_conversion(
    args: list[str], message: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # each ends before any work: a refused value, or a course that is not there (exit 2)
    runner = CliRunner()
    ours = runner.invoke(app, args)
    monkeypatch.setattr(cli_values, "_CHECKED", False)
    theirs = runner.invoke(app, args)
    assert (ours.exit_code, ours.output) == (theirs.exit_code, theirs.output)
    assert ours.exit_code == 2 and message in ours.output, ours.output


def test_a_plan_command_line_does_not_import_pydantic() -> None:
    code = (
        "import sys\n"
        "from sailroute.cli import main\n"
        "sys.argv = ['sailroute', 'plan', 'no-such-course.yaml', '-s', 'wrf10', '-r', 'griddp',"
        " '--backend', 'auto', '--no-plots', '-q', '-o', 'out-x']\n"
        "try:\n    main()\nexcept SystemExit as e:\n    print(e.code)\n"
        "print('pydantic' in sys.modules)\n"
    )
    res = python_c(code)
    assert res.stdout.split() == ["2", "False"], res.stdout + res.stderr
    assert "no-such-course.yaml" in res.stderr


@pytest.mark.parametrize(
    "tamper",
    [
        "import typer; typer.__version__ = '0.30.0'",
        "import typer._coercion as c; del c.RuntimeParam",
        "import typer._coercion as c; del c.build_runtime_param",
    ],
)
def test_another_typer_keeps_its_own_conversion(tamper: str) -> None:
    code = (
        f"{tamper}\n"
        "import sys, typer.main\n"
        "from typer._click import Context\n"
        "from sailroute import cli_values\n"
        "from sailroute.cli import app\n"
        "cmd = typer.main.get_command(app).commands['plan']\n"
        "ctx = cmd.make_context('plan', ['c.yaml', '--router', 'GRIDDP'])\n"
        "print(cli_values._CHECKED, ctx.params['router'], 'pydantic' in sys.modules)\n"
    )
    res = python_c(code)
    assert res.stdout.split() == ["False", "griddp", "True"], res.stdout + res.stderr


def test_the_installed_typer_is_a_checked_one() -> None:
    assert cli_values._CHECKED, (
        f"typer {typer.__version__} is not in sailroute.cli_values.CHECKED_TYPER: run "
        "tests/test_cli_values.py's comparisons on it (with _CHECKED forced) and add it"
    )
