"""Seeded Monte Carlo evaluation of an expected-time policy on its lattice.

Runs are simulated in chunks of a fixed size; chunk ``k`` draws from
``Generator(PCG64(SeedSequence(seed, spawn_key=(k,))))``, which is the same
stream as ``SeedSequence(seed).spawn(k + 1)[k]``.  Results therefore do not
depend on how the chunks are scheduled (serially, or over Dask with
``scheduler=``, see :mod:`sailroute.parallel`) nor on the number of workers:
:func:`simulate` is exactly the concatenation of :func:`simulate_chunk` for
chunks ``0, 1, ...``, truncated to ``n_runs``; a smaller ``n_runs`` gives a
prefix of a larger one.

Each run starts on the first row at ``(x0, tack0, θ0)``.  At every row it
looks up the policy's segment, adds the segment time (and ``λ`` if it tacks),
and draws the next shift bin from the segment's transition row (by default the
chain the policy was optimised for; pass ``transitions`` from another model to
evaluate a mismatched policy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError
from sailroute.parallel import TaskRunner, map_tasks
from sailroute.strategy.sdp import TACKS, ExpectedTimePolicy

CHUNK_SIZE = 1000
"""Runs per chunk; part of the definition of the random stream for a seed."""
BAND_PERCENTILES = (10, 30, 50, 70, 90)
"""Percentiles of the lateral-position bands [%]."""
TIME_PERCENTILES = (5, 10, 25, 50, 75, 90, 95)
"""Percentiles of the leg time reported by :meth:`SimulationResult.summary` [%]."""


def chunk_rng(seed: int, chunk_index: int) -> np.random.Generator:
    """Random generator of chunk ``chunk_index`` for ``seed`` (PCG64)."""
    if chunk_index < 0:
        raise InputError(f"chunk index {chunk_index} must be >= 0")
    ss = np.random.SeedSequence(seed, spawn_key=(int(chunk_index),))
    return np.random.Generator(np.random.PCG64(ss))


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Simulated runs of a lattice policy.

    Attributes
    ----------
    leg_time_s : ndarray, shape (n_runs,)
        Time from the first row to the mark [s] (``inf`` if a run reached a
        state with no feasible segment).
    n_tacks : ndarray of int, shape (n_runs,)
        Tacks sailed (changes of tack, including one at the start if the first
        segment is on the other tack than ``tack0``).
    x_m : ndarray of float32, shape (n_runs, n_rows + 1)
        Lateral position on each row [m].
    t_s : ndarray of float32, shape (n_runs, n_rows + 1)
        Elapsed time on reaching each row [s].
    theta_deg : ndarray of float32, shape (n_runs, n_rows + 1)
        Shift bin on each row [°].
    y_m : ndarray, shape (n_rows + 1,)
        Row positions [m].
    seed : int
    """

    leg_time_s: NDArray[np.float64]
    n_tacks: NDArray[np.int64]
    x_m: NDArray[np.float32]
    t_s: NDArray[np.float32]
    theta_deg: NDArray[np.float32]
    y_m: NDArray[np.float64]
    seed: int

    @property
    def n_runs(self) -> int:
        """Number of runs."""
        return int(self.leg_time_s.size)

    def lateral_bands(
        self, percentiles: tuple[float, ...] = BAND_PERCENTILES
    ) -> NDArray[np.float64]:
        """Percentiles of the lateral position per row [m], shape (n_pct, n_rows + 1)."""
        return np.percentile(self.x_m.astype(float), percentiles, axis=0)

    def prob_within(self, deadline_s: float) -> tuple[float, float]:
        """``P(T <= deadline)`` and its binomial standard error."""
        p = float(np.mean(self.leg_time_s <= deadline_s))
        return p, math.sqrt(max(p * (1.0 - p), 0.0) / max(self.n_runs, 1))

    def summary(self, deadlines_s: tuple[float, ...] = ()) -> dict[str, object]:
        """Leg-time statistics as a JSON-ready dict (times in seconds)."""
        return time_summary(self.leg_time_s, self.n_tacks, deadlines_s)


def time_summary(
    times_s: NDArray[np.float64],
    n_tacks: NDArray[np.int64] | None = None,
    deadlines_s: tuple[float, ...] = (),
) -> dict[str, object]:
    """Mean, sd, standard error, percentiles, ``P(T <= s)`` and tack counts of runs.

    Runs that never finish (``inf``) count in ``n_failed`` and as "later than
    any deadline"; mean and sd are over finished runs.
    """
    t = np.asarray(times_s, dtype=float)
    n = t.size
    fin = t[np.isfinite(t)]
    out: dict[str, object] = {"n_runs": int(n), "n_failed": int(n - fin.size)}
    if fin.size:
        out["mean_s"] = float(np.mean(fin))
        sd = float(np.std(fin, ddof=1)) if fin.size > 1 else 0.0
        out["sd_s"] = sd
        out["se_mean_s"] = sd / math.sqrt(fin.size)
        # failures sort last; percentiles that fall on them are inf (without inf - inf warnings)
        top = float(np.max(fin))
        pct = np.percentile(np.where(np.isfinite(t), t, 2.0 * abs(top) + 1.0), TIME_PERCENTILES)
        pct = np.where(pct > top, np.inf, pct)
        out["percentiles_s"] = {
            str(p): float(v) for p, v in zip(TIME_PERCENTILES, pct, strict=True)
        }
    probs = {}
    for s in deadlines_s:
        p = float(np.mean(t <= s))
        probs[f"{s:g}"] = {"p": p, "se": math.sqrt(p * (1 - p) / max(n, 1))}
    if probs:
        out["p_within_deadline"] = probs
    if n_tacks is not None:
        vals, counts = np.unique(np.asarray(n_tacks), return_counts=True)
        out["tacks"] = {
            "mean": float(np.mean(n_tacks)),
            "distribution": {str(int(v)): float(c) / n for v, c in zip(vals, counts, strict=True)},
        }
    return out


def simulate_chunk(
    policy: ExpectedTimePolicy,
    chunk_index: int,
    seed: int,
    chunk_size: int = CHUNK_SIZE,
    x0_m: float = 0.0,
    tack0: int = 1,
    theta0_deg: float = 0.0,
    transitions: NDArray[np.float64] | None = None,
) -> SimulationResult:
    """Simulate one chunk of ``chunk_size`` runs (see the module docstring).

    Parameters
    ----------
    policy : ExpectedTimePolicy
    chunk_index : int
        Which chunk of the seed's stream (``>= 0``).
    seed : int
        Seed of the whole simulation.
    chunk_size : int
        Runs per chunk; keep the default for results comparable across calls.
    x0_m, tack0, theta0_deg : float, int, float
        Start state: lateral position [m], tack (+1/-1), shift [°] (nearest bin).
    transitions : ndarray, shape (n_d, n_θ, n_θ), optional
        Shift transition rows per (segment, bin) of the "true" wind; default the
        policy's own (see :func:`sailroute.strategy.sdp.segment_transitions`).
    """
    if chunk_size < 1:
        raise InputError(f"chunk size {chunk_size} must be >= 1")
    rng = chunk_rng(seed, chunk_index)
    g = policy.grid
    seg = policy.segments
    trans = policy.transitions if transitions is None else np.asarray(transitions)
    if trans.shape != policy.transitions.shape:
        raise InputError(
            f"transitions have shape {trans.shape}, expected {policy.transitions.shape} "
            "(one row per segment and shift bin of the policy's grid)"
        )
    cum = np.cumsum(trans, axis=-1)
    cum[..., -1] = 1.0
    n = int(chunk_size)
    ix0, ik0, it0 = policy.state_index(x0_m, tack0, theta0_deg)
    ix = np.full(n, ix0, dtype=np.intp)
    ik = np.full(n, ik0, dtype=np.intp)
    it = np.full(n, it0, dtype=np.intp)
    t = np.zeros(n)
    tacks = np.zeros(n, dtype=np.int64)
    alive = np.ones(n, dtype=bool)
    x_hist = np.empty((n, g.n_rows + 1), dtype=np.float32)
    t_hist = np.empty((n, g.n_rows + 1), dtype=np.float32)
    th_hist = np.empty((n, g.n_rows + 1), dtype=np.float32)
    xg, thg = g.x_m, g.theta_deg
    seg_tack_idx = np.where(seg.tack == 1, 0, 1)
    dmax = (seg.d.size - 1) // 2
    u_all = rng.random((g.n_rows, n))
    for r in range(g.n_rows):
        x_hist[:, r] = xg[ix]
        t_hist[:, r] = t
        th_hist[:, r] = thg[it]
        a = policy.action[r, ik, it, ix].astype(np.intp)
        dead = a < 0
        alive &= ~dead
        a = np.where(dead, dmax, a)
        dt = seg.time_s[a, it]
        new_k = seg_tack_idx[a, it]
        tacked = new_k != ik
        t = t + dt + policy.tack_penalty_s * tacked
        tacks += tacked
        ix = np.clip(ix + seg.d[a], 0, g.n_x - 1)
        ik = new_k
        c = cum[a, it]  # (n, n_θ)
        it = np.minimum((u_all[r][:, None] > c).sum(axis=1), thg.size - 1)
    x_hist[:, -1] = xg[ix]
    t_hist[:, -1] = t
    th_hist[:, -1] = thg[it]
    t = np.where(alive & np.isfinite(t), t, np.inf)
    return SimulationResult(t, tacks, x_hist, t_hist, th_hist, g.y_m, int(seed))


def simulate(
    policy: ExpectedTimePolicy,
    n_runs: int,
    seed: int,
    x0_m: float = 0.0,
    tack0: int = 1,
    theta0_deg: float = 0.0,
    transitions: NDArray[np.float64] | None = None,
    scheduler: str | TaskRunner | None = None,
) -> SimulationResult:
    """Simulate ``n_runs`` runs: chunks ``0, 1, ...`` of :data:`CHUNK_SIZE`, concatenated.

    See :func:`simulate_chunk` for the other parameters.

    Parameters
    ----------
    scheduler : str, TaskRunner or None
        Where the chunks run (:func:`sailroute.parallel.map_tasks`): ``None``
        or ``"serial"`` (default), ``"processes"``, a Dask scheduler address,
        or an open runner.  The result is the same, bit for bit.
    """
    if n_runs < 1:
        raise InputError(f"number of Monte Carlo runs {n_runs} must be >= 1")
    if tack0 not in TACKS:
        raise InputError(f"start tack must be +1 (starboard) or -1 (port), got {tack0}")
    n_chunks = -(-int(n_runs) // CHUNK_SIZE)
    parts = map_tasks(
        _chunk_task,
        range(n_chunks),
        shared=(policy, seed, x0_m, tack0, theta0_deg, transitions),
        scheduler=scheduler,
    )
    return concatenate(parts, n_runs)


def _chunk_task(
    chunk_index: int,
    policy: ExpectedTimePolicy,
    seed: int,
    x0_m: float,
    tack0: int,
    theta0_deg: float,
    transitions: NDArray[np.float64] | None,
) -> SimulationResult:
    """One chunk of :func:`simulate` (a top-level function, so Dask can pickle it)."""
    return simulate_chunk(
        policy, chunk_index, seed, CHUNK_SIZE, x0_m, tack0, theta0_deg, transitions
    )


def concatenate(parts: list[SimulationResult], n_runs: int | None = None) -> SimulationResult:
    """Join chunk results in order, keeping the first ``n_runs`` runs."""
    if not parts:
        raise InputError("no simulation chunks to concatenate")
    sl = slice(0, n_runs)
    return SimulationResult(
        leg_time_s=np.concatenate([p.leg_time_s for p in parts])[sl],
        n_tacks=np.concatenate([p.n_tacks for p in parts])[sl],
        x_m=np.concatenate([p.x_m for p in parts])[sl],
        t_s=np.concatenate([p.t_s for p in parts])[sl],
        theta_deg=np.concatenate([p.theta_deg for p in parts])[sl],
        y_m=parts[0].y_m,
        seed=parts[0].seed,
    )
