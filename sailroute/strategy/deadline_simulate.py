"""Monte Carlo of the deadline policies: Euler–Maruyama in Cartesian coordinates, with the
deadline upgrade and the fallback to the risk-neutral policy (Wang et al. 2024); one random
stream per chunk of runs, as in :mod:`sailroute.strategy.montecarlo`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError
from sailroute.parallel import TaskRunner, map_tasks
from sailroute.strategy.deadline_grid import SURE, _model_rates, _nearest_nodes
from sailroute.strategy.deadline_policy import DeadlinePolicy, RiskNeutralPolicy
from sailroute.strategy.montecarlo import CHUNK_SIZE, chunk_rng


@dataclass(frozen=True, eq=False)
class DeadlineSimulation:
    """Monte Carlo runs of a target-relative policy.

    Attributes
    ----------
    leg_time_s : ndarray, shape (n_runs,)
        Arrival time [s]; ``inf`` for runs that left ``r_max`` or passed ``t_max``.
    n_switches : ndarray of int, shape (n_runs,)
        Tack switches.
    fell_back : ndarray of bool, shape (n_runs,)
        Runs that switched to the risk-neutral policy (deadline out of reach).
    deadline_s : float or None
        Budget the risk-aware policy started with (after the upgrade); ``None``
        for the risk-neutral policy.
    tracks_xy_m : ndarray of float32, shape (n_tracks, n_steps, 2)
        Positions of the first runs (NaN after arrival) [m], mark at the origin,
        the initial wind from ``+y``.
    seed : int
    """

    leg_time_s: NDArray[np.float64]
    n_switches: NDArray[np.int64]
    fell_back: NDArray[np.bool_]
    deadline_s: float | None
    tracks_xy_m: NDArray[np.float32]
    seed: int


def start_budget(
    policy: DeadlinePolicy, r_m: float, theta_rad: float, tack: int, deadline_s: float
) -> float:
    """Budget after the deadline upgrade: the least ``s_k <= ŝ`` with ``w = 1`` if any."""
    g = policy.grid
    k_hat = int(min(round(deadline_s / g.ds_s), g.n_s))
    if k_hat < 0:
        raise InputError(f"deadline {deadline_s} s must be >= 0")
    curve = policy.success_curve(r_m, theta_rad, tack)[: k_hat + 1]
    sure = np.flatnonzero(curve >= SURE)
    return float(sure[0] * g.ds_s) if sure.size else float(k_hat * g.ds_s)


def simulate_deadline_chunk(
    rn: RiskNeutralPolicy,
    chunk_index: int,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None = None,
    deadline_s: float | None = None,
    dt_s: float | None = None,
    t_max_s: float | None = None,
    n_tracks: int = 0,
    chunk_size: int = CHUNK_SIZE,
    give_up_below: float = 0.0,
) -> DeadlineSimulation:
    """Simulate one chunk of runs (see :func:`simulate_deadline`)."""
    g = rn.grid
    a, sigma = _model_rates(rn.model)
    c = rn.tack_penalty_s
    dt = g.ds_s / 5.0 if dt_s is None else float(dt_s)
    if not dt > 0:
        raise InputError(f"time step {dt_s} s must be > 0")
    r0, th0, tack0 = start
    if tack0 not in (1, -1):
        raise InputError(f"start tack must be +1 or -1, got {tack0}")
    t_max = (g.ds_s * g.n_s * 3.0) if t_max_s is None else float(t_max_s)
    rng = chunk_rng(seed, chunk_index)
    n = int(chunk_size)
    u = rn.grid.controls_rad
    f = rn.speeds_ms
    # wind from +y at the start (φ = 0); β = φ - θ is the bearing of the mark from the boat
    beta0 = -th0
    x = np.full(n, r0 * math.sin(beta0))
    y = np.full(n, -r0 * math.cos(beta0))
    phi = np.zeros(n)
    q = np.full(n, 0 if tack0 == 1 else 1, dtype=np.int64)
    t = np.zeros(n)
    switches = np.zeros(n, dtype=np.int64)
    done = np.zeros(n, dtype=bool)
    result = np.full(n, np.inf)
    s_hat: float | None = None
    if ra is not None and deadline_s is not None:
        s_hat = start_budget(ra, r0, th0, tack0, deadline_s)
    use_ra = s_hat is not None
    s_budget = np.full(n, s_hat if s_hat is not None else 0.0)
    risk_aware = np.full(n, use_ra)
    fell_back = np.zeros(n, dtype=bool)
    last_switch = np.zeros(n, dtype=bool)
    tracks: list[NDArray] = []
    n_tr = min(n_tracks, n)
    while not np.all(done):
        r = np.hypot(x, y)
        theta = np.mod(phi - np.arctan2(x, -y), 2 * math.pi)
        node = _nearest_nodes(g, r, theta, q)
        act_steer = rn.steer[node].astype(np.int64)
        act_u, act_f = u[act_steer], f[act_steer]
        act_switch = rn.switch[node].copy()
        if use_ra:
            assert ra is not None
            k = np.rint(s_budget / g.ds_s).astype(np.int64)
            ok = risk_aware & (k >= 0) & (k <= g.n_s)
            kk = np.clip(k, 0, g.n_s)
            ra_w, ra_u, ra_f, ra_sw = ra.decide(kk, node)
            hopeless = ok & (ra_w <= give_up_below)
            newly = risk_aware & (~ok | hopeless) & ~done
            fell_back |= newly
            risk_aware &= ~newly
            act_u = np.where(risk_aware, ra_u, act_u)
            act_f = np.where(risk_aware, ra_f, act_f)
            act_switch = np.where(risk_aware, ra_sw, act_switch)
        # never two switches in a row (a coarse grid can make the lookups ping-pong)
        act_switch &= ~last_switch & ~done
        z = rng.standard_normal(n)
        # switch: stand still for C while the wind moves
        phi_sw = phi + a * c + sigma * math.sqrt(c) * z
        # steer: Euler–Maruyama step
        heading = phi + np.where(q == 0, 1.0, -1.0) * act_u
        sp_ = act_f
        xn = x - sp_ * np.sin(heading) * dt
        yn = y + sp_ * np.cos(heading) * dt
        phin = phi + a * dt + sigma * math.sqrt(dt) * z
        steering = ~act_switch & ~done
        rn_new = np.hypot(xn, yn)
        arrive = steering & (rn_new <= g.target_radius_m)
        frac = np.clip((r - g.target_radius_m) / np.maximum(r - rn_new, 1e-300), 0.0, 1.0)
        result = np.where(arrive, t + frac * dt, result)
        x = np.where(steering, xn, x)
        y = np.where(steering, yn, y)
        phi = np.where(steering, phin, np.where(act_switch, phi_sw, phi))
        q = np.where(act_switch, 1 - q, q)
        switches += act_switch
        step = np.where(act_switch, c, np.where(steering, dt, 0.0))
        t = t + step
        s_budget = s_budget - step
        last_switch = act_switch
        lost = ~done & ~arrive & (((rn_new > g.r_max_m) & steering) | (t > t_max))
        done |= arrive | lost
        if n_tr:
            tracks.append(
                np.stack(
                    [
                        np.where(done[:n_tr] & ~arrive[:n_tr], np.nan, x[:n_tr]),
                        np.where(done[:n_tr] & ~arrive[:n_tr], np.nan, y[:n_tr]),
                    ],
                    axis=-1,
                ).astype(np.float32)
            )
    tr = np.stack(tracks, axis=1) if tracks else np.zeros((0, 0, 2), dtype=np.float32)
    return DeadlineSimulation(
        leg_time_s=result,
        n_switches=switches,
        fell_back=fell_back,
        deadline_s=s_hat,
        tracks_xy_m=tr,
        seed=int(seed),
    )


def simulate_deadline(
    rn: RiskNeutralPolicy,
    n_runs: int,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None = None,
    deadline_s: float | None = None,
    dt_s: float | None = None,
    t_max_s: float | None = None,
    n_tracks: int = 0,
    give_up_below: float = 0.0,
    scheduler: str | TaskRunner | None = None,
) -> DeadlineSimulation:
    """Seeded Monte Carlo of the risk-aware policy ``α^ŝ`` (with ``ra`` and ``deadline_s``)
    or of the risk-neutral policy ``μ*`` (without).

    Parameters
    ----------
    rn : RiskNeutralPolicy
        ``μ*``: the policy itself, or the fallback once the deadline is out of
        reach (``w = 0`` at the nearest node, or the budget is spent).
    n_runs : int
    seed : int
        Chunk ``k`` uses the same stream as in :mod:`sailroute.strategy.montecarlo`.
    start : (float, float, int)
        ``(r [m], θ [rad], tack)``: distance to the mark, upwind direction
        counter-clockwise from the boat→mark line, +1 starboard / -1 port.
    ra : DeadlinePolicy, optional
    deadline_s : float, optional
        ``ŝ`` [s]; upgraded to the least budget with ``w = 1`` when the deadline
        is sure to be met.
    dt_s : float, optional
        Euler–Maruyama step [s]; default ``Δs / 5``.
    t_max_s : float, optional
        Runs still sailing then count as failures; default ``3 s_max``.
    n_tracks : int
        Keep the tracks of this many runs (from the first chunk only).
    give_up_below : float
        Fall back to ``μ*`` once ``w`` at the nearest node is at or below this.
    scheduler : str, TaskRunner or None
        Where the chunks of :data:`~sailroute.strategy.montecarlo.CHUNK_SIZE`
        runs go (:func:`sailroute.parallel.map_tasks`); the result does not
        depend on it.
    """
    if n_runs < 1:
        raise InputError(f"number of Monte Carlo runs {n_runs} must be >= 1")
    if (ra is None) != (deadline_s is None):
        raise InputError("give both a deadline policy and a deadline, or neither")
    n_chunks = -(-int(n_runs) // CHUNK_SIZE)
    parts = map_tasks(
        _deadline_chunk_task,
        range(n_chunks),
        shared=(rn, seed, start, ra, deadline_s, dt_s, t_max_s, n_tracks, give_up_below),
        scheduler=scheduler,
    )
    sl = slice(0, n_runs)
    return DeadlineSimulation(
        leg_time_s=np.concatenate([p.leg_time_s for p in parts])[sl],
        n_switches=np.concatenate([p.n_switches for p in parts])[sl],
        fell_back=np.concatenate([p.fell_back for p in parts])[sl],
        deadline_s=parts[0].deadline_s,
        tracks_xy_m=parts[0].tracks_xy_m,
        seed=int(seed),
    )


def _deadline_chunk_task(
    chunk_index: int,
    rn: RiskNeutralPolicy,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None,
    deadline_s: float | None,
    dt_s: float | None,
    t_max_s: float | None,
    n_tracks: int,
    give_up_below: float,
) -> DeadlineSimulation:
    """One chunk of :func:`simulate_deadline` (top level, so Dask can pickle it)."""
    return simulate_deadline_chunk(
        rn,
        chunk_index,
        seed,
        start,
        ra,
        deadline_s,
        dt_s,
        t_max_s,
        n_tracks if chunk_index == 0 else 0,
        CHUNK_SIZE,
        give_up_below,
    )
