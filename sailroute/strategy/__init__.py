"""Tack strategy on an upwind leg under wind shifts (Shepherd et al.; Wang et al. 2024).

* :mod:`~sailroute.strategy.shiftmodel` -- OU and drift-diffusion shift models and
  their Markov chains;
* :mod:`~sailroute.strategy.fit` -- fitting them to measured directions;
* :mod:`~sailroute.strategy.sdp` -- the expected-time stochastic DP (policy table);
* :mod:`~sailroute.strategy.montecarlo` -- seeded, chunked Monte Carlo of a policy;
* :mod:`~sailroute.strategy.deadline` -- the risk-aware (deadline) and risk-neutral
  target-relative solvers and their Monte Carlo;
* :mod:`~sailroute.report.strategy` -- figures and JSON;
* :mod:`~sailroute.strategy.study` -- a whole study (used by ``sailroute strategy``).

See ``docs/strategy.md`` and ``docs/design/strategy.md``.
"""

from sailroute.strategy.deadline import (
    DeadlineGrid,
    DeadlinePolicy,
    RiskNeutralPolicy,
    simulate_deadline,
    solve_deadline,
    solve_risk_neutral,
)
from sailroute.strategy.fit import fit_drift_diffusion, fit_ou, fit_station_file
from sailroute.strategy.montecarlo import SimulationResult, simulate, simulate_chunk
from sailroute.strategy.sdp import BeatGrid, ExpectedTimePolicy, solve_expected_time
from sailroute.strategy.shiftmodel import (
    DriftDiffusionShift,
    OUShift,
    chain_diagnostics,
    transition_matrix,
)

__all__ = [
    "BeatGrid",
    "DeadlineGrid",
    "DeadlinePolicy",
    "DriftDiffusionShift",
    "ExpectedTimePolicy",
    "OUShift",
    "RiskNeutralPolicy",
    "SimulationResult",
    "chain_diagnostics",
    "fit_drift_diffusion",
    "fit_ou",
    "fit_station_file",
    "simulate",
    "simulate_chunk",
    "simulate_deadline",
    "solve_deadline",
    "solve_expected_time",
    "solve_risk_neutral",
    "transition_matrix",
]
