# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # A dynamics run with a wheel flat
#
# The embedded scene `wheel-flat`: S1002 wheels on UIC60 rails, both wheels with a 50 mm rounded flat
# (depth L²/(16 r0) = 0.34 mm) that reaches the rail after about 0.2 m, 60 km/h, Hertz + FASTSIM, RK4, on a
# discretely supported track (a Timoshenko rail on pads, sleepers and ballast every 0.6 m; `[track_dynamics]
# model = "lumped"` for one rail mass on a pad per wheel, `"rigid"` for a rigid track).
# As the flat passes, the wheel drops into it: the normal force first falls (the wheel unloads, it may
# lift off) and then rises to an impact peak well above the static load.

# +
import dataclasses
import os
from pathlib import Path

import wheelrail as wr

QUICK = os.environ.get("WHEELRAIL_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "wheel_flat_run"
OUT.mkdir(parents=True, exist_ok=True)

scene = wr.load_scene("wheel-flat")
if QUICK:  # the flat's first passage only, on the lumped track (the beam's stiffest rail modes need steps of 0.03 ms
    # or less), at 0.025 ms: the impact peak 3.256 x the static load, its step-halving check 0.0003 (3.2546 / 3.2550 /
    # 3.2564 / 3.2560 at 0.1 / 0.05 / 0.025 / 0.0125 ms; the compiled search scans a flat's wheel in every stage)
    step = dataclasses.replace(scene.integrator, fixed_step_s=2.5e-5, output_step_s=2e-4)
    track = dataclasses.replace(scene.track_dynamics, model="lumped")
    scene = dataclasses.replace(scene, duration_s=0.014, integrator=step, track_dynamics=track)
run = wr.simulate(scene)
print(run)
assert run.success, run.message
# -

# The tidy table: one row per output time, one column per named quantity (units in the names).

# +
table = run.to_dataframe()
table.to_csv(OUT / "timeseries.csv", index=False)
static = scene.static_wheel_load_N
load = table["right_tread_normal_force_N"].fillna(0.0)
print(table[["time_s", "right_tread_normal_force_N", "right_tread_approach_m"]].describe().T[["min", "max"]])
print(f"static wheel load {static / 1e3:.1f} kN; right wheel from {load.min() / 1e3:.1f} to {load.max() / 1e3:.1f} kN")
assert load.max() > 1.3 * static  # the impact
assert load.min() < 0.7 * static  # the unloading as the wheel drops into the flat
print("events:", run.events)
wr.plot_dynamics(run, OUT / "wheel_flat.png", title="wheel flat, 60 km/h")
# -
