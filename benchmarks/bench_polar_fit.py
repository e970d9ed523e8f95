"""Polar fitting: sailroute's ``fit_polar`` vs hrosailing's ``PolarPipeline`` on real logs.

Fits the Tallinn 2023 instrument log (reference: the boat's ORC speed guide) and the SailGP
NZL log (reference: the F50 polar) with both tools, on the same filtered-free input arrays
(TWS, |TWA|, boat speed), and reports the RMS error vs the reference polar on sailroute's
covered cells and the wall time of each, measured in the same run (both warm: each
tool's modules are imported before its timed call).

Usage::

    .venv/bin/python benchmarks/bench_polar_fit.py [--smoke]

``--smoke``: the Tallinn log only, without hrosailing (checks the script runs).

Needs ``../shared/data/real`` (the NZL log and F50 polar have no stated licence: read in
place; without it the script says so and exits with code 0) and ``pip install hrosailing``
(extra ``bench``).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from sailroute.boat.fit import fit_polar
from sailroute.boat.fit_samples import (
    auto_tws_bins,
    compare_polars,
    samples_from_log,
)
from sailroute.boat.io import read_polar
from sailroute.boat.polar import fold_twa
from sailroute.commands.vpp import twa_grid
from sailroute.track.read import read_track
from sailroute.units import KNOT

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "real"
TALLINN = SHARED / "races" / "tallinn-wednesday-races-2023"


def cases(tmp: Path) -> list[tuple[str, Path, dict, Path, str | None, int]]:
    orc = TALLINN / "ORC_Speed_Guide_Ref_04340002PIL.csv"  # read as published (BTV)
    return [
        (
            "Tallinn 2023 vs ORC guide",
            TALLINN / "kolmak_2023_09_27.csv",
            {"speed_unit": "kn"},
            orc,
            None,
            10,
        ),
        (
            "SailGP NZL vs F50 polar",
            SHARED / "races" / "sailgp-auckland-2025" / "Boat_logs" / "data_NZL.csv",
            {"time_zone": "UTC"},
            SHARED / "polars" / "sailgp-f50" / "2502_m8_APW_HSB2_HSRW.kph.csv",
            "km/h",
            20,
        ),
    ]


def import_hrosailing():
    """hrosailing's pipeline and array handler modules, imported outside the timed region
    (sailroute's own modules are imported at the top of this script, so both tools are
    timed warm)."""
    if not hasattr(np, "float_"):  # hrosailing 0.12 still uses np.float_ (NumPy < 2)
        setattr(np, "float_", np.float64)  # noqa: B010
    import hrosailing.pipeline as pl
    from hrosailing.processing.datahandler import ArrayHandler

    return pl, ArrayHandler


def hrosailing_fit(t_s: np.ndarray, tws_kn: np.ndarray, twa: np.ndarray, bsp_kn: np.ndarray):
    """hrosailing's default pipeline on (TWS, TWA, BSP) in knots; returns a speed function."""
    from datetime import UTC, datetime

    pl, ArrayHandler = import_hrosailing()
    stamps = [datetime.fromtimestamp(float(x), UTC) for x in t_s]
    arr = np.array(
        [[d, w, a, b] for d, w, a, b in zip(stamps, tws_kn, twa, bsp_kn, strict=True)], dtype=object
    )
    pipeline = pl.PolarPipeline(data_handler=ArrayHandler())
    out = pipeline([(arr, ["datetime", "TWS", "TWA", "BSP"])])
    polar = out.polardiagram if hasattr(out, "polardiagram") else out.polar_diagram

    def speed(tws: np.ndarray, a: np.ndarray) -> np.ndarray:
        return np.array([float(polar(float(w), float(b))) for w, b in zip(tws, a, strict=True)])

    return speed


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="the Tallinn log only, without hrosailing (checks the script runs)",
    )
    args = ap.parse_args()
    if not SHARED.is_dir():
        print(
            f"bench_polar_fit.py: {SHARED} not present (the logs are read in place): "
            "nothing measured"
        )
        sys.exit(0)
    print(
        f"command: python {' '.join(sys.argv)}; load average (1, 5, 15 min): "
        f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}"
    )
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        rows = []
        for label, log, opts, ref_path, ref_unit, min_count in cases(tmp)[
            : 1 if args.smoke else None
        ]:
            ref = read_polar(ref_path, speed_unit=ref_unit, wind_unit=ref_unit)
            s = samples_from_log(read_track(log, **opts))
            for _ in range(2):  # the first call imports scipy.stats: time the second
                t0 = time.perf_counter()
                fit = fit_polar(
                    s.tws_ms,
                    s.twa_deg,
                    s.bsp_ms,
                    s.t_s,
                    tws_bins_ms=auto_tws_bins(s.tws_ms, 2 * KNOT),
                    twa_bins_deg=twa_grid(10.0),
                    heading_deg=s.heading_deg,
                    min_count=min_count,
                )
            t_ours = time.perf_counter() - t0
            err = compare_polars(fit.polar, fit.covered, ref)
            p = fit.polar
            cov = fit.covered
            ii, jj = np.nonzero(cov)
            tws_c, twa_c = p.tws_ms[jj], p.twa_deg[ii]
            inside = (
                (twa_c >= ref.twa_deg[0])
                & (twa_c <= ref.twa_deg[-1])
                & (tws_c >= ref.tws_ms[0])
                & (tws_c <= ref.tws_ms[-1])
            )
            tws_c, twa_c = tws_c[inside], twa_c[inside]
            r_ref = ref.speed(tws_c, twa_c)
            ok = np.isfinite(s.tws_ms) & np.isfinite(s.twa_deg) & np.isfinite(s.bsp_ms)
            try:
                if args.smoke:
                    raise RuntimeError("not run (--smoke)")
                import_hrosailing()  # the import (seconds) is not part of the fit's time
                t0 = time.perf_counter()
                spd = hrosailing_fit(
                    s.t_s[ok], s.tws_ms[ok] / KNOT, fold_twa(s.twa_deg[ok]), s.bsp_ms[ok] / KNOT
                )
                h = spd(tws_c / KNOT, twa_c) * KNOT
                t_hro = time.perf_counter() - t0
                rms_hro = float(np.sqrt(np.mean((h / r_ref - 1) ** 2)) * 100)
                hro = f"{rms_hro:6.1f} % {t_hro:8.3f} s"
            except Exception as exc:  # report what happened, keep the other case
                t_hro, hro = float("nan"), f"failed: {type(exc).__name__}: {exc}"[:120]
            rows.append((label, err.rms_pct, t_ours, hro, t_hro / t_ours, err.n_cells))
        print(
            f"{'log':<28}{'cells':>6}{'ours RMS':>10}{'ours time':>11}   hrosailing RMS, time"
            "   time ratio hro/ours"
        )
        for label, rms, t, hro, ratio, n in rows:
            print(f"{label:<28}{n:>6}{rms:>8.1f} %{t:>9.3f} s   {hro}   {ratio:.1f}x")


if __name__ == "__main__":
    main()
