"""Serial and Dask task maps (sailroute.parallel) and distributed Monte Carlo.

The cluster tests start one local cluster for the module (two worker processes
on 127.0.0.1) and are skipped when dask.distributed is not installed.
"""

from __future__ import annotations

import io
import re
import sys

import numpy as np
import pytest

from sailroute.boat.build import builtin_polar
from sailroute.commands.strategy import run_strategy_command
from sailroute.errors import InputError
from sailroute.parallel import (
    INSTALL_HINT,
    TaskRunner,
    check_scheduler,
    map_tasks,
    open_runner,
)
from sailroute.progress import Progress
from sailroute.strategy.montecarlo import CHUNK_SIZE, chunk_rng, simulate
from sailroute.strategy.shiftmodel import OUShift
from sailroute.strategy.study import StrategySettings, run_strategy

ITEMS = [7, 3, 11, 0, 5, 2, 9]
SQUARES = [49, 9, 121, 0, 25, 4, 81]
SMALL_STUDY = StrategySettings(
    length_m=400.0,
    half_width_m=200.0,
    lateral_m=4.0,
    runs=CHUNK_SIZE + 500,  # one full chunk and a partial one
    deadlines_s=(200.0,),
    n_r=30,
    n_theta=32,
)


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=":0",
    ) as c:
        yield c


@pytest.fixture(scope="module")
def serial_study():
    return run_strategy(builtin_polar("ilca7"), OUShift(10.0, 600.0), SMALL_STUDY)


# --- serial and argument checks (no Dask needed) ----------------------------------------


@pytest.mark.parametrize("scheduler", [None, "serial", " Serial "])
def test_serial_map_keeps_input_order(scheduler) -> None:
    assert map_tasks(pow, ITEMS, shared=(2,), scheduler=scheduler) == SQUARES
    assert map_tasks(pow, [], shared=(2,), scheduler=scheduler) == []


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        (None, "serial"),
        ("PROCESSES", "processes"),
        ("tcp://10.0.0.5:8786", "tcp://10.0.0.5:8786"),
        (" 10.0.0.5:8786 ", "10.0.0.5:8786"),
        ("tls://[::1]:8786", "tls://[::1]:8786"),
    ],
)
def test_scheduler_names_are_normalised(given, expected) -> None:
    assert check_scheduler(given) == expected


@pytest.mark.parametrize(
    "bad", ["", "local", "threads", "tcp://", "host:port", "http://h:8787", "ucx://h:1", 8786]
)
def test_unknown_scheduler_lists_the_choices(bad) -> None:
    with pytest.raises(InputError, match=r"expected 'serial', 'processes' or a scheduler addr"):
        map_tasks(pow, [1], shared=(2,), scheduler=bad)


@pytest.mark.parametrize("n", [0, -2, 1.5, True])
def test_worker_count_is_checked(n) -> None:
    with pytest.raises(InputError, match=r"n_workers .* whole number >= 1"):
        map_tasks(pow, [1], shared=(2,), scheduler="processes", n_workers=n)


def test_without_dask_serial_works_and_a_cluster_asks_to_install(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    assert map_tasks(pow, ITEMS, shared=(2,)) == SQUARES
    for scheduler in ("processes", "tcp://127.0.0.1:8786"):
        with pytest.raises(InputError, match=re.escape(INSTALL_HINT)):
            map_tasks(pow, [1], shared=(2,), scheduler=scheduler)


def test_strategy_command_rejects_a_bad_scheduler_before_solving(tmp_path) -> None:
    with pytest.raises(InputError, match="scheduler 'nowhere'"):
        run_strategy_command(scheduler="nowhere", out_dir=tmp_path, plots=False)
    assert not any(tmp_path.iterdir())


# --- Dask ------------------------------------------------------------------------------


def test_processes_scheduler_equals_serial() -> None:
    pytest.importorskip("distributed")
    got = map_tasks(pow, ITEMS, shared=(2,), scheduler="processes", n_workers=2)
    assert got == SQUARES


def _sigint_handler(_item: int) -> str:
    import signal

    return repr(signal.getsignal(signal.SIGINT))


def test_ctrl_c_reaches_only_the_parent_of_a_local_cluster() -> None:
    # A terminal's Ctrl-C goes to the whole process group: the local workers must ignore
    # it (they printed five Dask tracebacks), the parent keeps its own handler and stops
    # the run as the serial run does
    import signal

    pytest.importorskip("distributed")
    before = signal.getsignal(signal.SIGINT)
    with open_runner("processes", n_workers=1) as runner:
        assert signal.getsignal(signal.SIGINT) is before
        got = runner.map(_sigint_handler, [0])
    assert got == [repr(signal.SIG_IGN)]
    assert signal.getsignal(signal.SIGINT) is before


def test_explicit_address_equals_serial_and_runner_is_reusable(cluster) -> None:
    assert map_tasks(pow, ITEMS, shared=(3,), scheduler=cluster.scheduler_address) == [
        v**3 for v in ITEMS
    ]
    with open_runner(cluster.scheduler_address) as runner:
        assert isinstance(runner, TaskRunner) and runner.client is not None
        assert runner.description == cluster.scheduler_address
        assert map_tasks(pow, ITEMS, shared=(2,), scheduler=runner) == SQUARES
        assert map_tasks(divmod, ITEMS, shared=(4,), scheduler=runner) == [
            divmod(v, 4) for v in ITEMS
        ]


def test_task_errors_come_back_as_input_errors(cluster) -> None:
    with pytest.raises(InputError, match="chunk index -1 must be >= 0"):
        map_tasks(chunk_rng, [1], shared=(-1,), scheduler=cluster.scheduler_address)


def test_unreachable_scheduler_says_how_to_fix_it() -> None:
    pytest.importorskip("distributed")
    address = "tcp://127.0.0.1:1"  # privileged port: nothing listens there
    with pytest.raises(InputError) as err:
        map_tasks(pow, [1], shared=(2,), scheduler=address, timeout_s=0.5)
    msg = str(err.value)
    assert address in msg
    assert "dask scheduler" in msg and f"dask worker {address}" in msg


def test_scheduler_without_workers_is_reported_not_waited_for() -> None:
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=0, processes=True, host="127.0.0.1", dashboard_address=":0"
        ) as empty,
        pytest.raises(InputError, match="has no workers") as err,
    ):
        map_tasks(pow, [1], shared=(2,), scheduler=empty.scheduler_address, timeout_s=0.5)
    assert f"dask worker {empty.scheduler_address}" in str(err.value)


def test_monte_carlo_on_a_cluster_is_bit_identical(cluster, serial_study) -> None:
    dist = run_strategy(
        builtin_polar("ilca7"),
        OUShift(10.0, 600.0),
        SMALL_STUDY,
        scheduler=cluster.scheduler_address,
    )
    a, b = serial_study.sim, dist.sim
    assert a.n_runs == b.n_runs == SMALL_STUDY.runs
    for name in ("leg_time_s", "n_tacks", "x_m", "t_s", "theta_deg"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    da, db = serial_study.deadline, dist.deadline
    assert np.array_equal(da.sim_rn.leg_time_s, db.sim_rn.leg_time_s)
    assert np.array_equal(da.sim_rn.tracks_xy_m, db.sim_rn.tracks_xy_m, equal_nan=True)
    for d in SMALL_STUDY.deadlines_s:
        assert np.array_equal(da.sims_ra[d].leg_time_s, db.sims_ra[d].leg_time_s)
        assert np.array_equal(da.sims_ra[d].fell_back, db.sims_ra[d].fell_back)
    key = "expected_time_policy"
    assert serial_study.summary[key]["monte_carlo"] == dist.summary[key]["monte_carlo"]
    assert serial_study.summary["deadline"]["risk_aware"] == dist.summary["deadline"]["risk_aware"]


def test_partial_chunks_and_seeds_do_not_depend_on_the_scheduler(cluster, serial_study) -> None:
    pol = serial_study.policy
    with open_runner(cluster.scheduler_address) as runner:
        for n_runs, seed in ((CHUNK_SIZE - 1, 3), (2 * CHUNK_SIZE + 1, 4)):
            serial = simulate(pol, n_runs, seed, tack0=-1)
            dist = simulate(pol, n_runs, seed, tack0=-1, scheduler=runner)
            assert dist.leg_time_s.shape == (n_runs,)
            assert np.array_equal(serial.leg_time_s, dist.leg_time_s)
            assert np.array_equal(serial.n_tacks, dist.n_tacks)


def test_compare_scenarios_on_a_cluster_equals_serial(cluster) -> None:
    """Each scenario is one task; leg times and whole tracks come back bit-identical."""
    from pathlib import Path

    from sailroute.course.load import load_course
    from sailroute.planning.route import RunOptions, compare_scenarios

    course = load_course(
        Path(__file__).resolve().parents[1] / "courses" / "windward-leeward-template.yaml"
    )
    serial_cmp, serial_plans = compare_scenarios(course)
    stream = io.StringIO()
    dist_cmp, dist_plans = compare_scenarios(
        course,
        options=RunOptions(
            scheduler=cluster.scheduler_address, progress=Progress(course.n_legs, stream)
        ),
    )
    assert dist_cmp.scenarios == serial_cmp.scenarios == ("steady-12kn", "veered-10deg")
    # a line per scenario as it comes back, with its race time
    lines = stream.getvalue().splitlines()
    assert [line.split(" (")[0] for line in lines] == [
        "scenario 1 of 2 done",
        "scenario 2 of 2 done",
    ]
    totals = {p.scenario: f"{p.total_time_s:.1f} s" for p in serial_plans}
    assert {line.split("(")[1].split(")")[0] for line in lines} == {
        f"{n}, {t}" for n, t in totals.items()
    }
    np.testing.assert_array_equal(dist_cmp.times, serial_cmp.times)
    for a, b in zip(serial_plans, dist_plans, strict=True):
        for ra, rb in zip(a.results, b.results, strict=True):
            np.testing.assert_array_equal(ra.track.x, rb.track.x)
            np.testing.assert_array_equal(ra.track.t, rb.track.t)


def test_each_task_is_reported_as_it_finishes(cluster) -> None:
    # on_done(index, result) once per task, serially in order and on a cluster in any
    # order, for a progress line per finished task
    for scheduler in (None, cluster.scheduler_address):
        seen: list[tuple[int, int]] = []
        got = map_tasks(pow, ITEMS, shared=(2,), scheduler=scheduler, on_done=_recorder(seen))
        assert got == SQUARES
        assert sorted(seen) == list(enumerate(SQUARES))


def _recorder(seen: list[tuple[int, int]]):
    return lambda k, r: seen.append((k, r))
