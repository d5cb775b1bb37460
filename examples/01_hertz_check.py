# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Hertz check: the `hertz` model against Hertz's closed forms
#
# A ball of radius R on a flat (or two crossed cylinders) is the circular Hertz problem:
# a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), approach q = a^2 / R (Johnson 1985, eq 4.22-4.23).
# `wheelrail`'s `hertz` model solves the general elliptic problem; for equal relative curvatures it must
# give these numbers. Then the elliptic case: a / b grows with the curvature ratio, and the pressure
# integrates to the load.

# +
import math
import os
from pathlib import Path

import numpy as np

import wheelrail as wr

OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "hertz"
OUT.mkdir(parents=True, exist_ok=True)
# -

# Equal relative radii of curvature R = 0.3 m both ways; steel; 10 kN.

# +
radius_m, force_N = 0.3, 1e4
material = wr.Material.from_young(210e9, 0.3, 0.3)
geometry = wr.ContactGeometry.quadric(radius_m, radius_m)
result = wr.get_model("hertz").solve(geometry, wr.Creepage(), material, normal_force_N=force_N)
print(result)

e_star = material.combined_modulus_Pa
a_exact = (3 * force_N * radius_m / (4 * e_star)) ** (1 / 3)
p0_exact = 3 * force_N / (2 * math.pi * a_exact**2)
q_exact = a_exact**2 / radius_m
for name, value, exact in (
    ("semi-axis a [m]", result.semi_axis_long_m, a_exact),
    ("peak pressure p0 [Pa]", result.max_pressure_Pa, p0_exact),
    ("approach q [m]", result.approach_m, q_exact),
):
    print(f"{name:24s} model {value:.10g}  exact {exact:.10g}  rel. error {value / exact - 1:+.1e}")
    assert abs(value / exact - 1) < 1e-9
# -

# ## Elliptic patches: a/b against the curvature ratio, and the pressure integral
#
# The patch files written for an analytic model hold Hertz's pressure p0 sqrt(1 - x²/a² - y²/b²) of the
# model's semi-axes; integrated over the grid it returns the load (to the grid's resolution).

# +
rows = []
for ratio in (1.0, 2.0, 5.0, 20.0):
    patch = wr.ContactGeometry.quadric(0.46, 0.46 / ratio)
    r = wr.get_model("hertz").solve(patch, wr.Creepage(), material, normal_force_N=force_N)
    files = wr.write_patch_files(OUT, f"ratio-{ratio:g}", patch, r)
    data = np.load(OUT / files["npz"])
    total = np.trapezoid(np.trapezoid(data["pressure_Pa"], data["x_m"], axis=1), data["y_m"])
    rows.append((ratio, r.semi_axis_long_m / r.semi_axis_lat_m, r.max_pressure_Pa, total / force_N))
    print(
        f"R_long/R_lat = {ratio:5.1f}: a/b = {rows[-1][1]:.4f}, p0 = {r.max_pressure_Pa / 1e6:7.1f} MPa, "
        f"integral of p / P = {rows[-1][3]:.4f}"
    )
    assert abs(total / force_N - 1) < 0.01
assert all(b[1] > a[1] for a, b in zip(rows, rows[1:], strict=False))  # a/b grows as R_lat falls
wr.plot_patch(r, OUT / "hertz-ellipse.png")
# -
