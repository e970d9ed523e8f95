"""route.png drawn in a child process (sailroute.report.png_worker): same bytes, safe fallbacks."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from sailroute.course.load import load_course
from sailroute.planning.route import plan_course
from sailroute.report import png_worker

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def planned():
    return plan_course(load_course(ROOT / "courses" / "windward-leeward-template.yaml"))


def test_child_draws_the_same_bytes_as_in_process(planned, tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(png_worker, "_cpus", lambda: 2)
    ref = png_worker.draw_in_process(planned.plan, planned.wind, tmp_path / "ref.png", 100)
    with png_worker.start() as worker:
        assert worker.proc is not None  # a real child, not the fallback
        child = worker.proc
        got = worker.draw(planned.plan, planned.wind, tmp_path / "route.png", 100)
        assert worker.proc is None
    assert child.returncode == 0  # it answered and exited by itself
    assert got.read_bytes() == ref.read_bytes()


def test_a_failing_child_falls_back_to_drawing_here(planned, tmp_path) -> None:
    broken = subprocess.Popen(
        [sys.executable, "-c", "import sys; sys.exit(3)"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
    )
    got = png_worker.PngWorker(broken).draw(planned.plan, planned.wind, tmp_path / "r.png", 60)
    ref = png_worker.draw_in_process(planned.plan, planned.wind, tmp_path / "ref.png", 60)
    assert got.read_bytes() == ref.read_bytes()


def test_one_cpu_or_no_plots_starts_no_child(monkeypatch) -> None:
    monkeypatch.setattr(png_worker, "_cpus", lambda: 1)
    assert png_worker.start().proc is None
    monkeypatch.setattr(png_worker, "_cpus", lambda: 4)
    assert png_worker.start(enabled=False).proc is None


def test_leaving_the_block_stops_a_waiting_child(monkeypatch) -> None:
    # an error or Ctrl-C in the routing leaves the with-block: the child must not linger
    monkeypatch.setattr(png_worker, "_cpus", lambda: 2)
    with pytest.raises(KeyboardInterrupt), png_worker.start() as worker:
        child = worker.proc
        raise KeyboardInterrupt
    assert child is not None and child.poll() is not None
