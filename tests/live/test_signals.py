"""``sailroute live`` ended by SIGTERM or SIGHUP ends as Ctrl-C ends it."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.live.feed import TRIESTE, approach, trieste, write_feed


def _children(pid: int) -> set[int]:
    """Every descendant of ``pid`` now (from /proc)."""
    parent: dict[int, int] = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parent[int(d.name)] = int(fields[1])
    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        kids = [c for c, pp in parent.items() if pp == p]
        out.update(kids)
        todo.extend(kids)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_ends_the_run_cleanly(tmp_path: Path, sig: signal.Signals) -> None:
    """The run's worker processes (and multiprocessing's resource tracker) are gone after
    the signal, the log ends with its ``end`` line, the exit status is 0 and nothing is
    printed as a traceback.  SIGTERM left the workers and the tracker running and the
    log without its end."""
    feed = write_feed(tmp_path / "f.nmea", approach(trieste(), 900, speed_ms=1.0))
    log = tmp_path / "live.jsonl"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "sailroute",
            "live",
            str(TRIESTE),
            "--source",
            str(feed),
            "--boat",
            "self",
            "--scenario",
            "mean",
            "--speed",
            "3",
            "--port",
            "0",
            "--nmea-port",
            "0",
            "--log",
            str(log),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        end = time.monotonic() + 90
        while time.monotonic() < end:
            if log.exists() and '"kind":"plan"' in log.read_text():
                break
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.3)
        else:
            pytest.fail("no re-plan in 90 s")
        kids = _children(proc.pid)
        assert len(kids) >= 2  # the planner's worker processes (and the tracker)
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "re-plans:" in out
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_alive(k) for k in kids):
        time.sleep(0.2)
    assert not [k for k in kids if _alive(k)]
    last = json.loads(log.read_text().splitlines()[-1])
    assert last["kind"] == "end" and last["plans"] >= 1
