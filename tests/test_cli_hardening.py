"""Commands and output folders under hostile or careless input: names that would be paths
outside ``--out``, manifest entries through symbolic links, routing settings that would
not finish, the default folder of another router, and the ignored output folders."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.errors import InputError
from sailroute.outdir import MANIFEST_NAME, path_part_problem, safe_part, write_output_set
from tests.conftest import ROOT

runner = CliRunner()

COURSE = """\
name: small
start_time: "2024-06-01T14:00:00+02:00"
template:
  type: windward-leeward
  centre: {{lat: 43.069067, lon: 6.198550}}
  twd_deg: 270
  leg_length_m: {length}
  laps: 1
  gate_width_m: 50
  start_line_length_m: 100
  finish: leeward
boat: {{builtin: ilca7}}
routing: {routing}
scenarios:
  {name}: {{type: uniform, tws_kn: 12, twd_deg: 270}}
"""


def course(
    tmp_path: Path,
    name: str = "steady",
    routing: str = "{}",
    length: float = 300,
    stem: str = "small",
) -> Path:
    p = tmp_path / f"{stem}.yaml"
    p.write_text(COURSE.format(name=json.dumps(name), routing=routing, length=length))
    return p


# --- names that would be paths (scenarios) --------------------------------------------


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("../../escaped-plan", "it starts with '.' (a hidden or parent folder)"),
        ("/tmp/escaped-plan", "it contains '/' (a path separator or a control character)"),
        ("a\\b", "it contains '\\\\' (a path separator or a control character)"),
        ("..", "it starts with '.'"),
        ("c:x", "it contains ':'"),
    ],
)
@pytest.mark.parametrize("command", ["compare-scenarios", "plan"])
def test_a_scenario_name_that_is_a_path_is_refused_at_load(
    tmp_path, monkeypatch, name, why, command
):
    work = tmp_path / "a" / "b" / "c"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)  # plan's default folder out/<stem>/<scenario> is relative
    path = course(work, name)
    args = [command, str(path), "-q", "--no-plots"]
    if command == "compare-scenarios":
        args += ["-o", str(work / "o")]
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    assert (
        f"scenarios.{name}: the scenario name {name!r} cannot name an output folder: {why}"
    ) in res.output
    written = sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*"))
    assert written == ["a", "a/b", "a/b/c", "a/b/c/small.yaml"]  # nothing anywhere else


def test_path_part_rule():
    for ok in ("steady-12kn", "wrf10", "veered 10°", "ens#3", "Ω"):
        assert path_part_problem(ok) is None and safe_part(ok, "scenario") == ok
    for bad in ("", ".", "..", ".hidden", "a/b", "/abs", "a\\b", "a\0b", "a\nb", "C:", "x" * 101):
        assert path_part_problem(bad) is not None
    with pytest.raises(
        InputError,
        match=r"scenario '\.\./x' cannot name a folder of the "
        r"output: it starts with '\.'",
    ):
        safe_part("../x", "scenario")


def test_plan_scenario_option_cannot_climb_out_of_out(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(
        app, ["plan", str(course(tmp_path)), "-s", "../../../x", "-q", "--no-plots"]
    )
    assert res.exit_code == 2, res.output
    assert "scenario '../../../x' cannot name a folder of the output" in res.output
    assert not (tmp_path / "out").exists() and not (tmp_path.parent / "x").exists()


# --- symbolic links inside the output folder ------------------------------------------


def _outside_and_link(tmp_path: Path) -> tuple[Path, Path]:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "v2.txt").write_text("not sailroute's")
    out = tmp_path / "out"
    out.mkdir()
    (out / "linkdir").symlink_to(outside, target_is_directory=True)
    return out, outside


def test_removal_does_not_follow_a_symlink_out_of_the_folder(tmp_path):
    out, outside = _outside_and_link(tmp_path)
    (out / MANIFEST_NAME).write_text(json.dumps({"files": ["linkdir/v2.txt", "old.txt"]}))
    (out / "old.txt").write_text("ours")

    def write(d: Path) -> Path:
        (d / "new.txt").write_text("x")
        return d / "new.txt"

    write_output_set(out, write)
    assert (outside / "v2.txt").read_text() == "not sailroute's"  # was deleted
    assert (out / "linkdir").is_symlink() and not (out / "old.txt").exists()
    assert json.loads((out / MANIFEST_NAME).read_text())["files"] == ["new.txt"]


def test_no_file_is_written_through_a_symlinked_folder(tmp_path):
    out, outside = _outside_and_link(tmp_path)

    def write(d: Path) -> Path:
        (d / "linkdir").mkdir()
        (d / "linkdir" / "v2.txt").write_text("overwritten")
        return d / "linkdir" / "v2.txt"

    with pytest.raises(
        InputError,
        match=r"cannot write 'linkdir/v2.txt' into .*: .*linkdir' "
        r"is a symbolic link or a file, and sailroute writes only inside",
    ):
        write_output_set(out, write)
    assert (outside / "v2.txt").read_text() == "not sailroute's"
    assert sorted(p.name for p in out.iterdir()) == ["linkdir"]  # no staging folder left


# --- the default folder names a non-default router ------------------------------------


def test_griddp_run_does_not_replace_the_isochrone_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = course(tmp_path)
    for extra in ([], ["-r", "griddp"], ["-r", "isochrone"]):
        res = runner.invoke(app, ["plan", str(path), "-q", "--no-plots", *extra])
        assert res.exit_code == 0, res.output
    iso = json.loads((tmp_path / "out/small/steady/plan.json").read_text())
    dp = json.loads((tmp_path / "out/small/steady-griddp/plan.json").read_text())
    assert (iso["router"], dp["router"]) == ("isochrone", "griddp")
    assert sorted(p.name for p in (tmp_path / "out/small").iterdir()) == [
        "steady",
        "steady-griddp",
    ]  # -r isochrone is the course's router: no suffix


def test_usage_documents_the_router_folder():
    text = (ROOT / "docs" / "usage.md").read_text()
    assert "`out/<course file stem>/<scenario>-<router>`" in text


# --- routing settings that would not finish -------------------------------------------


@pytest.mark.parametrize(
    ("routing", "message"),
    [
        (
            "{dt_s: 1e-9}",
            "routing.dt_s: expected a time step >= 0.5 s (default 10; finer steps "
            "hardly change the route and make it slow); got 1e-09",
        ),
        ("{dt_s: 0.05}", "routing.dt_s: expected a time step >= 0.5 s"),
        (
            "{heading_step_deg: 1e-9}",
            "routing.heading_step_deg: expected a number in [0.1, 45] "
            "(default 2; finer steps only slow the router); got 1e-09",
        ),
        ("{heading_step_deg: 1e-4}", "routing.heading_step_deg: expected a number in [0.1, 45]"),
        ("{min_dt_s: 1e-9}", "routing.min_dt_s: min_dt_s must be >= 0.01 s (default 1)"),
        (
            "{max_front_points: 1000000000}",
            "routing.max_front_points: max_front_points must be an integer in [8, 100000]",
        ),
        (
            "{router: griddp, dp_cols: 1024, dp_rows: 200, dp_samples: 64, dp_refinements: 20}",
            "routing.dp_cols: dp_cols = 1024 with dp_rows = 200, dp_samples = 64 and "
            "dp_refinements = 20 needs about 2.8e+11 wind samples per leg (rows x cols^2 x "
            "samples x passes), more than 2e+08 (minutes of work)",
        ),
        (
            "{router: spline, spline_cols: 1000, spline_slopes: 1000}",
            "routing.spline_cols: spline_cols = 1000 with spline_slopes = 1000 needs 1.0e+12 "
            "edges between two rows and 4.8e+13 per leg, more than 2e+07 and 2e+09 (memory and "
            "minutes of work)",
        ),
    ],
)
def test_routing_settings_that_would_not_finish_are_refused(tmp_path, routing, message):
    res = runner.invoke(
        app,
        [
            "plan",
            str(course(tmp_path, routing=routing)),
            "-q",
            "--no-plots",
            "-o",
            str(tmp_path / "o"),
        ],
    )
    assert res.exit_code == 2, res.output
    assert message in res.output
    assert not (tmp_path / "o").exists()


def test_leg_work_is_estimated_before_routing(tmp_path):
    # within the ranges, but 0.5 s steps at 0.1 deg over an 8 km beat: ~2e10 moves
    res = runner.invoke(
        app,
        [
            "plan",
            str(course(tmp_path, routing="{dt_s: 0.5, heading_step_deg: 0.1}", length=8000)),
            "-q",
            "--no-plots",
            "-o",
            str(tmp_path / "o"),
        ],
    )
    assert res.exit_code == 2, res.output
    assert (
        "leg start -> 1: routing.dt_s = 0.5 s with routing.heading_step_deg = 0.1 needs about"
    ) in res.output
    assert "more than 1e+10 (minutes of work per leg); use routing.dt_s >= " in res.output
    assert not (tmp_path / "o").exists()


def test_grid_dp_and_spline_work_limits_pass_the_shipped_settings():
    from sailroute.routing.settings import routing_settings, settings_problems

    for kw in (
        {},
        {"dp_cols": 128, "dp_rows": 30, "dp_samples": 1, "dp_refinements": 0},
        {"dp_cols": 128},
        {"dp_cols": 1024},
        {"spline_refinements": 3},
    ):
        assert settings_problems(routing_settings(**kw)) == []


def test_leg_work_estimate_passes_the_defaults():
    from sailroute.routing.isochrone import MAX_LEG_WORK, leg_work
    from sailroute.routing.settings import RoutingSettings

    # a 1 h leg at the defaults: 360 steps of 2 x 726 points x 94 angles
    steps, per_step = leg_work(RoutingSettings(), 726, 90, 3600.0)
    assert steps == 360 and per_step == 726 * 2 * 94
    assert steps * per_step < MAX_LEG_WORK / 100


# --- output folders of the commands are not committed ---------------------------------


def test_default_output_folders_are_git_ignored():
    lines = (ROOT / ".gitignore").read_text().splitlines()
    for folder in ("out/", "vpp-out/", "strategy-out/", "polar-fit-out/"):
        assert folder in lines


# --- strategy: option names, work estimate, one rule for a wind above the polar -------


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["--runs", "0"],
            "--runs 0: expected a whole number of Monte Carlo runs in 1..1,000,000 (default 4000)",
        ),
        (
            ["--workers", "0", "--scheduler", "processes"],
            "--workers 0: expected a whole number >= 1 of worker processes",
        ),
        (["--length-m", "0"], "--length-m 0: must be finite and > 0 m"),
        (
            ["--length-m", "1605"],
            "--length-m 1605: expected a whole number (>= 1) of 10 m rows, e.g. 1600",
        ),
        (["--half-width-m", "-1"], "--half-width-m -1: must be finite and > 0 m"),
        (["--tack-penalty-s", "-1"], "--tack-penalty-s -1.0: must be finite and >= 0"),
        (["--sigma-deg", "-1"], "--sigma-deg -1.0: must be finite and >= 0"),
        # the work, estimated before solving (1e9 m asked for 22 TiB)
        (
            ["--length-m", "1e9", "--runs", "10"],
            "--length-m 1e+09 with --half-width-m 800: the expected-time lattice would have 3e+12 "
            "nodes",
        ),
        (["--length-m", "100000"], "give a beat of at most 32840 m at this width"),
        (
            ["--runs", "1000000"],
            "--runs 1000000 over 160 rows of --length-m 1600: 1.6e+08 Monte "
            "Carlo boat-steps per policy, more than 5e+07; use --runs <= 312500",
        ),
        # the polar ends at 28 kn: clamped silently before, an error as in plan now
        (
            ["--tws-kn", "100"],
            "--tws-kn 100: above the highest TWS column of --polar "
            "builtin:ilca7 (TWS 1.0 .. 28.0 kn); the boat speed would be clamped to that column "
            "without notice. Give --tws-kn up to 28.0, or a --polar with higher TWS columns",
        ),
    ],
)
def test_strategy_errors_name_the_options(tmp_path, monkeypatch, args, message):
    import sailroute.commands.strategy

    def solve(*a: object, **k: object) -> None:
        raise AssertionError("solving started")

    # on the name the command calls: patching sailroute.strategy.study would miss it once
    # the command module is imported, and bind the stand-in for good when it is imported
    # first here (the next test then saw "solving started")
    monkeypatch.setattr(sailroute.commands.strategy, "run_strategy", solve)
    res = runner.invoke(app, ["strategy", *args, "-q", "--no-plots", "-o", str(tmp_path / "o")])
    assert res.exit_code == 2, res.output
    assert res.output.startswith("error: --") and message in res.output
    assert len(res.output.strip().splitlines()) == 1
    for internal in ("runs =", "n_workers", "length_m", "beat grid", "tack penalty"):
        assert internal not in res.output
    assert not (tmp_path / "o").exists()


def test_strategy_wind_within_the_polar_runs(tmp_path):
    res = runner.invoke(
        app,
        [
            "strategy",
            "--tws-kn",
            "28",
            "--length-m",
            "200",
            "--half-width-m",
            "100",
            "--runs",
            "20",
            "-q",
            "--no-plots",
            "-o",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    assert json.loads((tmp_path / "summary.json").read_text())["boat"]["tws_kn"] == 28.0


# --- polar fit: option names ------------------------------------------------------------


def _log(tmp_path: Path) -> Path:
    # 10 minutes east at 5 kn, the wind 10 kn from the north: steady reaching
    log = tmp_path / "log.csv"
    rows = [
        f"2023-01-01T00:{k // 60:02d}:{k % 60:02d}Z,59.5,{24.8 + k * 4.5e-5:.6f},10,0"
        for k in range(600)
    ]
    log.write_text("time,lat,lon,tws_kn,twd_deg\n" + "\n".join(rows) + "\n")
    return log


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--percentile", "0"], "error: --percentile must be in (0, 100], e.g. 50; got 0.0"),
        (["--min-blocks", "0"], "error: --min-blocks must be a whole number >= 1; got 0"),
        (["--min-blocks", "100000"], "or lower --min-boats / --min-blocks"),
        (
            ["--min-blocks", "100000"],
            "(fewer TWS nodes: --tws-bins, a larger TWA step: --twa-step)",
        ),
    ],
)
def test_polar_fit_errors_name_the_options(tmp_path, args, message):
    res = runner.invoke(  # -q: the error alone, without the boat counted before it
        app, ["polar", "fit", str(_log(tmp_path)), *args, "-q", "-o", str(tmp_path / "o")]
    )
    assert res.exit_code == 2, res.output
    assert message in res.output and "learn_polar" not in res.output
    assert "min_blocks" not in res.output and len(res.output.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


# --- Ctrl-C at any point: one line, exit 130 ------------------------------------------

INTERRUPT_DURING_IMPORT = """\
import builtins, sys
real = builtins.__import__
def interrupted_import(name, *args, **kwargs):
    if name == {module!r}:
        raise KeyboardInterrupt
    return real(name, *args, **kwargs)
builtins.__import__ = interrupted_import
sys.argv = ["sailroute", *{args!r}]
from sailroute.__main__ import main
main()
"""


@pytest.mark.parametrize(
    ("module", "args"),
    [
        ("typer", ["--help"]),  # while the command line itself is imported
        ("sailroute.planning.route", ["plan", "c.yaml"]),  # while a command imports its modules
    ],
)
def test_ctrl_c_during_start_up_is_one_line_and_130(tmp_path, module, args):
    import subprocess
    import sys

    code = INTERRUPT_DURING_IMPORT.format(module=module, args=args)
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60
    )
    assert (res.returncode, res.stderr) == (130, "interrupted\n")


def test_ctrl_c_outside_the_work_is_reported_too(tmp_path, monkeypatch):
    import sailroute.cli

    def interrupted(*a: object, **k: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(sailroute.cli, "_finish", interrupted)  # typer exited 130 silently
    res = runner.invoke(
        app, ["plan", str(course(tmp_path)), "-q", "--no-plots", "-o", str(tmp_path / "o")]
    )
    assert res.exit_code == 130 and res.output == "interrupted\n"


def test_the_process_ends_with_its_objects_frozen_out_of_the_last_collections(monkeypatch):
    """``main`` freezes the heap as it returns (the interpreter's shutdown then does not
    traverse numba's registries), whatever way the command ends."""
    import gc
    import sys

    from sailroute.__main__ import main

    monkeypatch.setattr(sys, "argv", ["sailroute", "--help"])
    gc.unfreeze()
    assert gc.get_freeze_count() == 0
    try:
        with pytest.raises(SystemExit) as ended:
            main()
        assert ended.value.code == 0 and gc.get_freeze_count() > 1000
    finally:
        gc.unfreeze()


PROGRESS_LINE = re.compile(r"leg \d+/\d+ .+: (routing\.\.\.|.+ \(computed in .+ s\))")


@pytest.mark.cli
def test_sigint_while_routing_is_one_line_and_130(tmp_path):
    """Ctrl-C in the middle of a plan: the one line ``interrupted``, exit 130, no files.

    The signal goes when the first leg's progress line is on stderr: the process is then
    routing, whatever the load of the machine (a fixed delay could land in the
    interpreter's start-up, before the Ctrl-C guard, or after the work).  Fine routing
    settings keep the legs routing for many seconds of CPU, so the work cannot end first.
    """
    import shutil
    import signal
    import subprocess
    import sys

    exe = shutil.which("sailroute", path=str(Path(sys.executable).parent))
    assert exe is not None
    slow = course(tmp_path, routing="{dt_s: 0.5, heading_step_deg: 0.5}", length=2000)
    proc = subprocess.Popen(
        [exe, "plan", str(slow), "-o", str(tmp_path / "o")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    first = proc.stderr.readline()  # blocks until the first leg starts (or the end)
    assert first == "leg 1/2 start -> 1: routing...\n", first
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    *progress, last = (first + err).splitlines(keepends=True)
    assert (proc.returncode, last, out) == (130, "interrupted\n", "")
    assert all(PROGRESS_LINE.fullmatch(line.rstrip("\n")) for line in progress), progress
    assert not (tmp_path / "o").exists()
