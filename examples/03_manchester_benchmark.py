# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # The Manchester Contact Benchmark, case
#
# An S1002 wheelset on UIC60 rails inclined 1:40 is shifted laterally in steps of 0.5 mm (and yawed by
# 1.2 mrad per step) under a 10 kN wheel load (Shackleton & Iwnicki, VSD 46 (2008) 129-149). With CONTACT's
# kinematics per step (its roll and pitch rate, "deck"), the case solver finds the patches of both wheels and
# their loads; the right wheel's patches are compared with CONTACT's published solution (Vollebregt).

# +
import os
from pathlib import Path

import pandas as pd

from comparisons.manchester import TOLERANCES, sweep

QUICK = os.environ.get("WHEELRAIL_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "manchester"
OUT.mkdir(parents=True, exist_ok=True)
steps = (0, 4, 8) if QUICK else tuple(range(21))
method = "fastsim" if QUICK else "bem"  # bem runs on CONTACT's 0.2 mm grid (minutes for all 21 steps)
table = pd.DataFrame(sweep(method, steps=steps, kinematics="deck"))
table.to_csv(OUT / "a22.csv", index=False)
# -

# One row per patch. On the right wheel each patch is matched with CONTACT's (same number of patches): the
# normal force and the contact position on the rail are geometry and load sharing, which every rung shares,
# so they must agree within the benchmark tolerances whatever the tangential model.

# +
right = table[(table["side"] == "right") & table["contact_normal_force_N"].notna()]
columns = ["step", "patch", "normal_force_N", "contact_normal_force_N", "contact_y_rail_m", "contact_contact_y_rail_m"]
print(right[columns].to_string(index=False))
print("patches per step:", table.groupby("step").size().to_dict())
assert len(right) >= len(steps)
assert (right["diff_normal_force"].abs() < TOLERANCES["normal_force"]).all()
assert (right["diff_contact_y_rail"].abs() < TOLERANCES["contact_y_rail"]).all()
# -
