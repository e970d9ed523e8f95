"""A strategy map: where to tack on a beat when the wind oscillates.

Solves the expected-time tack strategy (stochastic dynamic programming, see
``docs/strategy.md``) for an ILCA 7 on a 1 km beat in 10 kn with oscillating
shifts (standard deviation 10°, time scale 5 min), checks it by Monte Carlo, and
draws the policy map: for the boat on starboard tack, at each point of the
course and for a 10° back, no shift and a 10° veer, whether to keep going or to
tack now.

Run: ``python docs/gallery/strategy_map.py [OUT_DIR]``; ``policy_map.png`` goes to
``OUT_DIR/strategy_map/``.
"""

import os
import sys
from pathlib import Path

import sailroute
from sailroute.report.strategy import plot_policy_map, policy_classes, save_figure

KNOT = 1852.0 / 3600.0  # m/s
OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "strategy_map"
)

settings = sailroute.StrategySettings(
    tws_ms=10 * KNOT, length_m=1000.0, half_width_m=500.0, lateral_m=4.0, runs=2000, seed=1
)
shifts = sailroute.OUShift(sigma_deg=10.0, timescale_s=300.0)
result = sailroute.run_strategy(sailroute.builtin_polar("ilca7"), shifts, settings)

policy, sim = result.policy, result.sim.summary()
steady = result.summary["expected_time_policy"]["steady_wind_one_tack_s"]
expected = policy.expected_time(0.0, settings.start_tack, 0.0)
print(
    f"{result.polar.name} at 10 kn, {settings.length_m:.0f} m beat, shifts "
    f"sd {shifts.sigma_deg:g}° over {shifts.timescale_s / 60:g} min"
)
print(f"expected_time_s = {expected:.2f}")
print(f"monte_carlo_mean_s = {sim['mean_s']:.2f}")
print(f"monte_carlo_se_s = {sim['se_mean_s']:.2f}")
print(f"mean_tacks = {sim['tacks']['mean']:.2f}")
print(f"steady_wind_one_tack_s = {steady:.2f}")
print(f"gain_from_playing_shifts_s = {steady - expected:.1f}")

# share of the course where the policy says "tack now" on starboard, per shift
for theta in (-10.0, 0.0, 10.0):
    cls = policy_classes(policy, theta, +1)  # 0 keep going, 1 tack, 2 infeasible
    feasible = cls != 2
    print(f"tack_share[{theta:+g}] = {float((cls == 1)[feasible].mean()):.3f}")

OUT.mkdir(parents=True, exist_ok=True)
path = save_figure(plot_policy_map(policy, (-10.0, 0.0, 10.0), tack=+1), OUT / "policy_map.png")
print(f"wrote policy_map: {path}")
