"""CLI conventions: help without type tags and with the choices, ``-h``, shell
completion, choices checked by the parser, ``--json`` for scripts,
``--out`` checked before the work, and output folders written as a set."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import get_args

import pytest
from typer.testing import CliRunner

import sailroute.cli as cli
from sailroute.cli import app
from sailroute.outdir import MANIFEST_NAME
from tests.conftest import COURSES

runner = CliRunner()
WL = str(COURSES / "windward-leeward-template.yaml")
COMMANDS = [
    ["plan"],
    ["compare-scenarios"],
    ["vpp"],
    ["strategy"],
    ["analyze"],
    ["polar", "fit"],
    ["polar"],
    [],
]


@pytest.mark.parametrize("cmd", COMMANDS, ids=lambda c: " ".join(c) or "sailroute")
def test_help_has_no_type_tags_and_h_is_help(cmd):
    res = runner.invoke(app, [*cmd, "--help"])
    assert res.exit_code == 0, res.output
    assert re.search(r"<(str|bool|int|float|list|path)", res.output) is None, res.output
    assert re.search(r"\{[a-z_]+\}", res.output.splitlines()[0]) is None  # usage: COURSE
    assert "-h, --help" in res.output
    short = runner.invoke(app, [*cmd, "-h"])
    assert short.exit_code == 0 and short.output == res.output


@pytest.mark.parametrize(
    ("cmd", "shown"),
    [
        (
            ["plan"],
            [
                "-r, --router [isochrone|griddp|spline]",
                "--backend [numpy|cupy|auto]",
                "-o, --out DIR",
                "Usage: root plan [OPTIONS] COURSE",
            ],
        ),
        (["compare-scenarios"], ["--router [isochrone|griddp|spline]", "--scheduler WHERE"]),
        (["vpp"], ["--unit [kn|m/s]", "--kinetics [steady|race]", "[BOAT]"]),
        (
            ["strategy"],
            [
                "--start-tack [starboard|port]",
                "--shift [ou|drift-diffusion]",
                "--fit-speed-unit [kn|m/s|km/h|mph]",
            ],
        ),
        (
            ["analyze"],
            [
                "--speed-unit [kn|m/s|km/h|mph]",
                "--router [isochrone|griddp|spline]",
                "COURSE TRACK...",
            ],
        ),
        (
            ["polar", "fit"],
            [
                "--speed-unit [kn|m/s|km/h|mph]",
                "--unit [kn|m/s]",
                "--reference-unit [kn|m/s|km/h|mph]",
            ],
        ),
    ],
)
def test_help_lists_the_choices(cmd, shown):
    out = runner.invoke(app, [*cmd, "--help"]).output
    for text in shown:
        assert text in out


def test_shell_completion_is_on_and_completes_choices(monkeypatch):
    out = runner.invoke(app, ["--help"]).output
    assert "--install-completion" in out and "--show-completion" in out
    monkeypatch.setenv("_SAILROUTE_COMPLETE", "complete_bash")
    monkeypatch.setenv("COMP_WORDS", "sailroute plan c.yaml --router ")
    monkeypatch.setenv("COMP_CWORD", "4")
    res = runner.invoke(app, [], prog_name="sailroute")
    assert res.output.split() == ["isochrone", "griddp", "spline"]


def test_choice_sets_match_the_code():
    from sailroute.boat.build import builtin_names
    from sailroute.commands.strategy import SHIFT_KINDS
    from sailroute.commands.vpp import UNITS
    from sailroute.routing.api import ROUTERS
    from sailroute.routing.types import SIDE_NAMES
    from sailroute.units import SPEED_UNITS

    assert get_args(cli.Router) == tuple(ROUTERS)
    assert get_args(cli.TableUnit) == UNITS
    assert get_args(cli.Shift) == SHIFT_KINDS
    assert set(get_args(cli.Tack)) == set(SIDE_NAMES) == {"port", "starboard"}
    assert set(get_args(cli.SpeedUnit)) <= set(SPEED_UNITS)
    assert cli._complete_polar("builtin:ilca7") == ["builtin:ilca7", "builtin:ilca7-steady"]
    assert len(cli._complete_polar("")) == len(builtin_names())


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["plan", WL, "--backend", "gpu"],
            "Invalid value for '--backend': 'gpu' is not one of 'numpy', 'cupy', 'auto'.",
        ),
        (
            ["strategy", "--shift", "random"],
            "Invalid value for '--shift': 'random' is not one of 'ou', 'drift-diffusion'.",
        ),
        (
            ["analyze", WL, "t.gpx", "--speed-unit", "knots"],
            "'knots' is not one of 'kn', 'm/s', 'km/h', 'mph'.",
        ),
    ],
)
def test_a_bad_choice_exits_2_naming_the_choices(tmp_path, args, message):
    res = runner.invoke(app, [*args, "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and message in res.output
    assert not (tmp_path / "o").exists()


def test_choices_ignore_case(tmp_path):
    res = runner.invoke(
        app, ["plan", WL, "-r", "ISOCHRONE", "--no-plots", "-q", "--json", "-o", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["router"] == "isochrone"


def test_json_prints_plan_json_and_nothing_else(tmp_path):
    res = runner.invoke(app, ["plan", WL, "--no-plots", "--json", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)  # stdout is the JSON document alone
    assert doc == json.loads((tmp_path / "plan.json").read_text())
    assert doc["course"] and len(doc["legs"]) == 6
    assert "leg 1/6" in res.stderr  # progress still goes to stderr


def test_compare_json_is_comparison_json(tmp_path):
    res = runner.invoke(
        app, ["compare-scenarios", WL, "--no-plots", "-q", "--json", "-o", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout) == json.loads((tmp_path / "comparison.json").read_text())


def test_wrote_lines_have_human_labels(tmp_path):
    res = runner.invoke(app, ["plan", WL, "--no-plots", "-q", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert f"wrote plan (JSON): {tmp_path / 'plan.json'}" in res.stdout
    assert f"wrote route (GPX): {tmp_path / 'route.gpx'}" in res.stdout
    assert "wrote plan:" not in res.stdout and "_json" not in res.stdout


@pytest.mark.parametrize(
    "args",
    [
        ["plan", WL],
        ["compare-scenarios", WL],
        ["vpp"],
        ["strategy"],
        ["polar", "fit", "log.csv"],
        ["analyze", WL, "track.gpx"],
    ],
)
def test_out_that_is_a_file_fails_before_any_work(tmp_path, monkeypatch, args):
    import sailroute.commands.analyze
    import sailroute.commands.polar_fit
    import sailroute.commands.strategy
    import sailroute.commands.vpp
    import sailroute.course.load

    def work(*a: object, **k: object) -> None:
        raise AssertionError("the work started before --out was checked")

    for mod, name in [
        (sailroute.course.load, "load_course"),
        (sailroute.commands.vpp, "vpp_polar"),
        (sailroute.commands.strategy, "run_strategy"),
        (sailroute.commands.polar_fit, "learn_fleet"),
        (sailroute.commands.analyze, "analyze_track"),
    ]:
        monkeypatch.setattr(mod, name, work)
    taken = tmp_path / "taken"
    taken.write_text("a file")
    res = runner.invoke(app, [*args, "--out", str(taken)])
    assert res.exit_code == 2, res.output
    assert (
        f"--out: cannot create the output folder {str(taken)!r} (a file of that name exists)"
    ) in res.output
    assert taken.read_text() == "a file"


def test_api_checks_the_default_out_before_routing(tmp_path, monkeypatch):
    import sailroute.commands.plan
    from sailroute.errors import InputError

    def route(*a: object, **k: object) -> None:
        raise AssertionError("routed before --out was checked")

    monkeypatch.setattr(sailroute.commands.plan, "plan_course", route)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").write_text("a file where out/<course>/<scenario> should go")
    with pytest.raises(InputError, match="is a file, not a folder"):
        sailroute.commands.plan.run_plan_command(WL)


def test_rerun_without_plots_removes_the_old_png_and_keeps_user_files(tmp_path):
    res = runner.invoke(app, ["plan", WL, "-q", "-o", str(tmp_path)])
    assert res.exit_code == 0 and (tmp_path / "route.png").is_file()
    (tmp_path / "my-notes.txt").write_text("mine")
    res = runner.invoke(app, ["plan", WL, "-q", "--no-plots", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        MANIFEST_NAME,
        "my-notes.txt",
        "plan.json",
        "route.gpx",
        "route.kml",
        "route.nmea",
        "track.csv",
    ]


@pytest.mark.parametrize(
    ("exc", "code"), [(RuntimeError("disk on fire"), 1), (KeyboardInterrupt(), 130)]
)
def test_a_run_that_dies_while_writing_leaves_the_previous_set(tmp_path, monkeypatch, exc, code):
    import sailroute.report.files

    out = tmp_path / "o"
    res = runner.invoke(app, ["plan", WL, "-q", "--no-plots", "-o", str(out)])
    assert res.exit_code == 0, res.output
    (out / "my-notes.txt").write_text("mine")
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def broken(path: object, plan: object) -> None:  # after plan.json and track.csv
        raise exc

    monkeypatch.setattr(sailroute.report.files, "write_gpx", broken)
    res = runner.invoke(app, ["plan", WL, "-q", "--no-plots", "-s", "veered-10deg", "-o", str(out)])
    assert res.exit_code == code, res.output
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["o"]  # no staging folder left


def test_strategy_prints_the_model_in_words(tmp_path):
    res = runner.invoke(
        app,
        [
            "strategy",
            "--length-m",
            "200",
            "--half-width-m",
            "100",
            "--runs",
            "50",
            "--sigma-deg",
            "8",
            "--timescale-min",
            "5",
            "--no-plots",
            "-q",
            "-o",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "shift model: oscillating (OU): sd 8.0°, time scale 5.0 min\n" in res.stdout
    assert "{'kind'" not in res.output and res.stderr == ""  # -q: no progress lines
    assert f"wrote summary (JSON): {tmp_path / 'summary.json'}" in res.stdout


def test_shift_model_text_drift_diffusion():
    from sailroute.report.strategy import shift_model_text
    from sailroute.strategy.shiftmodel import DriftDiffusionShift, OUShift

    assert shift_model_text(DriftDiffusionShift(0.5 / 60, 1.2 / 60**0.5)) == (
        "persistent (drift-diffusion): drift +0.50°/min, diffusion 1.20°/√min"
    )
    assert shift_model_text(OUShift(6.0, float("inf"), 2.0)) == (
        "oscillating (OU): sd 6.0°, time scale infinite (frozen wind), mean +2.0°"
    )


def test_no_heavy_imports_for_help():
    import subprocess
    import sys

    code = (
        "import sys, sailroute.cli; "
        "print(sorted(m for m in ('numpy', 'matplotlib', 'scipy', 'rich', 'pydantic') "
        "if m in sys.modules))"
    )
    res = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=Path(cli.__file__).parents[1],
    )
    assert res.stdout.strip() == "[]"
