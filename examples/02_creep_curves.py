# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Creep curves of every rung
#
# Longitudinal creep force against creepage for one Hertzian patch, by each rung of the ladder:
# Kalker's linear theory (the slope at zero), Vermeulen-Johnson (saturating cube), FASTSIM (Kalker's
# simplified theory) and the boundary-element solver `bem` (Kalker's exact theory on a grid).
# All saturate at mu N except the linear theory; at small creepage all share Kalker's slope G a b C11.

# +
import os
from pathlib import Path

import numpy as np

import wheelrail as wr

QUICK = os.environ.get("WHEELRAIL_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "creep"
OUT.mkdir(parents=True, exist_ok=True)

material = wr.STEEL
force_N = 1e5
curv_long, curv_lat = 0.5 / 0.46, 0.5 / 0.3  # A = 1/(2 R): wheel radius 0.46 m, rail crown 0.3 m
creepages = np.linspace(0.0, 4e-3, 9 if QUICK else 41)
# -

# The analytic rungs run as one vectorised batch (scalar curvatures broadcast against the creepages).

curves = {}
for method in ("linear", "vermeulen-johnson", "fastsim"):
    batch = wr.solve_batch(method, curv_long, curv_lat, creepages, 0.0, 0.0, material, normal_force_N=force_N)
    curves[method] = -batch.creep_force_long_N  # force on the wheel opposes its creepage
    print(method, np.round(curves[method][:4] / 1e3, 2), "kN ...")

# The boundary-element rung solves each creepage on a grid (small here; `nx = ny = 64` or more for accuracy).

# +
bem_points = creepages[:: 4 if QUICK else 2]
grid = {"nx": 16, "ny": 16} if QUICK else {"nx": 48, "ny": 48}
geometry = wr.ContactGeometry(curvature_long_1_per_m=curv_long, curvature_lat_1_per_m=curv_lat)
bem = []
for xi in bem_points:
    r = wr.get_model("bem").solve(geometry, wr.Creepage(xi, 0.0, 0.0), material, normal_force_N=force_N, options=grid)
    assert r.success, r.message
    bem.append(-r.creep_force_long_N)
bem = np.array(bem)
print("bem", np.round(bem / 1e3, 2), "kN")
# -

# Checks: every saturating law stays below mu N; FASTSIM and BEM agree to a few per cent in the
# saturated range (FASTSIM's known error against the exact theory); all start with the linear slope.

# +
mu_n = material.friction_coefficient * force_N
for name in ("vermeulen-johnson", "fastsim"):
    assert np.all(curves[name] <= mu_n * (1 + 1e-9))
assert np.all(bem <= mu_n * 1.01)
fastsim_at_bem = np.interp(bem_points, creepages, curves["fastsim"])
print("fastsim / bem at the largest creepage:", fastsim_at_bem[-1] / bem[-1])
assert abs(fastsim_at_bem[-1] / bem[-1] - 1) < 0.1

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(6, 4))
for name, values in curves.items():
    ax.plot(creepages * 1e3, values / 1e3, label=name)
ax.plot(bem_points * 1e3, bem / 1e3, "ko", label=f"bem {grid['nx']}x{grid['ny']}")
ax.axhline(mu_n / 1e3, color="grey", ls=":", label="mu N")
ax.set_ylim(0, 1.3 * mu_n / 1e3)
ax.set_xlabel("longitudinal creepage [1e-3]")
ax.set_ylabel("creep force on the wheel, -Fx [kN]")
ax.legend()
fig.savefig(OUT / "creep_curves.png", dpi=110, bbox_inches="tight")
# -
