"""A polar from the Laser VPP: a lighter sailor's ILCA 7 against the built-in one.

Runs the velocity prediction program (``docs/vpp.md``) for a 70 kg sailor on a
small grid, prints the best upwind and downwind VMG per wind speed next to the
built-in steady ILCA 7 polar (80 kg), and writes the new polar as a ``.pol`` file
(knots) that a course file can use (``boat: {polar: ilca7-70kg.pol}``).

Run: ``python docs/gallery/vpp_polar.py [OUT_DIR]``; the file goes to
``OUT_DIR/vpp_polar/``.
"""

import os
import sys
from pathlib import Path

import numpy as np

import sailroute

KNOT = 1852.0 / 3600.0  # m/s
OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "vpp_polar"
)

tws_kn = np.array([6.0, 10.0, 14.0])
light = sailroute.vpp(
    "ilca7", crew_mass_kg=70, tws_ms=tws_kn * KNOT, twa_deg=np.arange(30.0, 181.0, 5.0)
)
builtin = sailroute.builtin_polar("ilca7-steady")  # 80 kg sailor, steady VPP

up_a, up_v = light.vmg_upwind(light.tws_ms)
dn_a, dn_v = light.vmg_downwind(light.tws_ms)
ref_up = builtin.vmg_upwind(light.tws_ms)[1]
ref_dn = builtin.vmg_downwind(light.tws_ms)[1]
print(f"{light.name}, 70 kg sailor, against {builtin.name} (80 kg)")
print(
    f"{'TWS kn':>6} {'beat TWA':>8} {'VMG kn':>7} {'80 kg':>6} {'run TWA':>8} {'VMG kn':>7} "
    f"{'80 kg':>6}"
)
for k, tws in enumerate(tws_kn):
    print(
        f"{tws:6.1f} {up_a[k]:8.1f} {up_v[k] / KNOT:7.3f} {ref_up[k] / KNOT:6.3f} "
        f"{dn_a[k]:8.1f} {dn_v[k] / KNOT:7.3f} {ref_dn[k] / KNOT:6.3f}"
    )

for k, tws in enumerate(tws_kn):
    print(f"vmg_upwind_ms[{tws:g}] = {up_v[k]:.6f}")
    print(f"vmg_upwind_twa_deg[{tws:g}] = {up_a[k]:.3f}")

OUT.mkdir(parents=True, exist_ok=True)
path = sailroute.write_pol(light, OUT / "ilca7-70kg.pol", unit="kn")
print(f"wrote pol: {path}")
