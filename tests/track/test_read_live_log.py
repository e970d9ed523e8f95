"""A ``sailroute live`` JSON-lines log read as a track: fixes, channels carried to them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.track.read import LIVE_LOG_MAX_AGE_S, read_track


def _log(path: Path, records: list[dict]) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in records), encoding="utf-8")
    return path


def test_fixes_are_the_points_and_channels_take_their_last_recent_sample(tmp_path):
    t0 = 1_700_000_000.0
    records = [{"kind": "link", "up": True, "note": "", "wall": t0}]
    for k in range(5):  # a fix every 2 s, a true wind sample 1 s after each but the last
        records.append(
            {
                "kind": "input",
                "t": t0 + 2 * k,
                "lat": 45.0 + 1e-4 * k,
                "lon": 13.0,
                "sog_ms": 3.0,
                "cog_deg": 10.0,
            }
        )
        if k < 4:
            records.append(
                {
                    "kind": "input",
                    "t": t0 + 2 * k + 1,
                    "tws_ms": 5.0 + k,
                    "twd_deg": 270.0,
                    "stw_ms": 2.9,
                }
            )
    records.append({"kind": "plan", "t": t0 + 9, "number": 1})
    track = read_track(_log(tmp_path / "race.jsonl", records))
    assert np.allclose(track.t_s, t0 + 2 * np.arange(5))
    assert np.allclose(track.lat_deg, 45.0 + 1e-4 * np.arange(5))
    # the wind sample 1 s after fix k is the last one at fix k + 1
    assert np.isnan(track.channels["tws_ms"][0])
    assert np.allclose(track.channels["tws_ms"][1:], [5.0, 6.0, 7.0, 8.0])
    assert np.allclose(track.channels["bsp_ms"][1:], 2.9)  # speed through the water
    assert track.name == "race"


def test_a_channel_older_than_the_limit_is_missing(tmp_path):
    t0 = 1_700_000_000.0
    old = LIVE_LOG_MAX_AGE_S + 1.0
    records = [
        {"kind": "input", "t": t0, "tws_ms": 6.0, "twd_deg": 200.0},
        {"kind": "input", "t": t0 + 1.0, "lat": 45.0, "lon": 13.0},
        {"kind": "input", "t": t0 + old, "lat": 45.001, "lon": 13.0},
    ]
    track = read_track(_log(tmp_path / "a.jsonl", records))
    assert track.channels["tws_ms"][0] == 6.0 and np.isnan(track.channels["tws_ms"][1])


@pytest.mark.parametrize(
    ("lines", "message"),
    [
        (
            ['{"kind": "input", "t": 1.0, "lat": 45.0, "lon": 13.0}', "not json"],
            r"b\.jsonl: line 2: not a JSON object",
        ),
        (['{"kind": "input", "lat": 45.0, "lon": 13.0}'], r"line 1: an input sample needs a time"),
        (
            ['{"kind": "input", "t": 1.0, "tws_ms": 5.0}'],
            r"no position fix in this .* log \(1 input samples\)",
        ),
    ],
)
def test_bad_live_logs_name_the_file_and_line(tmp_path, lines, message):
    path = tmp_path / "b.jsonl"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=message):
        read_track(path)
