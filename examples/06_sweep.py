# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # A sweep on dask.distributed
#
# `wheelrail sweep STUDY.toml` runs every point of a parameter grid as a task on a dask cluster (a
# LocalCluster by default, any scheduler with `--scheduler ADDRESS`) and writes one tidy table. The same
# from Python: friction coefficient x contact model on the embedded contact case `hertz-quadric`.

# +
import os
from pathlib import Path

import pandas as pd
from distributed import Client, LocalCluster

from wheelrail.sweep import load_sweep, run_sweep

OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "sweep"
OUT.mkdir(parents=True, exist_ok=True)
study = OUT / "friction.toml"
study.write_text(
    """
description = "creep force against friction, three rungs"
case = "hertz-quadric"
metrics = ["patch0_creep_force_long_N"]
[grid]
method = ["linear", "vermeulen-johnson", "fastsim"]
"material.friction_coefficient" = [0.1, 0.2, 0.4]
"""
)
# `wheelrail sweep` starts a LocalCluster of worker processes; in a script or notebook, threads are simplest
cluster = LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None)
client = Client(cluster)
summary = run_sweep(load_sweep(study), OUT / "run", client=client)
print(summary)
# -

# The table loads in pandas as it is; a rerun into the same folder skips the finished points.

# +
table = pd.read_csv(OUT / "run" / "sweep.csv")
print(table.pivot(index="material.friction_coefficient", columns="method", values="patch0_creep_force_long_N"))
# the linear theory has no friction bound: where its |F_t| exceeds mu N the point says so, as `contact` does
assert summary["statuses"] == {"ok": 7, "beyond-friction-limit": 2}
assert set(table[table["status"] == "beyond-friction-limit"]["method"]) == {"linear"}
linear = table[table["method"] == "linear"]["patch0_creep_force_long_N"]
assert linear.nunique() == 1  # the linear theory does not see friction
again = run_sweep(load_sweep(study), OUT / "run", client=client)
assert again["ran"] == 0 and again["skipped"] == 9
client.close()
cluster.close()
# -
